"""Emulate stage, planning: the GRBL-style MotionProfile against hand-worked values and a per-move loop."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.errors import ConfigError
from gcodekit.plan import planner_settings
from gcodekit.plan.moves import PlannerMoves
from gcodekit.plan.motion_profile import BAAMMotionProfile, MotionProfile
from gcodekit.plan.shapes import ConstantVelocity, LinearRamp, SCurve, Trapezoid


def make_moves(points, speeds) -> PlannerMoves:
    """Moves through ``points`` (X, Y, Z), one speed (mm/s) each."""
    p = np.asarray(points, float)
    ends = np.column_stack([p, np.zeros(len(p))])
    n = len(p) - 1
    return PlannerMoves(ends[:-1], ends[1:], np.broadcast_to(np.asarray(speeds, float), (n,)).copy(),
                        np.arange(n), np.arange(n))


# -- one move ------------------------------------------------------------------------


def test_single_move_trapezoid_time():
    # d = 100 mm at v = 100 mm/s, a = 1000 mm/s^2: ramps of v/a = 0.1 s covering v^2/2a = 5 mm each,
    # cruise 90 mm in 0.9 s: t = d/v + v/a
    result = MotionProfile(max_acceleration=1000.0).plan(make_moves([[0, 0, 0], [100, 0, 0]], 100.0))
    assert result.duration_t[0] == pytest.approx(100 / 100 + 100 / 1000, rel=1e-12)
    assert (result.accel_t[0], result.cruise_t[0], result.decel_t[0]) == pytest.approx((0.1, 0.9, 0.1))


def test_short_move_is_triangular():
    # d = 1 mm cannot reach 100 mm/s: peak^2 = a*d, t = 2*sqrt(d/a)
    result = MotionProfile(max_acceleration=1000.0).plan(make_moves([[0, 0, 0], [1, 0, 0]], 100.0))
    assert result.duration_t[0] == pytest.approx(2 * math.sqrt(1 / 1000), rel=1e-12)
    assert result.cruise_v[0] == pytest.approx(math.sqrt(1000 * 1))
    assert result.cruise_t[0] == pytest.approx(0.0, abs=1e-12)


def test_no_acceleration_means_instant_speed_changes():
    points = [[0, 0, 0], [10, 0, 0], [10, 5, 0], [0, 5, 3], [0, 5, 3.5]]
    speeds = [20.0, 5.0, 80.0, 2.0]
    result = MotionProfile(max_velocity=50.0).plan(make_moves(points, speeds))
    d = np.linalg.norm(np.diff(np.asarray(points, float), axis=0), axis=1)
    v = np.minimum(speeds, 50.0)
    np.testing.assert_allclose(result.duration_t, d / v, rtol=1e-12)
    np.testing.assert_allclose(result.start_v, v)
    np.testing.assert_allclose(result.end_v, v)


def test_unknown_speed_gives_unknown_time_and_stops_neighbours():
    moves = make_moves([[0, 0, 0], [10, 0, 0], [20, 0, 0], [30, 0, 0]], [10.0, np.nan, 10.0])
    result = MotionProfile(max_acceleration=100.0).plan(moves)
    assert np.isnan(result.duration_t[1])
    assert result.end_v[0] == 0.0 and result.start_v[2] == 0.0
    assert result.duration_t[0] == pytest.approx(1 + 10 / 100)


# -- corners ---------------------------------------------------------------------------


def test_right_angle_corner_speed():
    # theta = 90 deg between the way back and the way on; sin(theta/2) = 1/sqrt(2), so
    # R = jd * s / (1 - s) = 0.05 * (1 + sqrt(2)) = 0.1207 mm and v^2 = a * R
    a, jd = 1000.0, 0.05
    s = math.sqrt(0.5)
    expected = math.sqrt(a * jd * s / (1 - s))
    assert expected == pytest.approx(10.987, abs=1e-3)
    result = MotionProfile(max_acceleration=a, junction_deviation=jd).plan(
        make_moves([[0, 0, 0], [10, 0, 0], [10, 10, 0]], 100.0))
    assert result.end_v[0] == pytest.approx(expected, rel=1e-12)
    assert result.start_v[1] == pytest.approx(expected, rel=1e-12)


def test_straight_continuation_is_not_slowed():
    split = MotionProfile(max_acceleration=1000.0).plan(make_moves([[0, 0, 0], [50, 0, 0], [100, 0, 0]], 100.0))
    assert split.end_v[0] == pytest.approx(100.0)
    assert split.duration_t.sum() == pytest.approx(100 / 100 + 100 / 1000, rel=1e-12)


def test_reversal_stops():
    result = MotionProfile(max_acceleration=1000.0).plan(make_moves([[0, 0, 0], [10, 0, 0], [0, 0, 0]], 50.0))
    assert result.end_v[0] == 0.0 and result.start_v[1] == 0.0
    assert result.duration_t.sum() == pytest.approx(2 * (10 / 50 + 50 / 1000))


def test_larger_junction_deviation_corners_faster():
    moves = make_moves([[0, 0, 0], [10, 0, 0], [10, 10, 0]], 100.0)
    slow = MotionProfile(max_acceleration=1000.0, junction_deviation=0.01).plan(moves)
    fast = MotionProfile(max_acceleration=1000.0, junction_deviation=0.2).plan(moves)
    assert slow.end_v[0] < fast.end_v[0]
    assert slow.duration_t.sum() > fast.duration_t.sum()


# -- the passes against a per-move loop (the oracle) -----------------------------------


def reference_plan(points, speeds, accel, jd, stops=None):
    """GRBL's planner one move at a time: corner caps, forward pass, backward pass, trapezoids."""
    p = np.asarray(points, float)
    n = len(p) - 1
    move_d = [float(np.linalg.norm(p[i + 1] - p[i])) for i in range(n)]
    unit = [(p[i + 1] - p[i]) / move_d[i] for i in range(n)]
    cap_v2 = []
    for i in range(n - 1):
        cos_theta = -float(np.dot(unit[i], unit[i + 1]))
        s = math.sqrt(max(0.5 * (1 - cos_theta), 0.0))
        corner_v2 = math.inf if s >= 1 else accel * jd * s / (1 - s)
        corner_v2 = min(corner_v2, speeds[i] ** 2, speeds[i + 1] ** 2)
        if stops is not None and stops[i]:
            corner_v2 = 0.0
        cap_v2.append(corner_v2)
    cap_v2.append(0.0)
    v2 = [0.0] * (n + 1)
    for i in range(n):  # forward: what can be reached accelerating
        v2[i + 1] = min(cap_v2[i], v2[i] + 2 * accel * move_d[i])
    for i in reversed(range(n)):  # backward: what still allows braking
        v2[i] = min(v2[i], v2[i + 1] + 2 * accel * move_d[i])
    duration = []
    for i in range(n):
        v0, v1, d = math.sqrt(v2[i]), math.sqrt(v2[i + 1]), move_d[i]
        peak = math.sqrt(max(min(speeds[i] ** 2, 0.5 * (v2[i] + v2[i + 1]) + accel * d), v2[i], v2[i + 1]))
        cruise_d = d - (2 * peak**2 - v2[i] - v2[i + 1]) / (2 * accel)
        duration.append((peak - v0) / accel + (peak - v1) / accel + max(cruise_d, 0.0) / peak)
    return np.sqrt(v2), np.array(duration)


DIRECTIONS = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1), (1, -2, 0.5)]


@st.composite
def toolpaths(draw, max_moves=25):
    n = draw(st.integers(1, max_moves))
    step = st.one_of(st.sampled_from(DIRECTIONS),
                     st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(lambda v: np.linalg.norm(v) > 1e-3))
    directions = draw(st.lists(step, min_size=n, max_size=n))
    lengths = draw(st.lists(st.floats(0.01, 50.0), min_size=n, max_size=n))
    speeds = draw(st.lists(st.floats(1.0, 200.0), min_size=n, max_size=n))
    stops = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    d = np.asarray(directions, float)
    d = d / np.linalg.norm(d, axis=1)[:, None] * np.asarray(lengths)[:, None]
    points = np.vstack([np.zeros(3), np.cumsum(d, axis=0)])
    return points, speeds, stops


@settings(max_examples=150, deadline=None)
@given(toolpaths(), st.floats(10.0, 5000.0), st.floats(0.001, 0.5), st.booleans())
def test_passes_match_per_move_loop(path, accel, jd, use_stops):
    points, speeds, stops = path
    stops = stops if use_stops else None
    v, duration = reference_plan(points, speeds, accel, jd, stops)
    result = MotionProfile(max_acceleration=accel, junction_deviation=jd).plan(
        make_moves(points, speeds), stops=None if stops is None else np.array(stops))
    # Near a reversal the corner speed is 1 - sin(theta/2) of nearly 1: the two
    # formulations round differently there, by micrometres per second.
    np.testing.assert_allclose(result.start_v, v[:-1], rtol=1e-9, atol=1e-5)
    np.testing.assert_allclose(result.end_v, v[1:], rtol=1e-9, atol=1e-5)
    np.testing.assert_allclose(result.duration_t, duration, rtol=1e-6, atol=1e-9)
    # every move is reachable: |end_v^2 - start_v^2| <= 2 a d
    d = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.all(np.abs(result.end_v**2 - result.start_v**2) <= 2 * accel * d * (1 + 1e-9) + 1e-9)


def test_passes_match_loop_across_scan_blocks():
    # more moves than scans.BLOCK, so the running minima restart mid-path
    rng = np.random.default_rng(7)
    n = 9000
    d = rng.normal(size=(n, 3))
    d[rng.random(n) < 0.3] = [1.0, 0.0, 0.0]  # long straight runs carry speed across blocks
    d *= rng.uniform(0.05, 3.0, n)[:, None] / np.linalg.norm(d, axis=1)[:, None]
    points = np.vstack([np.zeros(3), np.cumsum(d, axis=0)])
    speeds = rng.uniform(5.0, 150.0, n).tolist()
    v, duration = reference_plan(points, speeds, 800.0, 0.05)
    result = MotionProfile(max_acceleration=800.0).plan(make_moves(points, speeds))
    np.testing.assert_allclose(result.start_v, v[:-1], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(result.duration_t, duration, rtol=1e-9, atol=1e-12)


# -- segment profiles ------------------------------------------------------------------


def test_trapezoid_distance_limited_mode():
    # ramps of 25 mm each at mean speed 50 mm/s (0.5 s), 50 mm cruise at 100 mm/s (0.5 s)
    timing = Trapezoid(ramp_fraction=0.25).timing(100.0, 0.0, 100.0, 0.0)
    assert (float(timing.accel_t), float(timing.cruise_t), float(timing.decel_t)) == pytest.approx((0.5, 0.5, 0.5))
    with pytest.raises(ValueError, match="ramp_fraction"):
        Trapezoid(ramp_fraction=0.7)


def test_linear_ramp_and_constant_velocity():
    assert float(LinearRamp().duration(10.0, 5.0, 0.0, 15.0)) == pytest.approx(2 * 10 / (5 + 15))
    assert float(ConstantVelocity().duration(10.0, 0.0, 4.0, 0.0)) == pytest.approx(2.5)


def test_scurve_seven_phases():
    # dv = 100 >= a^2/j = 100: each ramp takes v/a + a/j, covers v/2 of it; t = d/v + v/a + a/j
    t = SCurve(max_jerk=10_000.0).duration(100.0, 0.0, 100.0, 0.0, 1000.0)
    assert float(t) == pytest.approx(1.0 + 0.1 + 0.1, rel=1e-12)


def test_scurve_ramps_that_never_reach_full_acceleration():
    # a^2/j = 1000 > dv = 100: each ramp takes 2*sqrt(v/j) and covers v/2 of it: t = d/v + 2*sqrt(v/j)
    t = SCurve(max_jerk=1000.0).duration(100.0, 0.0, 100.0, 0.0, 1000.0)
    assert float(t) == pytest.approx(1.0 + 2 * math.sqrt(100 / 1000), rel=1e-12)


def test_scurve_short_move_lowers_its_peak():
    # pure jerk ramps rest to rest: d = 2 * (vp/2) * 2*sqrt(vp/j), so vp = (d*sqrt(j)/2)^(2/3), t = 4*sqrt(vp/j)
    d, j = 1.0, 1e4
    vp = (d * math.sqrt(j) / 2) ** (2 / 3)
    timing = SCurve(max_jerk=j).timing(d, 0.0, 100.0, 0.0, 1e6)
    assert float(timing.cruise_v) == pytest.approx(vp, rel=1e-9)
    assert float(timing.duration_t) == pytest.approx(4 * math.sqrt(vp / j), rel=1e-9)


def test_scurve_direct_ramp_when_the_jerk_limit_cannot_fit():
    # 0 -> 20 mm/s needs 2.83 mm at j = 1000; in 1 mm the move is one ramp at mean speed 10 mm/s
    assert float(SCurve(max_jerk=1000.0).duration(1.0, 0.0, 50.0, 20.0, 1000.0)) == pytest.approx(0.1)


@st.composite
def reachable_moves(draw):
    d = draw(st.floats(0.01, 100.0))
    accel = draw(st.floats(10.0, 5000.0))
    v0 = draw(st.floats(0.0, 150.0))
    v1_max = math.sqrt(v0 * v0 + 2 * accel * d)
    v1 = draw(st.floats(0.0, 1.0)) * min(v1_max, 150.0)
    v0 = min(v0, math.sqrt(v1 * v1 + 2 * accel * d))
    cruise = max(v0, v1, 0.1) + draw(st.floats(0.0, 150.0))
    return d, v0, cruise, v1, accel


@settings(max_examples=200, deadline=None)
@given(reachable_moves(), st.floats(1.0, 1e6))
def test_scurve_never_faster_than_trapezoid(move, jerk):
    t_trap = float(Trapezoid().duration(*move))
    t_s = float(SCurve(max_jerk=jerk).duration(*move))
    assert t_s >= t_trap * (1 - 1e-9)


@settings(max_examples=100, deadline=None)
@given(reachable_moves())
def test_scurve_tends_to_trapezoid(move):
    t_trap = float(Trapezoid().duration(*move))
    assert float(SCurve(max_jerk=np.inf).duration(*move)) == pytest.approx(t_trap, rel=1e-9)
    assert float(SCurve(max_jerk=1e10).duration(*move)) == pytest.approx(t_trap, rel=1e-3)


@pytest.mark.parametrize("profile, move", [
    (Trapezoid(), (10.0, 0.0, 20.0, 0.0, 100.0)),
    (Trapezoid(), (1.0, 5.0, 100.0, 10.0, 200.0)),
    (Trapezoid(ramp_fraction=0.2), (10.0, 2.0, 20.0, 4.0, np.inf)),
    (SCurve(max_jerk=5000.0), (10.0, 0.0, 20.0, 0.0, 100.0)),
    (SCurve(max_jerk=1e4), (1.0, 0.0, 100.0, 0.0, 1e6)),
    (SCurve(max_jerk=1000.0), (1.0, 0.0, 50.0, 20.0, 1000.0)),
    (LinearRamp(), (10.0, 5.0, 0.0, 15.0, np.inf)),
    (ConstantVelocity(), (10.0, 0.0, 4.0, 0.0, np.inf)),
])
def test_sampled_speed_covers_the_move(profile, move):
    t, v = profile.sample(*move, num=20001)
    assert np.trapezoid(v, t) == pytest.approx(move[0], rel=1e-6)
    assert v.max() <= max(move[1:4]) * (1 + 1e-12)
    if not isinstance(profile, ConstantVelocity):
        assert (v[0], v[-1]) == pytest.approx((move[1], move[3]), abs=1e-9)


def test_plan_with_scurve_is_slower_than_trapezoid():
    moves = make_moves([[0, 0, 0], [10, 0, 0], [10, 10, 0], [30, 5, 2]], [80.0, 40.0, 120.0])
    planner = MotionProfile(max_acceleration=1000.0)
    trapezoid = planner.plan(moves)
    planner.profile_type = SCurve
    scurve = planner.plan(moves)
    np.testing.assert_allclose(scurve.start_v, trapezoid.start_v)
    assert np.all(scurve.duration_t >= trapezoid.duration_t)
    assert scurve.duration_t.sum() > trapezoid.duration_t.sum()


# -- the API ---------------------------------------------------------------------------


def test_profile_type_choices():
    planner = MotionProfile(max_acceleration=500.0, max_jerk=2000.0)
    assert planner.profile_type is Trapezoid
    planner.profile_type = SCurve
    assert planner.segment_profile().max_jerk == 2000.0
    planner.profile_type = "scurve"
    assert isinstance(planner.segment_profile(), SCurve)
    planner.profile_type = SCurve(max_jerk=7.0)
    assert planner.segment_profile().max_jerk == 7.0
    with pytest.raises(ValueError, match="'trapezoid'.*did you mean 'scurve'"):
        planner.profile_type = "scurv"
    with pytest.raises(TypeError):
        planner.profile_type = LinearRamp


def test_misspelt_max_accleration_still_works():
    with pytest.warns(DeprecationWarning, match="max_acceleration") as record:
        planner = MotionProfile(max_accleration=500.0, max_velocity=100.0, junction_deviation=0.05)
    assert planner.max_acceleration == 500.0
    assert record[0].filename == __file__  # points at the caller, not at gcodekit
    with pytest.warns(DeprecationWarning) as record:
        baam = BAAMMotionProfile(max_accleration=300.0)
    assert baam.max_acceleration == 300.0 and record[0].filename == __file__
    with warnings.catch_warnings(), pytest.raises(TypeError, match="once"):
        warnings.simplefilter("ignore", DeprecationWarning)
        MotionProfile(max_acceleration=1.0, max_accleration=2.0)
    with pytest.raises(TypeError, match="did you mean 'max_velocity'"):
        MotionProfile(max_velocty=1.0)


def test_bad_limits_are_rejected():
    with pytest.raises(ValueError, match="max_acceleration"):
        MotionProfile(max_acceleration=0.0)
    with pytest.raises(ValueError, match="junction_deviation"):
        MotionProfile(junction_deviation=-1.0)


# -- machine rules: BAAM ---------------------------------------------------------------


def seed_style_stops(points, junction_v):
    """The user guide's loop: stop into and out of every pure-Z move."""
    dxyz = np.diff(np.asarray(points, float), axis=0)
    vertical = (np.abs(dxyz[:, 0]) < 1e-9) & (np.abs(dxyz[:, 1]) < 1e-9)
    junction_v = junction_v.copy()
    for idx in np.where(vertical)[0]:
        if idx > 0:
            junction_v[idx - 1] = 0.0
        junction_v[idx] = 0.0
    return junction_v


def test_baam_stops_around_layer_changes():
    # a bead, a layer change straight up, a bead: all junctions are corners the base planner would carry speed through
    points = [[0, 0, 0], [100, 0, 0], [100, 0, 5], [0, 0, 5]]
    base = MotionProfile(max_acceleration=1000.0, junction_deviation=1.0).plan(make_moves(points, 100.0))
    assert base.end_v[0] > 0 and base.end_v[1] > 0
    baam = BAAMMotionProfile(max_acceleration=1000.0, junction_deviation=1.0).plan(make_moves(points, 100.0))
    assert baam.end_v[0] == 0.0 and baam.start_v[1] == 0.0
    assert baam.end_v[1] == 0.0 and baam.start_v[2] == 0.0


@settings(max_examples=50, deadline=None)
@given(toolpaths(max_moves=15))
def test_baam_stops_match_the_guide_loop(path):
    points, speeds, _ = path
    moves = make_moves(points, speeds)
    junction_v = np.full(len(moves), 7.0)
    _, ours = BAAMMotionProfile()._apply_machine_constraints(moves.start[:, :3], moves.end[:, :3],
                                                              np.asarray(speeds, float), junction_v)
    np.testing.assert_array_equal(ours, seed_style_stops(points, junction_v))


def test_baam_axis_caps_along_each_direction():
    points = [[0, 0, 0], [30, 40, 0], [30, 40, 10], [30, 0, 10]]
    caps = (20.0, 50.0, 5.0)
    result = BAAMMotionProfile(axis_max_velocity=caps).plan(make_moves(points, 100.0))
    # X moves 3/5 of the way: 20 / 0.6 = 33.3 mm/s; Y's 50 / 0.8 = 62.5 is looser
    assert result.cruise_v.tolist() == pytest.approx([20 / 0.6, 5.0, 50.0])
    axes_r = np.abs(np.diff(np.asarray(points, float), axis=0))
    axes_r /= np.linalg.norm(axes_r, axis=1)[:, None]
    assert np.all(result.cruise_v[:, None] * axes_r <= np.array(caps) * (1 + 1e-12))
    with pytest.raises(ValueError, match="axis_max_velocity"):
        BAAMMotionProfile(axis_max_velocity=(1.0, 2.0))


# -- as the planner of machine presets -------------------------------------------------


def test_linuxcnc_preset_uses_the_planner():
    assert gcodekit.load_machine("linuxcnc").planner == "motion_profile"
    # 1 mm at 600 mm/min = 10 mm/s with 500 mm/s^2: from rest to rest t = d/v + v/a = 0.1 + 0.02
    op = gcodekit.gcode_to_operation("G21 G1 X1 F600\n", "linuxcnc")
    assert op.to_dataframe()["time"].iloc[-1] == pytest.approx(0.12)
    assert op.to_dataframe()["time"].iloc[-1] > 1 / 10
    unplanned = gcodekit.gcode_to_operation("G21 G1 X1 F600\n", "linuxcnc", plan=False)
    assert unplanned.to_dataframe()["time"].iloc[-1] == pytest.approx(0.1)


def test_exact_stop_mode_and_dwell_stop_the_machine():
    blended = gcodekit.gcode_to_operation("G21 G64 G1 X10 F600\nX20\n", "linuxcnc").elapsed_time()[-1]
    exact = gcodekit.gcode_to_operation("G21 G61 G1 X10 F600\nX20\n", "linuxcnc").elapsed_time()[-1]
    dwell = gcodekit.gcode_to_operation("G21 G1 X10 F600\nG4 P0.5\nX20\n", "linuxcnc").elapsed_time()[-1]
    assert blended == pytest.approx(20 / 10 + 10 / 500)  # one 20 mm run at 10 mm/s
    assert exact == pytest.approx(2 * (10 / 10 + 10 / 500))  # two runs, each from rest to rest
    assert dwell == pytest.approx(exact + 0.5)


def test_arc_speed_limited_by_centripetal_acceleration():
    # R = 10 mm at 500 mm/s^2: v <= sqrt(a R) = 70.7 mm/s, below F6000 = 100 mm/s
    op = gcodekit.gcode_to_operation("G21 G0 X0 Y0\nG2 X20 Y0 I10 J0 F6000\n", "generic")
    assert op.to_dataframe()["cruise_v"].iloc[-1] == pytest.approx(math.sqrt(500 * 10), rel=1e-6)


def test_rotary_only_moves_keep_their_time():
    op = gcodekit.gcode_to_operation("G21 G1 X10 F600\nG1 A90 F1800\nG1 X20 F600\n", "linuxcnc")
    frame = op.to_dataframe()
    assert frame["time"].iloc[-2] == pytest.approx(3.0)  # 90 deg at 1800 deg/min
    assert frame["end_v"].iloc[-3] == 0.0  # X stops before the rotary move


def test_preset_settings_are_checked():
    with pytest.raises(ConfigError, match="'trapezoid', 'scurve'"):
        planner_settings("motion_profile", {"profile_type": "s-curve"})
    with pytest.raises(ConfigError, match="did you mean 'max_acceleration'"):
        planner_settings("motion_profile", {"max_accel": 500.0})
    settings_ = planner_settings("motion_profile", {"max_acceleration": 500.0, "profile_type": "scurve",
                                                    "max_jerk": 5000.0})
    assert isinstance(settings_.motion_profile().segment_profile(), SCurve)


def test_scurve_preset_is_slower():
    text = "G21 G1 X10 F1200\nY10\nX0 Y0\n"
    trap = gcodekit.gcode_to_operation(text, "linuxcnc").elapsed_time()[-1]
    scurve_settings = {"max_acceleration": 500.0, "max_velocity": 50.0, "profile_type": "scurve", "max_jerk": 5000.0}
    scurve = gcodekit.gcode_to_operation(text, "linuxcnc", planner_settings=scurve_settings).elapsed_time()[-1]
    assert scurve > trap
