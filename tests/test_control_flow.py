"""Preprocess stage: O-word control flow executed into plain lines.

Semantics follow LinuxCNC 2.9 (``interp_o_word.cc`` and the O Codes page):
subroutines with local #1..#30 and named locals, return values in
``#<_value>``, loops, conditionals, subroutine files, Fanuc M98/M99, and
limits that end runaway programs with an error naming the line.
"""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.errors import Diagnostics, GcodeError, GcodeLimitError, GcodeSyntaxError
from gcodekit.preprocess import ControlFlowStage, ParameterStore, SourceLine
from gcodekit.syntax import load_flavor
from gcodekit.syntax.flavor import Flavor

NGC = Flavor("ngc", line_comments=(";",), paren_comments=True, parameters=True)


def run(program: str, *, mode: str = "strict", file: str = "t.ngc", **options):
    """``[(line, text), ...]`` emitted, and the diagnostics."""
    diagnostics = Diagnostics(file, mode=mode)
    lines = [SourceLine(t, n, file) for n, t in enumerate(program.strip("\n").split("\n"), 1)]
    stage = ControlFlowStage(options.pop("flavor", NGC), **options)
    out = [(s.line, s.text) for s in stage.process(lines, diagnostics)]
    return out, diagnostics


def texts(program: str, **options) -> list[str]:
    return [t for _, t in run(program, **options)[0]]


def test_while_loop_emits_computed_moves_pointing_at_the_body_line():
    out, diagnostics = run("""
#1 = 0
o101 while [#1 LT 3]
  G1 X[#1 * 2 + 1] F100
  #1 = [#1 + 1]
o101 endwhile
M2
G0 X99
""")
    assert out == [(3, "  G1 X1 F100"), (3, "  G1 X3 F100"), (3, "  G1 X5 F100"), (6, "M2")]
    assert not diagnostics.items


def test_nested_calls_with_arguments_and_return_values():
    program = """
o<double> sub
  o<double> return [#1 * 2]
o<double> endsub
o<quad> sub
  #<half> = #1
  o<double> call [#1]
  o<double> call [#<_value>]
  G0 X#<_value> Y#1 Z#<half>
o<quad> endsub [#<_value> + 1]
#1 = 7
#<half> = 100
o<quad> call [3]
G1 X#<_value> Y#1 Z#<half> A#<_value_returned>
"""
    assert texts(program) == ["  G0 X12 Y3 Z3", "G1 X13 Y7 Z100 A1"]


def test_value_is_cleared_by_the_next_call():
    program = """
o1 sub
  o1 return [5]
o1 endsub
o2 sub
o2 endsub
o1 call
o2 call
G0 X#<_value> Y#<_value_returned>
"""
    assert texts(program) == ["G0 X0 Y0"]


def test_call_arguments_keep_the_callers_higher_parameters_and_restore_all():
    program = """
#1 = 1
#2 = 2
#31 = 0
o1 sub
  G0 X#1 Y#2
  #2 = 20
  #31 = 31
o1 endsub
o1 call [9]
G0 X#1 Y#2 Z#31
"""
    assert texts(program) == ["  G0 X9 Y2", "G0 X1 Y2 Z31"]


def test_local_named_parameters_are_not_seen_by_the_subroutine():
    program = """
#<depth> = 1
o1 sub
  G0 Z#<depth>
o1 endsub
o1 call
"""
    _, diagnostics = run(program, mode="lenient")
    assert [(d.line, "not defined" in d.message) for d in diagnostics.errors] == [(3, True)]
    assert texts("#<_depth> = 1\no1 sub\nG0 Z#<_depth>\no1 endsub\no1 call") == ["G0 Z1"]


def test_repeat_and_if_elseif_else_chain():
    program = """
#1 = 0
o1 repeat [4]
  o2 if [#1 EQ 0]
    G0 X0
  o2 elseif [#1 LT 2]
    G0 X1
  o2 elseif [#1 EQ 2]
    G0 X2
  o2 else
    G0 X9
  o2 endif
  #1 = [#1 + 1]
o1 endrepeat
"""
    assert texts(program) == ["    G0 X0", "    G0 X1", "    G0 X2", "    G0 X9"]


def test_do_while_break_and_continue():
    program = """
#1 = 0
o1 do
  #1 = [#1 + 1]
  o2 if [#1 EQ 2]
    o1 continue
  o2 endif
  o3 if [#1 EQ 4]
    o1 break
  o3 endif
  G0 X#1
o1 while [#1 LT 10]
G0 Y#1
"""
    assert texts(program) == ["  G0 X1", "  G0 X3", "G0 Y4"]


def test_do_runs_once_and_repeat_zero_not_at_all():
    assert texts("o1 do\nG0 X1\no1 while [0]\no2 repeat [0]\nG0 X2\no2 endrepeat") == ["G0 X1"]


def test_subroutine_file_on_the_search_path(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "square.ngc").write_text(
        "(a square of side #1)\no<square> sub\nG1 X#1\nG1 Y#1\no<square> endsub [#1 * 4]\nM2\n")
    program = "o<Square> call [5]\nG0 Z#<_value>"
    out, _ = run(program, search_path=[tmp_path / "lib"])
    assert out == [(3, "G1 X5"), (4, "G1 Y5"), (2, "G0 Z20")]
    diagnostics = Diagnostics("t.ngc", mode="strict")
    stage = ControlFlowStage(NGC, search_path=[tmp_path / "lib"])
    emitted = list(stage.process([SourceLine("o<square> call [1]", 1, "t.ngc")], diagnostics))
    assert {s.file for s in emitted} == {str(tmp_path / "lib" / "square.ngc")}


def test_the_programs_own_directory_is_searched_first(tmp_path):
    (tmp_path / "peck.ngc").write_text("o<peck> sub\nG0 Z1\no<peck> endsub\n")
    main = tmp_path / "main.ngc"
    main.write_text("o<peck> call\n")
    out, _ = run("o<peck> call", file=str(main))
    assert out == [(2, "G0 Z1")]


def test_errors_in_a_subroutine_file_name_that_file(tmp_path):
    (tmp_path / "bad.ngc").write_text("o<bad> sub\nG0 X[1/0]\no<bad> endsub\n")
    with pytest.raises(GcodeError, match=r"bad\.ngc:2:7: .*division by zero"):
        run("o<bad> call", search_path=[tmp_path])


def test_unknown_subroutine_is_an_error_with_a_suggestion():
    with pytest.raises(GcodeSyntaxError, match=r"t\.ngc:3:1: .*unknown subroutine o<probe>.*did you mean 'o<prob>'"):
        run("o<prob> sub\no<prob> endsub\no<probe> call")
    out, diagnostics = run("o<nothing> call\nG0 X1", mode="lenient")
    assert out == [(2, "G0 X1")] and len(diagnostics.errors) == 1


def test_file_names_cannot_leave_the_search_path(tmp_path):
    (tmp_path / "x.ngc").write_text("o<x> sub\no<x> endsub\n")
    (tmp_path / "sub").mkdir()
    for name in ("../x", "sub/../../x", "..\\x", "/etc/passwd"):
        _, diagnostics = run(f"o<{name}> call", mode="lenient", search_path=[tmp_path / "sub"])
        assert len(diagnostics.errors) == 1
        assert "called by its name, not a path" in diagnostics.errors[0].message


def test_subroutine_files_linked_from_elsewhere_are_not_read(tmp_path):
    outside = tmp_path / "outside.ngc"
    outside.write_text("o<x> sub\nG0 X9\no<x> endsub\n")
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "x.ngc").symlink_to(outside)
    out, diagnostics = run("o<x> call", mode="lenient", search_path=[tmp_path / "lib"])
    assert out == [] and "links to a file outside" in diagnostics.items[0].message


@pytest.mark.parametrize("program, line, message", [
    ("G0 X1\no1 endsub", 2, "without a matching o1 sub"),
    ("o1 while [1]\no2 endwhile\no1 endwhile", 2, "without a matching o2 while"),
    ("o1 else\nG0 X1", 1, "without a matching o1 if"),
    ("o1 if [1]\nG0 X1", 1, "not closed by o1 endif"),
    ("o1 repeat [2]\no1 endwhile", 2, "without a matching o1 while"),
    ("o1 if [1]\no1 else\no1 elseif [1]\no1 endif", 3, "after o1 else"),
    ("o1 break", 1, "without a matching o1 while or do"),
    ("o1 repeat [2]\no2 if [0]\no1 break\no2 endif\no1 endrepeat", 3, "without a matching o1 while or do"),
    ("o1 return", 1, "not inside a subroutine"),
    ("o1 sub\no2 sub\no2 endsub\no1 endsub", 2, "cannot be nested"),
    ("o1 frobnicate", 1, "unknown O-word keyword 'frobnicate'"),
    ("o1 if", 1, "needs a value"),
])
def test_structure_errors_name_the_line(program, line, message):
    with pytest.raises(GcodeError, match=rf"t\.ngc:{line}:\d+: .*{message}"):
        run(program)
    _, diagnostics = run(program, mode="lenient")
    assert any(d.line == line and message in d.message for d in diagnostics.errors)


def test_lenient_mode_ignores_a_stray_end_and_goes_on():
    out, diagnostics = run("G0 X1\no5 endwhile\nG0 X2", mode="lenient")
    assert [t for _, t in out] == ["G0 X1", "G0 X2"] and len(diagnostics.errors) == 1


def test_recursion_limit_names_the_call_line():
    program = """
o<down> sub
  G0 Z#1
  o<down> call [#1 + 1]
o<down> endsub
o<down> call [1]
"""
    with pytest.raises(GcodeLimitError, match=r"t\.ngc:3:3: .*nested deeper than 9 levels"):
        run(program)
    out, diagnostics = run(program, mode="lenient")
    assert [t.strip() for _, t in out] == [f"G0 Z{k}" for k in range(1, 10)]
    assert diagnostics.errors[0].line == 3


def test_bounded_recursion_returns_through_every_level():
    program = """
o<fact> sub
  o1 if [#1 LE 1]
    o<fact> return [1]
  o1 endif
  o<fact> call [#1 - 1]
  o<fact> return [#1 * #<_value>]
o<fact> endsub
o<fact> call [6]
G0 X#<_value>
"""
    assert texts(program) == ["G0 X720"]


def test_infinite_loop_hits_the_iteration_limit():
    with pytest.raises(GcodeLimitError, match=r"t\.ngc:2:1: .*more than max_iterations=100,000 loop iterations"):
        run("o1 while [1]\no1 endwhile")
    with pytest.raises(GcodeLimitError, match=r"t\.ngc:3:1: .*more than max_iterations=10,000 loop iterations"):
        run("o1 while [1]\n#1 = [#1 + 1]\no1 endwhile", max_iterations=10_000)
    out, diagnostics = run("o1 do\nG0 X1\no1 while [1]\nG0 X2", mode="lenient", max_iterations=5)
    assert len(out) == 6 and diagnostics.errors[0].line == 3


def test_executed_line_limit_bounds_fan_out_without_loops():
    subs = "\n".join(f"o{k} sub\n" + f"o{k + 1} call\n" * 10 + f"o{k} endsub" for k in range(1, 8))
    with pytest.raises(GcodeLimitError, match="more than 10000 lines executed"):
        run(subs + "\no8 sub\nG0 X1\no8 endsub\no1 call", max_lines=10_000)


def test_program_end_stops_inside_a_subroutine():
    assert texts("o1 sub\nG0 X1\nM30\no1 endsub\no1 call\nG0 X2") == ["G0 X1", "M30"]


def test_computed_call_label_and_comments_on_o_lines():
    program = "o102 sub (two)\nG0 X2\no102 endsub\n#101 = 100\no[#101 + 2] call (computed)"
    assert texts(program) == ["G0 X2"]


def test_assignments_on_a_line_see_old_values_inside_loops():
    program = "#1 = 1\n#2 = 0\no1 repeat [2]\n#1 = [#1 + 1] #2 = #1 G0 X#1 Y#2\no1 endrepeat"
    assert texts(program) == ["G0 X1 Y0", "G0 X2 Y1"]


def test_store_is_shared_with_the_caller():
    store = ParameterStore()
    stage = ControlFlowStage(NGC, store)
    list(stage.process([SourceLine("#<_done> = 1", 1, "t.ngc")], Diagnostics()))
    assert store.get("_done") == 1.0 and store.call_depth == 0


FANUC = load_flavor("fanuc")


def test_fanuc_m98_with_repeats_and_m99():
    program = """
%
O0001 (MAIN)
#1 = 0;
M98 P1000 L3;
G0 X#1;
M30;
O1000 (SUB)
#1 = [#1 + 1];
G1 X#1;
M98 P2000;
M99;
O2000
G1 Y#1;
M99;
%
"""
    out, diagnostics = run(program, flavor=FANUC)
    assert [t for _, t in out] == ["%", "G1 X1;", "G1 Y1;", "G1 X2;", "G1 Y2;", "G1 X3;", "G1 Y3;", "G0 X3;", "M30;"]
    assert not diagnostics.items


def test_fanuc_m98_l0_and_unknown_program():
    assert texts("M98 P1 L0\nG0 X1\nM30\nO1\nG0 X9\nM99", flavor=FANUC) == ["G0 X1", "M30"]
    with pytest.raises(GcodeError, match="unknown program o77"):
        run("M98 P77", flavor=FANUC)


def test_subprograms_called_in_the_other_style_are_reported_at_their_definition():
    # rs274 2.9 (tests/interp m98m99/06-error-mixed-sub-styles) reports these where the sub begins
    with pytest.raises(GcodeError, match=r"t.ngc:4:1: .*o1 must be called with M98.*called on line 1"):
        run("o1 call\nM30\n%\nO1\nG0 X1\nM99", flavor=load_flavor("rs274ngc"))
    with pytest.raises(GcodeError, match=r"t.ngc:4:1: error: 'o1 sub' must be called with 'o1 call'.*called on line 1"):
        run("M98 P1\nM30\n%\no1 sub\nG0 X1\no1 endsub", flavor=load_flavor("rs274ngc"))


def test_m98_alone_runs_the_subprogram_stage():
    # a program whose only flow is M98 still gets its subprograms (no O-word line starts it)
    op = gcodekit.gcode_to_operation("G21\nM98 P5\nM30\n", "linuxcnc", plan=False)
    assert ["call of unknown program o5" in d.message for d in op.diagnostics.items] == [True]


def test_m99_in_the_main_program_ends_it_with_a_warning():
    out, diagnostics = run("G0 X1\nM99\nG0 X2", flavor=FANUC)
    assert [t for _, t in out] == ["G0 X1"] and diagnostics.items[0].severity == "warning"


def test_pipeline_runs_o_word_programs():
    import gcodekit

    program = "G21 G90\n#1 = 0\no1 while [#1 LT 3]\nG1 X[#1 + 1] F600\n#1 = [#1 + 1]\no1 endwhile\nM2\n"
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False, mode="strict")
    motions = op.motions()
    assert motions["x"].tolist() == [1.0, 2.0, 3.0]
    assert motions["line"].tolist() == [4, 4, 4]


# -- never hang, never crash -------------------------------------------------

_FLOW = ["sub", "endsub", "call", "return", "if", "elseif", "else", "endif", "while", "endwhile",
         "do", "repeat", "endrepeat", "break", "continue", ""]
_VALUES = ["", " [1]", " [0]", " [#1 LT 3]", " [#1 + 1]", " [#<_value>]", " [1/0]", " [2]", " [#1]"]
_LINES = st.one_of(
    st.builds(lambda n, k, v: f"o{n} {k}{v}", st.sampled_from([1, 2, 3]), st.sampled_from(_FLOW),
              st.sampled_from(_VALUES)),
    st.sampled_from(["#1 = [#1 + 1]", "G0 X#1", "G1 X[#1 * 2] Y#<_value>", "M2", "M98 P1 L2", "M99",
                     "#<_x> = #1", "G0 Y#<_x>", "O1", "o<rec> call", "(comment)"]),
)


@settings(max_examples=300, deadline=None)
@given(st.lists(_LINES, max_size=25))
def test_random_flow_never_hangs_and_raises_only_gcodekit_errors(program):
    lines = [SourceLine(t, n, "r.ngc") for n, t in enumerate(program, 1)]
    stage = ControlFlowStage(NGC, max_iterations=200, max_lines=5_000)
    try:
        out = list(stage.process(lines, Diagnostics("r.ngc", mode="strict")))
    except GcodeError:
        return
    assert len(out) <= 5_000
    lenient = Diagnostics("r.ngc", mode="lenient")
    list(ControlFlowStage(NGC, max_iterations=200, max_lines=5_000).process(lines, lenient))


def test_return_with_another_label_leaves_the_sub_like_rs274():
    """LinuxCNC's retval.ngc: ``o1010 return [v]`` inside ``o1000 sub`` returns v from o1000."""
    text = ("o1000 sub\no1010 if [#1 GT 0]\no1010 return [123*#1]\no1010 endif\no1000 endsub [4712]\n"
            "o1000 call [0]\nG0 X#<_value>\no1000 call [2]\nG0 X#<_value>\nM2\n")
    import gcodekit

    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    assert op.motions()["x"].tolist() == [4712.0, 246.0]
    assert not op.diagnostics.items


def test_abort_comment_stops_with_its_message_where_it_runs() -> None:
    """LinuxCNC's ``(abort, ...)``: an error on the line that runs it, its parameters filled in (%f)."""
    import gcodekit

    text = ("#42 = 0\no100 while [#42 lt 5]\no200 if [#42 eq 3]\n(abort, at #42 of #<_n>)\no200 endif\n"
            "#42 = [#42 + 1]\no100 endwhile\nM2\n")
    op = gcodekit.gcode_to_operation(text, machine="linuxcnc", plan=False)
    assert [(d.line, d.message) for d in op.diagnostics.errors] == [(4, "program aborted: at 3.000000 of #<_n>")]
    quiet = gcodekit.gcode_to_operation("(not an abort, just a comment)\nG0 X1\nM2\n", machine="linuxcnc", plan=False)
    assert not quiet.diagnostics.errors


def test_subroutine_path_and_comments_between_call_arguments(tmp_path) -> None:
    """A subroutine file found on the machine's ``subroutine_path`` (a string splits at ':', as
    LinuxCNC's SUBROUTINE_PATH), called with a comment between its arguments, which rs274 skips."""
    import gcodekit

    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "go.ngc").write_text("o<go> sub\nG1 X#1 Y#2 F100\no<go> endsub\nM2\n")
    main = tmp_path / "main.ngc"
    main.write_text("o<go> call [3] (the Y next) [4]\nM2\n")
    op = gcodekit.gcode_to_operation(main, machine="linuxcnc", plan=False, subroutine_path=f"/nowhere:{subs}")
    assert not op.diagnostics.errors
    last = op.motions().iloc[-1]
    assert (last.x, last.y) == (3.0, 4.0)
    missing = gcodekit.gcode_to_operation(main, machine="linuxcnc", plan=False)
    # not found without the path: rs274 reports it where its search ends, the file's last line
    assert [d.line for d in missing.diagnostics.errors] == [2]
    assert "o<go> (called on line 1)" in missing.diagnostics.errors[0].message


def test_a_named_program_line_is_its_name() -> None:
    """``O<name>`` alone names the program as ``O1234`` does (LinuxCNC's tests/interp 13-named-program)."""
    import gcodekit

    op = gcodekit.gcode_to_operation("%\nO<MyProgram> (a name)\nG0 X1\nM30\n%\n", machine="linuxcnc", plan=False)
    assert not op.diagnostics.items
    assert op.motions().iloc[-1].x == 1.0


def test_call_level_counts_the_nested_calls():
    # rs274 2.9: 0 in the main program, 1 in a sub it calls, 2 in a sub that one calls
    program = """o<b> sub
G0 X#<_call_level>
o<b> endsub
o<a> sub
G0 X#<_call_level>
o<b> call
o<a> endsub
G0 X#<_call_level>
o<a> call
G0 X#<_call_level>
"""
    assert texts(program) == ["G0 X0", "G0 X1", "G0 X2", "G0 X0"]
