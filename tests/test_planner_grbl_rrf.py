"""GRBL 1.1 and RepRapFirmware 3 planners against numbers worked out by hand.

Neither firmware has a reference time in the corpus, so each test writes
the firmware's own formula out (a trapezoid, a junction speed, a chord
count) and checks the planner against it; a per-move oracle of grbl's
``planner_recalculate`` checks the vectorized passes.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import gcodekit
from gcodekit.plan import grbl, planner_settings, reprapfirmware
from gcodekit.plan.moves import firmware_moves

GRBL = grbl.GrblConfig(max_rate_x=6000.0, max_rate_y=6000.0, max_rate_z=600.0,
                       acceleration_x=100.0, acceleration_y=100.0, acceleration_z=50.0)
RRF = reprapfirmware.RrfConfig()


def grbl_plan(text: str, config: grbl.GrblConfig = GRBL):
    op = gcodekit.gcode_to_operation("G21 G90\n" + text, "grbl", plan=False)
    return grbl.plan(op, config)


def rrf_plan(text: str, config: reprapfirmware.RrfConfig = RRF):
    op = gcodekit.gcode_to_operation("M83\n" + text, "reprapfirmware", plan=False)
    return reprapfirmware.plan(op, config)


def trapezoid_time(d, v, a, v0=0.0, v1=0.0):
    """Time of a move of length d reaching v (accelerating at a from v0, braking to v1)."""
    up, down = (v * v - v0 * v0) / (2 * a), (v * v - v1 * v1) / (2 * a)
    if up + down > d:
        v = math.sqrt((2 * a * d + v0 * v0 + v1 * v1) / 2)
        return (v - v0) / a + (v - v1) / a
    return (v - v0) / a + (v - v1) / a + (d - up - down) / v


# -- GRBL ----------------------------------------------------------------------------------


def test_grbl_single_move():
    moves, result = grbl_plan("G1 X100 F1200\n")  # 20 mm/s, 100 mm/s^2: 2 mm ramps
    assert result.duration_t[0] == pytest.approx(0.2 + 96.0 / 20.0 + 0.2)


def test_grbl_drops_extruder_only_moves_as_blocks_without_steps():
    """GRBL has no extruder: ``plan_buffer_line`` drops a block without steps, so a 3D printer's retract
    neither takes time nor breaks the straight line through it (before, its infinite acceleration times
    zero length made every speed of the program NaN and its time 0)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy RuntimeWarning either
        moves, result = grbl_plan("G1 X10 F1200\nG1 E5\nG1 X100 E6\n")
    assert len(moves) == 2 and not np.isnan(result.start_v).any()
    # one straight 100 mm move at 20 mm/s and 100 mm/s^2, cut in two: 2 mm ramps
    assert float(result.duration_t.sum()) == pytest.approx(0.2 + 96.0 / 20.0 + 0.2)
    assert result.end_v[0] == pytest.approx(20.0)
    op = gcodekit.gcode_to_operation("G21 G90\nG1 X10 F1200\nG1 E5\nG1 X100 E6\n", "grbl")
    line = op.table.line[op.waypoints["command"]]
    assert op.waypoints["time"][line == 3].tolist() == [0.0] and np.isfinite(op.waypoints["time"]).all()
    assert float(op.waypoints["time"].sum()) == pytest.approx(5.2)
    said = [d for d in op.diagnostics if "extruder-only" in d.message]
    assert [(d.line, d.severity, d.message) for d in said] == [
        (3, "info", "GRBL moves X, Y and Z only: the 1 extruder-only move takes no time")]


def test_grbl_rapid_runs_at_the_max_rate():
    moves, result = grbl_plan("G0 X100 F100\n", grbl.GrblConfig(max_rate_x=3000.0, acceleration_x=100.0))
    assert result.cruise_v[0] == pytest.approx(50.0)
    assert result.duration_t[0] == pytest.approx(trapezoid_time(100.0, 50.0, 100.0))


def test_grbl_limits_along_the_unit_vector():
    # 3-4-5 move: rate min(20/0.6, 20/0.8) = 25 mm/s, acceleration min(100/0.6, 50/0.8) = 62.5 mm/s^2
    config = grbl.GrblConfig(max_rate_x=1200.0, max_rate_y=1200.0, acceleration_x=100.0, acceleration_y=50.0)
    moves, result = grbl_plan("G1 X30 Y40 F60000\n", config)
    assert result.cruise_v[0] == pytest.approx(25.0)
    assert result.accel[0] == pytest.approx(62.5)


def test_grbl_right_angle_junction_deviation():
    # planner.c: the junction unit vector (-1, 1)/sqrt 2 allows 100 * sqrt 2 mm/s^2;
    # v^2 = a * $11 * sin(theta/2) / (1 - sin(theta/2)) with theta/2 = 45 degrees
    a = 100.0 * math.sqrt(2.0)
    s = math.sin(math.radians(45))
    expected = math.sqrt(a * 0.010 * s / (1 - s))
    moves, result = grbl_plan("G1 X100 F6000\nG1 Y100\n")
    assert result.end_v[0] == pytest.approx(expected, rel=1e-9)
    assert result.start_v[1] == pytest.approx(expected, rel=1e-9)


def test_grbl_straight_junction_keeps_speed_and_reversal_stops():
    moves, result = grbl_plan("G1 X100 F3000\nG1 X200\nG1 X100\n")
    assert result.end_v.tolist()[:2] == pytest.approx([50.0, 0.0])


def test_grbl_arc_chords_within_tolerance():
    # mc_arc: floor(0.5 * angle * r / sqrt(tol * (2 r - tol))) = floor(15.708 / 0.19999) = 78
    expected = math.floor(0.5 * math.pi * 10.0 / math.sqrt(0.002 * (20.0 - 0.002)))
    moves, _ = grbl_plan("G1 X10 F1200\nG3 X-10 Y0 I-10 J0\n")
    assert expected == 78
    assert np.unique(moves.row, return_counts=True)[1].tolist() == [1, expected]


@pytest.mark.parametrize("between", ["G4 P0", "M8", "M3 S1000", "G55", "G92 X0"])
def test_grbl_comes_to_rest(between):
    moves, result = grbl_plan(f"G1 X100 F3000\n{between}\nG1 X200\n")
    assert result.end_v[0] == 0.0 and result.start_v[1] == 0.0


def test_grbl_spindle_speed_change_stops_except_in_laser_mode():
    text = "M3 S100\nG1 X100 F3000\nS200\nG1 X200\n"
    _, milling = grbl_plan(text)
    _, laser = grbl_plan(text, grbl.GrblConfig(**{**GRBL.__dict__, "laser_mode": True}))
    assert milling.end_v[0] == 0.0
    assert laser.end_v[0] == pytest.approx(50.0)


def test_grbl_dwell_is_in_seconds():
    base = gcodekit.gcode_to_operation("G21\nG1 X10 F600\n", "grbl").get_statistics()["time_s"]
    dwell = gcodekit.gcode_to_operation("G21\nG1 X10 F600\nG4 P1.5\n", "grbl").get_statistics()["time_s"]
    assert dwell - base == pytest.approx(1.5)


def test_grbl_inverse_time_feed():
    moves, result = grbl_plan("G93 G1 X10 F6\n")  # the 10 mm block takes 1/6 min: 1 mm/s
    assert result.cruise_v[0] == pytest.approx(1.0)


def test_grbl_settings_dump(tmp_path):
    dump = tmp_path / "grbl.txt"
    dump.write_text("$0=10\n$11=0.020\n$12=0.005\n$32=1\n$110=3000.000 (x max rate, mm/min)\n"
                    "$120=250.000\n$122=40\nok\n")
    c = grbl.GrblConfig.from_settings(dump)
    assert (c.junction_deviation, c.arc_tolerance, c.laser_mode) == (0.02, 0.005, True)
    assert (c.max_rate_x, c.acceleration_x, c.acceleration_z, c.max_rate_y) == (3000.0, 250.0, 40.0, 500.0)


def test_grbl_settings_dump_errors(tmp_path):
    dump = tmp_path / "grbl.txt"
    dump.write_text("Grbl 1.1h ['$' for help]\n")
    with pytest.raises(gcodekit.ConfigError, match="grbl.txt"):
        grbl.GrblConfig.from_settings(dump)


def test_grbl_preset_plans_the_pipeline():
    machine = gcodekit.load_machine("grbl")
    assert machine.planner == "grbl"
    op = gcodekit.gcode_to_operation("G21 G90\nG1 X100 F1200\nM2\n", "grbl")
    c = planner_settings("grbl", machine.planner_settings)
    assert op.get_statistics()["time_s"] == pytest.approx(trapezoid_time(100.0, 20.0, c.acceleration_x))


def grbl_oracle(op, config):
    """grbl's plan_buffer_line + planner_recalculate, one block at a time."""
    moves = firmware_moves(op, None, lambda travel, angle, radius, speed_v: grbl.arc_segments(
        travel, angle, radius, config.arc_tolerance))
    acc, rate = config.acceleration, config.max_rate_v
    blocks, prev_unit, prev_nominal = [], None, 0.0
    for i in range(len(moves)):
        d = moves.axes_d[i][:3]
        mm = math.sqrt(sum(c * c for c in d))
        unit = [c / mm for c in d]
        a = min(acc[k] / abs(unit[k]) for k in range(3) if unit[k])
        rapid_rate = min(rate[k] / abs(unit[k]) for k in range(3) if unit[k])
        rapid = op.waypoints["motion"][moves.waypoint[i]] == 1  # G0 runs at the axes' max rate
        nominal = rapid_rate if rapid else max(min(moves.speed_v[i], rapid_rate), 1.0 / 60.0)
        if prev_unit is None:
            junction_sqr = 0.0
        else:
            cos_theta = -sum(prev_unit[k] * unit[k] for k in range(3))
            if cos_theta > 0.999999:
                junction_sqr = 0.0
            elif cos_theta < -0.999999:
                junction_sqr = math.inf
            else:
                ju = [unit[k] - prev_unit[k] for k in range(3)]
                n = math.sqrt(sum(c * c for c in ju))
                ja = min(acc[k] / abs(ju[k] / n) for k in range(3) if ju[k])
                sin_d2 = math.sqrt(0.5 * (1 - cos_theta))
                junction_sqr = ja * config.junction_deviation * sin_d2 / (1 - sin_d2)
        max_entry = min(junction_sqr, nominal**2, prev_nominal**2)
        blocks.append({"mm": mm, "a": a, "nominal": nominal, "max_entry": max_entry, "entry": 0.0})
        prev_unit, prev_nominal = unit, nominal
    for i in reversed(range(len(blocks))):
        nxt = blocks[i + 1]["entry"] if i + 1 < len(blocks) else 0.0
        blocks[i]["entry"] = min(blocks[i]["max_entry"], nxt + 2 * blocks[i]["a"] * blocks[i]["mm"])
    for i in range(1, len(blocks)):
        p = blocks[i - 1]
        blocks[i]["entry"] = min(blocks[i]["entry"], p["entry"] + 2 * p["a"] * p["mm"])
    out = []
    for i, b in enumerate(blocks):
        v1 = math.sqrt(blocks[i + 1]["entry"]) if i + 1 < len(blocks) else 0.0
        out.append(trapezoid_time(b["mm"], b["nominal"], b["a"], math.sqrt(b["entry"]), v1))
    return np.array(out)


def test_grbl_vectorized_plan_matches_the_oracle():
    program = ("G1 X10 Y0 F3000\nG1 X20 Y1\nG1 X21 Y1.5\nG1 X21.2 Y3 Z-1 F1200\nG0 X40 Y30\nG1 X41 Y31 F800\n"
               "G2 X51 Y21 I0 J-10 F2000\nG1 X10 Y10\nG1 X10.5 Y10.2 F6000\nG1 X10 Y10.4\nG1 X9.5 Y10.2\nG1 X0 Y0\n")
    op = gcodekit.gcode_to_operation("G21 G90\n" + program, "grbl", plan=False)
    config = grbl.GrblConfig(max_rate_x=4000.0, max_rate_y=3000.0, max_rate_z=500.0,
                             acceleration_x=120.0, acceleration_y=80.0, acceleration_z=30.0)
    moves, result = grbl.plan(op, config)
    expected = grbl_oracle(op, config)
    assert len(moves) == expected.size > 40
    np.testing.assert_allclose(result.duration_t, expected, rtol=1e-9)


# -- RepRapFirmware -------------------------------------------------------------------------


def test_rrf_single_printing_move():
    # X limits at 1000 mm/s^2 (E at 250 / 0.05 = 5000 would allow more), 50 mm/s: 1.25 mm ramps
    moves, result = rrf_plan("M201 X1000\nG1 X100 E5 F3000\n")
    assert result.accel[0] == pytest.approx(1000.0)
    assert result.duration_t[0] == pytest.approx(trapezoid_time(100.0, 50.0, 1000.0))


def test_rrf_printing_then_travel_stops():
    # DDA::InitStandardMove joins moves only of the same kind (printing or not)
    text = "M201 X1000\nM566 X6000\nG1 X50 E2 F3000\nG1 X100 {}F3000\n"
    _, to_travel = rrf_plan(text.format(""))
    _, to_print = rrf_plan(text.format("E2 "))
    _, policy = rrf_plan(text.format(""), reprapfirmware.RrfConfig(jerk_policy=1))
    assert to_travel.end_v[0] == 0.0
    assert to_print.end_v[0] == pytest.approx(50.0)
    assert policy.end_v[0] == pytest.approx(50.0)


def test_rrf_junction_by_instantaneous_speed_change():
    # MatchSpeeds: a 60 degree turn changes the X direction component by 0.5 and
    # Y by sin 60; with 10 mm/s allowed on each, v = 10 / sin 60 = 11.547 mm/s
    x2, y2 = 50 + 50 * math.cos(math.radians(60)), 50 * math.sin(math.radians(60))
    text = f"M201 X1000 Y1000\nM566 X600 Y600\nG1 X50 E2 F3000\nG1 X{x2:.9f} Y{y2:.9f} E2\n"
    _, result = rrf_plan(text)
    assert result.end_v[0] == pytest.approx(10.0 / math.sin(math.radians(60)), rel=1e-6)
    # M205 (RRF 3.3+) is the same limit in mm/s
    _, same = rrf_plan(text.replace("M566 X600 Y600", "M205 X10 Y10"))
    assert same.end_v[0] == pytest.approx(result.end_v[0])


def test_rrf_default_jerk_is_mm_per_minute():
    # RrfConfig's 900 mm/min: a right angle between printing moves is taken at 15 mm/s
    _, result = rrf_plan("M201 X1000 Y1000\nG1 X50 E2 F3000\nG1 Y50 E2\n")
    assert result.end_v[0] == pytest.approx(RRF.instant_dv_x / 60.0)


def test_rrf_m204_for_xy_moves_only():
    _, result = rrf_plan("M201 X5000 Y5000 Z100 E3000\nM204 P700 T1800\n"
                         "G1 X50 E2 F3000\nG1 X100 F3000\nG1 E-1 F2400\nG1 Z5 F600\n")
    assert result.accel.tolist() == [700.0, 1800.0, 3000.0, 100.0]


def test_rrf_m203_is_mm_per_minute():
    _, result = rrf_plan("M203 X600\nG1 X100 F6000\n")
    assert result.cruise_v[0] == pytest.approx(10.0)


def test_rrf_minimum_movement_speed():
    _, result = rrf_plan("G1 X1 F6\n")  # 0.1 mm/s asked, 0.5 mm/s (M203 I30) is the floor
    assert result.cruise_v[0] == pytest.approx(0.5)


def test_rrf_arc_chords():
    moves, _ = rrf_plan("G1 X10 Y0 F3000\nG3 X-10 Y0 I-10 J0\n")  # 50 mm/s: 0.25 mm chords, 126 of them
    assert np.unique(moves.row, return_counts=True)[1].tolist() == [1, math.floor(10 * math.pi / 0.25 + 0.8)]


def test_rrf_dwell_stops():
    _, result = rrf_plan("M566 X6000\nG1 X50 E2 F3000\nG4 P0\nG1 X100 E2\n")
    assert result.end_v[0] == 0.0


def test_rrf_config_g(tmp_path):
    config_g = tmp_path / "config.g"
    config_g.write_text("; motion\nM201 X3000 Y3000 Z100 E5000:5000\nM203 X18000 Y18000 Z900 E3600 I20\n"
                        "M204 S2000\nM566 X480 Y480 Z24 E300 P1\nM92 X80 Y80\n")
    c = reprapfirmware.RrfConfig.from_config_g(config_g)
    assert (c.max_acceleration_e, c.max_feedrate_x, c.minimum_movement_speed) == (5000.0, 18000.0, 20.0)
    assert (c.max_printing_acceleration, c.max_travel_acceleration, c.instant_dv_z, c.jerk_policy) == \
        (2000.0, 2000.0, 24.0, 1)


def test_rrf_preset_plans_the_pipeline():
    machine = gcodekit.load_machine("reprapfirmware")
    assert machine.planner == "reprapfirmware"
    c = planner_settings("reprapfirmware", machine.planner_settings)
    op = gcodekit.gcode_to_operation("G1 X100 F3000\n", "reprapfirmware")
    expected = trapezoid_time(100.0, 50.0, min(c.max_acceleration_x, c.max_travel_acceleration))
    assert op.get_statistics()["time_s"] == pytest.approx(expected)


def test_rrf_says_when_m203_caps_the_feeds():
    """RepRapFirmware reads M203 in mm/min (Marlin in mm/s): a Marlin program's ``M203 X200`` caps a 100 mm/s
    move at 3.3 mm/s.  The info says so, with the time it adds at cruise: 100 mm at 200/60 mm/s instead of
    100 mm/s, 30 - 1 = 29 s.  Limits in mm/min, as RepRapFirmware's own programs write them, say nothing."""
    marlin_style = gcodekit.gcode_to_operation("M203 X200 Y200\nG1 X100 F6000\n", "reprapfirmware")
    said = [d for d in marlin_style.diagnostics if "faster than the machine allows" in d.message]
    assert len(said) == 1 and said[0].line == 2 and said[0].severity == "info"
    assert "6000 mm/min against 200 mm/min, M203, in mm/min on RepRapFirmware" in said[0].message
    assert "adds about 29.0 s" in said[0].message
    own = gcodekit.gcode_to_operation("M203 X12000 Y12000\nG1 X100 F6000\n", "reprapfirmware")
    assert not [d for d in own.diagnostics if "faster than the machine allows" in d.message]


def test_rrf_plans_moves_at_f0_at_the_minimum_movement_speed():
    """After ``G1 F0`` RepRapFirmware moves at M203 I (``DDA::InitStandardMove``), G1 as G0: each waypoint
    has the planner's time, not an unknown one.  The preset's 0.5 mm/s is below M566's 10 mm/s, so X13
    joins the X10 travel move at it and brakes to rest before the Z move (not an XY move)."""
    op = gcodekit.gcode_to_operation("G1 X10 F800\nG1 F0\nG1 X13\nG0 Z3\n", "reprapfirmware")
    c = planner_settings("reprapfirmware", gcodekit.load_machine("reprapfirmware").planner_settings)
    v = c.minimum_movement_speed / 60.0
    x13 = trapezoid_time(3.0, v, min(c.max_acceleration_x, c.max_travel_acceleration), v0=v)
    z3 = trapezoid_time(3.0, v, c.max_acceleration_z)
    assert v == 0.5 and x13 == pytest.approx(6.0 + 0.5 / 1500 - 0.25 / 3000 / 0.5, rel=1e-12)
    np.testing.assert_allclose(op.waypoints["time"][2:], [x13, z3], rtol=1e-9)


def test_rrf_moves_before_any_f_at_its_boot_feed():
    """RepRapFirmware starts at ``DefaultFeedRate``, 3000 mm/min (Configuration.h; Marlin and Klipper start at
    1500): a long move before any F cruises at 50 mm/s, the next at its own F."""
    op = gcodekit.gcode_to_operation("G1 X200\nG1 X0 F1200\n", "reprapfirmware")
    moves, result = op.plan
    assert moves.speed_v.tolist() == [50.0, 20.0]
    assert result.cruise_v.tolist() == [50.0, 20.0]
    marlin = gcodekit.gcode_to_operation("G1 X200\n", "marlin")
    assert marlin.plan[0].speed_v.tolist() == [25.0]


def test_rrf_scales_by_m220_only_moves_that_name_an_axis():
    """RepRapFirmware's ``applyM220M221`` needs an axis named on the move (``GCodes::LoadFeedrateFromGCode``): a
    retraction keeps its F.  Marlin and Klipper scale every move."""
    text = "M220 S50\nG1 X100 F6000\nG1 E-2 F2400\nG0 X0 F6000\n"
    rrf = gcodekit.gcode_to_operation(text, "reprapfirmware")
    assert rrf.plan[0].speed_v.tolist() == [50.0, 40.0, 50.0]
    for machine in ("marlin", "klipper"):
        assert gcodekit.gcode_to_operation(text, machine).plan[0].speed_v.tolist() == [50.0, 20.0, 50.0]
