"""GER wizards: registry, the WizardStage and the built-in toolpaths."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.errors import (
    ConfigError,
    Diagnostics,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    GcodeSyntaxError,
)
from gcodekit.preprocess import SourceLine
from gcodekit.preprocess.wizards import (
    DEFAULT_REGISTRY,
    WizardArgumentError,
    WizardContext,
    WizardError,
    WizardRegistry,
    WizardStage,
    WizardWarning,
    needs_wizards,
    register_wizard,
    unregister_wizard,
    wizard,
    wizards,
)
from gcodekit.syntax import load_flavor

GER = load_flavor("ger")
TOOL_MM = 6.35  # the documented default tool diameter
BUILTINS = ["BoltCircle", "CirclePocket", "DrillGrid", "Face", "Pocket"]


def expand(text: str, *, mode: str = "lenient", registry=None, **kwargs):
    """Run the stage over ``text``; (emitted lines, diagnostics)."""
    diagnostics = Diagnostics("part.ger", mode)
    lines = [SourceLine(t, k, "part.ger") for k, t in enumerate(text.split("\n"), 1)]
    out = list(WizardStage(GER, registry, **kwargs).process(lines, diagnostics))
    return out, diagnostics


def cuts(op):
    """Rows of feed moves below the surface."""
    df = op.to_dataframe()
    return df[(df.code.isin(["G1", "G2", "G3"])) & (df.z < 0)]


@pytest.fixture
def registered():
    """Names registered by a test in the default registry; removed afterwards."""
    names: list[str] = []
    yield names
    for name in names:
        if name in DEFAULT_REGISTRY:
            unregister_wizard(name)


# -- the manual's example, emulated -------------------------------------------


@pytest.mark.parametrize("stepdown, passes", [(None, math.ceil(10 / (TOOL_MM / 2))), (2.5, 4), (3.0, 4), (10, 1)])
def test_manual_pocket_expands_and_emulates(stepdown, passes):
    call = "Pocket 75.0 30.0 10.0" + ("" if stepdown is None else f" {stepdown}")
    op = gcodekit.gcode_to_operation(f"G21\n{call}\nG0 X0 Y0\n", "ger", plan=False)
    assert not op.diagnostics.errors
    r = TOOL_MM / 2
    c = cuts(op)
    # The tool centre stays inside the outline shrunk by the tool radius and reaches its walls.
    assert c.x.min() == pytest.approx(-37.5 + r) and c.x.max() == pytest.approx(37.5 - r)
    assert c.y.min() == pytest.approx(-15 + r) and c.y.max() == pytest.approx(15 - r)
    assert c.z.min() == pytest.approx(-10.0)
    assert len(np.unique(c.z.round(6))) == passes
    bounds = op.get_bounds("feed")
    assert bounds["min"][0] >= -37.5 + r - 1e-6 and bounds["max"][1] <= 15 - r + 1e-6
    # Every emitted move points at the call; the tool ends above the part.
    assert set(op.to_dataframe().line) == {1, 2, 3}
    assert op.to_dataframe().query("line == 2").z.iloc[-1] > 0


def test_pocket_rows_cover_the_floor():
    op = gcodekit.gcode_to_operation("G21\nPocket 40 20 2 2 2\n", "ger", plan=False)
    rows = np.unique(cuts(op).y.round(6))
    assert np.diff(rows).max() <= 2 + 1e-9  # the stepover
    assert rows[0] == pytest.approx(-10 + TOOL_MM / 2) and rows[-1] == pytest.approx(10 - TOOL_MM / 2)


def test_pocket_in_inches_uses_a_quarter_inch_tool():
    op = gcodekit.gcode_to_operation("G20\nPocket 3 1.2 0.4\n", "ger", plan=False)
    c = cuts(op)  # emulated positions are in mm
    assert c.x.max() == pytest.approx((1.5 - 0.125) * 25.4)
    assert c.z.min() == pytest.approx(-0.4 * 25.4)


def test_circle_pocket_stays_inside_the_circle():
    op = gcodekit.gcode_to_operation("G21\nCirclePocket 40 6 3\n", "ger", plan=False)
    assert not op.diagnostics.errors
    bounds = op.get_bounds("feed")
    edge = 20 - TOOL_MM / 2
    assert bounds["min"][:2] == pytest.approx([-edge, -edge]) and bounds["max"][:2] == pytest.approx([edge, edge])
    assert bounds["min"][2] == pytest.approx(-6)
    c = cuts(op)
    assert len(np.unique(c.z.round(6))) == 2
    assert (c.code == "G3").sum() > 0


def test_drill_grid_and_bolt_circle_holes():
    op = gcodekit.gcode_to_operation("G21\nDrillGrid 3 2 10 15 5\nBoltCircle 4 50 3 90\n", "ger", plan=False)
    assert not op.diagnostics.errors
    df = op.to_dataframe()
    grid = df[(df.line == 2) & (df.code == "G1")]
    assert sorted(zip(grid.x.round(6), grid.y.round(6))) == [(x, y) for x in (0, 10, 20) for y in (0, 15)]
    assert (grid.z == -5).all()
    bolts = df[(df.line == 3) & (df.code == "G1")]
    assert np.allclose(bolts[["x", "y"]].to_numpy(), [[0, 25], [-25, 0], [0, -25], [25, 0]], atol=1e-4)
    assert (bolts.z == -3).all()


def test_drill_grid_pecks():
    out, diags = expand("G21\nDrillGrid 1 1 0 0 5 2")
    plunges = [s.text for s in out if s.text.startswith("G1 Z")]
    assert [p.split()[1] for p in plunges] == ["Z-2", "Z-4", "Z-5"]
    assert not diags.items


def test_face_covers_the_rectangle():
    op = gcodekit.gcode_to_operation("G21\nFace 100 50 1 0.5\n", "ger", plan=False)
    c = cuts(op)
    r = TOOL_MM / 2
    assert c.x.min() == pytest.approx(-r) and c.x.max() == pytest.approx(100 + r)
    assert c.y.min() == pytest.approx(0) and c.y.max() == pytest.approx(50)
    assert np.unique(c.z.round(6)).tolist() == [-1.0, -0.5]


@pytest.mark.parametrize("call", ["Pocket 75 30 10", "CirclePocket 40 6 3 1.5", "DrillGrid 3 2 10 15 5 2",
                                  "BoltCircle 6 50 3", "Face 100 50 1 0.5 4"])
def test_builtin_output_is_plain_gcode_for_ger_and_rs274ngc(call):
    out, diags = expand(f"G21\nG91\n{call}\nG90")
    assert not diags.items
    text = "\n".join(s.text for s in out) + "\n"
    assert text.splitlines()[2] == "G90" and text.splitlines()[-2] == "G91"  # incremental program
    assert not needs_wizards(text)
    words = {w[0] for line in text.splitlines() for w in line.split()}
    assert words <= set("GXYZIJF")
    for flavor, machine in (("ger", "ger"), ("rs274ngc", "linuxcnc")):
        op = gcodekit.gcode_to_operation(text, machine, flavor=flavor, mode="strict", plan=False)
        assert len(op.to_dataframe()) > 3


# -- the stage ----------------------------------------------------------------


def test_emitted_lines_keep_the_call_line_and_file():
    out, diags = expand("G21\n(a note)\n  pocket 20 20 1\nG0 X0")
    assert [s.line for s in out if s.line == 3] and all(s.file == "part.ger" for s in out)
    assert out[0].text == "G21" and out[-1].text == "G0 X0" and out[-1].line == 4
    assert {s.line for s in out[2:-1]} == {3}  # case-insensitive name
    assert not diags.items


def test_comments_are_not_calls():
    text = "G21 (a comment\nPocket 75 30 10\nthat spans lines)\nG0 X1 (Face 1 1 1)\nPocket 20 20 1 (note\nstill a note)"
    out, diags = expand(text)
    assert not diags.items
    assert [s.text for s in out[:4]] == text.split("\n")[:4]
    assert (out[-2].text, out[-2].line, out[-1].text) == ("(", 5, "still a note)")  # the comment goes on
    op = gcodekit.gcode_to_operation(text, "ger", plan=False)
    df = op.to_dataframe()
    assert not op.diagnostics.items and set(df[df.kind != "comment"].line) == {1, 4, 5}


def test_context_follows_units_distance_and_tool():
    seen: list[WizardContext] = []
    reg = WizardRegistry(builtins=False)
    reg.register("Probe", lambda ctx: seen.append(ctx) or [])
    text = "Probe\nG21 G91\nProbe\nM6 T2\nG20\nProbe\nG90 (G91)\nProbe"
    expand(text, registry=reg, settings={"tool_diameter": 3.0, "tools": {2: 12.7}})
    assert [(c.units, c.distance) for c in seen] == [("inch", "absolute"), ("mm", "incremental"),
                                                     ("inch", "incremental"), ("inch", "absolute")]
    assert seen[0].tool_diameter == pytest.approx(3 / 25.4) and seen[1].tool_diameter == 3.0
    assert seen[2].tool_diameter == pytest.approx(0.5)
    assert seen[0].settings is seen[3].settings and [c.line for c in seen] == [1, 3, 6, 8]


def test_flavor_without_wizards_passes_lines_through():
    lines = [SourceLine("Pocket 1 2 3", 1, "a.ngc")]
    assert list(WizardStage(load_flavor("rs274ngc")).process(lines, Diagnostics())) == lines


# -- user wizards and the registry -----------------------------------------------


def test_user_wizard_with_a_quoted_string(registered):
    def label(ctx, text: str, height: float, *rest):
        return [f"({text} {ctx.units} {len(rest)})", f"G1 X{height} F100", "G0 Z1"]

    register_wizard("Label", label)
    registered.append("Label")
    assert wizards()["Label"] is label and list(wizards()) == sorted(wizards(), key=str.lower)
    op = gcodekit.gcode_to_operation('G21\nLABEL "Hi; x" 2.5 1 "z"\n', "ger", plan=False)
    assert not op.diagnostics.errors
    df = op.to_dataframe()
    assert df[df.code == "G1"].x.tolist() == [2.5] and set(df.line) == {1, 2}
    out, _ = expand('Label "Hi (there); x" 2.5')
    assert out[0].text == "(Hi (there); x inch 0)"


def test_decorator_and_int_arguments():
    reg = WizardRegistry(builtins=False)

    @wizard("Rows", registry=reg)
    def rows(ctx, n: int, step: float = 1.0):
        assert isinstance(n, int)
        return (f"G1 Y{k * step}" for k in range(n))

    out, diags = expand("Rows 3 2", registry=reg)
    assert [s.text for s in out] == ["G1 Y0.0", "G1 Y2.0", "G1 Y4.0"]
    _, diags = expand("Rows 2.5", registry=reg)
    assert "whole number" in diags.items[0].message and diags.items[0].column == 6


def test_clash_warns_and_keeps_the_old_one(registered):
    def mine(ctx, *args):
        return ["G0 X1"]

    with pytest.warns(WizardWarning, match="already registered"):
        register_wizard("POCKET", mine)
    assert wizards()["Pocket"] is not mine
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        register_wizard("Pocket", wizards()["Pocket"])  # the same function again: silent
        old = register_wizard("Pocket", mine, replace=True) and DEFAULT_REGISTRY.get("pocket")
    try:
        assert old is mine
        out, _ = expand("Pocket 1 2 3")
        assert [s.text for s in out] == ["G0 X1"]
    finally:
        from gcodekit.preprocess.wizards import pocket

        register_wizard("Pocket", pocket, replace=True)
    assert sorted(wizards()) == BUILTINS


def test_registry_rejects_bad_names_and_reports_unknown_ones():
    reg = WizardRegistry()
    for bad in ("P1", "X", "1Pocket", "Pock et", ""):
        with pytest.raises(ConfigError):
            reg.register(bad, lambda ctx: [])
    with pytest.raises(TypeError):
        reg.register("Fine", "not callable")
    with pytest.raises(KeyError, match="did you mean 'Pocket'"):
        reg.unregister("Pockt")
    assert reg.unregister("face") is not None and "Face" not in reg and len(reg) == 4


# -- errors ---------------------------------------------------------------------


@pytest.mark.parametrize("call, column, kind, words", [
    ("Pocket 75 30", 1, GcodeSyntaxError, "takes 3 to 5 arguments (width height depth [stepdown] [stepover]); got 2"),
    ("Pocket 75 30 10 1 1 1", 1, GcodeSyntaxError, "got 6 arguments"),
    ('Pocket 75 "wide" 10', 11, GcodeExpressionError, "height must be a number"),
    ("Pocket 75 30 1O", 14, GcodeSyntaxError, "'1O' is neither a number"),
    ('Pocket 75 30 "10', 14, GcodeSyntaxError, "closing"),
    ("Pocket 75 30 10;G0 X1", 16, GcodeSyntaxError, "run to the end of the line"),
    ('Pocket 75 30 10 "a"1', 20, GcodeSyntaxError, "expected a space"),
    ("Pocket75 30 10", 1, GcodeSyntaxError, "unknown wizard 'Pocket75' (did you mean 'Pocket'?)"),
    ("  Pockt 75 30 10", 3, GcodeSyntaxError, "did you mean 'Pocket'"),
    ("Pocket 2 30 10", 8, GcodeExpressionError, "width 2 is less than the tool diameter"),
    ("Pocket 75 30 -1", 14, GcodeExpressionError, "depth must be positive"),
    ("Pocket 75 30 10 2 9", 19, GcodeExpressionError, "stepover must be"),
    ("DrillGrid 0 1 1 1 1", 11, GcodeExpressionError, "nx must be at least 1"),
    ("DrillGrid 1.5 1 1 1 1", 11, GcodeExpressionError, "whole number"),
])
def test_argument_errors_name_line_and_column(call, column, kind, words):
    out, diags = expand(f"G21\n{call}\nG0 X1")
    assert [s.text for s in out] == ["G21", "G0 X1"]
    (d,) = diags.items
    assert (d.line, d.column) == (2, column) and words in d.message and d.text == call
    with pytest.raises(kind) as info:
        expand(f"G21\n{call}", mode="strict")
    assert f"part.ger:2:{column}:" in str(info.value)


def test_unknown_wizard_through_the_pipeline():
    op = gcodekit.gcode_to_operation("G21\nPokcet 75 30 10\nG1 X1 F100\n", "ger", plan=False)
    (d,) = op.diagnostics.errors
    assert (d.line, d.column) == (2, 1) and "did you mean 'Pocket'" in d.message
    with pytest.raises(GcodeSyntaxError, match="<string>:2:1"):
        gcodekit.gcode_to_operation("G21\nPokcet 75 30 10\n", "ger", mode="strict", plan=False)


def test_a_failing_wizard_is_a_diagnostic_or_a_gcode_error():
    reg = WizardRegistry(builtins=False)
    reg.register("Boom", lambda ctx, x: [f"G0 X{1 / x}"])
    reg.register("Bad", lambda ctx: ["G0 X1", 3])
    reg.register("Arg", lambda ctx, a, b: (_ for _ in ()).throw(WizardArgumentError("b is silly", 1)))
    out, diags = expand("Boom 0\nBoom 2\nBad\nArg 1 2", registry=reg)
    assert [s.text for s in out] == ["G0 X0.5"]
    assert "wizard Boom failed: ZeroDivisionError: float division by zero" in diags.items[0].message
    assert "not a line of text" in diags.items[1].message
    assert (diags.items[2].column, diags.items[2].message) == (7, "Arg: b is silly")
    with pytest.raises(WizardError) as info:
        expand("G0\nBoom 0", registry=reg, mode="strict")
    assert isinstance(info.value, GcodeError) and isinstance(info.value.__cause__, ZeroDivisionError)
    assert (info.value.diagnostic.line, info.value.diagnostic.column) == (2, 1)


def test_output_limit_stops_runaway_wizards():
    reg = WizardRegistry()
    reg.register("Forever", lambda ctx: iter(lambda: "G0 X1", None))
    out, diags = expand("Forever\nPocket 75 30 10 0.01\nG0 X2", registry=reg, max_lines=1000)
    assert [s.text for s in out] == ["G0 X2"]
    assert all("more than 1000 lines" in d.message for d in diags.items) and len(diags.items) == 2
    with pytest.raises(GcodeLimitError):
        expand("Forever", registry=reg, max_lines=1000, mode="strict")
    _, diags = expand("Pocket 75 30 1e-300")  # no exponent in GER numbers
    assert "neither a number" in diags.items[0].message
    _, diags = expand("Pocket 75 30 100000000 0.0000001")
    assert "steps" in diags.items[0].message and diags.items[0].column == 14


# -- random calls -----------------------------------------------------------------

_NUMBERS = st.one_of(st.integers(-5, 200).map(str), st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: f"{v:.6f}"),
                     st.sampled_from(["0", "-0", ".5", "1.", "+3", "1e5", "9" * 400, "--1", "."]))
_STRINGS = st.text(st.characters(blacklist_characters='"\n\r', max_codepoint=0x2ff), max_size=8).map(lambda s: f'"{s}"')
_ARGS = st.lists(st.one_of(_NUMBERS, _STRINGS, st.sampled_from(['"', "(", ")", ";", "(c)", "X1"])), max_size=8)
_NAMES = st.sampled_from(BUILTINS + ["pocket", "FACE", "Pockets", "Zz", "Boom"])


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=_NAMES, args=_ARGS, units=st.sampled_from(["G20", "G21"]), sep=st.sampled_from([" ", "\t", "  "]))
def test_random_calls_never_crash(name, args, units, sep):
    reg = WizardRegistry()
    reg.register("Boom", lambda ctx, *a: [str(1 / len(a))])
    text = f"{units}\n{sep.join([name, *args])}\nG0 X1"
    out, diags = expand(text, registry=reg, max_lines=5000)  # lenient: never raises
    assert all(isinstance(s.text, str) and s.line in (1, 2, 3) for s in out)
    assert all(d.line == 2 for d in diags.items)
    try:
        expand(text, registry=reg, max_lines=5000, mode="strict")
    except GcodeError as exc:
        assert exc.diagnostic is not None and exc.diagnostic.line == 2


_SIZES = st.floats(0.5, 60, allow_nan=False).map(lambda v: round(v, 3))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(BUILTINS), args=st.lists(_SIZES, min_size=0, max_size=6))
def test_random_builtin_calls_emulate(name, args):
    if name in ("DrillGrid", "BoltCircle") and args:
        args[0] = min(args[0], 8)  # hole counts
    text = "G21\n" + " ".join([name, *map(str, args)]) + "\nG0 X0 Y0\n"
    op = gcodekit.gcode_to_operation(text, "ger", plan=False)
    assert all(d.line == 2 for d in op.diagnostics.errors)
    try:
        gcodekit.gcode_to_operation(text, "ger", mode="strict", plan=False)
    except GcodeError as exc:
        assert exc.diagnostic.line == 2
