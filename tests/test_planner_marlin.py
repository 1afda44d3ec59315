"""Marlin 2's planner: PrusaSlicer's estimates, hand-worked junctions, and a per-move oracle.

PrusaSlicer 2.5 writes its own estimate into each file it slices
(``; estimated printing time (normal mode) = 21m 25s``), computed with the
Marlin model and the M201-M205 limits the file emits; the planner must
come within 1 % of it using only those limits.
"""

from __future__ import annotations

import gzip
import math
import re
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.plan import planner_settings
from gcodekit.plan import lookahead, marlin
from gcodekit.plan.moves import firmware_moves
from gcodekit.plan.moves import speed_factor as _speed_factor
from gcodekit.parse.table import NAME_ID
from shared_corpus import CORPUS as SHARED_CORPUS

CASES = Path(__file__).parent / "golden" / "klipper" / "cases"  # cube20_marlin2.gcode lives there
SHARED_FFF = SHARED_CORPUS / "fff"
CLASSIC = marlin.MarlinConfig(classic_jerk=True)


def corpus_file(name: str) -> Path:
    path = CASES / name if (CASES / name).exists() else SHARED_FFF / name
    if not path.exists():
        pytest.skip(f"{name} is only in the shared corpus")
    return path


def slicer_estimate(path: Path) -> float:
    """PrusaSlicer's "estimated printing time (normal mode)" from the file's footer, in seconds."""
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt", encoding="utf-8") as f:
        for line in f:
            if line.startswith("; estimated printing time (normal mode)"):
                text = line.split("=", 1)[1]
                units = {"d": 86400, "h": 3600, "m": 60, "s": 1}
                return float(sum(int(v) * units[u] for v, u in re.findall(r"(\d+)([dhms])", text)))
    raise AssertionError(f"{path.name} has no PrusaSlicer estimate")


def plan_text(text: str, config: marlin.MarlinConfig = CLASSIC):
    op = gcodekit.gcode_to_operation(text, "marlin", plan=False)
    return marlin.plan(op, config)


# -- PrusaSlicer's estimates ------------------------------------------------------------


@pytest.mark.parametrize("name", ["cube20_marlin2.gcode", "cylinder_marlin2.gcode", "vase_spiral_marlin2.gcode"])
def test_prusaslicer_estimate_within_1_percent(name):
    path = corpus_file(name)
    total = gcodekit.gcode_to_operation(path, "marlin").get_statistics()["time_s"]
    assert total == pytest.approx(slicer_estimate(path), rel=0.01)


def test_plate150_within_1_percent():  # 3.1 M lines: about 13 s
    path = corpus_file("plate150_marlin2.gcode.gz")
    total = gcodekit.gcode_to_operation(path, "marlin").get_statistics()["time_s"]
    assert total == pytest.approx(slicer_estimate(path), rel=0.01)


def test_arcwelder_file_close_to_the_unwelded_estimate():
    # ArcWelder rewrote the file after slicing and kept the slicer's footer, so
    # the estimate is of the polyline program.  Marlin 2.1 cuts the arcs into
    # at least 72 chords per turn, which corner faster than the polylines: the
    # plan comes out a few percent shorter, never longer.  Cutting every arc
    # into one chord (or dropping them) would land outside this band.
    path = corpus_file("cylinder_marlin2_arcwelder.gcode")
    total = gcodekit.gcode_to_operation(path, "marlin").get_statistics()["time_s"]
    estimate = slicer_estimate(path)
    assert 0.94 * estimate < total < estimate


# -- limits from the program -------------------------------------------------------------


def test_m204_print_travel_and_retract_accelerations():
    moves, result = plan_text("M204 P800 R1500 T2500\n"
                              "G1 X50 E2 F3000\n"      # printing: P
                              "G1 X100 F3000\n"        # travel: T
                              "G1 E-1 F2100\n"         # extruder only: R
                              "M204 S600\n"            # legacy S: print and travel
                              "G1 X150 E2\nG1 X200\n")
    assert result.accel.tolist() == [800.0, 2500.0, 1500.0, 600.0, 600.0]


def test_m201_caps_acceleration_per_axis():
    # 3-4-5 triangle: Y carries 4/5 of the acceleration, so 400 on Y allows 500 along the move
    moves, result = plan_text("M201 X5000 Y400\nM204 T3000\nG1 X30 Y40 F6000\n")
    assert result.accel[0] == pytest.approx(400.0 / 0.8)


def test_m203_caps_the_speed_and_m205_s_raises_it():
    moves, result = plan_text("M203 X20\nG1 X100 F6000\nM205 S15\nG1 X110 E1 F60\n")
    assert result.cruise_v[0] == pytest.approx(20.0)
    assert result.cruise_v[1] == pytest.approx(15.0)  # 1 mm/s requested, 15 mm/s minimum extruding feed


def test_m220_scales_the_feed():
    moves, result = plan_text("M220 S50\nG1 X300 F6000\n")
    assert result.cruise_v[0] == pytest.approx(50.0)


# -- junctions, worked by hand -----------------------------------------------------------


def test_classic_jerk_right_angle_runs_at_the_jerk():
    # X then Y at 50 mm/s with 10 mm/s jerk: each axis may jump by 10 mm/s,
    # so the corner is taken at 10 mm/s (X drops 10 -> 0, Y rises 0 -> 10)
    moves, result = plan_text("M205 X10 Y10\nM204 T1000\nG1 X100 F3000\nG1 Y100\n")
    assert result.end_v[0] == pytest.approx(10.0)
    assert result.start_v[1] == pytest.approx(10.0)


def test_classic_jerk_shallow_corner():
    # a 30 degree turn at 50 mm/s: X changes by 50 (1 - cos 30) = 6.7 mm/s, Y by
    # 50 sin 30 = 25 mm/s > 10, so the shared speed scales by 10/25 to 20 mm/s
    x, y = 100 + 100 * math.cos(math.radians(30)), 100 * math.sin(math.radians(30))
    moves, result = plan_text(f"M205 X10 Y10\nM204 T1000\nG1 X100 F3000\nG1 X{x:.6f} Y{y:.6f}\n")
    assert result.end_v[0] == pytest.approx(20.0, rel=1e-5)


def test_junction_deviation_right_angle():
    # v^2 = a * jd * sin(theta/2) / (1 - sin(theta/2)), theta/2 = 45 degrees
    a, jd = 1000.0, 0.013
    s = math.sin(math.radians(45))
    expected = math.sqrt(a * jd * s / (1 - s))
    moves, result = plan_text("M204 T1000\nM205 J0.013\nG1 X100 F3000\nG1 Y100\n", marlin.MarlinConfig())
    assert result.end_v[0] == pytest.approx(expected, rel=1e-6)


def test_dwell_brings_marlin_to_rest():
    # collinear moves cruise through their junction; with G4 between them the
    # first ends at MINIMUM_PLANNER_SPEED and the second restarts at the jerk speed
    _, through = plan_text("M205 X10\nM204 T1000\nG1 X100 F3000\nG1 X200\n")
    _, stopped = plan_text("M205 X10\nM204 T1000\nG1 X100 F3000\nG4 P0\nG1 X200\n")
    assert through.end_v[0] == pytest.approx(50.0)
    assert stopped.end_v[0] == pytest.approx(0.05)
    assert stopped.start_v[1] == pytest.approx(10.0)


def test_restart_after_rest_is_not_limited_by_the_move_before():
    # a 0.01 mm crawl ends the queue; after G4 the next move starts at its jerk speed
    # (10 mm/s), not at what accelerating over the crawl would allow (~4.6 mm/s)
    moves, result = plan_text("M205 X10\nM204 T1000\nG1 X0.01 F60\nG4 P0\nG1 X100 F3000\n")
    assert result.start_v[1] == pytest.approx(10.0)


def test_dwell_times_add_to_the_plan():
    # at the end of the program the machine is at rest anyway: G4 only adds its time (P ms, S s)
    base = gcodekit.gcode_to_operation("G1 X100 F3000\n", "marlin").get_statistics()["time_s"]
    dwell = gcodekit.gcode_to_operation("G1 X100 F3000\nG4 P500\nG4 S1\n", "marlin").get_statistics()["time_s"]
    assert dwell - base == pytest.approx(1.5)


def test_single_move_trapezoid_by_hand():
    # 100 mm at 50 mm/s, 1000 mm/s^2, starting at the 10 mm/s jerk, braking to 0.05 mm/s
    moves, result = plan_text("M205 X10\nM204 T1000\nG1 X100 F3000\n")
    up = (50.0 - 10.0) / 1000.0
    down = (50.0 - 0.05) / 1000.0
    cruise = (100.0 - (50.0**2 - 10.0**2) / 2000.0 - (50.0**2 - 0.05**2) / 2000.0) / 50.0
    assert result.duration_t[0] == pytest.approx(up + cruise + down, rel=1e-9)


def test_s_curve_keeps_block_times():
    text = "M204 T1000\nG1 X100 F3000\nG1 Y100\nG1 X0 Y0\n"
    _, linear = plan_text(text)
    _, s_curve = plan_text(text, marlin.MarlinConfig(classic_jerk=True, s_curve_acceleration=True))
    np.testing.assert_array_equal(linear.duration_t, s_curve.duration_t)


# -- arcs ----------------------------------------------------------------------------------


def test_arc_chords_follow_marlin_2_1_rule():
    # half turn of radius 10: 31.4 mm gives 31 chords of 1 mm, but 72 per turn asks for 36;
    # half turn of radius 50: 157 mm gives 157 chords (more than 36)
    moves, _ = plan_text("G1 X10 Y0 F3000\nG3 X-10 Y0 I-10 J0\nG1 X50 Y0\nG3 X-50 Y0 I-50 J0\n")
    rows = np.unique(moves.row, return_counts=True)[1]
    assert rows.tolist() == [1, 36, 1, 157]


def test_arc_segments_rule():
    travel = np.array([0.5, 31.4159, 157.08])
    angle = np.array([0.05, np.pi, np.pi])
    radius = np.array([10.0, 10.0, 50.0])
    assert marlin.arc_segments(travel, angle, radius).tolist() == [1.0, 36.0, 157.0]


# -- settings -------------------------------------------------------------------------------


def test_preset_names_the_marlin_planner():
    machine = gcodekit.load_machine("marlin")
    settings = planner_settings(machine.planner, machine.planner_settings)
    assert machine.planner == "marlin" and settings.classic_jerk


def test_m503_report(tmp_path):
    report = tmp_path / "m503.txt"
    report.write_text("echo:  M201 X1000.00 Y1000.00 Z200.00 E5000.00\n"
                      "echo:  M203 X200.00 Y200.00 Z12.00 E120.00\n"
                      "echo:  M204 P1250.00 R1250.00 T1500.00\n"
                      "echo:  M205 B20000.00 S0.00 T0.00 X8.00 Y8.00 Z0.40 E4.50 ; classic jerk\n")
    c = marlin.MarlinConfig.from_m503(report)
    assert (c.max_acceleration_y, c.max_feedrate_z, c.travel_acceleration, c.max_jerk_e) == (1000.0, 12.0, 1500.0, 4.5)
    assert c.classic_jerk


def test_m503_needs_motion_lines(tmp_path):
    report = tmp_path / "m503.txt"
    report.write_text("echo: Marlin 2.1\n")
    with pytest.raises(gcodekit.ConfigError, match="m503.txt"):
        marlin.MarlinConfig.from_m503(report)


# -- the oracle: Marlin's planner move by move ---------------------------------------------

REST = [NAME_ID[n] for n in marlin.REST_NAMES]


def oracle(op, config: marlin.MarlinConfig):
    """Marlin 2.1 ``_populate_block`` + ``recalculate``, one block at a time, as the firmware runs them."""
    t = op.table
    moves = firmware_moves(op, _speed_factor(op), lambda travel, angle, radius, speed_v: marlin.arc_segments(
        travel, angle, radius, config.max_arc_segment_mm, config.min_circle_segments))
    s = {"max_feedrate": list(config.axes("max_feedrate")), "max_acceleration": list(config.axes("max_acceleration")),
         "max_jerk": list(config.axes("max_jerk")), "acceleration": config.acceleration,
         "retract_acceleration": config.retract_acceleration, "travel_acceleration": config.travel_acceleration,
         "junction_deviation": config.junction_deviation, "min_feedrate": config.min_feedrate,
         "min_travel_feedrate": config.min_travel_feedrate}
    blocks, last_row = [], -1
    previous = None
    for i in range(len(moves)):
        rest = previous is None
        for row in range(last_row + 1, int(moves.row[i])):
            name = int(t.name[row])
            rest |= name in REST
            p = t.command(row).params
            if name == NAME_ID["set_max_accel"] or name == NAME_ID["set_max_feed"]:
                key = "max_acceleration" if name == NAME_ID["set_max_accel"] else "max_feedrate"
                for k, a in enumerate("XYZE"):
                    if a in p:
                        s[key][k] = p[a]
            elif name == NAME_ID["set_accel"]:
                if "S" in p:
                    s["acceleration"] = s["travel_acceleration"] = p["S"]
                for letter, key in (("P", "acceleration"), ("R", "retract_acceleration"), ("T", "travel_acceleration")):
                    if letter in p:
                        s[key] = p[letter]
            elif name == NAME_ID["set_jerk"]:
                for k, a in enumerate("XYZE"):
                    if a in p:
                        s["max_jerk"][k] = p[a]
                for letter, key in (("J", "junction_deviation"), ("S", "min_feedrate"), ("T", "min_travel_feedrate")):
                    if letter in p:
                        s[key] = p[letter]
        last_row = int(moves.row[i])  # chords of one arc share its row: nothing between them
        block = populate_block(moves.axes_d[i], float(moves.speed_v[i]), s, config, None if rest else previous)
        block["rest_before"] = rest
        blocks.append(block)
        previous = block
    recalculate(blocks, config.minimum_planner_speed)
    return np.array([trapezoid_time(b) for b in blocks]), np.array([b["entry"] for b in blocks])


def populate_block(d, fr_mm_s, s, config, previous):
    xyz = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    has_xyz = any(d[k] != 0 for k in range(3))
    esteps = d[3] != 0
    millimeters = xyz if has_xyz else abs(d[3])
    fr_mm_s = max(fr_mm_s, s["min_feedrate"] if esteps else s["min_travel_feedrate"], config.minimum_planner_speed)
    inverse_secs = fr_mm_s / millimeters
    current_speed = [d[k] * inverse_secs for k in range(4)]
    speed_factor = 1.0
    for k in range(4):
        cs = abs(current_speed[k])
        if cs > s["max_feedrate"][k]:
            speed_factor = min(speed_factor, s["max_feedrate"][k] / cs)
    current_speed = [c * speed_factor for c in current_speed]
    nominal_speed = fr_mm_s * speed_factor
    if not has_xyz:
        acceleration = s["retract_acceleration"]
    else:
        acceleration = s["acceleration"] if esteps else s["travel_acceleration"]
        for k in range(4):
            if d[k] != 0:
                acceleration = min(acceleration, s["max_acceleration"][k] * millimeters / abs(d[k]))
    block = {"millimeters": millimeters, "nominal_speed": nominal_speed, "acceleration": acceleration,
             "current_speed": current_speed}
    if config.classic_jerk:
        safe_speed, limited = nominal_speed, False
        for k in range(4):
            jerk, maxj = abs(current_speed[k]), s["max_jerk"][k]
            if jerk > maxj:
                if limited:
                    if jerk * safe_speed > nominal_speed * maxj:
                        safe_speed = nominal_speed * maxj / jerk
                else:
                    safe_speed *= maxj / jerk
                    limited = True
        block["safe_speed"] = safe_speed
        if previous is None:
            vmax_junction = safe_speed
        else:
            prev_nominal = previous["nominal_speed"]
            vmax_junction = min(nominal_speed, prev_nominal)
            smaller_speed_factor = vmax_junction / prev_nominal
            v_factor, limited = 1.0, False
            for k in range(4):
                v_exit = previous["current_speed"][k] * smaller_speed_factor
                v_entry = current_speed[k]
                if limited:
                    v_exit *= v_factor
                    v_entry *= v_factor
                if v_exit > v_entry:
                    jerk = v_exit - v_entry if (v_entry > 0 or v_exit < 0) else max(v_exit, -v_entry)
                else:
                    jerk = v_entry - v_exit if (v_entry < 0 or v_exit > 0) else max(-v_exit, v_entry)
                if jerk > s["max_jerk"][k]:
                    v_factor *= s["max_jerk"][k] / jerk
                    limited = True
            vmax_junction *= v_factor
            threshold = vmax_junction * 0.99
            if previous["safe_speed"] > threshold and safe_speed > threshold:
                vmax_junction = safe_speed
        max_entry_sqr = vmax_junction**2
    else:
        norm = math.sqrt(sum(c * c for c in d)) if esteps else millimeters
        unit = [d[k] / norm for k in range(4)] if esteps else [d[0] / norm, d[1] / norm, d[2] / norm, 0.0]
        block["unit"] = unit
        if previous is None:
            max_entry_sqr = config.minimum_planner_speed**2
        else:
            pu = previous["unit"]
            cos_theta = -sum(pu[k] * unit[k] for k in range(4))
            if cos_theta > 0.999999:
                max_entry_sqr = config.minimum_planner_speed**2
            else:
                ju = [unit[k] - pu[k] for k in range(4)]
                jn = math.sqrt(sum(c * c for c in ju))
                ju = [c / jn for c in ju]
                ja = acceleration
                for k in range(4):
                    if ju[k] and ja * abs(ju[k]) > s["max_acceleration"][k]:
                        ja = abs(s["max_acceleration"][k] / ju[k])
                cos_theta = max(cos_theta, -0.999999)
                sin_d2 = math.sqrt(0.5 * (1.0 - cos_theta))
                max_entry_sqr = ja * s["junction_deviation"] * sin_d2 / (1.0 - sin_d2)
                if config.jd_handle_small_segments and millimeters < 1 and cos_theta < -0.7071067812:
                    theta = math.acos(-cos_theta)
                    if theta > 0:
                        max_entry_sqr = min(max_entry_sqr, millimeters * ja / theta)
            max_entry_sqr = min(max_entry_sqr, nominal_speed**2, previous["nominal_speed"] ** 2)
    v_allowable_sqr = config.minimum_planner_speed**2 + 2 * acceleration * millimeters
    block.update(max_entry_sqr=max_entry_sqr, entry_sqr=min(max_entry_sqr, v_allowable_sqr),
                 nominal_length=nominal_speed**2 <= v_allowable_sqr)
    return block


def recalculate(blocks, minimum_planner_speed):
    stop_sqr = minimum_planner_speed**2
    n = len(blocks)
    for i in reversed(range(n)):  # reverse_pass_kernel
        b = blocks[i]
        last = i + 1 == n or blocks[i + 1]["rest_before"]
        next_entry = stop_sqr if last else blocks[i + 1]["entry_sqr"]
        b["entry_sqr"] = b["max_entry_sqr"] if b["nominal_length"] else min(
            b["max_entry_sqr"], next_entry + 2 * b["acceleration"] * b["millimeters"])
    for i in range(1, n):  # forward_pass_kernel
        p, b = blocks[i - 1], blocks[i]
        if b["rest_before"] or p["nominal_length"]:
            continue
        if p["entry_sqr"] < b["entry_sqr"]:
            b["entry_sqr"] = min(b["entry_sqr"], p["entry_sqr"] + 2 * p["acceleration"] * p["millimeters"])
    for i, b in enumerate(blocks):
        last = i + 1 == n or blocks[i + 1]["rest_before"]
        b["exit_sqr"] = stop_sqr if last else blocks[i + 1]["entry_sqr"]
        b["entry"] = math.sqrt(b["entry_sqr"])


def trapezoid_time(b):
    """calculate_trapezoid_for_block in distances, then the time of each phase."""
    a, d, vc2 = b["acceleration"], b["millimeters"], b["nominal_speed"] ** 2
    v0_2, v1_2 = b["entry_sqr"], b["exit_sqr"]
    accelerate = (vc2 - v0_2) / (2 * a)
    decelerate = (vc2 - v1_2) / (2 * a)
    if accelerate + decelerate > d:
        accelerate = min(max((d + (v1_2 - v0_2) / (2 * a)) / 2, 0.0), d)
        decelerate = d - accelerate
        vc2 = v0_2 + 2 * a * accelerate
    else:
        accelerate = max(accelerate, 0.0)
        decelerate = min(max(decelerate, 0.0), d - accelerate)
    vc = math.sqrt(vc2)
    v0 = math.sqrt(min(v0_2, vc2))
    v1 = math.sqrt(max(vc2 - 2 * a * decelerate, 0.0))
    plateau = d - accelerate - decelerate
    return (vc - v0) / a * (accelerate > 0) + (plateau / vc if plateau > 0 else 0.0) + (vc - v1) / a * (decelerate > 0)


ORACLE_PROGRAM = """M201 X900 Y700 Z100 E4000
M203 X150 Y120 Z10 E60
M204 P900 R1200 T1500
M205 X9 Y7 Z0.4 E3 S2 T1
G1 Z0.3 F720
G1 X20 Y5 F9000
G1 E1 F2400
G1 X40 Y5 E1.2 F2700
G1 X41 Y5.2 E0.05
G1 X41.5 Y6 E0.04
G1 X41 Y8 E0.1
G1 X20 Y8.1 E1 F1800
G1 E-0.8 F2100
G1 X5 Y30 Z0.5 F9000
M204 S700
G1 X5.2 Y30.1 E0.02 F1200
G1 X5.4 Y30.0 E0.02
G4 P10
G1 X30 Y30 E1.5 F3000
G2 X40 Y20 I0 J-10 E2 F2400
G1 X10 Y10 F12000
M220 S80
G1 X15 Y12 E0.4 F3000
G1 X15 Y12 Z2 F600
"""


@pytest.mark.parametrize("block", [1 << 16, 7], ids=["one_block", "blocks_of_7"])
@pytest.mark.parametrize("classic_jerk", [True, False], ids=["classic_jerk", "junction_deviation"])
def test_vectorized_plan_matches_the_oracle(classic_jerk, block, monkeypatch):
    monkeypatch.setattr(marlin, "BLOCK", block)  # element-wise steps run block by block
    monkeypatch.setattr(lookahead, "BLOCK", block)
    config = marlin.MarlinConfig(classic_jerk=classic_jerk)
    op = gcodekit.gcode_to_operation(ORACLE_PROGRAM, "marlin", plan=False)
    moves, result = marlin.plan(op, config)
    times, entry = oracle(op, config)
    assert len(moves) == times.size > 30
    np.testing.assert_allclose(result.duration_t, times, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(result.start_v, np.minimum(entry, result.cruise_v), rtol=1e-9, atol=1e-12)


def test_vectorized_plan_matches_the_oracle_on_a_real_file():
    op = gcodekit.gcode_to_operation(corpus_file("cube20_marlin2.gcode"), "marlin", plan=False)
    moves, result = marlin.plan(op, CLASSIC)
    times, _ = oracle(op, CLASSIC)
    np.testing.assert_allclose(result.duration_t, times, rtol=1e-9, atol=1e-12)


def test_a_g0_on_a_machine_whose_rapids_are_not_the_feed_plans_at_the_rapid_rate():
    """Sailfish moves G0 at the axes' maximum rate (the MakerBot preset's ``rapid_feed``), not at the modal F,
    and the emulator times it so: the planner must request that speed too.  The G0 plans exactly as the same
    move written as G1 at the rapid rate (before: at F800, 7.5 s for 100 mm against the emulator's 0.33 s)."""
    rapid = gcodekit.gcode_to_operation("G1 F800 X10\nG0 X110\n", "makerbot")
    written = gcodekit.gcode_to_operation("G1 F800 X10\nG1 X110 F18000\n", "makerbot")
    assert rapid.waypoints["time"].tolist() == written.waypoints["time"].tolist()
    assert rapid.waypoints["time"][1] < 1.0
    # where G0 moves at the feed (Marlin), it plans at the feed
    marlin = gcodekit.gcode_to_operation("G1 F800 X10\nG0 X110\n", "marlin")
    at_feed = gcodekit.gcode_to_operation("G1 F800 X10\nG1 X110\n", "marlin")
    assert marlin.waypoints["time"].tolist() == at_feed.waypoints["time"].tolist()
