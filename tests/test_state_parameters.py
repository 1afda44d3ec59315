"""LinuxCNC state parameters (#5420, #<_x>, #<_imperial>, ...) read the emulated machine.

rs274's own output for most of them is the golden case
``golden/linuxcnc/own/state_parameters.ngc``; these tests cover what that
case cannot: values worked out by hand on a metric machine, and errors.
"""

from __future__ import annotations

import numpy as np
import pytest

import gcodekit


def run(text: str, **options):
    return gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, **options)


def moves(op, axis: str = "x") -> list[float]:
    w = op.waypoints
    return w[axis][w["motion"] > 0].tolist()


def test_position_is_read_after_the_lines_before_it_ran():
    # G92 shifts the program origin: #5420 is the program position, not the machine's
    op = run("G21 G0 X10 Y4\nG92 X0\nG1 X[#5420+2] Y[#<_y>/2] F100\nG0 X[#<_x>*3]\nM2\n")
    np.testing.assert_allclose(moves(op), [10.0, 12.0, 16.0])  # program 2, then 6, plus the 10 of G92
    assert moves(op, "y") == [4.0, 2.0, 2.0]


def test_inch_program_reads_inches():
    # the line is read before its G21 runs: X1.5 there is 1.5 mm, as in rs274
    op = run("G20 G0 X1\nG0 X[#<_x>+0.5]\nG21 G0 X[#<_x>]\nM2\n")
    np.testing.assert_allclose(moves(op), [25.4, 38.1, 1.5])


def test_tool_offsets_are_in_machine_units(tmp_path):
    table = tmp_path / "tools.tbl"
    table.write_text("T1 P1 Z12.5 D6 ;\n")
    op = run("G21 T1 M6 G43\nG0 X[#5403]\nM2\n", tool_table=table)
    assert moves(op) == pytest.approx([12.5])
    inch = run("G21 T1 M6 G43\nG0 X[#5403]\nM2\n", tool_table=table, tool_table_units="inch")
    assert moves(inch) == pytest.approx([12.5])  # the table's number, as rs274 gives it


@pytest.mark.parametrize("line", ["#<_x> = 5", "#5420 = 3"])
def test_writing_one_is_an_error_on_its_line(line):
    op = run(f"G0 X1\n{line}\nM2\n")
    errors = [d for d in op.diagnostics.items if d.severity == "error"]
    assert [(d.line, "read-only" in d.message) for d in errors] == [(2, True)]


def test_other_dialects_keep_ordinary_parameters():
    # Fanuc macro programs use #5001.. for positions; #5420 is just a variable there
    op = gcodekit.gcode_to_operation("G21 G0 X10\n#5420 = 3\nG0 X[#5420]\nM30\n", "fanuc", plan=False)
    assert moves(op) == [10.0, 3.0]


def test_stored_offsets_read_and_write_the_machine():
    # mm machine (the default tool table units): G10 L2 P2 X5 stores 5 in #5241, R30 in #5230
    op = run("G21\nG10 L2 P2 X5\nG10 L2 P1 R30\nG0 X[#5241] Y[#5230]\nM2\n")
    assert not op.diagnostics.items
    assert moves(op, "x") == pytest.approx([5 * np.cos(np.radians(30)) - 30 * np.sin(np.radians(30))])
    # a written G54 offset waits for G54 to be selected again (rs274 ignores G54 while in G54)
    op = run("G21\n#5221 = 3\nG0 X0\nG54\nG0 X0\nG55\nG54\nG0 X0\nM2\n")
    assert not op.diagnostics.items
    assert moves(op) == [0.0, 0.0, 3.0]


def test_stored_g92_offset_and_home_positions():
    # G92.2 suspends the offset (#5210 0) but keeps it stored (#5211) for G92.3, a written one too
    op = run("G21\nG0 X10\nG92 X4\nG92.2\nG0 X[#5210] Y[#5211]\n#5211 = 1\nG92.3\nG0 X0\nM2\n")
    assert [tuple(p) for p in zip(moves(op, "x"), moves(op, "y"))] == [(10, 0), (0, 6), (1, 6)]
    # G28 goes through the current point (no length) to the position written in #5161..
    op = run("G21\nG0 X1 Y1\n#5161 = 7\n#5162 = 8\nG28\nM2\n")
    assert [tuple(p) for p in zip(moves(op, "x"), moves(op, "y"))] == [(1, 1), (1, 1), (7, 8)]


def test_ini_values_and_subroutine_path(tmp_path):
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "park.ngc").write_text("o<park> sub\nG0 X#<_ini[vars]park_x>\no<park> endsub\n")
    ini = tmp_path / "machine.ini"
    ini.write_text("[VARS]\nPARK_X = 12.5\n# a comment\nPARK_X = 99\n[RS274NGC]\nSUBROUTINE_PATH = subs\n")
    program = tmp_path / "p.ngc"
    program.write_text("G21 G0 Y#<_InI[Vars]Park_X>\no<park> call\nM2\n")
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False, ini_file=str(ini))
    assert not op.diagnostics.items
    assert moves(op, "y") == [12.5, 12.5] and moves(op, "x") == [0.0, 12.5]  # the first PARK_X wins
    op = run("#<_ini[vars]park_x> = 1\nG0 X#<_ini[vars]nothing>\nM2\n", ini_file=str(ini))
    assert [(d.line, "read-only" in d.message or "not defined" in d.message) for d in op.diagnostics.items
            if d.severity == "error"] == [(1, True), (2, True)]
    with pytest.raises(gcodekit.ConfigError, match="cannot read the INI file"):
        run("G0 X1\n", ini_file=str(tmp_path / "missing.ini"))


def test_motion_mode_is_the_motion_code_in_tenths():
    # rs274 2.9 gives G80 (800) at the start, then 10, 20, 810, 800 and 383 here (each read before its line runs)
    text = ("G21\nG0 X[#<_motion_mode>]\nG1 X1 F100\nG0 X[#<_motion_mode>]\nG2 X12 R1\nG0 Y[#<_motion_mode>]\n"
            "G81 X3 Y3 Z-1 R1\nX4\nG0 X[#<_motion_mode> / 10]\nG80\nG0 Z[#<_motion_mode> / 100]\nG38.3 Z-1\n"
            "G0 Z[#<_motion_mode> / 100]\nM2\n")
    op = run(text)
    assert not op.diagnostics.items
    assert [moves(op, "x")[i] for i in (0, 2)] == [800.0, 10.0] and 20.0 in moves(op, "y")
    assert 81.0 in moves(op, "x") and moves(op, "z")[-3] == 8.0 and moves(op, "z")[-1] == pytest.approx(3.83)
