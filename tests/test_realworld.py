"""Real programs from other tools (../shared/corpus/realworld), read in place: each as the machine it was
written for, with only true diagnostics, nothing on stderr, and times beside the files' own estimates.

The files are third-party (their README names each one's tool and source) and are not copied here; the
tests skip when ../shared is absent.  Where a tool's style needs a case the set lacks, a small program of
our own in that style follows (plasma, a Fusion 360 move before any F, Bambu and MakerBot dialects,
LightBurn laser power, a GRBL ``$$`` dump).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.syntax import detect_flavor, load_flavor
from shared_corpus import CORPUS

# file -> (flavor, machine, process): what its header or content says it was written for (README.md's kind)
EXPECTED = {
    "bambustudio_1.7.6_x1_cube.gcode": ("bambu", "bambu", "additive"),
    "cambam_electric_turtle.nc": ("rs274ngc", "linuxcnc", "subtractive"),
    "crealityprint_5.1.4.gcode": ("klipper", "klipper", "additive"),
    "cura_5.9.1_k1max.gcode": ("klipper", "klipper", "additive"),
    "cura_legacy_fabtotum_cable_ties.gcode": ("marlin", "marlin", "additive"),
    "fullcontrol_ripple_vase.gcode": ("marlin", "marlin", "additive"),
    "fusion360_sheeptile.nc": ("rs274ngc", "linuxcnc", "subtractive"),
    "jscut_jsdc.gcode": ("rs274ngc", "linuxcnc", "subtractive"),
    "kisslicer_1.1.0.14_cube.gcode": ("marlin", "marlin", "additive"),
    "lightburn_0.9.24_g2_lens.nc": ("grbl_laser", "grbl_laser", "subtractive"),
    "maxnc_traindriveshaft.nc": ("rs274ngc", "linuxcnc", "subtractive"),
    "miraclegrue_0.04_20mm_box.gcode": ("makerbot", "makerbot", "additive"),
    "ncefi_linuxcnc.nc": ("rs274ngc", "linuxcnc", "subtractive"),
    "openvoronoi_ttt_vcarve.ngc": ("rs274ngc", "linuxcnc", "subtractive"),
    "orca_2.3.0b2_k1max_klipper.gcode": ("klipper", "klipper", "additive"),
    "pycam_0.5.1.1_shapeoko_cal.ngc": ("rs274ngc", "linuxcnc", "subtractive"),
    "slic3r_pe_1.36.2_duplo.gcode": ("marlin", "marlin", "additive"),
    "vectric_demo.gcode": ("rs274ngc", "linuxcnc", "subtractive"),
}

THIN = "chosen on thin evidence"
NO_TOOL_TABLE = "no tool table: tool"
# Every diagnostic each file still gets, as (severity, line, words of the message), and why it is true.
# Codes a flavor gives no meaning are listed apart (UNMODELLED): one info each.
DIAGNOSTICS = {
    # CamBam names no controller, and G21 G90 G64 G40 are any mill's: rs274ngc is a default, said so
    "cambam_electric_turtle.nc": [("info", 1, THIN),
                                  # its M30 on line 2161 is followed by another profile (M3 S1000 on 2163)
                                  ("warning", 2163, "blocks after the program end")],
    # Cura 15 writes no M201-M205: its estimate used its own printer definition, which the file does not carry
    "cura_legacy_fabtotum_cable_ties.gcode": [("info", 1, "wrote no machine limits into the file")],
    # the file says ;FLAVOR:Marlin but starts with Klipper's START_PRINT and EXCLUDE_OBJECT: the two conflict
    "cura_5.9.1_k1max.gcode": [("info", 1, THIN)],
    # Fusion's header names no controller (the post is grbl-style, the codes any mill's)
    "fusion360_sheeptile.nc": [("info", 1, THIN),
                               # no tool table is given, and rs274ngc's tools have lengths
                               ("warning", 10, NO_TOOL_TABLE),
                               # line 14 'G1 X77.219 Y29.85' comes before any F: LinuxCNC refuses it
                               ("error", 14, "Cannot do g1 with zero feed rate")],
    # jscut's comments and codes are any controller's
    "jscut_jsdc.gcode": [("info", 1, THIN),
                         # it ends 'G0 X0 Y0 F2540': no M2/M30 and no '%', which LinuxCNC requires
                         ("error", 2428, "File ended with no percent sign or program end")],
    # '; fiber_dia_mm = 3' in KISSlicer's settings block
    "kisslicer_1.1.0.14_cube.gcode": [("info", 1, "filament diameter 3 mm, as the program states"),
                                      # E0.0124 after E1.25 with no M83: relative E words read as positions
                                      ("warning", 198, "the E words look relative")],
    # the MAXNC post's header names no controller
    "maxnc_traindriveshaft.nc": [("info", 1, THIN),
                                 # 'N3520 G49 M29': M29 is no LinuxCNC code (rs274 says the same)
                                 ("error", 3527, "Unknown m code used: M29")],
    # ncEFI writes bare G-code with no header
    "ncefi_linuxcnc.nc": [("info", 1, THIN),
                          # the file never gives an F: LinuxCNC refuses its first arc
                          ("error", 6, "Cannot make arc with zero feed rate"),
                          # it stops after its last arc, with no M2/M30 or '%'
                          ("error", 312, "File ended with no percent sign or program end")],
    # PyCAM's program selects T4 with M6, and no tool table is given
    "pycam_0.5.1.1_shapeoko_cal.ngc": [("warning", 42, NO_TOOL_TABLE)],
    # Vectric's header names no controller; 'T1' selects a tool no table describes
    "vectric_demo.gcode": [("info", 1, THIN), ("warning", 3, NO_TOOL_TABLE)],
}
# Codes each file uses that its flavor keeps without effect (firmware extensions): one info per code.
UNMODELLED = {
    "bambustudio_1.7.6_x1_cube.gcode": {
        "M17", "G380", "M960", "M73.2", "M1002", "G29.1", "M977", "M975", "M620", "M621", "M620.1", "M412",
        "G29.2", "M972", "M622", "M500", "M623", "M970.3", "M974", "M976", "M900", "M973", "M971", "M963", "M964",
        "M969", "M980.3", "M981", "M622.1", "M991", "M624", "M625", "M1003", "M201.2"},
    "cura_legacy_fabtotum_cable_ties.gcode": {"M728"},  # FABtotum's beep
    "fullcontrol_ripple_vase.gcode": {"M900"},  # linear advance: no effect on the path
    "kisslicer_1.1.0.14_cube.gcode": {"M542", "M551", "M543"},  # the printer's own start codes
    "orca_2.3.0b2_k1max_klipper.gcode": {"M191", "M141"},  # chamber heater: Klipper has none built in
}

# file -> (the file's own estimate, s, where it says it) for the files that give one
ESTIMATES = {
    "cura_legacy_fabtotum_cable_ties.gcode": (37 * 60, ";Print time: 37 minutes"),
    "crealityprint_5.1.4.gcode": (39 * 60 + 45, "; estimated printing time (normal mode) = 39m 45s"),
    "orca_2.3.0b2_k1max_klipper.gcode": (3600 + 32 * 60 + 43, "; estimated printing time (normal mode) = 1h 32m 43s"),
    "cura_5.9.1_k1max.gcode": (2848, ";TIME:2848"),
    "kisslicer_1.1.0.14_cube.gcode": (7.01 * 60, "; Estimated Build Time:   7.01 minutes"),
    "pycam_0.5.1.1_shapeoko_cal.ngc": (17 * 60, ";Estimated machine time: 17 minutes"),
}


@pytest.fixture(scope="module")
def realworld(request) -> Path:
    path = CORPUS / "realworld"
    if not path.is_dir():
        pytest.skip(f"reference folder {path} not found")
    return path


@pytest.fixture(scope="module")
def read_all(realworld):
    """Each file read once, with what it printed and warned."""
    import contextlib
    import io

    out = {}
    for name in EXPECTED:
        err = io.StringIO()
        with contextlib.redirect_stderr(err), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            op = gcodekit.gcode_to_operation(realworld / name)
        out[name] = (op, err.getvalue(), [str(w.message) for w in caught])
    return out


def test_the_set_is_the_readme_list(realworld):
    listed = set(re.findall(r"^\| (\S+\.(?:gcode|nc|ngc)) \|", (realworld / "README.md").read_text(), re.M))
    assert listed == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_each_file_is_read_as_its_machine(read_all, name):
    op, stderr, caught = read_all[name]
    summary = op.summary()
    assert (summary["flavor"], summary["machine"], summary["process"]) == EXPECTED[name]
    assert stderr == "" and caught == []  # nothing printed, no Python warning (numpy casts included)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_each_remaining_diagnostic_is_the_true_one(read_all, name):
    op, _, _ = read_all[name]
    unmodelled = [d for d in op.diagnostics.items
                  if "has no meaning in gcodekit's" in d.message or "code gcodekit does not model" in d.message]
    assert all(d.severity == "info" for d in unmodelled)
    codes = [d.message.split()[0] for d in unmodelled]
    assert len(codes) == len(set(codes)) and set(codes) == UNMODELLED.get(name, set())
    rest = [(d.severity, d.line, d.message) for d in op.diagnostics.items if d not in unmodelled]
    expected = DIAGNOSTICS.get(name, [])
    assert len(rest) == len(expected), rest
    for (severity, line, message), (want_severity, want_line, words) in zip(rest, expected):
        assert (severity, line) == (want_severity, want_line) and words in message, (severity, line, message)
    assert op.diagnostics.dropped == 0


def test_the_same_bytes_are_read_alike_under_any_name(realworld):
    for name in EXPECTED:
        head = (realworld / name).read_text(encoding="utf-8", errors="replace")[:65536]
        chosen = {suffix: detect_flavor(head, "program" + suffix).name
                  for suffix in (".gcode", ".nc", ".ngc", ".tap", ".txt", "")}
        assert set(chosen.values()) == {EXPECTED[name][0]}, (name, chosen)


@pytest.mark.parametrize("name", sorted(ESTIMATES))
def test_time_beside_the_files_own_estimate(read_all, realworld, name):
    estimate, words = ESTIMATES[name]
    assert words in (realworld / name).read_text(encoding="utf-8", errors="replace")
    ours = read_all[name][0].summary()["time_s"]
    # Within a fifth of the tool's own figure.  The tools time with their own models (Cura and KISSlicer
    # with their machine settings, PyCAM with length over feed plus its rapid guess; Orca and Creality Print
    # with the Klipper limits of their profile) and ours plan with the default machine of the flavor.
    assert 0.8 * estimate <= ours <= 1.2 * estimate, (ours, estimate)


def test_bambu_time_between_the_model_time_and_the_total(read_all, realworld):
    # '; model printing time: 8m 57s; total estimated time: 15m 42s': the total counts the printer's own
    # calibration and heating, run behind M1002 flags and waits gcodekit gives no duration
    assert "; model printing time: 8m 57s; total estimated time: 15m 42s" in (
        realworld / "bambustudio_1.7.6_x1_cube.gcode").read_text()
    assert 8 * 60 + 57 <= read_all["bambustudio_1.7.6_x1_cube.gcode"][0].summary()["time_s"] <= 15 * 60 + 42


def test_makerbot_a_axis_is_the_filament(read_all, realworld):
    # Miracle-Grue's A words are the absolute extruder position: the filament used is the last A
    op = read_all["miraclegrue_0.04_20mm_box.gcode"][0]
    last_a = float(re.findall(r"\bA(-?\d+\.\d+)", (realworld / "miraclegrue_0.04_20mm_box.gcode").read_text())[-1])
    assert op.summary()["filament_mm"] == pytest.approx(last_a, abs=1e-6)
    assert op.n_layers > 10  # '(Slice N, ...)' comments mark the layers


def test_fusion_and_laser_times_are_not_invented(read_all, realworld):
    fusion = read_all["fusion360_sheeptile.nc"][0].summary()
    # 'G1 X77.219 Y29.85', 'Z15' and 'Z3' come before the first F: three moves with no time to give
    assert fusion["untimed_moves"] == 3
    as_grbl = gcodekit.gcode_to_operation(realworld / "fusion360_sheeptile.nc", flavor="grbl").summary()
    assert as_grbl["untimed_moves"] == 3
    # before, GRBL's 1 mm/min minimum timed them: 2 h 11 min for a 19 min job; now the cut alone is timed
    assert as_grbl["time_s"] < 1.25 * fusion["time_s"]
    laser = read_all["lightburn_0.9.24_g2_lens.nc"][0]
    w = laser.waypoints
    feeding = (w["motion"] >= 2) & (w["feed"] > 0)
    by_feed = float(np.sum(w["distance"][feeding] / (w["feed"][feeding] / 60.0)))
    # the diode-laser preset plans the job near its feeds (the router-like grbl preset made it 4.6x longer)
    assert by_feed <= laser.summary()["time_s"] <= 1.1 * by_feed


def test_laser_power_is_a_column_and_a_colouring(read_all):
    from gcodekit.view.coloring import waypoint_scalars

    op = read_all["lightburn_0.9.24_g2_lens.nc"][0]
    power = op.waypoints["power"]
    # LightBurn scans with S255 (lit) and S0 (unlit) on G1 under M4; G0 moves are unlit
    assert power.max() == 255.0 and (power[op.waypoints["motion"] == 1] == 0).all()
    assert set(np.unique(power)) >= {0.0, 255.0}
    assert op.columns.loc["power", "unit"] == "S"
    assert "power" in op.to_dataframe().columns
    values, categories = waypoint_scalars(op, "power")
    assert categories is None and np.array_equal(values, power)


# -- small programs of our own in the tools' styles ------------------------------------------------------

# A plasma cutting script written as .gcode: the feed set once, the torch on M3, a pierce delay whose
# comment has words (read as Marlin, the 'f' of 'finish' was a bare F that cleared the feed)
SQUARE = "M3 (torch on)\nG4 P0.5 (pause to finish the pierce)\nG1 X{x1}\nG1 Y100\nG1 X{x0}\nG1 Y0\nM5 (torch off)\n"
PLASMA = ("(Plasma: two 100 mm squares)\nG21\nG90\nF1000\nG0 X0 Y0\n" + SQUARE.format(x0=0, x1=100)
          + "G0 X150 Y0\n" + SQUARE.format(x0=150, x1=250) + "G0 X0 Y0\nM30\n")


def test_plasma_program_named_gcode_is_a_mill_program(tmp_path):
    for name in ("cut.gcode", "cut.nc", "cut.txt"):
        path = tmp_path / name
        path.write_text(PLASMA)
        op = gcodekit.gcode_to_operation(path, plan=False)
        assert op.flavor.name == "rs274ngc" and op.machine.process == "subtractive"
        assert [d.severity for d in op.diagnostics.items] == ["info"]  # thin evidence, said so
        w = op.waypoints
        # two squares of 400 mm at 1000 mm/min: 48 s of cutting, plus two 0.5 s pierce dwells
        assert float(np.nansum(w["time"][w["motion"] >= 2])) == pytest.approx(48.0)
        assert float(np.nansum(w["time"][w["motion"] == 0])) == pytest.approx(1.0)
        assert op.summary()["untimed_moves"] == 0


FUSION_STYLE = """(1001)
(T1  D=6 CR=0 - ZMIN=-1 - flat end mill)
G90 G94
G17
G21
G54
G1 X10 Y10
G1 Z-1 F300
G1 X20
M30
"""


def test_move_before_any_feed_is_refused_and_untimed():
    ngc = gcodekit.gcode_to_operation(FUSION_STYLE, flavor="rs274ngc", plan=False)
    assert [(d.severity, d.line) for d in ngc.diagnostics.items] == [("error", 7)]
    # Z-1 at 300 mm/min: 0.2 s, X20 (10 mm): 2 s; the first move has no time and is counted apart
    assert ngc.summary()["time_s"] == pytest.approx(2.2) and ngc.summary()["untimed_moves"] == 1
    grbl = gcodekit.gcode_to_operation(FUSION_STYLE, flavor="grbl")  # planned by GRBL's planner
    assert [(d.severity, d.line) for d in grbl.diagnostics.items] == [("error", 7)]  # GRBL's error 22
    assert grbl.summary()["untimed_moves"] == 1
    assert grbl.summary()["time_s"] < 3.0  # not 14 mm at GRBL's 1 mm/min floor (848 s)


def test_printer_move_before_any_feed_uses_the_boot_feed_and_says_so():
    op = gcodekit.gcode_to_operation("M82\nG28\nG1 X30 E1\nG1 X60 F3000\n", flavor="marlin", plan=False)
    infos = [d for d in op.diagnostics.items if d.severity == "info"]
    assert len(infos) == 1 and infos[0].line == 3 and "1500 mm/min" in infos[0].message
    w = op.waypoints
    assert w["time"][w["motion"] >= 2].tolist() == pytest.approx([30 / 25.0, 30 / 50.0])  # 1500 and 3000 mm/min
    assert op.summary()["untimed_moves"] == 0


BAMBU_STYLE = """; HEADER_BLOCK_START
; BambuStudio 01.07.06.92
; HEADER_BLOCK_END
M1002 gcode_claim_action : 2
M620 S0A
M624 AQAAAAAAAAA=
M900 K0.02 L1000 M10
G1 X10 Y10 F600
G1 X20 E1
M625
M1002 judge_flag timelapse_record_flag
M621 S0A
"""


def test_bambu_dialect_reads_its_text_arguments_quietly():
    op = gcodekit.gcode_to_operation(BAMBU_STYLE, plan=False)
    assert op.flavor.name == "bambu" and op.machine.name == "bambu"
    assert {d.severity for d in op.diagnostics.items} == {"info"}
    codes = [d.message.split()[0] for d in op.diagnostics.items]
    assert sorted(codes) == sorted({"M1002", "M620", "M624", "M900", "M625", "M621"})  # one info per code
    assert op.summary()["filament_mm"] == pytest.approx(1.0)


SKEINFORGE_MAKERBOT = """(<?xml version="1.0" ?>)
(<extruderInitialization>)
M103
G21
G90
G162 X Y F2500 (home XY axes maximum)
G92 X0 Y0 Z0 A0
(</extruderInitialization>)
(<layer> 0.3 )
M108 R3.0
M101
G1 X10 Y0 Z0.3 F1800.0
G1 X10 Y10 Z0.3 F1800.0
M103
(</layer>)
"""


def test_skeinforge_makerbot_file_is_makerbot():
    detection = detect_flavor(SKEINFORGE_MAKERBOT, "part.gcode")
    assert detection.name == "makerbot" and not detection.weak
    op = gcodekit.gcode_to_operation(SKEINFORGE_MAKERBOT, plan=False)
    assert not [d for d in op.diagnostics.items if d.severity != "info"]
    # 3D-style: the extruder runs on M101 at its M108 rate, which says no length: no filament is made up
    assert op.summary()["filament_mm"] == 0.0


def test_makerbot_a_and_b_words_are_the_extruders():
    text = "(Makerbot Industries)\nG92 A0 B0\nG1 X10 F600 A2\nG1 X20 A3\nG92 B0\nG1 X30 B1.5\n"
    op = gcodekit.gcode_to_operation(text, plan=False)
    assert op.flavor.name == "makerbot"
    assert op.waypoints["de"][op.waypoints["motion"] >= 2].tolist() == pytest.approx([2.0, 1.0, 1.5])


def test_grbl_dump_makes_a_laser_and_caps_feeds(tmp_path):
    dump = tmp_path / "settings.txt"
    dump.write_text("$$\n$11=0.010\n$12=0.002\n$30=1000\n$32=1\n$110=3000.000\n$111=3000.000\n$112=500.000\n"
                    "$120=1000.000\n$121=1000.000\n$122=100.000\nok\n")
    text = "G21 G90\nM3 S500\nG1 X300 F6000\nG0 X0\nM5\nM2\n"
    op = gcodekit.gcode_to_operation(text, machine="grbl", machine_config=dump)
    w = op.waypoints
    assert op.machine.laser and w["power"][w["motion"] == 2].tolist() == [500.0]
    assert (w["power"][w["motion"] != 2] == 0).all()  # G0 runs unlit
    notices = [d for d in op.diagnostics.items if "faster than the machine allows" in d.message]
    # 300 mm asked at 100 mm/s, capped at 50 mm/s: 3 s more than the program's feed says
    assert len(notices) == 1 and notices[0].line == 3 and "about 3.0 s" in notices[0].message


def test_laser_m4_power_follows_the_planned_speed():
    # M4: power scales with speed; a 2 mm move cannot reach 6000 mm/min with 1000 mm/s^2, so its average
    # power is below S; M3 keeps S whatever the speed
    text = "$32=1\nG21 G90\n{mode} S1000\nG1 X2 F6000\nM5\nM2\n"
    dynamic = gcodekit.gcode_to_operation(text.format(mode="M4"), machine="grbl_laser")
    constant = gcodekit.gcode_to_operation(text.format(mode="M3"), machine="grbl_laser")
    w = dynamic.waypoints
    move = int(np.flatnonzero(w["motion"] == 2)[0])
    average = w["distance"][move] / w["time"][move] / 100.0  # planned average over programmed (100 mm/s)
    assert w["power"][move] == pytest.approx(1000.0 * average) and average < 0.5
    assert constant.waypoints["power"][move] == 1000.0


def test_no_cast_warning_on_exclude_object_polygons():
    text = ("EXCLUDE_OBJECT_DEFINE NAME=a CENTER=150,150 POLYGON=[[38.6934,48.8939],[38.7471,48.6609]"
            + ",[261.307,125.001]" * 200 + "]\nG1 X1 E1 F600\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        op = gcodekit.gcode_to_operation(text, flavor="klipper", plan=False)
    assert op.flavor.name == "klipper"


def test_comments_and_percent_after_m2_are_no_unrun_blocks():
    op = gcodekit.gcode_to_operation("%\nG21\nG1 X1 F100\nM2\n(done)\n; end\n%\n", flavor="rs274ngc", plan=False)
    assert not op.diagnostics.items
    op = gcodekit.gcode_to_operation("G21\nG1 X1 F100\nM2\n(more)\nG1 X2\n", flavor="rs274ngc", plan=False)
    assert [(d.severity, d.line) for d in op.diagnostics.items] == [("warning", 5)]


def test_no_linuxcnc_tool_table_warning_under_grbl():
    text = "T1 M6\nG21 G90\nG1 X1 F100\nM2\n"
    assert not [d for d in gcodekit.gcode_to_operation(text, flavor="grbl", plan=False).diagnostics.items
                if "tool table" in d.message]
    assert [d for d in gcodekit.gcode_to_operation(text, flavor="rs274ngc", plan=False).diagnostics.items
            if "tool table" in d.message]


def test_one_kind_of_unreadable_text_is_one_summary():
    # a Marlin reading of a '( ... )'-commented mill program: the same error on every line
    text = "".join(f"G1 X{i} F100 (cut)\n" for i in range(1000))
    op = gcodekit.gcode_to_operation(text, flavor="marlin", plan=False)
    same = [d for d in op.diagnostics.items if d.message.startswith("unexpected character '('")]
    assert len(same) == 21 and "and 980 more times from this line on" in same[-1].message
    assert op.summary()["diagnostics_total"] == len(op.diagnostics.items) + op.diagnostics.dropped


def test_relative_e_without_m83_is_said_once():
    # KISSlicer's style: E per move (0.05 and 0.02 mm by turns), no M83
    moves = "".join(f"G1 X{i} Y{i % 2} E{0.05 if i % 2 else 0.02}\n" for i in range(1, 40))
    op = gcodekit.gcode_to_operation("; KISSlicer\nG90\nG1 Z0.3 F600\n" + moves, flavor="marlin", plan=False)
    warned = [d for d in op.diagnostics.items if "look relative" in d.message]
    # read as positions, E falls on the 19 moves to E0.02 of the 39, and the net is the last E
    assert len(warned) == 1 and warned[0].line == 5 and "E falls on 19 of 39" in warned[0].message
    assert op.summary()["filament_mm"] == pytest.approx(0.05)
    with_m83 = gcodekit.gcode_to_operation("M83\nG1 Z0.3 F600\n" + moves, flavor="marlin", plan=False)
    assert not with_m83.diagnostics.items and with_m83.summary()["filament_mm"] == pytest.approx(20 * 0.05 + 19 * 0.02)


def test_stated_filament_diameter_gives_the_volume(tmp_path):
    text = "; filament_diameter = 2.85\nM83\nG1 X10 E1 F600\n"
    op = gcodekit.gcode_to_operation(text, flavor="marlin", plan=False)
    assert op.machine.filament_diameter == 2.85
    assert op.summary()["volume_mm3"] == pytest.approx(np.pi * 2.85**2 / 4)
    given = gcodekit.gcode_to_operation(text, flavor="marlin", plan=False, filament_diameter=1.75)
    assert given.machine.filament_diameter == 1.75 and not given.diagnostics.items


LOOKS = "the program looks written for"


def _hints(op) -> list:
    return [d for d in op.diagnostics.items if d.message.startswith(LOOKS)]


def test_printer_program_read_as_a_mill_dialect_says_which_dialect_it_looks_written_for(realworld):
    op = gcodekit.gcode_to_operation(realworld / "kisslicer_1.1.0.14_cube.gcode", flavor="rs274ngc", plan=False)
    hints = _hints(op)
    # one warning, first, at 1:1, beside the 109 true rs274ngc diagnostics it explains (31 of them errors;
    # 78 are repeats of listed messages, counted in their summaries)
    assert len(hints) == 1 and op.diagnostics.items[0] is hints[0]
    assert (hints[0].severity, hints[0].line, hints[0].column) == ("warning", 1, 1)
    assert op.summary()["diagnostics_total"] == 110 and len(op.diagnostics.errors) == 31
    assert hints[0].message == (
        "the program looks written for 'marlin' (header '; KISSlicer - FREE' on line 1), but was read as "
        "'rs274ngc' (the flavor given): the errors may come from that; to read it as 'marlin', give --flavor marlin "
        "(flavor='marlin')")
    assert hints[0].text == "; KISSlicer - FREE"  # line 1, quoted like any diagnostic's
    # the flavor came with the machine: the advice is a machine for the dialect
    on_mill = _hints(gcodekit.gcode_to_operation(realworld / "kisslicer_1.1.0.14_cube.gcode", machine="linuxcnc",
                                                 plan=False))
    assert len(on_mill) == 1 and "(the linuxcnc machine's flavor)" in on_mill[0].message
    assert on_mill[0].message.endswith("give a machine for it, e.g. --machine marlin (machine='marlin')")


def test_printer_program_read_as_grbl_says_so_for_the_codes_grbl_does_not_know(realworld):
    # no error or warning here: GRBL keeps M104, M109, ... as codes without meaning (an info each)
    op = gcodekit.gcode_to_operation(realworld / "kisslicer_1.1.0.14_cube.gcode", flavor="grbl", plan=False)
    assert not op.diagnostics.errors and len(op.diagnostics.unknown_codes) == 7
    hints = _hints(op)
    assert len(hints) == 1 and "but was read as 'grbl' (the flavor given): the codes unknown to 'grbl' may" \
        in hints[0].message
    assert hints[0].severity == "info"  # as what it explains


def _something_to_explain(op) -> bool:
    return bool(op.diagnostics.errors or op.diagnostics.unknown_codes
                or any(d.severity == "warning" for d in op.diagnostics.items))


@pytest.mark.parametrize("name, flavor", [
    # a Marlin program read by firmware that inherits Marlin's codes
    ("kisslicer_1.1.0.14_cube.gcode", "marlin"), ("kisslicer_1.1.0.14_cube.gcode", "prusa"),
    ("kisslicer_1.1.0.14_cube.gcode", "klipper"), ("cura_legacy_fabtotum_cable_ties.gcode", "klipper"),
    # Cura's ;FLAVOR:Marlin beside Klipper's START_PRINT: klipper by a point, marlin close behind, so the
    # evidence does not rule Marlin out (8 errors to explain, and no hint)
    ("cura_5.9.1_k1max.gcode", "marlin"),
])
def test_no_hint_for_the_program_s_own_dialect_or_one_it_builds_on(realworld, name, flavor):
    op = gcodekit.gcode_to_operation(realworld / name, flavor=flavor, plan=False)
    assert _hints(op) == []
    if name == "cura_5.9.1_k1max.gcode":
        assert _something_to_explain(op)


@pytest.mark.parametrize("name, flavor, looks, errors, header", [
    # firmware that does not know the dialect's own commands: Marlin has no Klipper macros or MakerBot
    # comments, Prusa's firmware no Bambu M620
    ("orca_2.3.0b2_k1max_klipper.gcode", "marlin", "klipper", 64,
     "'EXCLUDE_OBJECT_DEFINE NAME=AzulTileTray.stl_id_0_copy_0 CENT...' on line 112"),
    ("miraclegrue_0.04_20mm_box.gcode", "marlin", "makerbot", 261, "'(Makerbot Industries)' on line 2"),
    ("bambustudio_1.7.6_x1_cube.gcode", "prusa", "bambu", 100, "'; BambuStudio 01.07.06.92' on line 2"),
])
def test_a_printer_program_read_by_a_relative_that_cannot_read_it_gets_the_hint(realworld, name, flavor, looks,
                                                                                  errors, header):
    op = gcodekit.gcode_to_operation(realworld / name, flavor=flavor, plan=False)
    hints = _hints(op)
    assert len(op.diagnostics.errors) == errors and len(hints) == 1
    # the evidence: the header lines, quoted (a long one cut) with their numbers
    assert hints[0].message.startswith(f"the program looks written for {looks!r} (header {header}")
    assert f"but was read as {flavor!r} (the flavor given): the errors may come from that" in hints[0].message


def test_linuxcnc_program_read_as_marlin_hints_only_on_strong_evidence(shared_dir):
    nc_files = shared_dir / "corpus" / "linuxcnc" / "nc_files"
    # g20sub.ngc opens with 'O<g20sub> sub': LinuxCNC's own syntax, which Marlin reads as 19 errors
    op = gcodekit.gcode_to_operation(nc_files / "g20sub.ngc", flavor="marlin", plan=False)
    hints = _hints(op)
    assert len(hints) == 1 and len(op.diagnostics.errors) == 19
    assert hints[0].message.startswith("the program looks written for 'rs274ngc' (header 'O<g20sub> sub' on line 2)")
    assert hints[0].message.endswith("give --flavor rs274ngc (flavor='rs274ngc')")
    # 3dtest.ngc has 22 errors as Marlin, but only its .ngc name points to LinuxCNC: too little to say
    thin = gcodekit.gcode_to_operation(nc_files / "3dtest.ngc", flavor="marlin", plan=False)
    assert len(thin.diagnostics.errors) == 22 and _hints(thin) == []
    assert not detect_flavor((nc_files / "3dtest.ngc").read_text(), "3dtest.ngc").rules_out(load_flavor("marlin"))


def test_dialect_hint_needs_evidence_and_something_to_explain():
    # a Cura banner and an E word: strong evidence, and rs274ngc's two errors to explain
    op = gcodekit.gcode_to_operation(";FLAVOR:Marlin\nM104 S200\nG1 X1 E1 F600\n", flavor="rs274ngc", plan=False)
    assert [d.line for d in _hints(op)] == [1] and len(op.diagnostics.errors) == 2
    # the same errors without the banner: a guess, not evidence (the detection scores nothing)
    bare = gcodekit.gcode_to_operation("M104 S200\nG1 X1 E1 F600\n", flavor="rs274ngc", plan=False)
    assert len(bare.diagnostics.errors) == 2 and _hints(bare) == []
    # the banner on a program rs274ngc reads without a complaint: nothing to explain
    clean = gcodekit.gcode_to_operation(";FLAVOR:Marlin\nG21\nG1 X1 F600\nM2\n", flavor="rs274ngc", plan=False)
    assert clean.diagnostics.items == []
    # detected, not given: the reading is the detection's, nothing to add
    detected = gcodekit.gcode_to_operation(";FLAVOR:Marlin\nM104 S200\nG1 X1 E1 F600\n", plan=False)
    assert detected.flavor.name == "marlin" and _hints(detected) == []


def test_dialect_hint_when_parsing_only():
    op = gcodekit.parse_program(";FLAVOR:Marlin\nM104 S200\nG1 X1 E1 F600\n", flavor="fanuc")
    assert len(_hints(op)) == 1 and "but was read as 'fanuc'" in _hints(op)[0].message


def test_a_note_put_first_leaves_the_summaries_counting():
    from gcodekit.errors import Diagnostics

    diagnostics = Diagnostics("part.ngc", repeats=2)
    for line in (1, 2, 3):
        diagnostics.report(line, 1, "bad")
    note = diagnostics.report_first(1, 1, "explains them")
    diagnostics.report(4, 1, "bad")  # counted into the summary, which moved one place down
    assert [d.message for d in diagnostics.items] == [
        "explains them", "bad", "bad", "bad -- and 2 more times from this line on, not listed"]
    assert diagnostics.items[0] is note and note.severity == "warning" and diagnostics.dropped == 2


def test_a_relative_s_unknown_codes_alone_give_no_hint(shared_dir):
    """PrusaSlicer's cube for a Prusa MK3 (its M862.3 header names Prusa's firmware) planned on a Marlin
    machine: Marlin notes M862.3 and G80 as codes without meaning, which is all; the user may well mean
    to plan it on Marlin, so no hint.  Read as GRBL, a dialect of another family, it gets one."""
    cube = shared_dir / "corpus" / "fff" / "cube20_marlin2.gcode"
    on_marlin = gcodekit.gcode_to_operation(cube, "marlin", plan=False)
    assert len(on_marlin.diagnostics.unknown_codes) == 2 and not on_marlin.diagnostics.errors
    assert detect_flavor(cube.read_text()[:65536], cube.name).rules_out(load_flavor("marlin"))
    assert _hints(on_marlin) == []
    on_grbl = _hints(gcodekit.gcode_to_operation(cube, "grbl", plan=False))
    assert len(on_grbl) == 1 and on_grbl[0].message.startswith("the program looks written for 'prusa'")


UNREADABLE = "could not be read (each has an error below): the summary describes only the rest"


def test_a_text_that_is_no_program_says_so_first():
    # a markdown note: lines 1 and 3-6 have errors (a '#' expression, words without numbers), line 2 is blank
    text = "# Notes\n\nThese are notes about the shop, not a program.\n| tool | size |\n| --- | --- |\n| T1 | 6 mm |\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    first = op.diagnostics.items[0]
    assert (first.severity, first.line) == ("warning", 1)
    assert first.message.startswith(f"5 of its 6 lines {UNREADABLE}")


def test_unreadable_lines_are_counted_listed_or_not():
    # the same error on every line: 21 listed, the rest counted into a summary; every line counts
    text = "".join(f"G1 X{i} F100 (cut)\n" for i in range(1000))
    op = gcodekit.gcode_to_operation(text, flavor="marlin", plan=False)
    assert op.diagnostics.items[0].message.startswith(f"1,000 of its 1,000 lines {UNREADABLE}")
    longer = gcodekit.gcode_to_operation(text * 12, flavor="marlin", plan=False)  # 12,000 lines: the head counts
    assert longer.diagnostics.items[0].message.startswith(f"10,000 of its first 10,000 lines {UNREADABLE}")


@pytest.mark.parametrize("bad, good", [(2, 0), (4, 4), (3, 10)])
def test_a_program_with_a_few_unreadable_lines_gets_no_such_note(bad, good):
    # two bad lines are too few to say so; half the lines, or fewer, are a program with errors, not a text
    text = "G21 G90\n" * good + "G1 X1 F100 Q\n" * bad
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    assert op.diagnostics.has_error
    assert not any(UNREADABLE in d.message for d in op.diagnostics.items)


def test_three_of_five_lines_unreadable_is_said():
    text = "G21 G90\nG1 X1 F100\n" + "G1 X1 F100 Q\n" * 3
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    assert op.diagnostics.items[0].message.startswith(f"3 of its 5 lines {UNREADABLE}")
