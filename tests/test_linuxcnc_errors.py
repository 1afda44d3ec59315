"""Golden tests: programs LinuxCNC's rs274 refuses are refused on the same line.

Cases sit in ``tests/golden/linuxcnc/errors`` (``errors.py`` beside the
golden cases collects them; ``manifest.tsv`` there says which error programs
are skipped and why).  Each kept program must give an error-severity
diagnostic on rs274's line in lenient mode, and strict mode must raise a
:class:`~gcodekit.errors.GcodeError` there.
"""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

import gcodekit
from gcodekit.errors import GcodeError

ERRORS = Path(__file__).parent / "golden" / "linuxcnc" / "errors"


def _cases() -> list[tuple[str, int, str, str]]:
    with (ERRORS / "expected.tsv").open(newline="") as f:
        return [(r["case"], int(r["line"]), r["message"], r["block"]) for r in csv.DictReader(f, delimiter="\t")]


CASES = _cases()


def _run(name: str, mode: str):
    from test_linuxcnc_golden import tool_table  # the table rs274 ran the program with

    return gcodekit.gcode_to_operation(ERRORS / name, "linuxcnc", plan=False, mode=mode, tool_table=tool_table(name),
                                       tool_table_units="inch")  # rs274 standalone reads tables in inches


def test_cases_present() -> None:
    assert len(CASES) >= 80, f"too few error cases in {ERRORS}; run tests/golden/linuxcnc/errors.py"


@pytest.mark.parametrize(("name", "line", "message", "block"), CASES, ids=[c[0] for c in CASES])
def test_lenient_reports_error_on_rs274_line(name: str, line: int, message: str, block: str) -> None:
    errors = [d for d in _run(name, "lenient").diagnostics if d.severity == "error"]
    if not any(d.line == line for d in errors):
        pytest.fail(f"{name}: rs274 stops on line {line} ({message}: {block!r}); "
                    f"our errors: {[str(d) for d in errors[:5]]}", pytrace=False)


@pytest.mark.parametrize(("name", "line", "message", "block"), CASES, ids=[c[0] for c in CASES])
def test_strict_raises_on_rs274_line(name: str, line: int, message: str, block: str) -> None:
    with pytest.raises(GcodeError) as info:
        _run(name, "strict")
    diagnostic = info.value.diagnostic
    assert diagnostic is not None and diagnostic.line == line, (
        f"{name}: rs274 stops on line {line} ({message}: {block!r}); we raised {info.value}")


def test_unknown_code_is_an_error_but_known_linuxcnc_codes_are_not() -> None:
    op = gcodekit.gcode_to_operation("G21 G96 S100 M3\nM52 P1\nG6.2 X1 Y1\nG0 X1\nM2\n", "linuxcnc", plan=False)
    errors = [d for d in op.diagnostics if d.severity == "error"]
    assert {d.line for d in errors} == {3}  # G96 and M52 are LinuxCNC codes gcodekit does not emulate
    assert errors[0].message.startswith("Unknown g code used: G6.2")


def test_axis_word_the_machine_lacks_is_an_error() -> None:
    with pytest.raises(GcodeError, match="Bad character 'w' used") as info:
        gcodekit.gcode_to_operation("G21\nG1 X1 F100\nG1 W100\nM2\n", "linuxcnc", plan=False, mode="strict")
    assert info.value.diagnostic.line == 3


def test_program_file_needs_an_end(tmp_path: Path) -> None:
    body = "#<depth> = -1\nG21 G1 Z#<depth> F100\n"
    assert not gcodekit.gcode_to_operation(body, "linuxcnc", plan=False).diagnostics.errors  # MDI-like text
    for text, ok in ((body, False), (body + "M2\n", True), ("%\n" + body + "%\n", True), ("%\n" + body, False)):
        path = tmp_path / "p.ngc"
        path.write_text(text)
        errors = gcodekit.gcode_to_operation(path, "linuxcnc", plan=False).diagnostics.errors
        assert [d.line for d in errors] == ([] if ok else [text.count("\n")]), text
