"""Plan stage: each waypoint's planned time, computed from the plan a block of waypoints at a time when read.

A plan keeps each move's speeds and computes its phase times when read
(:class:`.trapezoids.TrapezoidPlan`); the waypoints' ``time`` column is
their sum per waypoint.  :class:`PlannedTimes` stands for that column: an
operation keeps it (no 25 MB array of a 3 M-move print's times) and its
:class:`~gcodekit.columns.Waypoints` mapping computes the array on the
first read.  Read by windows it computes only their waypoints; either way
each time is the same sum, to the last bit.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..columns import Column, ColumnReader, RunColumn, stored
from .moves import PlannedMoves, PlannerMoves, PlanResult
from .trapezoids import TrapezoidPlan

__all__ = ["PlannedTimes", "waypoint_times", "times_to_plan"]

BLOCK = 1 << 16  # waypoints computed at once


class PlannedTimes(ColumnReader):
    """Per-waypoint planned time from per-move results, computed when read (indexed like a 1-D array).

    A waypoint's time is the sum of its moves' durations; a waypoint that
    moves without a planned move (a move to where the tool already is) takes
    none, and one that does not move (a dwell) keeps its own.  A feed move
    with no feed rate in force gets NaN: its time is unknown, not the
    planner's crawl at its minimum speed, unless the emulator timed it too
    (RepRapFirmware takes F0 as written and does crawl at M203 I); a move
    planned at no speed (an infinite time) gets NaN as well.

    Parameters
    ----------
    w : mapping
        The waypoint columns: ``motion``, ``distance``, ``feed`` and the
        emulator's ``time`` are read (kept as they are stored).
    moves, result
        The plan: each move's waypoint, and its durations.
    """

    def __init__(self, w: Mapping[str, Column], moves: PlannerMoves | PlannedMoves,
                 result: PlanResult | TrapezoidPlan):
        self.size = len(stored(w, "x"))
        self.motion, self.distance, self.emulated, self.feed = (stored(w, k) for k in ("motion", "distance", "time",
                                                                                       "feed"))
        self.waypoint, self.result = moves.waypoint, result
        m = self.waypoint.size
        self._in_order = not m or bool((self.waypoint[1:] >= self.waypoint[:-1]).all())
        self._summed: np.ndarray | None = None  # every waypoint's sum, when the moves are out of order

    dtype = np.dtype(np.float64)

    def __repr__(self) -> str:
        return f"PlannedTimes({self.size} waypoints, {self.waypoint.size} moves)"

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        out = np.empty(self.size)
        for lo in range(0, self.size, BLOCK):  # a block at a time: small temporaries
            out[lo:lo + BLOCK] = self.window(lo, min(lo + BLOCK, self.size))
        return out if dtype is None else out.astype(dtype, copy=False)

    def window(self, lo: int, hi: int) -> np.ndarray:
        """The times of waypoints ``lo`` to ``hi - 1``."""
        hi = max(hi, lo)
        times, has_moves = self._summed_window(lo, hi)
        motion, emulated = np.asarray(self.motion[lo:hi]), np.asarray(self.emulated[lo:hi], float)
        idle = ~has_moves
        times[idle] = np.where(motion[idle] > 0, 0.0, emulated[idle])
        # a feed move with no feed in force has no time a planner could know (its minimum speed is no answer)
        # where the emulator knew none either; nor has a move a planner gave no speed at all (a printer's G0
        # at F0): unknown, as the emulator has it.  The emulator times F0 where the firmware moves at a
        # minimum speed it knows (RepRapFirmware's M203 I), and then the planner's crawl is the firmware's.
        unknown = (motion >= 2) & ~(np.asarray(self.feed[lo:hi], float) > 0) & (np.asarray(self.distance[lo:hi]) > 0)
        unknown &= ~np.isfinite(emulated)
        times[unknown] = np.nan
        times[np.isinf(times)] = np.nan
        return times

    def _summed_window(self, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
        """The moves' durations summed per waypoint ``lo`` to ``hi - 1`` (each in move order, as
        ``np.bincount`` sums), and which of them have moves."""
        waypoint = self.waypoint
        if not self._in_order:  # every move's duration at once, kept
            if self._summed is None:
                self._summed = np.bincount(waypoint, weights=self.result.durations(slice(None)),
                                           minlength=self.size).astype(float, copy=False)
            has_moves = np.zeros(hi - lo, bool)
            inside = waypoint[(waypoint >= lo) & (waypoint < hi)]
            has_moves[inside - lo] = True
            return self._summed[lo:hi].copy(), has_moves
        first, stop = (int(k) for k in np.searchsorted(waypoint, np.array((lo, hi), waypoint.dtype)))  # (no cast)
        sel = slice(first, stop)
        times = np.bincount(waypoint[sel] - lo, weights=self.result.durations(sel), minlength=hi - lo).astype(float, copy=False)
        has_moves = np.zeros(hi - lo, bool)
        has_moves[waypoint[sel] - lo] = True
        return times, has_moves


def waypoint_times(w: Mapping[str, Column], moves: PlannerMoves | PlannedMoves,
                   result: PlanResult | TrapezoidPlan) -> np.ndarray:
    """Every waypoint's planned time, as an array (see :class:`PlannedTimes`)."""
    return np.asarray(PlannedTimes(w, moves, result))


def times_to_plan(w: Mapping[str, np.ndarray]) -> Column:
    """The emulator's ``time`` column as a planner that times every move reads it
    (:func:`gcodekit.plan.times_every_move`).

    Such a plan gives every moving waypoint its time (:class:`PlannedTimes`),
    so the emulator's finite times of moves are dropped (as 0) and what stays
    is the time of each waypoint that does not move (a dwell) and the NaN of
    each move the emulator could not time: on a print, a few runs instead of
    25 MB of times the plan replaces, freed before the planner's own arrays.
    """
    time = np.asarray(w["time"], float)
    replaced = (np.asarray(w["motion"]) > 0) & np.isfinite(time)
    return RunColumn.encode(np.where(replaced, 0.0, time))
