"""Problems in a subroutine file name that file, its line and its text, not the caller's."""

from __future__ import annotations

import pytest

import gcodekit
from gcodekit.errors import GcodeError

SUB = "o<edge> sub\nG1 X10 F100\nG2 X20 Y0 R3\nM999\n#1 = [1 / 0]\no<edge> endsub\nM2\n"
MAIN = "G21 G90\nG0 X0 Y0\no<edge> call\nG0 X0\nG1 X1 Y1\nM2\n"


@pytest.fixture
def program(tmp_path):
    (tmp_path / "edge.ngc").write_text(SUB)
    main = tmp_path / "main.ngc"
    main.write_text(MAIN)
    return main


def test_each_problem_names_the_subroutine_file(program):
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False)
    sub = str(program.with_name("edge.ngc"))
    found = {(d.file, d.line, d.text) for d in op.diagnostics.items if d.severity == "error"}
    assert found == {
        (sub, 5, "#1 = [1 / 0]"),  # the parameter stage
        (sub, 4, "M999"),  # the parser: unknown code
        (sub, 3, "G2 X20 Y0 R3"),  # the machine: the arc cannot reach its end
    }


def test_rows_keep_their_files_own_line_numbers(program):
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False)
    moves = op.motions()
    # G0 X0 Y0, the sub's G1 and G2 (its lines 2 and 3), G0 X0, G1 X1 Y1
    assert moves["line"].tolist() == [2, 2, 3, 4, 5]


def test_strict_mode_raises_on_the_subroutine_files_line(program):
    program.with_name("edge.ngc").write_text("o<edge> sub\nG1 X10 F100\nG2 X20 Y0 R3\no<edge> endsub\nM2\n")
    with pytest.raises(GcodeError) as raised:
        gcodekit.gcode_to_operation(program, "linuxcnc", plan=False, mode="strict")
    where = raised.value.diagnostic
    assert (where.file, where.line) == (str(program.with_name("edge.ngc")), 3)


def test_the_report_names_the_subroutine_file(program):
    from gcodekit.report.build import report_data

    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False)
    rows = {(d["elsewhere"], d["line"]) for d in report_data(op, transpile=False)["summary"]["diagnostics"]}
    assert rows == {("edge.ngc", 3), ("edge.ngc", 4), ("edge.ngc", 5)}
