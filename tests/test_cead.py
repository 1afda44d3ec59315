"""CEAD programs (Sinumerik 840D, the public AM Flexbot Slicer 2 writer): EM=1, EXTRUDERSPEED2, layers, volume.

Expected values are worked out by hand from examples/cead_wall.mpf: a 1000 x
500 mm rectangle, two layers at Z2 and Z4, an 8 x 2 mm bead, perimeters at
F1400 mm/min, a 150 mm lead-in written with EM=1 as the writer does.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit import analysis
from gcodekit.errors import ConfigError
from gcodekit.read.tokenize import LineTokenizer
from gcodekit.errors import Diagnostics
from gcodekit.syntax import load_flavor

WALL = Path(__file__).parents[1] / "examples" / "cead_wall.mpf"
BEAD = 8.0 * 2.0  # mm^2, EXTRUDERSPEED2(8.0000,2.0000,1400)


def test_detected_from_the_flexbot_header():
    op = gcodekit.gcode_to_operation(WALL)
    assert (op.flavor.name, op.machine.name) == ("cead", "cead")
    assert list(op.diagnostics) == []


def test_sinumerik_assignments_and_calls_are_read():
    diagnostics = Diagnostics("t.mpf")
    tok = LineTokenizer(load_flavor("cead"), diagnostics)
    (block,) = tok.tokenize("G1 F1400 X10.5 Y0 EM=1 ; PERIMETER", 7)
    assert [(w[0], w[1]) for w in block.words] == [("G", 1.0), ("F", 1400.0), ("X", 10.5), ("Y", 0.0)]
    assert block.assignments == [("EM", 1.0, 19)] and block.comments[0][0] == "PERIMETER"
    (block,) = tok.tokenize("H[10]=1 ; EXTRUDER OFF", 8)
    assert block.assignments == [("H[10]", 1.0, 1)]
    (block,) = tok.tokenize("N20 R1=2.5 X=10", 9)  # "X=10" is the word X10 on Sinumerik
    assert block.assignments == [("R1", 2.5, 5)] and ("X", 10.0, 12) in block.words
    (block,) = tok.tokenize("CYCLE832(2,_finish,1) ; ENABLE HIGH SPEED MACHINING CYCLE", 10)
    assert block.named == ("CYCLE832", "2,_finish,1", 1) and block.comments
    tok.tokenize("EXTRUDERSPEED2(8,2", 11)
    (problem,) = list(diagnostics)
    assert (problem.line, problem.column) == (11, 15) and "not closed" in problem.message


def test_em_switches_material_on_feed_moves():
    op = gcodekit.gcode_to_operation(WALL)
    stats = op.get_statistics()
    # the lead-in (EM=1) and 4 + 4 perimeter sides; EM=0 travels and the final lift after the
    # zero bead EXTRUDERSPEED2(0,0,1) lay nothing
    assert stats["moves"]["extruding"] == 9
    assert stats["distance_mm"]["extrude"] == pytest.approx(150 + 2 * 3000)
    # Z200 (200 mm), approach to (0,-150,2) (hypot(150, 198)), lead-in 150, 2 x 3000, layer travel 2, lift 50
    assert stats["distance_mm"]["feed"] == pytest.approx(200 + math.hypot(150, 198) + 150 + 6000 + 2 + 50)
    assert stats["time_s"] == pytest.approx(200 / 50 + math.hypot(150, 198) / 100 + 150 / 100
                                            + 6000 / (1400 / 60) + 2 / 100 + 50 / 50)
    assert stats["layers"] == 2
    printing = analysis.depositing(op.waypoints)
    assert np.unique(op.waypoints["z"][printing]).tolist() == [2.0, 4.0]
    assert set(analysis.features(op)[printing]) == {"PERIMETER", ""}  # the lead-in's comment is not a region


def test_bead_volume_is_width_times_height_times_length():
    op = gcodekit.gcode_to_operation(WALL)
    feeds = [p for p in op.process_data if p.motion == "feed" and p.deposited_volume > 0]
    assert [p.deposited_volume for p in feeds[:2]] == [pytest.approx(150 * BEAD), pytest.approx(1000 * BEAD)]
    assert feeds[1].bead_area == pytest.approx(BEAD)
    part = gcodekit.AdditivePart(op)
    assert part.n_layers == 2
    assert part.deposition_length == pytest.approx(6150.0)
    assert part.volume == pytest.approx(6150.0 * BEAD)  # 98,400 mm^3


def test_volume_is_unknown_before_the_first_bead_call():
    op = gcodekit.gcode_to_operation("G1 F600 X10 EM=1\nEXTRUDERSPEED2(4,1,1400)\nG1 X20 EM=1\nM30\n", "cead")
    volumes = op.deposited_volumes()
    moved = op.waypoints["distance"] > 0
    assert np.isnan(volumes[moved][0]) and volumes[moved][1] == pytest.approx(10 * 4.0)


def test_m3_screw_programs_run_with_the_screw_extruder_type():
    # one version of the writer drives the screw like a spindle: "M3 S<rpm> ; UPDATE EXTRUDER RPM"
    text = "G1 F600 X0 Y0 EM=0\nM3 S60\nG1 X100 EM=1\nM5\nM30\n"
    op = gcodekit.gcode_to_operation(text, "cead", extruder_type="screw", screw_displacement=1.5)
    # 100 mm at 600 mm/min is 10 s; 60 rpm for 10 s is 10 rev of 1.5 cm^3
    assert op.deposited_volumes().sum() == pytest.approx(10 * 1.5 * 1000)


def test_named_codes_need_assignments_or_extended_commands(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\n[codes]\nEM = "deposition_switch"\n')
    with pytest.raises(ConfigError, match="assignments = true"):
        load_flavor(path)
