"""Beckhoff 5-axis DED dialect: moves, weld state, slices and fractions as the seed's parser reads them."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.analysis import ded_moves, part_name, tool_vectors

HERE = Path(__file__).parent
PROGRAMS = [HERE / "golden" / "ded" / "hemisphere_seed.nc", HERE.parent / "examples" / "dome_ded_beckhoff.nc"]


def seed_reading(path: Path) -> tuple[str, list[dict]]:
    """The seed document's rules, written out independently: line by line, regexes on comments."""
    part, moves, weld, slice_no, fraction_no = None, [], "off", 0, 0
    for number, raw in enumerate(path.read_text().splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith(";"):
            continue
        if line.startswith("("):
            if part is None and (m := re.search(r"\(Part name:\s*(.+?)\)", line)):
                part = m.group(1).strip()
            elif m := re.search(r"\(New Slice of body .*?No\.:\s*(\d+)", line):
                slice_no = int(m.group(1))
            elif m := re.search(r"Fraction\s+(\d+)", line):
                fraction_no = int(m.group(1))
            continue
        if line.startswith("M62"):
            weld = "off"
        elif line.startswith(("G00", "G01")):
            axes = {k: float(v) for k, v in re.findall(r"\b([XYZAB])(-?\d+\.?\d*)", line)}
            if not {"X", "Y", "Z"} <= set(axes):
                continue
            if "M61" in line:
                weld = "on"
            moves.append(dict(line_no=number, x=axes["X"], y=axes["Y"], z=axes["Z"], a=axes.get("A", 0.0),
                              b=axes.get("B", 0.0), move_type="rapid" if line.startswith("G00") else "cut",
                              weld_state=weld, slice_no=slice_no, fraction_no=fraction_no))
    return part or path.stem, moves


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_moves_match_the_seed_reading(path):
    op = gcodekit.gcode_to_operation(path)
    assert op.flavor.name == "beckhoff_ded"
    name, expected = seed_reading(path)
    assert part_name(op) == name
    got = ded_moves(op)
    assert len(got) == len(expected)
    for column in ("line_no", "x", "y", "z", "a", "b", "move_type", "weld_state", "slice_no", "fraction_no"):
        assert got[column].tolist() == [m[column] for m in expected], column


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_tool_vectors_follow_the_formula_and_are_unit(path):
    moves = ded_moves(gcodekit.gcode_to_operation(path))
    uvw = moves[["u", "v", "w"]].to_numpy()
    np.testing.assert_allclose(np.linalg.norm(uvw, axis=1), 1.0, atol=1e-12)
    a, b = math.radians(moves["a"].iloc[-1]), math.radians(moves["b"].iloc[-1])
    assert uvw[-1] == pytest.approx([math.sin(b), -math.sin(a) * math.cos(b), math.cos(a) * math.cos(b)])
    assert tool_vectors(np.array([0.0]), np.array([0.0])).tolist() == [[0.0, -0.0, 1.0]]


def test_a_move_missing_an_axis_is_reported_and_left_out():
    text = "(Part name: T)\nG54\nG00 X0 Y0 Z1\nG01 X1 Y1 M61\nG01 X2 Y2 Z1\nM62\n"
    op = gcodekit.gcode_to_operation(text, "beckhoff_ded")
    warnings = [d for d in op.diagnostics if "without Z" in d.message]
    assert [d.line for d in warnings] == [4]
    assert ded_moves(op)["line_no"].tolist() == [3, 5]
    assert ded_moves(op)["weld_state"].tolist() == ["off", "on"]
