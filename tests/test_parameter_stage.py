"""Preprocess stage: parameters and expressions substituted into program lines.

Semantics follow LinuxCNC 2.9: assignments on a line take effect after the
whole line was read, comments are never touched, errors name file:line:col.
"""

import math
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gcodekit.errors import (
    Diagnostics,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    GcodeSyntaxError,
)
from gcodekit.preprocess import (
    ParameterStage,
    ParameterStore,
    SourceLine,
    Stage,
    needs_parameters,
    run_stages,
)
from gcodekit.preprocess.parameters import O_WORD_MESSAGE, format_number
from gcodekit.syntax.flavor import Flavor

NGC = Flavor("ngc", line_comments=(";",), paren_comments=True, parameters=True)


def lines_of(program: str, file: str = "t.ngc") -> list[SourceLine]:
    return [SourceLine(text, n, file) for n, text in enumerate(program.split("\n"), 1)]


def run(program: str, *, mode: str = "lenient", store=None, flavor=NGC):
    diagnostics = Diagnostics("t.ngc", mode=mode)
    stage = ParameterStage(flavor, store)
    out = list(stage.process(lines_of(program), diagnostics))
    assert [s.line for s in out] == list(range(1, program.count("\n") + 2))
    return [s.text for s in out], diagnostics, stage.store


def test_stage_interface():
    stage = ParameterStage(NGC)
    assert isinstance(stage, Stage)
    assert stage.name == "parameters"
    line = SourceLine("G1 X1", 3, "a.ngc")
    with pytest.raises(AttributeError):
        line.text = "x"
    assert needs_parameters("G1 X#1") and needs_parameters("G1 X[1]")
    assert not needs_parameters("G1 X1 (no parameters)")


def test_run_stages_chains_lazily():
    seen = []

    class Upper:
        name = "upper"

        def process(self, lines, diagnostics):
            for line in lines:
                seen.append(line.line)
                yield SourceLine(line.text.upper(), line.line, line.file)

    out = run_stages(lines_of("#1 = 2\ng1 x#1"), [ParameterStage(NGC), Upper()], Diagnostics())
    assert seen == []  # nothing runs before the caller pulls
    assert [s.text for s in out] == ["", "G1 X2"]


def test_words_are_substituted():
    texts, diagnostics, _ = run(
        "#1 = 2\n"
        "#<Depth> = -1.5\n"
        "G1 X[#1 + 2] Y#1 Z#<depth> F[#1 * 100]\n"
        "G1 X-#1 Y+#1 Z--1 A SIN[30] B-[1 + 1]\n"
        "G1 X ATAN[1]/[1] Y EXISTS[#<depth>] Z EXISTS[#<nope>]\n"
        "G#1 M[1 + 2] g1x#1y [1]\n"
        "N10 G1 X1 Y2"
    )
    assert texts == [
        "",
        "",
        "G1 X4 Y2 Z-1.5 F200",
        "G1 X-2 Y2 Z1 A 0.49999999999999994 B-2",
        "G1 X 45 Y 1 Z 0",
        "G2 M3 g1x2y 1",
        "N10 G1 X1 Y2",
    ]
    assert len(diagnostics) == 0


def test_assignments_apply_after_the_line():
    texts, _, store = run("#1=1\n#1=2 G1 X#1\nG1 X#1")
    assert texts == ["", "G1 X1", "G1 X2"]
    # Parallel setting (LinuxCNC read_parameter_setting): #2 reads the old #1.
    texts, diagnostics, store = run("#1 = 5\n#1 = 10 #2 = #1\n#<a> = 1 #<b> = [#<a> + 1]")
    assert store.get(1) == 10.0 and store.get(2) == 5.0
    assert texts == ["", "", ""]
    # #<a> does not exist yet when #<b>'s value is read on the same line.
    assert [d.message for d in diagnostics] == ["named parameter #<a> is not defined"]
    assert not store.exists("a") and not store.exists("b")


def test_numbered_and_named_parameters():
    texts, diagnostics, store = run(
        "#1 = 3\n#3 = 7\nG1 X##1 Y#[#1 - 2] Z#[1 + 2]\n"
        "#<My Var> = 4\n#<_Global> = 5\nG1 X#<myvar> Y#<MYVAR> Z#< my var > A#<_global>\n"
        "##1 = 9\nG1 X#3"
    )
    assert texts[2] == "G1 X7 Y3 Z7"
    assert texts[5] == "G1 X4 Y4 Z4 A5"
    assert texts[7] == "G1 X9"
    assert store.get("_global") == 5.0
    assert len(diagnostics) == 0


def test_comments_are_untouched():
    program = (
        "(#1)\n"
        "G1 X#1 (X#1 [1/0]) Y[1] ; #2 = [#<undefined>]\n"
        "; #1 = 5\n"
        "#1 = 4 (set #1) ; (#1)\n"
        "G1 X#1 (unclosed [1/0]"
    )
    texts, diagnostics, store = run(program)
    assert texts == [
        "(#1)",
        "G1 X0 (X#1 [1/0]) Y1 ; #2 = [#<undefined>]",
        "; #1 = 5",
        "(set #1) ; (#1)",
        "G1 X4 (unclosed [1/0]",
    ]
    assert len(diagnostics) == 0
    assert store.get(1) == 4.0


def test_comment_syntax_comes_from_the_flavor():
    no_parens = Flavor("semi", line_comments=(";",), paren_comments=False, parameters=True)
    texts, diagnostics, _ = run("G1 X#1 ; (#1)", flavor=no_parens)
    assert texts == ["G1 X0 ; (#1)"]
    texts, diagnostics, _ = run("G1 X[1] ([2])", flavor=no_parens)
    assert texts == [""]
    assert diagnostics.items[0].message.startswith("an expression must be the value of a word")


def test_assignment_text_is_removed_cleanly():
    texts, _, _ = run("#1 = 5 G1 X#1\nG1 X#1 #1 = 6\nG1 X1 #1=7 Y2\n  #1 = 1  #2 = 2  \n#1=1(c)")
    assert texts == ["G1 X0", "G1 X5", "G1 X1 Y2", "", "(c)"]


def test_numbers_are_plain_decimals_that_round_trip():
    texts, _, _ = run("G1 X[1/3] Y[10**20] Z[0.1 + 0.2] A[1/1024/1024/1024] B[0 - 0] C-[0]")
    assert texts == [
        "G1 X0.3333333333333333 Y100000000000000000000 Z0.30000000000000004 "
        "A0.0000000009313225746154785 B0 C0"
    ]


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_format_number_round_trips(value):
    text = format_number(value)
    assert "e" not in text.lower()
    assert float(text) == value
    assert text == "0" or not text.endswith((".", "0")) or "." not in text


def test_errors_are_located_and_lines_blanked():
    program = "G1 X1\nG1 X[1/0]\nG1 Y#<nope>\n#1 = 3 G1 X[1 + 2\n#1 = 5 G1 X#1\nG1 [1]\nG1 X#1"
    texts, diagnostics, store = run(program)
    assert texts == ["G1 X1", "", "", "", "G1 X0", "", "G1 X5"]
    assert [(d.line, d.column) for d in diagnostics] == [(2, 7), (3, 5), (4, 12), (6, 4)]
    assert [d.text for d in diagnostics] == ["G1 X[1/0]", "G1 Y#<nope>", "#1 = 3 G1 X[1 + 2", "G1 [1]"]
    assert "division by zero" in diagnostics.items[0].message
    assert str(diagnostics.items[0]) == "t.ngc:2:7: error: division by zero: 'G1 X[1/0]'"
    # The failed line's assignment (#1 = 3) was skipped.
    assert store.get(1) == 5.0


def test_assignment_errors():
    store = ParameterStore(system=lambda key: 1.5 if key == 5420 else None)
    texts, diagnostics, _ = run(
        "#5420 = 1\n#5602 = 1\n#0 = 1\n#1 2\n#1.5 = 2\nG1 X#5420", store=store
    )
    assert texts == ["", "", "", "", "", "G1 X1.5"]
    messages = [d.message for d in diagnostics]
    assert "read-only" in messages[0]
    assert "outside 1 .. 5601" in messages[1] and "outside" in messages[2]
    assert "'=' expected" in messages[3]
    assert "not an integer" in messages[4]


def test_strict_mode_raises_located_errors():
    with pytest.raises(GcodeExpressionError) as info:
        run("G1 X1\nG1 X[SQRT[-4]]", mode="strict")
    assert info.value.diagnostic.line == 2 and info.value.diagnostic.column == 6
    assert str(info.value).startswith("t.ngc:2:6: error: SQRT of negative number")


def test_o_words_are_not_supported_yet():
    program = "o100 sub\n  N20 O<loop> while [#1 LT 3]\n/o1 endsub\nG1 X1 (o100 call)\nG1 X2 ; O100"
    texts, diagnostics, _ = run(program)
    assert texts == ["", "", "", "G1 X1 (o100 call)", "G1 X2 ; O100"]
    assert [(d.line, d.column, d.message) for d in diagnostics] == [
        (1, 1, O_WORD_MESSAGE), (2, 7, O_WORD_MESSAGE), (3, 2, O_WORD_MESSAGE)
    ]
    with pytest.raises(GcodeSyntaxError, match="issue #4"):
        run("O100 sub", mode="strict")


def test_limits():
    deep = "G1 X" + "[" * 100 + "1" + "]" * 100
    texts, diagnostics, _ = run(deep + "\nG1 X" + "[" * 10_000 + "1" + "]" * 10_000)
    assert texts == ["", ""]
    assert "nested deeper" in diagnostics.items[0].message
    assert "longer than" in diagnostics.items[1].message
    with pytest.raises(GcodeLimitError):
        run(deep, mode="strict")
    with pytest.raises(GcodeLimitError):
        run("G1 X" + "[" * 10_000 + "1" + "]" * 10_000, mode="strict")


def test_flavor_without_parameters_passes_lines_through():
    marlin = Flavor("marlin", line_comments=(";",), parameters=False)
    texts, diagnostics, _ = run("G1 X#1 [1/0]\nO100 sub", flavor=marlin)
    assert texts == ["G1 X#1 [1/0]", "O100 sub"]
    assert len(diagnostics) == 0


# --- Hypothesis: nothing but gcodekit errors, and never in lenient mode ---

TOKENS = ["G1", " ", "X", "Y", "#", "#1", "#<a>", "=", "[", "]", "1", ".5", "-", "+", "*",
          "/", "**", "(", ")", ";", "SIN", "ATAN", "EXISTS", "MOD", "o", "N10", "<", ">",
          "#<_g>", "##", "0", "/[", "\t", "e", "EQ"]
line_text = st.one_of(
    st.lists(st.sampled_from(TOKENS), max_size=40).map("".join),
    st.text(max_size=120),
    st.binary(max_size=120).map(lambda b: b.decode("utf-8", "replace")),
    st.binary(max_size=120).map(lambda b: b.decode("latin-1")),
)
programs = st.lists(line_text, min_size=1, max_size=8)


@settings(max_examples=300, deadline=None)
@given(program=programs)
def test_random_programs_in_lenient_mode_never_raise(program):
    lines = [SourceLine(text, n, "r.ngc") for n, text in enumerate(program, 1)]
    diagnostics = Diagnostics("r.ngc")
    out = list(ParameterStage(NGC).process(lines, diagnostics))
    assert [s.line for s in out] == [s.line for s in lines]
    for d in diagnostics:
        assert 1 <= d.column <= len(lines[d.line - 1].text) + 1
    # A line that went through holds no parameter or expression outside comments.
    for s in out:
        if not _O_WORD_LINE.match(s.text):
            assert not needs_parameters(code_part(s.text)), s.text


_O_WORD_LINE = re.compile(r"[ \t]*(/[ \t]*)?([nN][0-9. \t]*)?[oO]")


def code_part(text: str) -> str:
    """``text`` without ``( ... )`` and ``;`` comments."""
    code, depth = [], False
    for c in text:
        if depth:
            depth = c != ")"
        elif c == "(":
            depth = True
        elif c == ";":
            break
        else:
            code.append(c)
    return "".join(code)


@settings(max_examples=300, deadline=None)
@given(program=programs)
def test_random_programs_in_strict_mode_raise_only_gcodekit_errors(program):
    lines = [SourceLine(text, n, "r.ngc") for n, text in enumerate(program, 1)]
    try:
        list(ParameterStage(NGC).process(lines, Diagnostics("r.ngc", mode="strict")))
    except GcodeError as exc:
        assert exc.diagnostic is not None and exc.diagnostic.file == "r.ngc"


@settings(max_examples=200, deadline=None)
@given(
    values=st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=5),
)
def test_substituted_values_read_back_exactly(values):
    program = "\n".join(f"#{n} = [{format_number(v)}]" for n, v in enumerate(values, 1))
    program += "\nG1 " + " ".join(f"X#{n}" for n in range(1, len(values) + 1))
    texts, diagnostics, _ = run(program)
    assert len(diagnostics) == 0
    words = texts[-1].split()[1:]
    assert [float(w[1:]) for w in words] == [v + 0.0 for v in values]
    assert all(math.isfinite(float(w[1:])) for w in words)


def test_program_with_parameters_runs_through_the_pipeline():
    import gcodekit

    text = "#1 = 10\n#<depth> = -2\nG21 G0 X#1 Y[#1 / 4]\nG1 Z#<depth> F[60 * 2]\nO100 (a Fanuc program number)\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc")
    assert op.motions()[["x", "y", "z"]].values.tolist() == [[10, 2.5, 0], [10, 2.5, -2]]
    assert op.motions()["feed"].iloc[1] == 120
    assert not [d for d in op.diagnostics if d.severity == "error"]


def test_o_word_flow_runs_even_without_parameters():
    import gcodekit

    op = gcodekit.gcode_to_operation("o100 sub\nG1 X1 F10\no100 endsub\no100 call\no100 call\n", "linuxcnc",
                                     plan=False)
    assert op.motions()["line"].tolist() == [2, 2]
    assert not [d for d in op.diagnostics if d.severity == "error"]
