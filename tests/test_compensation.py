"""Cutter radius compensation (G41/G42) against tool paths worked out by hand.

A 2 mm end mill (radius 1) runs round the corners of a 10 mm square; the
expected points follow from offsetting each edge by 1 mm and, as LinuxCNC
does, rolling round outside corners on an arc about the programmed corner
and cutting inside corners short where the offset edges meet.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gcodekit


@pytest.fixture
def tool_table(tmp_path):
    path = tmp_path / "tools.tbl"
    path.write_text("T1 P1 D2.0 ;2 mm end mill\n")
    return path


def motions(text: str, tool_table):
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, tool_table=tool_table, tool_table_units="mm")
    return op.motions()


def test_g42_outside_a_square_rolls_round_corners(tool_table):
    m = motions("G21 G17 G90 T1 M6\nG0 X-5 Y0\nG42 G1 X0 Y0 F600\nX10\nY10\nX0\nG40 G0 X-5 Y20\n", tool_table)
    expected = [
        ("rapid", -5, 0), ("feed", 0, -1),            # entry: end shifted right of the +X move
        ("feed", 10, -1), ("arc_ccw", 11, 0),         # outside corner about (10, 0)
        ("feed", 11, 10), ("arc_ccw", 10, 11),        # ... and about (10, 10)
        ("feed", 0, 11), ("rapid", -5, 20),           # exit runs to the programmed point
    ]
    assert m["motion"].tolist() == [e[0] for e in expected]
    np.testing.assert_allclose(m[["x", "y"]].to_numpy(), [e[1:] for e in expected], atol=1e-12)
    arcs = m[m["motion"] == "arc_ccw"]
    np.testing.assert_allclose(arcs[["cx", "cy"]].to_numpy(), [[10, 0], [10, 10]], atol=1e-12)


def test_g41_inside_corner_is_cut_short(tool_table):
    m = motions("G21 G17 G90 T1 M6\nG0 X0 Y-5\nG41 G1 X0 Y0 F600\nX10\nY10\n", tool_table)
    expected = [
        ("rapid", 0, -5), ("feed", -1, 0),            # entry: end shifted left of the +Y move
        ("arc_cw", 0, 1),                             # right turn with the tool on the left: outside
        ("feed", 9, 1),                               # inside corner: offset edges meet at (9, 1)
        ("feed", 9, 10),
    ]
    assert m["motion"].tolist() == [e[0] for e in expected]
    np.testing.assert_allclose(m[["x", "y"]].to_numpy(), [e[1:] for e in expected], atol=1e-12)


def test_compensated_moves_have_their_new_lengths(tool_table):
    op = gcodekit.gcode_to_operation("G21 G17 G90 T1 M6\nG0 X-5 Y0\nG42 G1 X0 Y0 F600\nX10\nY10\n",
                                     "linuxcnc", plan=False, tool_table=tool_table, tool_table_units="mm")
    df = op.to_dataframe()
    moves = df[df["distance"] > 0]
    entry = math.hypot(5, 1)
    np.testing.assert_allclose(moves["distance"].to_numpy(), [5, entry, 10, math.pi / 2, 10], atol=1e-9)


def test_arc_radius_grows_on_the_outside(tool_table):
    # G42 on a CCW circle puts the tool outside: radius 5 becomes 6
    m = motions("G21 G17 G90 T1 M6\nG0 X5 Y-5\nG42 G1 X5 Y0 F600\nG3 X-5 Y0 I-5 J0\n", tool_table)
    last = m.iloc[-1]
    assert last["motion"] == "arc_ccw"
    assert (last["x"], last["y"]) == pytest.approx((-6, 0))
    assert (last["cx"], last["cy"]) == pytest.approx((0, 0))


# Gouge checks: programs and messages checked with LinuxCNC 2.9's rs274
# (tool 4 of tooltables/simpockets.tbl, 3/8" diameter), which refuses both on line 6.
GOUGE_CASES = {
    "step_shorter_than_radius": ("G20 G17 G90 T4 M6\nG0 X-1 Y0 Z0\nG41 G1 X0 Y0 F10\nX2\nY0.1\nX4\nY-1\nM2\n",
                                 "Straight feed in concave corner cannot be reached by the tool without gouging"),
    "arc_smaller_than_tool": ("G20 G17 G90 T4 M6\nG0 X-1 Y0 Z0\nG41 G1 X0 Y0 F10\nX2\nG3 X2.2 Y0.2 I0 J0.2\n"
                              "G1 X0.5\nY-1\nM2\n",
                              "Arc to straight motion makes a corner the compensated tool can't fit in without gouging"),
}


@pytest.mark.parametrize("name", sorted(GOUGE_CASES))
def test_gouging_is_refused_on_rs274s_line(name):
    from pathlib import Path

    text, message = GOUGE_CASES[name]
    table = Path(__file__).parent / "golden" / "linuxcnc" / "tooltables" / "simpockets.tbl"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, tool_table=table, tool_table_units="inch")
    assert [(d.line, d.message) for d in op.diagnostics if d.severity == "error"] == [(6, message)]
