"""Transpiler: every stage's output, read again, moves the machine the same way."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.transpile import STAGES, Transpiler

GOLDEN = Path(__file__).parent / "golden" / "linuxcnc" / "cases"
EXAMPLES = Path(__file__).parents[1] / "examples"
PROGRAMS = sorted(p for p in GOLDEN.glob("*.ngc") if p.with_name(p.name + ".canon.csv").exists()) + [
    EXAMPLES / "bracket_mill.ngc"]  # the others are subroutines a case calls


def path_of(op: gcodekit.Operation) -> np.ndarray:
    """Machine-frame end points (mm) of every motion, and arc centres where known.

    An arc that compensation shrank to a point is written back as G1, so its
    centre is left out and its motion counted as a feed.
    """
    w = op.waypoints
    moved = np.flatnonzero(np.asarray(w["motion"]) > 0)
    path = np.column_stack([np.asarray(w[k], float)[moved] for k in ("x", "y", "z", "a", "b", "c", "cx", "cy", "cz")])
    before = np.column_stack([np.asarray(w[k], float)[moved - 1] for k in "xyz"])
    point_arc = np.nansum((path[:, 6:9] - before) ** 2, axis=1) < 1e-18
    path[point_arc, 6:9] = np.nan
    return path


def operation(path: Path) -> gcodekit.Operation:
    from test_linuxcnc_golden import tool_table  # the table rs274 ran the case with

    table = tool_table(path.name) if path.parent == GOLDEN else None
    options = {"tool_table": table, "tool_table_units": "inch"} if table else {}
    return gcodekit.gcode_to_operation(path, "linuxcnc", plan=False, **options)


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_last_stage_moves_like_the_original(path):
    original = operation(path)
    text = Transpiler(original).stage(6)
    again = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    a, b = path_of(original), path_of(again)
    assert a.shape == b.shape
    np.testing.assert_allclose(b, a, atol=1e-3, equal_nan=True)  # 4 decimals in the output


@pytest.mark.parametrize("stage", [4, 5])
def test_compensated_program_moves_alike_from_stage_4(stage):
    """From stage 4 moves come from compensated waypoints: G41/G42 must not apply twice."""
    from test_linuxcnc_golden import tool_table

    original = operation(GOLDEN / "comp.ngc")
    again = gcodekit.gcode_to_operation(Transpiler(original).stage(stage), "linuxcnc", plan=False,
                                        tool_table=tool_table("comp.ngc"), tool_table_units="inch")
    np.testing.assert_allclose(path_of(again), path_of(original), atol=1e-3, equal_nan=True)


@pytest.mark.parametrize("path", PROGRAMS[:4] + [EXAMPLES / "bracket_mill.ngc"], ids=lambda p: p.name)
def test_every_stage_reads_back_without_errors(path):
    t = Transpiler(operation(path))
    for k in STAGES:
        op = gcodekit.gcode_to_operation(t.stage(k), "linuxcnc", plan=False)
        assert not [d for d in op.diagnostics if d.severity == "error"], (k, op.diagnostics.items[:3])


def test_last_stage_vocabulary_and_line_numbers():
    t = gcodekit.transpile_program("G21 G0 X0 Y0 Z5\nG55 G81 X10 Y10 Z-2 R1 F100\nX20\nG80\nG91 G1 X5\nM2\n", "linuxcnc",
                   work_offsets={"G55": (100.0, 0.0, 0.0)})
    lines = [line for line in t.stage(6).splitlines() if not line.startswith("(")]
    assert lines[0] == "G21" and lines[-1] == "N6 M2"  # it names its units, and the program still ends
    lines = lines[1:-1]
    assert all(line.split()[1] in ("G0", "G1", "G2", "G3", "G4") for line in lines)
    # rs274 starts in G99: the second hole starts and ends at R, so no climb first (as rs274 runs it)
    assert [line.split()[0] for line in lines] == ["N1"] + ["N2"] * 4 + ["N3"] * 3 + ["N5"]
    assert lines[2] == "N2 G0 X110 Y10 Z1"  # the G55 offset is in the coordinates now
    assert lines[-1] == "N5 G1 X125 Y10 Z1 F100"


def test_stage_1_converts_units():
    t = gcodekit.transpile_program("G20 G91 G0 X1\nG1 X0.5 F10\n", "linuxcnc")
    assert "N1 G0 X25.4" in t.stage(1) and "N2 G1 F254 X12.7" in t.stage(1)


@pytest.mark.parametrize("flavor, text", [
    ("fanuc", "G21 G90 G17 G0 X0 Y0\nG55\nG16\nG1 X10 Y30 F100\nY90\nG15\nG1 X1 Y1\n"),
    ("ger", "G21 G91\nG16\nG01 X10 Y90 F100\nX10 Y0\nG15\nG01 X1 Y1\n"),
])
def test_g16_polar_moves_alike_at_every_stage(flavor, text):
    t = gcodekit.transpile_program(text, flavor, work_offsets={"G55": (100.0, 50.0, 0.0)})
    reference = path_of(t.op)
    for k in STAGES:
        out = t.stage(k)
        code_lines = [line for line in out.splitlines() if not line.startswith("(")]
        assert any("G16" in line for line in code_lines) == (k < 2), f"stage {k}"
        again = gcodekit.gcode_to_operation(out, flavor, plan=False, work_offsets={"G55": (100.0, 50.0, 0.0)})
        np.testing.assert_allclose(path_of(again), reference, atol=1e-3, equal_nan=True, err_msg=f"stage {k}")


CYCLES_UNDER_OFFSETS = """G20 G17 G90
G10 L2 P1 X0.4 Y-0.2 Z0.12
G54 G0 X0 Y0 Z0.8
G98 G81 X0.04 Y0.04 Z-0.12 R0.08 F4
X0.16
G99 G83 X0.24 Y0.08 Z-0.24 R0.04 Q0.08
M3 S500
G98 G87 X0.32 Y0.08 Z-0.3 R-0.04 I0.02 J0 K-0.2
G80
G0 Z0.8
G18 G10 L2 P1 X0.28 Y0 Z-0.16
O100 SUB
  G0 X0.08 Z0
  G1 X0.16 Z-0.2
  G2 X0.24 Z-0.28 I0.08
  G1 X0.32
O100 ENDSUB
G0 X0.4 Z0.2
G70 Q100 X0.4 Z0.08 P2 D0.02
G71 Q100 X0.4 Z0.08 D0.01 I0.04
G0 X0.5 Z0.1
G76 P0.05 Z-0.4 I-0.02 J0.004 K0.03
G7 G0 X1 Z0.1
G76 P0.05 Z-0.4 I-0.04 J0.008 K0.06
G8
M2
"""


def test_cycles_move_alike_at_every_stage():
    """Cycle words (drilling's X Y Z R, a lathe cycle's point and profile, G76's) take the units and offsets."""
    t = gcodekit.transpile_program(CYCLES_UNDER_OFFSETS, "linuxcnc")
    reference = path_of(t.op)
    assert not t.op.diagnostics.items
    for k in STAGES:
        again = gcodekit.gcode_to_operation(t.stage(k), "linuxcnc", plan=False)
        assert not again.diagnostics.items, (k, again.diagnostics.items[:2])
        np.testing.assert_allclose(path_of(again), reference, atol=1e-3, equal_nan=True, err_msg=f"stage {k}")


def test_rotated_work_systems_move_alike_at_every_stage():
    """Under G10 L2 R, moves (cycles and G90.1 arcs too) are written from waypoints from stage 2."""
    from test_linuxcnc_golden import tool_table

    case = GOLDEN / "own__xy_rotation.ngc"
    t = Transpiler(operation(case))
    reference = path_of(t.op)
    for k in STAGES:
        again = gcodekit.gcode_to_operation(t.stage(k), "linuxcnc", plan=False, tool_table=tool_table(case.name),
                                            tool_table_units="inch")
        assert not again.diagnostics.items, (k, again.diagnostics.items[:2])
        np.testing.assert_allclose(path_of(again), reference, atol=1e-3, equal_nan=True, err_msg=f"stage {k}")
    code = [line for line in t.stage(2).splitlines() if not line.startswith("(")]
    assert not [line for line in code if "G10" in line or "G81" in line]  # the rotation and its cycles resolved


@pytest.mark.parametrize("path", PROGRAMS[:12], ids=lambda p: p.name)
def test_summary_counts_what_each_stage_writes(path):
    # counted in one pass over the commands for all stages; here from each stage's text, line by line
    t = Transpiler(operation(path))
    expected = []
    for k in STAGES:
        lines = t.stage(k).splitlines()[1:]
        moves = sum(1 for line in lines if any(f" G{g} " in f" {line} " for g in (0, 1, 2, 3)))
        expected.append((k, len(lines), moves))
    assert [(s["stage"], s["lines"], s["moves"]) for s in t.summary()] == expected


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_stages_written_together_match_each_stage_written_alone(path):
    # summary() writes the seven stages of a row one after another and shares a text between stages that
    # resolve nothing new for the row (stage 1 in mm, stages 4-6 of a plain move); stage(k) alone shares nothing
    op = operation(path)
    together = Transpiler(op)
    rows = {k: [] for k in STAGES}
    for row in range(len(op.table)):
        for k in STAGES:
            rows[k].extend(together._row(row, k))  # the walk summary() makes
    for k in STAGES:
        alone = Transpiler(op).stage(k).splitlines()
        assert alone[1 + len(together._head(k)):len(alone) - len(together._tail())] == rows[k], k


def test_lines_streams_the_stage_text_and_the_summary_counts_it():
    t = Transpiler(operation(EXAMPLES / "bracket_mill.ngc"))
    for k in STAGES:
        lines = list(t.lines(k))
        assert "\n".join(lines) + "\n" == t.stage(k)
        assert len(lines) == t.summary()[k]["lines"] + 1  # the title line
    from gcodekit.errors import ConfigError

    with pytest.raises(ConfigError, match="stage must be one of 0-6"):
        t.lines(7)  # said at once, not when the lines are first read
