"""The slicer's own figures beside gcodekit's, on files the slicers made.

References, all independent of gcodekit:

- ``tests/golden/slicers/``: files made here by ``make_slicer_files.py`` with
  PrusaSlicer 2.5 (an MK3S, normal and silent mode, M73 marks) and CuraEngine
  4.13 with the Creality Ender-3 definitions of Debian's ``cura`` package (the
  header is the one the engine logs, as Cura's front end writes it);
- the real files in ``../shared/corpus/fff`` and ``../shared/corpus/realworld``
  (OrcaSlicer 2.3, Creality Print 5.1, Cura 5.9, Slic3r PE 1.36), read in place
  and skipped without ``../shared``;
- the figures each slicer wrote: filament (within 0.1 %), layer count
  (exact), estimated time (within 2 % with the limits the slicer assumed).
"""

from __future__ import annotations

import collections
import dataclasses
import gzip
import json
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

import gcodekit
from gcodekit import cli
from gcodekit.emulate.presets import load_machine, machine_named_in
from gcodekit.model.slicer import compare, parse_duration
from gcodekit.plan.marlin import limits_from_slicer
from shared_corpus import CORPUS

GOLDEN = Path(__file__).parent / "golden" / "slicers"
SHARED = CORPUS
CURA_DEFINITIONS = Path("/usr/share/cura/resources/definitions")

PRUSA_FILES = ["prusa_mk3s_cube20.gcode.gz", "prusa_mk3s_cylinder_estimate_only.gcode.gz"]
CURA_FILES = ["cura_ender3_cube20.gcode.gz", "cura_ender3_cylinder.gcode.gz"]
#: Real files elsewhere whose slicer wrote filament and layers: (folder, name).
REAL_FILES = [("realworld", "orca_2.3.0b2_k1max_klipper.gcode"), ("realworld", "crealityprint_5.1.4.gcode"),
              ("realworld", "cura_5.9.1_k1max.gcode"), ("realworld", "slic3r_pe_1.36.2_duplo.gcode"),
              ("realworld", "cura_legacy_fabtotum_cable_ties.gcode"),  # two objects one at a time: 72 + 58 layers
              ("fff", "cube20_marlin2.gcode"), ("fff", "cube20_klipper.gcode"), ("fff", "cylinder_marlin2.gcode"),
              ("fff", "vase_spiral_marlin2.gcode")]


def text_of(path: Path) -> str:
    return (gzip.open(path, "rt") if path.suffix == ".gz" else open(path)).read()


def shared_file(folder: str, name: str) -> Path:
    path = SHARED / folder / name
    if not path.exists():
        pytest.skip(f"{path} is only in the shared corpus")
    return path


def header_value(text: str, pattern: str) -> str:
    """A figure read straight from the file text, independently of gcodekit's parser."""
    m = re.search(pattern, text, re.M)
    assert m, pattern
    return m[1]


@pytest.fixture(scope="module")
def golden():
    return {name: gcodekit.gcode_to_operation(GOLDEN / name) for name in PRUSA_FILES + CURA_FILES}


# -- what the files say ---------------------------------------------------------------------------


def test_prusaslicer_figures_are_read_as_written(golden):
    text = text_of(GOLDEN / "prusa_mk3s_cube20.gcode.gz")
    f = golden["prusa_mk3s_cube20.gcode.gz"].slicer_figures()
    assert (f.slicer, f.version, f.family) == ("PrusaSlicer", "2.5.0", "slic3r")
    assert f.filament_mm == float(header_value(text, r"^; filament used \[mm\] = ([\d.]+)"))
    assert f.filament_cm3 == float(header_value(text, r"^; filament used \[cm3\] = ([\d.]+)"))
    assert f.filament_g == float(header_value(text, r"^; total filament used \[g\] = ([\d.]+)"))
    m, s = map(int, re.search(r"normal mode\) = (\d+)m (\d+)s", text).groups())
    assert f.time_s == 60 * m + s
    m, s = map(int, re.search(r"silent mode\) = (\d+)m (\d+)s", text).groups())
    assert f.time_silent_s == 60 * m + s
    assert (f.printer, f.firmware) == ("MK3S", "marlin2")
    # every M73 of the file, normal (P, R) and silent (Q, S) marks apart
    normal = re.findall(r"^M73 P(\d+) R(\d+)", text, re.M)
    silent = re.findall(r"^M73 Q(\d+) S(\d+)", text, re.M)
    marks = {mode: [mk for mk in f.marks if mk.mode == mode] for mode in ("normal", "silent")}
    assert [(int(p), 60 * int(r)) for p, r in normal] == [(mk.percent, mk.remaining_s) for mk in marks["normal"]]
    assert [(int(p), 60 * int(r)) for p, r in silent] == [(mk.percent, mk.remaining_s) for mk in marks["silent"]]
    assert marks["normal"][-1].elapsed_s == f.time_s and marks["silent"][-1].elapsed_s == f.time_silent_s


def test_cura_figures_are_read_as_written(golden):
    text = text_of(GOLDEN / "cura_ender3_cube20.gcode.gz")
    f = golden["cura_ender3_cube20.gcode.gz"].slicer_figures()
    assert (f.slicer, f.version, f.family, f.firmware) == ("CuraEngine", "4.13.0", "cura", "Marlin")
    assert f.time_s == int(header_value(text, r"^;TIME:(\d+)"))
    assert f.filament_mm == pytest.approx(1000 * float(header_value(text, r"^;Filament used: ([\d.]+)m")))
    assert f.layers == int(header_value(text, r"^;LAYER_COUNT:(\d+)"))
    elapsed = [float(v) for v in re.findall(r"^;TIME_ELAPSED:([\d.]+)", text, re.M)]
    assert [mk.elapsed_s for mk in f.marks] == elapsed and len(elapsed) == f.layers


@pytest.mark.parametrize("text, seconds", [("21m 25s", 1285), ("1h 32m 43s", 5563), ("1d 0h 0m 1s", 86401),
                                           ("37 minutes", 2220), ("1667", 1667), ("0.815957s", 0.815957)])
def test_durations_in_each_slicers_words(text, seconds):
    assert parse_duration(text) == pytest.approx(seconds)


def test_a_program_without_a_slicer_says_nothing():
    op = gcodekit.gcode_to_operation("G21\nG1 X10 F600\n", "linuxcnc")
    f = op.slicer_figures()
    assert f.slicer is None and f.time_s is None and f.marks == ()
    assert op.summary()["slicer"] is None


# -- gcodekit against them ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", PRUSA_FILES + CURA_FILES)
def test_filament_layers_and_time_against_the_slicer(golden, name):
    op = golden[name]
    f, stats = op.slicer_figures(), op.get_statistics()
    assert stats["filament_mm"] == pytest.approx(f.filament_mm, rel=1e-3)
    assert stats["layers"] == (f.layers if f.layers is not None else len(re.findall(
        r"^;LAYER_CHANGE", text_of(GOLDEN / name), re.M)))
    if name in PRUSA_FILES:  # the MK3S preset (or the file's M201-M205): PrusaSlicer's own limits
        assert op.machine.name == "prusa_mk3s"
        assert stats["time_s"] == pytest.approx(f.time_s, rel=0.02)


@pytest.mark.parametrize("folder, name", REAL_FILES)
def test_real_files_filament_and_layers(folder, name):
    path = shared_file(folder, name)
    op = gcodekit.gcode_to_operation(path, plan=False)
    f, stats = op.slicer_figures(), op.get_statistics()
    assert stats["filament_mm"] == pytest.approx(f.filament_mm, rel=1e-3), name
    if f.layers is not None:
        assert stats["layers"] == f.layers, name


@pytest.mark.parametrize("name", CURA_FILES)
def test_cura_time_gap_is_its_xy_jerk_rule(golden, name):
    """Cura's estimator (Marlin 1.0's planner) limits a corner by the change of the XY velocity
    vector against machine_max_jerk_xy; Marlin 2's classic jerk takes each axis alone, which lets a
    right-angle corner through sqrt(2) faster.  With the definition's limits the firmware is a few
    percent quicker than Cura says; with the jerk divided by sqrt(2) (the vector rule at right
    angles) the plan lands within 2 % of Cura's estimate."""
    op = golden[name]
    cura_s = op.slicer_figures().time_s
    firmware_s = op.get_statistics()["time_s"]
    assert op.machine.name == "marlin"  # Cura 4 names no printer: chosen by --machine, as an info says
    assert any("wrote no machine limits" in d.message and d.severity == "info" for d in op.diagnostics)
    ender = load_machine("creality_ender3")
    as_firmware = gcodekit.gcode_to_operation(GOLDEN / name, ender).get_statistics()["time_s"]
    vector_jerk = dict(ender.planner_settings, max_jerk_x=10 / np.sqrt(2), max_jerk_y=10 / np.sqrt(2))
    as_cura = gcodekit.gcode_to_operation(GOLDEN / name, dataclasses.replace(ender, planner_settings=vector_jerk))
    assert -0.05 < (as_firmware - cura_s) / cura_s < 0
    assert as_cura.get_statistics()["time_s"] == pytest.approx(cura_s, rel=0.02)
    assert firmware_s < as_firmware  # Marlin's stock limits (3000 mm/s^2) are far quicker than the Ender's


def test_time_by_layer_against_curas_marks(golden):
    op = golden["cura_ender3_cube20.gcode.gz"]
    table = op.slicer_layer_times()
    elapsed = [float(v) for v in re.findall(r"^;TIME_ELAPSED:([\d.]+)", text_of(GOLDEN / "cura_ender3_cube20.gcode.gz"),
                                            re.M)]
    assert list(table.index) == list(range(op.n_layers)) and list(table["layers"]) == [1] * op.n_layers
    assert np.allclose(table["slicer_elapsed_s"], elapsed)
    assert np.allclose(table["slicer_time_s"], np.diff(elapsed, prepend=0.0))
    # gcodekit's side: its own planned time up to the mark, layer by layer
    by_layer = op.time_by("layer")
    inner = table.index[1:-1]  # the first holds the start code, the last closes before the final retraction
    assert np.allclose(table.loc[inner, "time_s"], by_layer.loc[inner, "time_s"], rtol=0.02)
    assert table["difference_s"].iloc[-1] == pytest.approx(table["elapsed_s"].iloc[-1] - elapsed[-1])


def test_time_by_layer_against_prusaslicers_marks(golden):
    op = golden["prusa_mk3s_cube20.gcode.gz"]
    for mode, within in (("normal", 0.01), ("silent", 0.02)):  # gcodekit plans the normal mode's limits
        table = op.slicer_layer_times(mode)
        assert len(table) > 10 and table["layers"].sum() == table.index[-1] + 1
        # each mark is where the whole percent or the whole minutes left change: its time is known to a
        # few seconds, and gcodekit's plan stays that close all the way through
        assert (table["difference_s"].abs() < 5 + within * table["slicer_elapsed_s"]).all(), mode


# -- presets from what the file says --------------------------------------------------------------------


def test_limits_from_prusaslicers_configuration_block():
    path = GOLDEN / "prusa_mk3s_cylinder_estimate_only.gcode.gz"
    text = text_of(path)
    assert not re.search(r"^M20[1345]\b", text, re.M)  # the limits are only in the configuration block
    by_hand = {"max_acceleration_x": 1000.0, "max_acceleration_y": 1000.0, "max_acceleration_z": 200.0,
               "max_acceleration_e": 5000.0, "acceleration": 1250.0, "retract_acceleration": 1250.0,
               "travel_acceleration": 1500.0, "max_feedrate_x": 200.0, "max_feedrate_y": 200.0,
               "max_feedrate_z": 12.0, "max_feedrate_e": 120.0, "max_jerk_x": 8.0, "max_jerk_y": 8.0,
               "max_jerk_z": 0.4, "max_jerk_e": 4.5, "min_feedrate": 0.0, "min_travel_feedrate": 0.0,
               "classic_jerk": True}
    op = gcodekit.gcode_to_operation(path, "marlin")  # stock Marlin limits, replaced by the file's
    assert limits_from_slicer(op.slicer_figures().settings) == by_hand
    assert any("configuration block" in d.message and d.severity == "info" for d in op.diagnostics)
    marlin = load_machine("marlin")
    typed = gcodekit.gcode_to_operation(
        path, dataclasses.replace(marlin, planner_settings={**marlin.planner_settings, **by_hand}))
    assert op.get_statistics()["time_s"] == pytest.approx(typed.get_statistics()["time_s"], rel=1e-9)
    assert op.get_statistics()["time_s"] == pytest.approx(op.slicer_figures().time_s, rel=0.02)
    # a file that sets its own limits keeps them
    with_m20x = gcodekit.gcode_to_operation(GOLDEN / "prusa_mk3s_cube20.gcode.gz", "marlin")
    assert not any("configuration block" in d.message for d in with_m20x.diagnostics)
    assert limits_from_slicer({"machine_limits_usage": "ignore", "machine_max_acceleration_x": "9"}) == {}


def test_ender3_preset_is_curas_definition():
    if not (CURA_DEFINITIONS / "creality_base.def.json").exists():
        pytest.skip("Debian's cura package (printer definitions) is not installed")
    overrides = {}
    for name in ("creality_base", "creality_ender3"):
        data = json.loads((CURA_DEFINITIONS / f"{name}.def.json").read_text())
        overrides.update({k: v.get("value", v.get("default_value")) for k, v in data["overrides"].items()})
    p = load_machine("creality_ender3").planner_settings
    for axis in "xyze":
        assert p[f"max_feedrate_{axis}"] == overrides[f"machine_max_feedrate_{axis}"]
        assert p[f"max_acceleration_{axis}"] == overrides[f"machine_max_acceleration_{axis}"]
    assert p["max_jerk_x"] == p["max_jerk_y"] == overrides["machine_max_jerk_xy"]
    assert (p["max_jerk_z"], p["max_jerk_e"]) == (overrides["machine_max_jerk_z"], overrides["machine_max_jerk_e"])
    assert overrides["acceleration_enabled"] is False  # so Cura estimates with machine_acceleration
    assert p["acceleration"] == p["travel_acceleration"] == overrides["machine_acceleration"]
    assert overrides["machine_name"] == "Creality Ender-3"
    # each printer the preset names is a Cura definition on creality_base with no limits of its own
    defined = {}
    for path in CURA_DEFINITIONS.glob("creality_*.def.json"):
        data = json.loads(path.read_text())
        defined[data["overrides"].get("machine_name", {}).get("default_value")] = data
    for name in load_machine("creality_ender3").printer_names:
        data = defined[name]
        while data.get("inherits") != "creality_base":
            data = json.loads((CURA_DEFINITIONS / f"{data['inherits']}.def.json").read_text())
            assert not any(k.startswith("machine_max") or k == "machine_acceleration" for k in data["overrides"])
        assert not any(k.startswith("machine_max") or k == "machine_acceleration" for k in defined[name]["overrides"])


def test_machine_chosen_from_the_printer_a_cura_5_file_names():
    text = text_of(GOLDEN / "cura_ender3_cube20.gcode.gz").replace(
        ";Generated with", ";TARGET_MACHINE.NAME:Creality Ender-3\n;Generated with", 1)
    assert machine_named_in(text[:5000], "marlin") == "creality_ender3"
    assert machine_named_in(text[:5000], "klipper") is None  # a preset of another firmware is not taken
    assert gcodekit.gcode_to_operation(text, plan=False).machine.name == "creality_ender3"
    assert gcodekit.gcode_to_operation(GOLDEN / "cura_ender3_cube20.gcode.gz", plan=False).machine.name == "marlin"


# -- the firmware the file was sliced for: no untrue warnings ------------------------------------------

#: Warnings that stay on the real files, each true.
TRUE_WARNINGS = {
    # PrusaSlicer wrote M204 P800 (Marlin's form) for a Klipper printer; Klipper's cmd_M204 wants S,
    # or P and T together, and ignores the rest, so the printer keeps its acceleration.
    "cube20_klipper.gcode": ["Klipper ignores M204 without S"],
}


@pytest.mark.parametrize("path", [GOLDEN / n for n in PRUSA_FILES + CURA_FILES]
                         + [SHARED / "fff" / n for n in ("cube20_marlin2.gcode", "cube20_klipper.gcode",
                                                         "cylinder_marlin2.gcode", "cylinder_marlin2_arcwelder.gcode",
                                                         "vase_spiral_marlin2.gcode", "cura_cube20_ender3.gcode",
                                                         "plate150_marlin2.gcode.gz")],
                         ids=lambda p: p.name)
def test_no_untrue_warning_on_slicer_files(path):
    if not path.exists():
        pytest.skip(f"{path} is only in the shared corpus")
    op = gcodekit.gcode_to_operation(path)  # planned, as `gcodekit info` does: the planner warns too
    warnings = [d.message for d in op.diagnostics if d.severity != "info"]
    expected = TRUE_WARNINGS.get(path.name, [])
    assert len(warnings) == len(expected) and all(w.startswith(e) for w, e in zip(warnings, expected)), warnings


def test_prusa_firmware_is_detected_and_its_codes_kept_quietly():
    text = 'M862.3 P "MK3S" ; printer model check\nM115 U3.13.0\nG28 W\nG80\nM900 K0.05\nM105\nM105\nG1 X10 E1 F600\n'
    op = gcodekit.gcode_to_operation(text, plan=False)
    assert (op.flavor.name, op.machine.name) == ("prusa", "prusa_mk3s")
    assert op.table.code(3) == "G80" and op.commands[3].name == "mesh_level"  # Prusa's G80 levels the bed
    infos = [d for d in op.diagnostics if d.severity == "info"]
    assert [d.message.split()[0] for d in infos] == ["M862.3", "M115", "M900", "M105"]  # once per code
    assert all(d.severity == "info" for d in op.diagnostics)
    # on stock Marlin, G80 and M862 mean nothing gcodekit knows: said (once each, as infos: issue 27's rule
    # for codes a flavor gives no meaning), not run as mesh levelling
    marlin = gcodekit.gcode_to_operation(text, "marlin", plan=False)
    assert sorted(d.message.split()[0] for d in marlin.diagnostics if "has no meaning" in d.message) == ["G80", "M862.3"]
    assert marlin.commands[3].name != "mesh_level"


def test_klipper_does_not_know_marlins_quiet_codes():
    op = gcodekit.gcode_to_operation("M105\nM900 K0.05\nG1 X1 F600\n", "klipper", plan=False)
    said = [(d.severity, d.message.split()[0], "has no meaning" in d.message) for d in op.diagnostics]
    assert said == [("info", "M105", False), ("info", "M900", True)]  # M900 is not Klipper's: it means nothing there


# -- front ends ----------------------------------------------------------------------------------------------


def test_info_json_and_text_show_the_slicers_figures(capsys):
    path = GOLDEN / "cura_ender3_cube20.gcode.gz"
    status, out, _ = run(["info", path, "--json"], capsys)
    record = json.loads(out)
    assert status == 0 and record["slicer"]["slicer"] == "CuraEngine" and record["slicer"]["layers"] == 100
    assert len(record["slicer"]["marks"]) == 100 and record["slicer"]["time_s"] == 1895
    status, out, _ = run(["info", path], capsys)
    line = next(x for x in out.splitlines() if x.strip().startswith("slicer"))
    rows = compare(record)
    time_diff = next(r["difference"] for r in rows if r["figure"] == "time")
    assert "CuraEngine 4.13.0 says" in line and f"(gcodekit {100 * time_diff:+.1f} %)" in line
    assert "layers 100 (gcodekit the same)" in line


def test_report_summary_has_the_slicers_figures():
    from gcodekit.report.build import report_data

    op = gcodekit.gcode_to_operation(GOLDEN / "prusa_mk3s_cube20.gcode.gz")
    data = report_data(op)
    figures = {r["figure"]: r for r in data["slicer_rows"]}
    assert set(figures) == {"time", "filament"}  # PrusaSlicer 2.5 writes no layer count
    assert figures["time"]["difference"] == pytest.approx(
        (op.get_statistics()["time_s"] - op.slicer_figures().time_s) / op.slicer_figures().time_s)
    assert data["slicer_layers"] and data["slicer_layers"][-1]["slicer_elapsed_s"] == op.slicer_figures().time_s


def test_report_page_row_says_what_the_slicer_says_escaped():
    from gcodekit.report.html import program_page

    text = text_of(GOLDEN / "cura_ender3_cube20.gcode.gz").replace(
        ";Generated with Cura_SteamEngine 4.13.0", ";Generated with Cura_SteamEngine <b>4.13</b>", 1)
    op = gcodekit.gcode_to_operation(text, "creality_ender3")
    from gcodekit.report.build import report_data

    page = program_page(report_data(op), collections.defaultdict(lambda: None))  # no pictures needed here
    row = re.search(r"<th>Slicer says</th><td>(.*?)</td>", page)[1]
    assert row.startswith("CuraEngine &lt;b&gt;4.13&lt;/b&gt;:") and "<b>4.13" not in page
    ours = op.get_statistics()["time_s"]
    assert f"time 0:31:35 (gcodekit {100 * (ours - 1895) / 1895:+.1f} %)" in row
    assert "layers 100 (gcodekit the same)" in row


def test_figures_of_bambu_studio_and_creality_print_headers():
    bambu = gcodekit.gcode_to_operation(shared_file("realworld", "bambustudio_1.7.6_x1_cube.gcode"), plan=False)
    f = bambu.slicer_figures()
    # "; model printing time: 8m 57s; total estimated time: 15m 42s" and "; total layer number: 92"
    assert (f.slicer, f.version, f.time_s, f.layers) == ("BambuStudio", "01.07.06.92", 15 * 60 + 42, 92)
    assert f.filament_mm is None  # Bambu Studio 1.7 writes no filament figure
    assert f.time_model_s == 8 * 60 + 57  # "model printing time": the model alone, without the printer's start-up
    rows = {r["figure"]: r for r in compare(gcodekit.gcode_to_operation(
        shared_file("realworld", "bambustudio_1.7.6_x1_cube.gcode")).summary())}
    ours = rows["time"]["gcodekit"]
    assert (rows["time"]["slicer"], rows["model time"]["slicer"], rows["model time"]["gcodekit"]) == (942, 537, ours)
    assert rows["model time"]["difference"] == pytest.approx((ours - 537) / 537)
    creality = gcodekit.gcode_to_operation(shared_file("realworld", "crealityprint_5.1.4.gcode"), plan=False)
    f = creality.slicer_figures()
    # "; filament cost = 0.65; total filament used [g] = 32.46" is two settings on one line
    assert (f.slicer, f.filament_g, f.filament_cost, f.layers) == ("Creality Print", 32.46, 0.65, 20)
    assert f.time_s == 39 * 60 + 45  # "estimated printing time (normal mode) = 39m 45s"


def test_figures_of_kisslicer_as_a_volume_and_of_pycam():
    path = shared_file("realworld", "kisslicer_1.1.0.14_cube.gcode")
    text = text_of(path)
    # "; KISSlicer - FREE", "; version 1.1.0.14", "; Estimated Build Time:   7.01 minutes",
    # "; Estimated Build Volume: 0.681 cm^3"
    f = gcodekit.gcode_to_operation(path, plan=False).slicer_figures()
    assert (f.slicer, f.version, f.filament_mm) == ("KISSlicer", header_value(text, r"^; version (\S+)$"), None)
    assert f.time_s == pytest.approx(float(header_value(text, r"^; Estimated Build Time:\s+([\d.]+) minutes")) * 60)
    assert f.filament_cm3 == float(header_value(text, r"^; Estimated Build Volume: ([\d.]+) cm\^3"))
    # its E words are relative, which the program leaves to the firmware: with M83 after its G90 the volume pushed
    # (the E words' sum over the 3 mm filament's section, by hand below) is the slicer's figure
    fixed = text.replace("G90\n", "G90\nM83\n", 1)
    e_sum = sum(float(e) for e in re.findall(r"^G1 .*E(-?[\d.]+)", fixed, re.M))
    assert e_sum * np.pi * 1.5**2 / 1000 == pytest.approx(0.681, rel=1e-3)
    rows = compare(gcodekit.gcode_to_operation(fixed, "marlin").summary())
    volume = next(r for r in rows if r["figure"] == "filament volume")
    assert (volume["slicer"], volume["gcodekit"]) == (0.681, pytest.approx(e_sum * np.pi * 1.5**2 / 1000, rel=1e-9))
    assert [r["figure"] for r in rows] == ["time", "filament volume"]

    pycam = shared_file("realworld", "pycam_0.5.1.1_shapeoko_cal.ngc")
    f = gcodekit.gcode_to_operation(pycam, plan=False).slicer_figures()
    # ";PYCAM-META-DATA: Version: 0.5.1.1", ";Estimated machine time: 17 minutes"
    assert (f.slicer, f.version, f.time_s, f.filament_cm3) == ("PyCAM", "0.5.1.1", 17 * 60, None)


def test_cam_program_report_row_is_what_the_cam_program_says():
    from gcodekit.report.build import report_data
    from gcodekit.report.html import program_page

    op = gcodekit.gcode_to_operation(";PYCAM-META-DATA: Version: 0.5.1.1\n;Estimated machine time: 1 minutes\n"
                                     "G21 G90 F600\nG1 X100\nM2\n", "linuxcnc")
    page = program_page(report_data(op), collections.defaultdict(lambda: None))
    row = re.search(r"<th>CAM says</th><td>(.*?)</td>", page)[1]
    # 100 mm at 600 mm/min: 10 s and the ramps, against PyCAM's minute
    assert row.startswith("PyCAM 0.5.1.1: time 0:01:00 (gcodekit -83.")
