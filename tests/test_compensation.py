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


def test_rapids_round_an_outside_corner_go_straight(tool_table):
    # no rapid arc: straight from (10, -1) to (11, 0), sqrt(2) mm at the 3000 mm/min rapid rate
    op = gcodekit.gcode_to_operation("G21 G17 G90 T1 M6\nG0 X-5 Y0\nG42 G0 X0 Y0\nX10\nY10\nG40 X-5\n", "linuxcnc",
                                     plan=False, tool_table=tool_table, tool_table_units="mm")
    m = op.motions()
    assert m["motion"].tolist() == ["rapid"] * 6
    np.testing.assert_allclose(m[["x", "y"]].to_numpy()[2:4], [(10, -1), (11, 0)], atol=1e-12)
    w = op.waypoints
    moved = w["motion"] > 0
    assert w["distance"][moved][3] == pytest.approx(math.sqrt(2))
    assert w["time"][moved][3] == pytest.approx(math.sqrt(2) / 3000 * 60)


def test_corners_within_rs274s_tolerance_are_taken_straight_on(tool_table):
    # 0.02 rad is under TOLERANCE_CONCAVE_CORNER (0.05): no roll arc, the next move starts where the tool is
    m = motions("G21 G17 G90 T1 M6\nG0 X-5 Y0\nG42 G1 X0 Y0 F600\nX10\nX20 Y-0.2\nG40 X30\n", tool_table)
    assert m["motion"].tolist() == ["rapid", "feed", "feed", "feed", "feed"]
    slope = math.atan2(-0.2, 10)
    np.testing.assert_allclose(m[["x", "y"]].to_numpy()[3], (20 - math.sin(-slope), -0.2 - math.cos(slope)),
                               atol=1e-12)


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


# Lathe tools in G18: a 2 mm nose (radius 1) with orientation Q2 or Q9.  In the
# (Z, X) plane a -Z move has its right (G42) towards +X; the nose centre runs 1
# mm off the profile and rs274 then moves every compensated point from the nose
# centre to the tool's control point, (-1, -1) in (Z, X) for Q2 and nothing for
# Q9 (interp_queue.cc latheorigin_z/x).  Values checked with LinuxCNC 2.9's rs274
# (the same program in inches with the table in inches gives the same numbers).
LATHE_PROGRAM = "G21 G18 G90 T{tool} M6\nG0 X10 Z5\nG42 G1 X5 F100\nG1 Z-10\nG40 G0 X10\nM2\n"


@pytest.fixture
def lathe_tools(tmp_path):
    path = tmp_path / "lathe.tbl"
    path.write_text("T2 P2 D2 Q2 ;front tool\nT3 P3 D2 Q9 ;nose centre\n")
    return path


@pytest.mark.parametrize("tool, nose_to_tip", [(3, (0, 0)), (2, (-1, -1))])
def test_g42_in_g18_offsets_the_nose_then_the_control_point(lathe_tools, tool, nose_to_tip):
    m = motions(LATHE_PROGRAM.format(tool=tool), lathe_tools)
    dz, dx = nose_to_tip
    # entry ends 1 to the right of the -X move (-Z), cut short where the -Z move's
    # offset line X6 meets it (an inside corner); the -Z move runs on X6; the exit is plain
    expected = [("rapid", 10, 5), ("feed", 6 + dx, 4 + dz), ("feed", 6 + dx, -10 + dz), ("rapid", 10, -10)]
    assert m["motion"].tolist() == [e[0] for e in expected]
    np.testing.assert_allclose(m[["x", "z"]].to_numpy(), [e[1:] for e in expected], atol=1e-12)
    assert (m["plane"] == "XZ").all()


def test_lathe_entry_arc_first_feeds_the_control_point_shift(lathe_tools):
    # G41.1 D2 L3: nose radius 1, control point (-1, +1) from the nose centre in (Z, X);
    # the entry arc (G2 R10 from Z10 X20 to Z0 X10) ends 1 left of its -Z tangent, at X9
    text = "G21 G18 G90 F100\nG0 X20 Z10\nG41.1 D2 L3\nG2 X10 Z0 R10\nG1 Z-10\nG40 G0 X30\nM2\n"
    m = motions(text, lathe_tools)
    assert m["motion"].tolist() == ["rapid", "feed", "arc_cw", "feed", "rapid"]
    np.testing.assert_allclose(m[["x", "z"]].to_numpy()[:4], [[20, 10], [21, 9], [10, -1], [10, -11]], atol=1e-9)
    arc = m.iloc[2]
    start, end, centre = np.array([9.0, 21.0]), np.array([-1.0, 10.0]), np.array([arc["cz"], arc["cx"]])
    assert np.hypot(*(start - centre)) == pytest.approx(np.hypot(*(end - centre)))


def test_tool_orientation_from_table_and_g10(lathe_tools):
    from gcodekit.emulate.tooltable import ToolTable

    assert ToolTable.read(lathe_tools)[2].orientation == 2
    # G10 L1 Q gives T3 orientation 2: its path is then the Q2 one
    m = motions(LATHE_PROGRAM.format(tool=3).replace("M6\n", "M6\nG10 L1 P3 Q2\n", 1), lathe_tools)
    np.testing.assert_allclose(m[["x", "z"]].to_numpy()[1:3], [[5, 3], [5, -11]], atol=1e-12)


def test_states_follow_the_codes_and_the_moves(tool_table, monkeypatch):
    # The pass's states (rs274's cutter_comp_side and cutter_comp_firstmove), as the program
    # says: G42 arms the entry, a plunge is no entry, the first move in the plane is; G40 arms
    # the exit, which a spindle start does not take, the next move does.
    from gcodekit.emulate import compensation

    after: dict[int, str] = {}  # source line -> state after its last waypoint

    class Recording(compensation.Compensator):
        def _step(self, step):
            super()._step(step)
            after[int(self.table.line[step.row])] = self.state.value

    monkeypatch.setattr(compensation, "Compensator", Recording)
    text = "G21 G17 G90 T1 M6\nG0 X-5 Y0\nG42\nG0 Z1\nG1 X0 Y0 F600\nX10\nG40\nM3 S100\nG0 X20\n"
    m = motions(text, tool_table)
    assert after == {1: "off", 2: "off", 3: "entry", 4: "entry", 5: "on", 6: "on", 7: "exit", 8: "exit", 9: "off"}
    # the plunge keeps the tool where it was; the entry ends 1 mm right of the +X move
    np.testing.assert_allclose(m[["x", "y", "z"]].to_numpy()[1:5], [[-5, 0, 1], [0, -1, 1], [10, -1, 1],
                                                                     [20, 0, 1]], atol=1e-12)
