"""Output stage: speed over time as each move's velocity trapezoid, laid out as corners when a plot asks.

A planned move accelerates from ``start_v`` to ``cruise_v``, cruises and
decelerates to ``end_v``: the four corners of its trapezoid (time, distance,
speed) are what a speed plot draws.  A 3 M-line print has 12 M corners, and
laying them all out costs seconds and half a gigabyte, so
:class:`VelocityMoves` keeps one row per move (the plan's own arrays, and
each move's start) and makes the corners of a range of moves on demand, the
same numbers, to the bit, as :func:`gcodekit.analysis.velocity_corners`
gives for the whole program.  Without a planner each moving waypoint holds
its commanded feed: two corners.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G1 X10 F600\\nG1 X20\\n", "marlin")
>>> v = VelocityMoves(op)
>>> len(v), v.per_move, v.corners(1, 2, ("planned",))["planned"].size
(2, 4, 4)
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..model.operation import Operation

#: Moves whose speeds are reduced at a time (whole-program arrays of every phase took twice as long).
SPEED_BLOCK = 1 << 16
#: The corner columns, in the order velocity_corners returns them.
COLUMNS = ("time", "distance", "planned", "commanded", "line")


class VelocityMoves:
    """One row per planned move (or moving waypoint, without a plan): its trapezoid, and its corners on demand.

    Attributes
    ----------
    per_move : int
        Corners per move: 4 (a planned trapezoid) or 2 (a held feed).
    """

    def __init__(self, op: "Operation"):
        self.op = op
        if op.plan is None:
            self.moved = np.flatnonzero(op.waypoints["motion"] > 0)
            self.per_move, self.n = 2, int(self.moved.size)
        else:
            self.moves, self.result = op.plan
            self.per_move, self.n = 4, len(self.moves)

    def __len__(self) -> int:
        return self.n

    # -- per move, each computed once over the whole program (sums run along it) --------

    @cached_property
    def _time(self) -> tuple[np.ndarray, np.ndarray]:
        """Each move's start time and duration, s."""
        op, w = self.op, self.op.waypoints
        if op.plan is None:
            t_end = op.elapsed_time()[self.moved]
            return t_end - np.nan_to_num(np.asarray(w["time"], float)[self.moved]), t_end
        # a move starts when its waypoint started plus the moves of that waypoint before it
        moves, dur = self.moves, self.result.duration_t
        wp = moves.waypoint
        t_start_wp = op.elapsed_time()[wp] - np.nan_to_num(np.asarray(w["time"], float)[wp])
        within = np.cumsum(dur) - dur
        first = np.r_[0, np.flatnonzero(wp[1:] != wp[:-1]) + 1]
        offset = np.repeat(within[first], np.diff(np.r_[first, len(moves)]))
        return t_start_wp + (within - offset), dur

    @cached_property
    def _distance(self) -> tuple[np.ndarray, np.ndarray]:
        """Each move's start and end distance travelled so far (planned: start and length), mm."""
        if self.op.plan is None:
            d = np.asarray(self.op.waypoints["distance"], float)[self.moved]
            d_end = np.cumsum(d)
            return d_end - d, d_end
        d = self.moves.length_d
        return np.cumsum(d) - d, d

    @cached_property
    def line(self) -> np.ndarray:
        """Each move's source line."""
        from ..model.derived import waypoint_rows

        op = self.op
        if op.plan is None:
            return op.table.line[waypoint_rows(op)[self.moved]]
        return op.table.line[self.moves.row]

    def start(self, x: str = "time") -> np.ndarray:
        """Each move's first corner on ``x`` (``"time"``, s, or ``"distance"``, mm): the corners' x at every ``per_move``-th."""
        return self._time[0] if x == "time" else self._distance[0]

    def commanded(self) -> np.ndarray:
        """Each move's commanded speed, mm/s."""
        if self.op.plan is None:
            return np.asarray(self.op.waypoints["feed"], float)[self.moved] / 60.0
        return self.moves.speed_v

    def speed_range(self, out: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Each move's lowest and highest planned speed (the extremes of its corners), mm/s, into ``out`` if given."""
        lo, hi = out if out is not None else (np.empty(self.n), np.empty(self.n))
        if self.op.plan is None:
            lo[:] = hi[:] = self.commanded()
            return lo, hi
        # the speeds a block of moves at a time (a planner may compute them when read): small temporaries
        for a in range(0, self.n, SPEED_BLOCK):
            sl = slice(a, min(a + SPEED_BLOCK, self.n))
            r = self.result.phases(sl)
            np.minimum(np.minimum(r.start_v, r.cruise_v), r.end_v, out=lo[sl])
            np.maximum(np.maximum(r.start_v, r.cruise_v), r.end_v, out=hi[sl])
        return lo, hi

    # -- corners ----------------------------------------------------------------------

    def corners(self, a: int = 0, b: int | None = None, columns: tuple[str, ...] = COLUMNS) -> dict[str, np.ndarray]:
        """The corners of moves ``a`` to ``b`` (``per_move`` each, in order), only the ``columns`` asked.

        :func:`gcodekit.analysis.velocity_corners` is ``corners()`` (every move, every column).
        """
        return self.corners_of(slice(a, self.n if b is None else b), columns)

    def corners_of(self, moves: slice | np.ndarray, columns: tuple[str, ...] = COLUMNS) -> dict[str, np.ndarray]:
        """The corners of ``moves`` (a slice or indices), as (k, ``per_move``) rows flattened, per column."""
        out = {}
        needs_plan = self.op.plan is not None and bool(set(columns) - {"line", "commanded"})
        planned = self.result.phases(moves) if needs_plan else None  # every planned field in one computation
        for name in columns:
            out[name] = self._column(name, moves, planned).ravel()
        return out

    def _column(self, name: str, sel: slice | np.ndarray, r=None) -> np.ndarray:
        """Column ``name`` of the moves ``sel``; ``r``: their planned phases (``self.result.phases(sel)``)."""
        if name == "line":
            return np.repeat(self.line[sel], self.per_move)
        if self.op.plan is None:
            if name == "time":
                t0, t_end = self._time
                return np.column_stack([t0[sel], t_end[sel]])
            if name == "distance":
                d0, d_end = self._distance
                return np.column_stack([d0[sel], d_end[sel]])
            return np.repeat(self.commanded()[sel], 2)  # planned and commanded: the feed, held
        if name == "time":
            t0, dur = self._time
            t0, accel_t = t0[sel], r.accel_t
            return np.column_stack([t0, t0 + accel_t, t0 + accel_t + r.cruise_t, t0 + dur[sel]])
        if name == "distance":
            d0, d = self._distance
            d0, d, accel = d0[sel], d[sel], r.accel
            start_v, cruise_v, end_v = r.start_v, r.cruise_v, r.end_v
            accel_d = (cruise_v**2 - start_v**2) / (2 * accel)
            decel_d = (cruise_v**2 - end_v**2) / (2 * accel)
            return np.column_stack([d0, d0 + accel_d, d0 + d - decel_d, d0 + d])
        if name == "planned":
            cruise_v = r.cruise_v
            return np.column_stack([r.start_v, cruise_v, cruise_v, r.end_v])
        if name == "commanded":
            return np.repeat(self.moves.speeds(sel), 4)
        raise ValueError(f"no corner column {name!r}: choose from {', '.join(COLUMNS)}")
