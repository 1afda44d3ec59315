"""Plan stage: the compiled loops (Numba) give the NumPy planners' arrays, to the last bit.

The NumPy code is the reference (itself checked against Klipper, Marlin's
slicer estimates and the per-move oracles); planning the same program with
each engine must give identical moves, velocities and times, bit for bit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit import columns
from gcodekit.plan import kernels, marlin, planner_settings, run_planner, scans
from gcodekit.plan import moves as moves_module
from shared_corpus import CORPUS as SHARED_CORPUS

if kernels.compiled() is None:
    pytest.skip("Numba is not installed (pip install 'gcodekit[fast]')", allow_module_level=True)

HERE = Path(__file__).parent / "golden" / "klipper"
CASES = HERE / "cases"
SHARED_FFF = SHARED_CORPUS / "fff"


def assert_bits_equal(a, b, what: str) -> None:
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape and a.dtype == b.dtype, what
    if a.dtype.kind == "f":  # -0.0 and 0.0 differ, NaN equals NaN
        differ = np.flatnonzero(a.view(np.int64) != b.view(np.int64))
        assert differ.size == 0, f"{what}: {differ.size} differ, first {differ[0]}: {a[differ[0]]!r} {b[differ[0]]!r}"
    else:
        assert np.array_equal(a, b), what


FIELDS = ("start_v", "cruise_v", "end_v", "accel", "accel_t", "cruise_t", "decel_t")


def plan_both(op, planner: str, config):
    """The plan by each engine, with its fields read (a plan may compute them when read) by the same engine."""
    out = []
    for name in ("numpy", "numba"):
        with kernels.using(name):
            plan = run_planner(op, planner, config)
            r = plan.result
            single = {f: getattr(r, f) for f in FIELDS}  # each read alone
            some = r.phases(slice(1, None, 2)) if len(r) else None
            out.append((plan, r.phases(), single, r.duration_t, some))
    return out


def assert_same_plan(ref, got) -> None:
    (ref_plan, ref_all, ref_single, ref_duration, ref_some), (plan, every, single, duration, some) = ref, got
    assert_bits_equal(ref_plan.time, plan.time, "waypoint time")
    for field in ("speed_v", "row", "waypoint", "length_d"):
        assert_bits_equal(getattr(ref_plan.moves, field), getattr(plan.moves, field), field)
    for field in FIELDS:
        assert_bits_equal(getattr(ref_all, field), getattr(every, field), field)
        assert_bits_equal(ref_single[field], single[field], field + " read alone")
        assert_bits_equal(ref_single[field], getattr(every, field), field + " read alone and with the others")
        if some is not None:
            assert_bits_equal(getattr(ref_some, field), getattr(some, field), field + " of some moves")
    assert_bits_equal(ref_duration, duration, "duration_t")


def corpus(name: str) -> Path:
    path = CASES / name if (CASES / name).exists() else SHARED_FFF / name
    if not path.exists():
        pytest.skip(f"{name} is only in the shared corpus")
    return path


PROGRAMS = ["cube20_marlin2.gcode", "cube20_klipper.gcode", "b_square.gcode", "c_arcs.gcode", "f_stops.gcode",
            "g_ejunction.gcode", "cylinder_marlin2.gcode", "cylinder_marlin2_arcwelder.gcode",
            "vase_spiral_marlin2.gcode"]


@pytest.mark.parametrize("name", PROGRAMS)
@pytest.mark.parametrize("classic_jerk", [False, True])
def test_marlin_engines_agree(name, classic_jerk):
    op = gcodekit.gcode_to_operation(corpus(name), "marlin", plan=False)
    assert_same_plan(*plan_both(op, "marlin", marlin.MarlinConfig(classic_jerk=classic_jerk)))


@pytest.mark.parametrize("name", PROGRAMS)
def test_klipper_engines_agree(name):
    config = HERE / "klipper_printer.cfg"
    op = gcodekit.gcode_to_operation(corpus(name), "klipper", machine_config=config, plan=False)
    assert_same_plan(*plan_both(op, "klipper", planner_settings("klipper", {}, config)))


def test_hand_cases_agree():
    # stops, reversals, extruder-only moves, a zero-length move, an arc, no feed yet, limits changed on the way
    text = ("G1 X10 E1\nG1 X20 Y0 E2 F3000\nG1 X10 E3\nG1 E2 F1800\nG1 E3\nG4 P100\nG1 X10 Y10 F6000\n"
            "M204 P500 T800\nG1 X10.001 Y10\nG2 X20 Y10 I5 J0 E4\nM205 X2 Y2\nG1 X0 Y0 Z0.2\nM400\nG1 X1\n")
    for planner in ("marlin", "klipper"):
        op = gcodekit.gcode_to_operation(text, planner, plan=False)
        for config in ([marlin.MarlinConfig(), marlin.MarlinConfig(classic_jerk=True)] if planner == "marlin"
                       else [planner_settings(planner, {})]):
            assert_same_plan(*plan_both(op, planner, config))


def test_klipper_limits_changed_on_the_way():
    text = ("G1 X10 E1 F3000\nSET_VELOCITY_LIMIT VELOCITY=40 ACCEL=800 SQUARE_CORNER_VELOCITY=2\nG1 X10 Y10 E2\n"
            "G1 Z1 F600\nG1 X0 Y0 Z0.5 E2.5 F6000\nM204 S1500\nG1 X5 E1.5\nG1 E2\n"
            "SET_VELOCITY_LIMIT MINIMUM_CRUISE_RATIO=0.3\nG1 X5 Y5\nG1 X0 Y5 E3\n")
    op = gcodekit.gcode_to_operation(text, "klipper", plan=False)
    assert_same_plan(*plan_both(op, "klipper", planner_settings("klipper", {})))


speeds_v2 = st.one_of(st.floats(0.0, 1e6), st.sampled_from([0.0, -0.0, np.inf, 1e-300, 1e-7]))


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # inf - inf in the NumPy scans' sums
@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(speeds_v2, speeds_v2), max_size=40), st.sampled_from([0.0, 2.5, np.inf]),
       st.sampled_from([1, 3, 4096]))
def test_scans_agree(pairs, first, block):
    cap = np.array([p[0] for p in pairs], float)
    inc = np.array([p[1] for p in pairs], float)
    old = scans.BLOCK
    scans.BLOCK = block  # small blocks: the carry from block to block
    try:
        with kernels.using("numpy"):
            ref = scans.forward_min(cap, inc, first), scans.backward_min(cap, inc, first)
        with kernels.using("numba"):
            got = scans.forward_min(cap, inc, first), scans.backward_min(cap, inc, first)
    finally:
        scans.BLOCK = old
    assert_bits_equal(ref[0], got[0], "forward_min")
    assert_bits_equal(ref[1], got[1], "backward_min")
    for engine in ("numpy", "numba"):  # written over the caps, as the planners call them: the same values
        with kernels.using(engine):
            scans.BLOCK = block
            try:
                forward, backward = cap.copy(), cap.copy()
                assert scans.forward_min(forward, inc, first, out=forward) is forward
                assert scans.backward_min(backward, inc, first, out=backward) is backward
            finally:
                scans.BLOCK = old
        assert_bits_equal(ref[0], forward, f"forward_min over its caps ({engine})")
        assert_bits_equal(ref[1], backward, f"backward_min over its caps ({engine})")


def test_scans_check_where_they_write():
    cap, inc = np.ones(3), np.ones(3)
    for bad in (np.empty(2), np.empty(3, np.float32), np.empty(6)[::2]):
        with pytest.raises(ValueError, match="contiguous float64 array of 3"):
            scans.forward_min(cap, inc, out=bad)
    frozen = np.empty(3)
    frozen.flags.writeable = False
    with pytest.raises(ValueError):
        scans.backward_min(cap, inc, out=frozen)


def test_auto_engine_by_size():
    assert kernels.engine(10) is None
    assert kernels.engine(kernels.COMPILED_AFTER_MOVES) is kernels.compiled()
    with kernels.using("numpy"):
        assert kernels.engine(10**9) is None
    with pytest.raises(ValueError):
        with kernels.using("fortran"):
            pass


def test_an_engine_chosen_in_one_thread_is_that_thread_s_alone():
    import threading

    chosen, seen = threading.Event(), {}

    def other() -> None:
        chosen.wait()
        seen["other"] = kernels.engine(10**9)  # another thread, planning meanwhile: still the default

    worker = threading.Thread(target=other)
    worker.start()
    with kernels.using("numpy"):
        chosen.set()
        worker.join()
        seen["here"] = kernels.engine(10**9)
    assert seen["here"] is None and seen["other"] is kernels.compiled() is not None
    assert kernels.engine(10**9) is kernels.compiled()  # restored at the block's end


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(*[st.sampled_from([0.0, 1.0, 2.0, 4.0, 9.0, 1e-12, np.inf])] * 5, st.booleans()),
                min_size=1, max_size=30))
def test_klipper_cruise_agrees(rows):
    from gcodekit.plan import klipper

    start_v2, mcr_start_v2, delta_v2, mcr_delta_v2, max_cruise_v2 = (np.array(c, float) for c in list(zip(*rows))[:5])
    flush = np.array([r[5] for r in rows])
    flush[0] = True
    m = {"delta_v2": delta_v2, "mcr_delta_v2": mcr_delta_v2}
    ref = klipper._cruise(start_v2, mcr_start_v2, m, max_cruise_v2, flush)
    into = max_cruise_v2.copy()  # the planner's call: the speeds written over their caps
    none, no_runs = np.zeros(0), np.zeros(0, np.int64)
    stored = (none, none, no_runs, none, no_runs)  # the increments as given, not made
    got = kernels.compiled().klipper_cruise(start_v2, mcr_start_v2, delta_v2, mcr_delta_v2, into, flush,
                                            klipper.TIE, into, *stored)
    assert got is into
    assert_bits_equal(ref, got, "cruise_v2")
    apart = kernels.compiled().klipper_cruise(start_v2, mcr_start_v2, delta_v2, mcr_delta_v2, max_cruise_v2, flush,
                                              klipper.TIE, np.empty(len(rows)), *stored)
    assert_bits_equal(ref, apart, "cruise_v2 into a new array")


lengths = st.sampled_from([0.0, 1e-9, 0.3, 2.5, 40.0])
accels = st.sampled_from([500.0, 1000.0, 3000.0, 99999999.9, 1234.5678])


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(speeds_v2, lengths, accels, accels, st.booleans()), min_size=1, max_size=40),
       st.sampled_from(["array", "runs", "one"]), st.booleans(), st.booleans(), st.sampled_from([1, 3, 4096]))
def test_increments_made_where_read_are_the_stored_ones(moves, kept_as, pseudo, cut, block):
    """The compiled scans and Klipper's cruise loop make ``2 * move_d * accel`` (the least of it and the
    pseudo acceleration's, where there is one; the cap where ``free``) as they read it: the same speeds, bit
    for bit, as the NumPy scans given the increments stored."""
    from gcodekit.plan import klipper

    cap, move_d, accel, pseudo_accel, free = (np.array(c) for c in zip(*moves))
    if kept_as == "one":
        accel = np.full(accel.size, accel[0])
    kept = {"array": accel, "runs": columns.RunColumn.encode(accel, 1),
            "one": np.broadcast_to(accel[0], accel.shape)}[kept_as]
    made = scans.Increments(move_d, kept, columns.RunColumn.encode(pseudo_accel, 1) if pseudo else None,
                            free if cut else None)
    old = scans.BLOCK
    scans.BLOCK = block
    try:
        out = {}
        for engine in ("numpy", "numba"):
            with kernels.using(engine):
                out[engine] = (scans.forward_min(cap.copy(), made, 1.0), scans.backward_min(cap.copy(), made, 0.5))
        stored = made.array(cap, forward=True), made.array(cap, forward=False)
        with kernels.using("numpy"):
            ref = scans.forward_min(cap, stored[0], 1.0), scans.backward_min(cap, stored[1], 0.5)
    finally:
        scans.BLOCK = old
    for engine in out:
        assert_bits_equal(ref[0], out[engine][0], f"forward_min, {engine}")
        assert_bits_equal(ref[1], out[engine][1], f"backward_min, {engine}")
    if pseudo and not cut:  # Klipper's cruise loop: delta_v2 and mcr_delta_v2 made as it goes
        delta = scans.Increments(move_d, kept).at(slice(None))
        flush = np.r_[True, free[1:]]
        start_v2, mcr_start_v2 = np.sort(cap)[::-1].copy(), np.sort(cap).copy()
        ref = klipper._cruise(start_v2, mcr_start_v2, {"delta_v2": delta, "mcr_delta_v2": made.at(slice(None))},
                              cap.copy(), flush)
        got = kernels.compiled().klipper_cruise(start_v2, mcr_start_v2, np.zeros(0), np.zeros(0), cap.copy(), flush,
                                                klipper.TIE, np.empty(cap.size), *made.kernel_args()[:5])
        assert_bits_equal(ref, got, "cruise_v2, increments made")


def test_move_points_agree():
    # homing, a zero-length move, an extruder-only move, a full circle, a position jump (G92) and NaN-free floats
    text = ("G28\nG1 X0 Y0 F600\nG1 X10 E1\nG1 X10\nG1 E2\nG92 X0\nG1 X5 E3\nG2 X5 Y0 I1 J0\nG1 X-0 Y-0\n"
            "G28 X\nG1 X3 Y3\nG1 Z0.3\n")
    for planner in ("marlin", "klipper"):
        op = gcodekit.gcode_to_operation(text, planner, plan=False)
        out = []
        for name in ("numpy", "numba"):
            with kernels.using(name):
                out.append(moves_module.firmware_moves(op))
        ref, got = out
        for field in ("start", "end", "speed_v", "row", "waypoint"):
            assert_bits_equal(getattr(ref, field), getattr(got, field), field)
        assert np.shares_memory(ref.start, ref.end) == np.shares_memory(got.start, got.end)


@pytest.mark.parametrize("text", [
    # chained moves, the first from waypoint 0 (starts at the origin)
    "G1 X1 Y2 E0.5 F600\nG1 X3 E1\nG1 E1.5\nG1 X-0 Y-0\nG1 Z0.3\n",
    # homing first, a zero-length move, a position jump (G92): not chained
    "G28\nG1 X0 Y0 F600\nG1 X10 E1\nG1 X10\nG1 E2\nG92 X0\nG1 X5 E3\nG28 X\nG1 X3 Y3\nG1 Z0.3\n",
])
@pytest.mark.parametrize("name", ["numpy", "numba"])
def test_gathered_move_points_are_the_stored_ones(text, name):
    """Marlin reads the moves' points a block at a time from the waypoints; every slice is the stored one."""
    op = gcodekit.gcode_to_operation(text, "marlin", plan=False)
    with kernels.using(name):
        stored = moves_module.firmware_moves(op)
        gathered = moves_module.firmware_moves(op, gathered=True)
    assert not isinstance(gathered.start, np.ndarray) and gathered.start.shape == stored.start.shape
    n = len(stored)
    for lo in range(n + 1):
        for hi in range(lo, n + 2):
            assert_bits_equal(stored.start[lo:hi], gathered.start[lo:hi], f"start[{lo}:{hi}]")
            assert_bits_equal(stored.end[lo:hi], gathered.end[lo:hi], f"end[{lo}:{hi}]")
    assert_bits_equal(stored.axes_d, gathered.axes_d, "axes_d")
    for field in ("speed_v", "row", "waypoint"):
        assert_bits_equal(getattr(stored, field), getattr(gathered, field), field)


@pytest.mark.parametrize("text", [
    "G1 X1 Y2 E0.5 F600\nG1 X3 E1\nG1 E1.5\nG1 X-0 Y-0\nG1 Z0.3\nG1 X2 Y2 Z0.6 E2\n",
    "G28\nG1 X0 Y0 F600\nG1 X10 E1\nG1 X10\nG1 E2\nG92 X0\nG1 X5 E3\nG28 X\nG1 X3 Y3\nG1 Z0.3\n",
    # relative E from a signed zero on: the running sum starts at -0.0, as np.cumsum's does
    "M83\nG1 X1 E-0 F600\nG1 X2 E0.1\nG1 E-0.3\nG1 X3 E0.1234567\nG92 E0\nG1 X4 E1e-9\nG1 X5 E0.2\n",
    # M220 scales the speeds the loop reads at each waypoint; G0 runs at the feed (Klipper) or the rapid rate
    "G1 X1 F600\nM220 S37\nG1 X2 Y1 E1\nG0 X5 F9000\nM220 S150\nG1 X7\nG0 Y3\n",
])
@pytest.mark.parametrize("machine", ["klipper", "makerbot"])
def test_klippers_compiled_set_up_reads_gathered_points_as_stored_ones(text, machine):
    """Stored points, gathered points with the extruder summed in the loop (the planner's way) and gathered
    points with the summed extruder column handed over give the same set-up, bit for bit."""
    from gcodekit.plan import klipper
    from gcodekit.plan.points import MoveEnds, RunningSum

    op = gcodekit.gcode_to_operation(text, machine, plan=False)
    config = klipper.KlipperConfig()
    rows, limits = klipper._velocity_limits(op, config)
    factor = moves_module.speed_factor(op)
    out = []
    for way in ("stored", "summed in the loop", "sums handed over"):
        moves = moves_module.firmware_moves(op, factor, gathered=way != "stored")
        assert moves.read_from_source == (way != "stored")  # gathered: speeds and rows read in the loop
        if way == "sums handed over":
            ends = moves.start.ends
            assert isinstance(ends.columns[3], RunningSum)
            summed = MoveEnds((*ends.columns[:3], np.cumsum(op.waypoints["de"])), ends.idx, ends.chained)
            moves = moves_module.PlannerMoves(summed.start, summed.end, moves.speed_v, moves.row, moves.waypoint)
        flush = np.zeros(len(moves), bool)
        flush[0] = True
        out.append(klipper._compiled_moves(kernels.compiled(), moves, rows, limits, config, flush))
    (stored, stored_junction), *others = out
    for got, got_junction in others:
        for key in stored:
            if isinstance(stored[key], scans.Increments):  # made where read: what they are made from
                for part in ("move_d", "accel", "pseudo_accel"):
                    assert_bits_equal(*(np.asarray(getattr(m[key], part) if getattr(m[key], part) is not None
                                                   else np.zeros(0)) for m in (stored, got)), f"{key}.{part}")
                continue
            assert_bits_equal(stored[key], got[key], key)
        assert_bits_equal(stored_junction, got_junction, "junction")


def test_a_running_sum_reads_as_np_cumsum():
    from gcodekit.plan.points import RunningSum

    de = np.array([-0.0, 0.1, 0.2, -0.3, 1e-17, 5.0])
    column = RunningSum(de)
    assert column._sums is None and len(column) == 6  # nothing summed until read
    assert_bits_equal(column[np.array([0, 2, 5])], np.cumsum(de)[[0, 2, 5]], "indices")
    assert_bits_equal(np.asarray(column), np.cumsum(de), "whole")


def test_a_running_sum_read_in_order_holds_only_a_stretch():
    from gcodekit.plan.points import RunningSum

    rng = np.random.default_rng(5)
    de = rng.normal(size=50_000) * (rng.random(50_000) < 0.7)
    de[0] = -0.0
    reference = np.cumsum(de)
    column = RunningSum(de)
    waypoints = np.sort(rng.choice(50_000, 20_000, replace=False))
    for lo in range(0, waypoints.size, 1000):  # Marlin's way: a block's ends, then its starts a move earlier
        ends, starts = waypoints[lo:lo + 1000], np.maximum(waypoints[max(lo - 2, 0):lo + 999] - 1, 0)
        assert_bits_equal(column[ends], reference[ends], "ends")
        assert_bits_equal(column[starts], reference[starts], "starts")
        assert column._sums is None and column._window.size < 10_000  # a stretch, not every sum
    assert_bits_equal(column[np.array([3, 7])], reference[[3, 7]], "read back: every sum made once")
    assert column._sums is not None


def test_gathered_points_of_a_program_with_arcs_are_stored_chords():
    op = gcodekit.gcode_to_operation("G1 X1 Y0 F600\nG2 X-1 Y0 I-1 J0 E1\nG1 X0\n", "marlin", plan=False)
    cut = lambda travel, *_: np.maximum(np.floor(travel / 0.5), 1.0)  # noqa: E731
    stored = moves_module.firmware_moves(op, None, cut)
    gathered = moves_module.firmware_moves(op, None, cut, gathered=True)
    assert len(stored) > 3 and isinstance(gathered.start, np.ndarray)
    assert_bits_equal(stored.start, gathered.start, "start")
    assert np.shares_memory(gathered.start, gathered.end) == np.shares_memory(stored.start, stored.end)


trapezoid_v2 = st.one_of(st.floats(0.0, 1e5), st.sampled_from([0.0, 1.0, 4.0, 25.0, 1e-300, np.inf]))


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.0, 1e-9, 0.5, 1.0, 2.0, 10.0]),
                          st.sampled_from([0.0, 500.0, 3000.0, np.inf]), trapezoid_v2, trapezoid_v2, trapezoid_v2),
                min_size=1, max_size=20),
       st.sampled_from(["marlin", "klipper"]))
def test_trapezoids_agree(rows, planner):
    from gcodekit.plan import klipper, lookahead
    from gcodekit.plan.trapezoids import TrapezoidPlan

    move_d, accel, a, b, c = (np.array(col, float) for col in zip(*rows))
    shape, kernel = ((lookahead._trapezoid_block, "marlin_trapezoids") if planner == "marlin"
                     else (klipper._set_junction_block, "klipper_trapezoids"))
    plan = TrapezoidPlan(shape, move_d, accel, a, b, c, kernel=kernel)
    with kernels.using("numpy"):
        ref, ref_duration = plan.phases(), plan.duration_t
    with kernels.using("numba"):
        got, duration = plan.phases(), plan.duration_t
    for field in FIELDS:
        assert_bits_equal(getattr(ref, field), getattr(got, field), field)
    assert_bits_equal(ref_duration, duration, "duration_t")
