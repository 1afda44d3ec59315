"""Syntax stage: flavor files load, validate strictly, inherit and detect."""

from pathlib import Path
from types import MappingProxyType

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.errors import ConfigError
from gcodekit.syntax import (
    BLOCK_SPLITS,
    COMMANDS,
    PARAMETERS,
    Flavor,
    detect_flavor,
    list_flavors,
    load_flavor,
)
from gcodekit.syntax.detect import HEAD_CHARS, guess_flavor
from gcodekit.syntax.loader import FLAVOR_DIR

FLAVORS = list_flavors()


def test_bundled_flavors():
    assert {"rs274ngc", "fanuc", "marlin", "klipper", "reprapfirmware", "grbl",
            "beckhoff_ded", "ger", "freecad"} <= set(FLAVORS)


@pytest.mark.parametrize("name", FLAVORS)
def test_every_flavor_loads(name):
    flavor = load_flavor(name)
    assert isinstance(flavor, Flavor) and flavor.name == name and flavor.description
    assert flavor.block_split in BLOCK_SPLITS
    assert set(flavor.codes.values()) <= COMMANDS
    assert set(flavor.words.values()) <= PARAMETERS
    assert isinstance(flavor.codes, MappingProxyType) and isinstance(flavor.words, MappingProxyType)
    assert isinstance(flavor.line_comments, tuple) and isinstance(flavor.string_codes, frozenset)
    assert flavor.codes_for("rapid") == ("G0",)
    assert load_flavor(name) is flavor  # cached


def test_flavor_semantics():
    ngc = load_flavor("rs274ngc")
    assert ngc.command("G59.3") == "work_offset_9" and ngc.command("M60") == "program_stop"
    marlin = load_flavor("marlin")
    assert marlin.extrusion == "absolute" and marlin.rapid_is_feed and marlin.words["E"] == "e"
    assert "M30" in marlin.string_codes and marlin.command("M30") is None
    ger = load_flavor("ger")
    assert ger.statement_separators == (";",) and ";" not in ger.line_comments
    assert ger.units == "inch" and ger.multiline_comments and ger.line_number_letter == ""
    ded = load_flavor("beckhoff_ded")
    assert [ded.command(c) for c in ("M60", "M61", "M62", "M63")] == ["weld_start", "laser_on", "laser_off", None]


def test_klipper_inherits_marlin():
    marlin, klipper = load_flavor("marlin"), load_flavor("klipper")
    assert klipper.extended_commands and not marlin.extended_commands
    assert klipper.command("SET_VELOCITY_LIMIT") == "set_accel"
    assert klipper.command("G1") == "linear" and klipper.layer_comments == marlin.layer_comments
    assert klipper.command("M205") is None and marlin.command("M205") == "set_jerk"  # removed by ""
    assert load_flavor("reprapfirmware").command("M566") == "set_jerk"


def test_load_by_path_and_unknown_name():
    assert load_flavor(FLAVOR_DIR / "grbl.toml") is load_flavor("grbl")
    assert load_flavor(str(FLAVOR_DIR / "grbl.toml")) is load_flavor("grbl")
    with pytest.raises(ConfigError, match="did you mean 'marlin'"):
        load_flavor("marln")


def _write(tmp_path, text, name="bad"):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('name = "bad"\nline_coments = [";"]\n', r"bad\.toml: line_coments: unknown key \(did you mean 'line_comments'\?\)"),
        ('name = "bad"\n[detect]\nextention = [".nc"]\n', r"\[detect\] extention: unknown key \(did you mean 'extensions'\?\)"),
        ('name = "bad"\nblock_split = "modall"\n', r"block_split: 'modall' is not one of .*did you mean 'modal'"),
        ('name = "bad"\nunits = "cm"\n', r"bad\.toml: units: 'cm' is not one of 'mm', 'inch'"),
        ('name = "bad"\nextrusion = "relativ"\n', r"extrusion: .*did you mean 'relative'"),
        ('name = "bad"\nchecksum = "yes"\n', r"checksum: expected true or false, got 'yes'"),
        ('name = "bad"\n[codes]\nG1 = "lineer"\n', r"\[codes\] G1: 'lineer' is not a command name \(did you mean 'linear'\?\)"),
        ('name = "bad"\n[codes]\nG01 = "linear"\n', r"\[codes\] G01: write codes without leading zeros: 'G1'"),
        ('name = "bad"\n[words]\nE = "extrude"\n', r"\[words\] E: 'extrude' is not a parameter name"),
        ('name = "bad"\nstatement_separators = [";"]\n', r"statement_separators: ';' is also in line_comments"),
        ('name = "bad"\nlayer_comments = ["(unclosed"]\n', r"layer_comments: invalid regular expression"),
        ('name = "bad"\nfeature_comment = "^TYPE:"\n', r"feature_comment: .* needs a \(group\)"),
        ('name = "bad"\n[codes]\nPRINT_START = "program_stop"\n', r"PRINT_START: named commands need extended_commands"),
        ('name = "bad"\nline_number_letter = ""\n[words]\nN = "line_number"\n', r"\[words\] N: maps to 'line_number'"),
        ('name = "bad"\ninherit = "marlinn"\n', r"inherit: unknown flavor 'marlinn' \(did you mean 'marlin'\?\)"),
        ('name = "bad"\n[detect]\npriority = "high"\n', r"\[detect\] priority: expected an integer"),
        ('name = "bad"\nunits = [\n', r"bad\.toml: invalid TOML"),
        ('description = "no name"\n', r"name: missing required key"),
    ],
)
def test_validation_errors_name_file_table_key(tmp_path, text, expected):
    with pytest.raises(ConfigError, match=expected):
        load_flavor(_write(tmp_path, text))


def test_inheritance_merges_tables(tmp_path):
    path = _write(tmp_path, """
name = "mymarlin"
inherit = "marlin"
checksum = false
layer_comments = ['^NEW_LAYER$']
[codes]
M600 = "program_stop"
M73 = ""
[detect]
priority = 0
""", "mymarlin")
    mine, marlin = load_flavor(path), load_flavor("marlin")
    assert mine.name == "mymarlin" and not mine.checksum and mine.extrusion == "absolute"
    assert mine.command("M600") == "program_stop" and mine.command("M73") is None
    assert mine.command("G1") == "linear" and mine.layer_comments == ("^NEW_LAYER$",)
    assert mine.detect.priority == 0 and mine.detect.codes == marlin.detect.codes
    assert mine.words == marlin.words


def test_inheritance_from_sibling_and_cycles(tmp_path):
    _write(tmp_path, 'name = "base"\nunits = "inch"\n[codes]\nG0 = "rapid"\n', "base")
    child = _write(tmp_path, 'name = "child"\ninherit = "base"\n', "child")
    assert load_flavor(child).units == "inch" and load_flavor(child).command("G0") == "rapid"
    _write(tmp_path, 'name = "a"\ninherit = "b"\n', "a")
    _write(tmp_path, 'name = "b"\ninherit = "a"\n', "b")
    with pytest.raises(ConfigError, match="circular inheritance"):
        load_flavor(tmp_path / "a.toml")


def test_lineage_follows_inherit(tmp_path):
    assert load_flavor("klipper").lineage == ("marlin",) and load_flavor("bambu").lineage[-1] == "marlin"
    assert load_flavor("grbl_laser").lineage == ("grbl",) and load_flavor("rs274ngc").lineage == ()
    _write(tmp_path, 'name = "base"\n', "base")
    _write(tmp_path, 'name = "child"\ninherit = "base"\n', "child")
    grandchild = load_flavor(_write(tmp_path, 'name = "grandchild"\ninherit = "child"\n', "grandchild"))
    assert grandchild.lineage == ("child", "base")
    with pytest.raises(ConfigError, match="lineage: unknown key"):  # the loader's to set, not a file's
        load_flavor(_write(tmp_path, 'name = "bad"\nlineage = ["marlin"]\n'))


def _head(path: Path) -> str:
    with path.open(errors="replace") as fh:
        return fh.read(HEAD_CHARS)


def test_detect_fff_corpus(shared_dir):
    files = sorted((shared_dir / "corpus" / "fff").glob("*.gcode"))
    assert files
    for path in files:
        # PrusaSlicer's MK3S files check the printer (M862.3 P "MK3S"): Prusa's firmware, a Marlin fork
        text = _head(path)
        expected = ("klipper" if path.name == "cube20_klipper.gcode" else
                    "prusa" if 'M862.3 P "MK3S"' in text else "marlin")
        assert detect_flavor(_head(path), path.name).name == expected, path.name
        assert detect_flavor(_head(path)).name == expected, path.name


def test_detect_ded_corpus(shared_dir):
    files = sorted((shared_dir / "corpus" / "ded").glob("*.nc"))
    assert files
    for path in files:
        detection = detect_flavor(_head(path), path)
        assert detection.name == "beckhoff_ded", path.name
        assert any("Part name" in r for r in detection.reasons)


def test_detect_linuxcnc_corpus(shared_dir):
    files = sorted((shared_dir / "corpus" / "linuxcnc" / "nc_files").glob("*.ngc"))
    assert len(files) > 50
    wrong = [p.name for p in files if detect_flavor(_head(p), p.name).name != "rs274ngc"]
    assert wrong == []


def test_detect_klipper_reasons_and_candidates():
    head = "; generated by PrusaSlicer 2.5.0\nM190 S60\nPRINT_START BED=60\nM83\nG1 X1 E0.5\n"
    detection = detect_flavor(head, "part.gcode")
    assert detection.name == "klipper"
    assert dict(detection.candidates)["marlin"] < detection.score
    assert any("PRINT_START" in r for r in detection.reasons)


def test_detect_tie_lists_candidates():
    detection = detect_flavor("; generated by PrusaSlicer 2.5.0\nM82\nG1 X1 E0.5\n")
    assert detection.name == "marlin"
    assert detection.candidates[1] == ("klipper", detection.score)
    assert any("close candidates" in r and "priority" in r for r in detection.reasons)


def test_detect_rules_out_the_dialects_that_cannot_read_the_program_and_names_its_evidence():
    # Cura's ';FLAVOR:Marlin' beside Klipper's START_PRINT: klipper (15) by a point over marlin (14), on other
    # headers, so the choice is weak: neither is ruled out, nor Prusa, which reads Marlin's programs;
    # LinuxCNC and GRBL are
    both = detect_flavor(";FLAVOR:Marlin\nSTART_PRINT\nM82\nG1 X1 E0.5\n")
    assert (both.name, both.score, both.weak) == ("klipper", 15.0, True)
    assert [both.rules_out(load_flavor(f)) for f in ("klipper", "marlin", "prusa", "rs274ngc", "grbl")] == [
        False, False, False, True, True]
    assert both.evidence == ("header 'START_PRINT' on line 2",)
    # a Marlin banner (11) and LinuxCNC's o<x> sub (10): a point apart, of two families
    mixed = detect_flavor(";FLAVOR:Marlin\no<x> sub\nG1 X1\no<x> endsub\n")
    assert (mixed.name, mixed.score, dict(mixed.candidates)["rs274ngc"]) == ("marlin", 11.0, 10.0)
    assert not mixed.rules_out(load_flavor("rs274ngc")) and not mixed.rules_out(load_flavor("marlin"))
    assert mixed.rules_out(load_flavor("grbl"))  # it reads neither
    # no header: 3 points (E words, M104), too few; the evidence is then every reason
    thin = detect_flavor("G1 X1 E0.5\nM104 S200\n")
    assert thin.score == 3.0 and not thin.rules_out(load_flavor("rs274ngc"))
    assert thin.evidence == ("E words on moves", "typical codes M104")


def test_detect_ger_sample():
    head = "(GER sample: a pocket\n  made by a wizard)\nG20 G90\nG00 X1.0 Y1.0; G01 Z-0.1 F10\nPocket 0.75 0.30 0.10\nM30\n"
    assert detect_flavor(head).name == "ger"
    assert guess_flavor(head).statement_separators == (";",)


def test_detect_other_headers():
    assert detect_flavor("%\nO1234 (BRACKET)\nG21 G17 G90\nG00 X0 Y0\nM30\n%\n").name == "fanuc"
    assert detect_flavor("$H\nG21 G90\nG0 X10\n").name == "grbl"
    assert detect_flavor(";FLAVOR:Marlin\nM82\n", "x.gcode").name == "marlin"


@pytest.mark.parametrize(
    ("head", "filename", "expected"),
    [
        ("G1 X1 E2\nG1 X2 E3\n", None, "marlin"),
        ("(part)\nG0 X1\nG1 Y2\n", None, "rs274ngc"),
        ("", None, "rs274ngc"),
    ],
)
def test_detect_fallback(head, filename, expected):
    detection = detect_flavor(head, filename)
    assert detection.name == expected and detection.score == 0
    assert "default" in detection.reasons[0]


@settings(max_examples=200, deadline=None)
@given(st.text(alphabet=st.characters(codec="utf-8"), max_size=2000), st.none() | st.text(max_size=20))
def test_detect_never_raises(text, filename):
    detection = detect_flavor(text, filename)
    assert detection.name in FLAVORS


# LinuxCNC's tests/interp/m98m99/01-basics: Fanuc-style subprograms in a .ngc file with ';' comments
M98_NGC = ("%\n( A simple O sub example )\n\nF40\nG90 G0 X0 Y0 Z0.25\nM98 P1 L3\nM30\n\nO1\n"
           "G91 G0 X1                ; Jog 1\" along X (relative)\nG90 G99 G81 Z-1.0 R0.25  ; Drill to Z-1.0\nM99\n%\n")


def test_detect_linuxcnc_syntax_over_fanuc_subprograms_whatever_the_extension():
    # LinuxCNC runs M98/M99 too, and words after ';' are no Fanuc block; the file name is weak
    # evidence, so the same bytes are read alike under every name; LinuxCNC's own .ngc confirms
    # the choice, under any other name it is said to be thin
    for name in ("test.ngc", "test.nc", "test.gcode", "test.txt", None):
        detection = detect_flavor(M98_NGC, name)
        assert (detection.name, detection.weak) == ("rs274ngc", name != "test.ngc"), name
        assert dict(detection.candidates).get("fanuc", 0) < 3
    assert "file extension .ngc" in "; ".join(detect_flavor(M98_NGC, "test.ngc").reasons)
    fanuc = "%\nO1234 (BRACKET)\nG21 G17 G90\nM98 P2000\nM30\n%\n"
    assert detect_flavor(fanuc, "part.nc").name == "fanuc"


def test_detect_named_linuxcnc_syntax_beats_a_program_number():
    text = "O0100 (FANUC-LIKE NUMBER)\n#<depth> = 2\nG0 Z[#<depth> + 1]\nM98 P2\nM30\n"
    assert detect_flavor(text, "part.nc").name == "rs274ngc"


def test_weak_detection_is_an_info_diagnostic_naming_the_flavor_and_why(tmp_path):
    weak = tmp_path / "part.nc"
    weak.write_text("G21 G90\nG0 X1 Y2\nG1 X3 F100\nM2\n")
    infos = [d for d in gcodekit.gcode_to_operation(weak, plan=False).diagnostics.items if d.severity == "info"]
    assert len(infos) == 1 and infos[0].line == 1
    assert "'rs274ngc'" in infos[0].message and "default" in infos[0].message
    strong = tmp_path / "part.ngc"
    strong.write_text(M98_NGC)
    op = gcodekit.gcode_to_operation(strong, plan=False, tool_table_units="inch")
    assert not [d for d in op.diagnostics.items if d.severity == "info"]
    assert op.flavor.name == "rs274ngc" and len(op.motions()) == 13  # rs274's 13 motions (LinuxCNC's expected)
    given = gcodekit.gcode_to_operation(weak, flavor="rs274ngc", plan=False)
    assert not [d for d in given.diagnostics.items if d.severity == "info"]


def test_ini_disabling_fanuc_subprograms_refuses_m98(tmp_path):
    """LinuxCNC's tests/interp/m98m99/09-disable-fanuc-subs: rs274 stops at the M98 (line 6)."""
    program, ini = tmp_path / "test-fanuc.ngc", tmp_path / "test-no-fanuc.ini"
    program.write_text(M98_NGC)
    ini.write_text("[RS274NGC]\nDISABLE_FANUC_STYLE_SUB = 1\n[EMC]\nDEBUG = 2147483647\n")
    op = gcodekit.gcode_to_operation(program, plan=False, ini_file=str(ini))
    errors = [d for d in op.diagnostics.items if d.severity == "error"]
    assert [(d.line, d.message) for d in errors] == [(6, "DISABLE_FANUC_STYLE_SUB set in INI file, but found m98")]
    assert len(op.motions()) == 1  # the G0 before it, as rs274's canon has
    allowed = tmp_path / "test-fanuc.ini"
    allowed.write_text("[RS274NGC]\nDISABLE_FANUC_STYLE_SUB = 0\n")
    assert len(gcodekit.gcode_to_operation(program, plan=False, ini_file=str(allowed)).motions()) == 13


def test_e_words_on_one_long_line():
    """Found by the fuzz suite (seed 17): one 120 000-character line of moves took the E-word
    search 40 s (a regex backtracking over every pair of positions); the answer is unchanged."""
    from gcodekit.syntax.detect import _e_words_on_moves

    line = "G1 X1 " * 20_000
    assert not _e_words_on_moves(line) and _e_words_on_moves(line + " E0.5")
    assert detect_flavor(line + "\n").name == detect_flavor("G1 X1\n").name
