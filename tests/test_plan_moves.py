"""The moves a planner takes: which setting commands come between two moves (``plan.moves.happens_before``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit import plan
from gcodekit.plan.lookahead import lookahead
from gcodekit.plan.moves import PlannedMoves, PlannerMoves, PlanResult, happens_before
from gcodekit.plan.times import PlannedTimes


def _moves(rows: list[int]) -> PlannerMoves:
    n = len(rows)
    return PlannerMoves(start=np.zeros((n, 4)), end=np.zeros((n, 4)), speed_v=np.ones(n),
                        row=np.asarray(rows, np.int32), waypoint=np.arange(n, dtype=np.int32))


def _by_hand(move_rows: list[int], command_rows: list[int]) -> list[bool]:
    """Move i: is there a command row strictly between the previous move's row (-1 for the first) and its own?"""
    return [any(previous < r < row for r in command_rows)
            for previous, row in zip([-1, *move_rows[:-1]], move_rows)]


def test_a_dwell_between_moves_marks_the_move_after_it():
    # rows: 0 G1, 1 G1, 2 G4 (the command), 3 G1, 4 G1 (a segmented arc: two moves), 5 M400, 6 G1
    moves = _moves([0, 1, 3, 4, 4, 6])
    assert happens_before(moves, np.array([2, 5])).tolist() == [False, False, True, False, False, True]
    assert happens_before(moves, np.array([4])).tolist() == [False] * 6  # a move's own row is not between
    assert happens_before(moves, np.array([9])).tolist() == [False] * 6  # after the last move: none follows
    assert happens_before(moves, np.array([], np.int64)).tolist() == [False] * 6


@settings(max_examples=300, deadline=None)
@given(st.lists(st.integers(0, 60), max_size=40), st.sets(st.integers(0, 70), max_size=12), st.booleans())
def test_commands_between_moves_as_counted_by_hand(move_rows, command_rows, in_order):
    if in_order:
        move_rows = sorted(move_rows)  # as firmware_moves makes them; otherwise the move-by-move count
    commands = sorted(command_rows)
    got = happens_before(_moves(move_rows), np.asarray(commands, np.int64))
    assert got.tolist() == _by_hand(move_rows, commands)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.integers(0, 3), max_size=60), st.integers(0, 70), st.integers(0, 70), st.booleans(),
       st.integers(0, 2**32 - 1))
def test_waypoint_times_read_by_windows_are_one_bincount(gaps, lo, hi, in_order, seed):
    """Each waypoint's time is the sum np.bincount gives, to the last bit, whichever window it is read in."""
    waypoint = np.cumsum(gaps).astype(np.int32)  # runs of moves per waypoint (an arc's chords), waypoints skipped
    if not in_order:
        np.random.default_rng(seed).shuffle(waypoint)
    durations = np.random.default_rng(seed).random(waypoint.size) * 10.0 ** np.arange(waypoint.size) % 7
    n = int(waypoint.max()) + 3 if waypoint.size else 2
    w = {"x": np.zeros(n), "motion": np.full(n, 2, np.uint8), "time": np.zeros(n), "feed": np.ones(n),
         "distance": np.ones(n)}
    result = PlanResult(*(np.zeros(waypoint.size) for _ in range(4)), durations, np.zeros(waypoint.size),
                        np.zeros(waypoint.size))
    moves = PlannedMoves(np.ones(waypoint.size), waypoint, waypoint, np.ones(waypoint.size))
    expected = np.bincount(waypoint, weights=durations, minlength=n)
    times = PlannedTimes(w, moves, result)
    np.testing.assert_array_equal(plan.waypoint_times(w, moves, result).view(np.int64), expected.view(np.int64))
    np.testing.assert_array_equal(times[lo:hi].view(np.int64), expected[lo:hi].view(np.int64))
    assert len(times) == n and times[n - 1] == expected[n - 1] and times[-n] == expected[0]
    np.testing.assert_array_equal(times[::2], expected[::2])


v2 = st.one_of(st.floats(0.0, 1e4), st.sampled_from([0.0, 0.0025, 1.0]))  # finite, as planners cap


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(v2, v2, st.booleans(), st.booleans()), min_size=1, max_size=30))
def test_lookahead_writing_over_its_inputs_gives_the_same_speeds(moves):
    """``lookahead(reuse=True)`` overwrites the caller's caps and increments: the speeds must not change,
    and both must be the grbl recurrences, computed here move by move."""
    cap, delta, rest, nominal = (np.array(c) for c in zip(*moves))
    rest[-1] = True  # the program ends at rest
    kept = lookahead(cap.copy(), delta.copy(), rest, rest_v2=0.0025, nominal_length=nominal)
    reused = lookahead(cap.copy(), delta.copy(), rest, rest_v2=0.0025, nominal_length=nominal, reuse=True)
    for a, b in zip(kept, reused):
        np.testing.assert_array_equal(np.asarray(a).view(np.int64), np.asarray(b).view(np.int64))
    # by hand: reverse from each stop (or nominal_length move) at its cap, then forward
    n, entry = len(cap), np.empty(len(cap))
    for i in reversed(range(n)):
        free = rest[i] or nominal[i]
        bound = min(cap[i], 0.0025 + delta[i]) if rest[i] and not nominal[i] else cap[i]
        entry[i] = bound if free or i == n - 1 else min(bound, entry[i + 1] + delta[i])
    for i in range(1, n):
        if not (rest[i - 1] or nominal[i - 1]):
            entry[i] = min(entry[i], entry[i - 1] + delta[i - 1])
    np.testing.assert_allclose(kept[0], entry, rtol=1e-9, atol=1e-9)  # the scans rebuild sums block-wise
    # each move exits at the next one's entry, the very value, but at the rest speed after a stop and the last
    exit_v2 = [0.0025 if rest[i] or i == n - 1 else kept[0][i + 1] for i in range(n)]
    np.testing.assert_array_equal(np.asarray(kept[1]).view(np.int64), np.array(exit_v2).view(np.int64))


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 12), st.data())
def test_next_entry_reads_like_the_stored_exits(n, data):
    """:class:`NextEntry` indexed any way gives what the stored exits did (the old rule, written here)."""
    from gcodekit.plan.trapezoids import NextEntry

    entry = np.arange(n, dtype=float) + 0.5
    entry[::3] = -0.0  # signed zeros copied as they are
    rest = np.array(data.draw(st.lists(st.booleans(), min_size=n, max_size=n)), bool)
    stored = np.empty(n)
    stored[:-1] = entry[1:]
    stored[-1:] = 0.0025
    stored[rest] = 0.0025
    exits = NextEntry(entry, np.flatnonzero(rest), 0.0025)
    assert len(exits) == n and exits.shape == (n,)

    def same(got, expected):
        np.testing.assert_array_equal(np.asarray(got).view(np.int64), np.asarray(expected).view(np.int64))

    same(np.asarray(exits), stored)
    lo, hi = data.draw(st.integers(-n - 2, n + 2)), data.draw(st.integers(-n - 2, n + 2))
    step = data.draw(st.sampled_from([None, 1, 2, -1]))
    same(exits[lo:hi:step], stored[lo:hi:step])
    if n:
        picked = np.array(data.draw(st.lists(st.integers(-n, n - 1), max_size=8)), np.int64)
        same(exits[picked], stored[picked])
        same(exits[rest], stored[rest])
        k = data.draw(st.integers(-n, n - 1))
        same(exits[k], stored[k])


def test_the_points_of_no_moves_are_empty_arrays():
    from gcodekit.plan.points import MoveEnds

    for chained in (True, False):
        start, end = MoveEnds((np.zeros(3),) * 4, np.zeros(0, np.int32), chained).arrays()
        assert start.shape == end.shape == (0, 4)


def test_a_move_planned_at_no_speed_has_an_unknown_time():
    """Klipper's planner moves a G0 at the modal F: read as RepRapFirmware writes it (which takes F0 as
    written; Klipper's own flavor keeps the feed), after ``G1 F0`` it has no speed, its time is infinite.
    The waypoint's time is unknown (NaN, as the emulator has it), not infinity, and no "runs for years"
    warning follows (its number was 1.8e308 s, written out in 300 digits)."""
    op = gcodekit.gcode_to_operation("G1 F800 X10\nG1 F0\nG0 Z3\n", "klipper", flavor="reprapfirmware")
    assert np.isinf(op.plan[1].duration_t[1])
    t = op.waypoints["time"]
    v, accel = 800 / 60, 3000.0  # Klipper's default max_accel: 10 mm from rest to rest, cruising at v
    assert np.isnan(t[2]) and t[0] == pytest.approx(10 / v + v / accel, rel=1e-12)
    assert not any("years" in d.message for d in op.diagnostics)


@pytest.mark.parametrize("machine, program, speed_by_line", [
    # M220 scales the feed from its row on (S / 100, as the planner reads it); an arc cut into chords
    # repeats its line's speed
    ("marlin", "M220 S50\nG1 X10 F1200\nG2 X20 I5 F600\nM220 S150\nG1 X30 Y5\nG1 E2 F300\n",
     {2: 1200 / 60.0 * 0.5, 3: 600 / 60.0 * 0.5, 5: 600 / 60.0 * 1.5, 6: 300 / 60.0 * 1.5}),
    ("klipper", "G1 X10 F1200\nG3 X0 Y0 I-5 J0 F900\nM220 S80\nG1 X5 Y5 F3000\n",
     {1: 1200 / 60.0, 2: 900 / 60.0, 4: 3000 / 60.0 * 0.8}),
    # Sailfish's G0 at the preset's rapid rate, 18000 mm/min, not the feed
    ("makerbot", "G1 F800 X10\nG0 X110\nG1 X120 F600\n", {1: 800 / 60.0, 2: 18000 / 60.0, 3: 600 / 60.0}),
])
def test_kept_moves_read_their_speeds_and_rows_again(machine, program, speed_by_line):
    """Marlin's and Klipper's plans keep no speed or row per move: read back from the waypoint columns, each
    move's row is its line's and its speed the one worked out by hand, and a slice of them is the slice.
    (That the values are those the planner was handed, bit for bit, the corpus plans' hashes showed.)"""
    op = gcodekit.gcode_to_operation(program, machine)
    kept, _ = op.plan
    assert kept.source is not None and len(kept) >= len(speed_by_line)
    lines = op.table.line[kept.row]
    assert set(lines.tolist()) == set(speed_by_line)
    assert kept.speed_v.tolist() == [speed_by_line[line] for line in lines.tolist()]
    assert kept.speeds(slice(1, 3)).tolist() == kept.speed_v[1:3].tolist()
    assert kept.speeds(np.array([0, len(kept) - 1])).tolist() == kept.speed_v[[0, -1]].tolist()


def test_moves_read_from_the_waypoints_cannot_be_changed_apart_from_them():
    op = gcodekit.gcode_to_operation("G1 X10 F1200\nG1 X20\n", "marlin", plan=False)
    moves = plan.moves.firmware_moves(op)
    with pytest.raises(ValueError):
        moves.speed_v[0] = 1.0
    with pytest.raises(ValueError, match="source"):
        PlannedMoves(None, None, moves.waypoint, np.ones(len(moves)))
