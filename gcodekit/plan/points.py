"""Plan stage: where each firmware move starts and ends, stored or gathered a slice at a time.

A move ends at its waypoint's X, Y, Z and extruder position (the running
sum of ``de``) and starts where the waypoint before it ended.  Stored, the
points of a 3 M-move print take 98 MB (one array of ``n + 1`` points when
each move starts where the previous one ended, the usual case); a planner
that reads them a block of moves at a time (Marlin's) takes them from the
waypoint columns instead, as :class:`MoveEnds` gathers them.  Both give the
same numbers, bit for bit.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MoveEnds", "RunningSum", "chained"]


class RunningSum:
    """A column's running sum (``np.cumsum(deltas)``, the extruder position from each waypoint's ``de``).

    Indexed like the array it stands for.  Read in order, a block of
    waypoints at a time (Marlin's planner), it sums only as far as asked and
    keeps only the stretch the last two reads covered; read out of order,
    it makes every sum once.  Either way the sums are ``np.cumsum``'s to the
    last bit: each stretch is summed on from the sum before it, in the same
    order.  A compiled loop that walks the waypoints in order sums
    :attr:`deltas` itself (Klipper's set-up).
    """

    def __init__(self, deltas: np.ndarray, sums: np.ndarray | None = None):
        self.deltas = deltas
        self._sums = sums
        self._window = np.empty(0)  # the sums of waypoints _first .. _first + len(_window) - 1
        self._first = 0
        self._last_read = 0  # the lowest waypoint of the read before

    @property
    def sums(self) -> np.ndarray:
        if self._sums is None:
            self._sums = np.cumsum(self.deltas)
            self._window = np.empty(0)
        return self._sums

    def __len__(self) -> int:
        return int(np.shape(self.deltas)[0])

    def __getitem__(self, index) -> np.ndarray:
        index = np.asarray(index)
        if self._sums is not None or index.dtype == bool or index.ndim != 1 or index.size == 0:
            return self.sums[index]
        lo, hi = int(index.min()), int(index.max()) + 1
        if lo < self._first or lo < 0:
            return self.sums[index]
        self._extend(hi)
        keep = min(lo, self._last_read)
        self._last_read = lo
        if keep > self._first:
            self._window = self._window[keep - self._first:].copy()
            self._first = keep
        return self._window[index - self._first]

    def _extend(self, hi: int) -> None:
        """Sum on to waypoint ``hi - 1``, from the last sum held (np.cumsum adds in order)."""
        end = self._first + self._window.size
        if hi <= end:
            return
        if self._window.size:
            more = np.cumsum(np.r_[self._window[-1], self.deltas[end:hi]])[1:]
        else:  # nothing summed yet
            more = np.cumsum(self.deltas[:hi])
        self._window = np.concatenate([self._window, more])

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return self.sums if dtype is None else self.sums.astype(dtype)


def chained(columns: tuple[np.ndarray, ...], idx: np.ndarray) -> bool:
    """Whether every move ending at waypoints ``idx`` starts where the move before it ended.

    Where a move's waypoint follows the previous move's, it does; the rest
    are compared (every one when a column holds NaN, which equals nothing).
    """
    before = np.maximum(idx - 1, 0)
    gaps = np.flatnonzero(before[1:] != idx[:-1])
    return all(np.array_equal(col[before[1:][gaps]], col[idx[:-1][gaps]]) if not np.isnan(col).any() else
               np.array_equal(col[before[1:]], col[idx[:-1]]) for col in columns)


class MoveEnds:
    """The start and end points (X, Y, Z, E) of the moves ending at waypoints ``idx``.

    ``columns`` are the waypoints' X, Y, Z and extruder position (an array
    or a :class:`RunningSum` of the extrusion per waypoint).  When the
    moves are ``chained``, move ``k`` starts at the end of move ``k - 1``;
    otherwise at the waypoint before its own.  The first move of the program
    starts at the origin.  :attr:`start` and :attr:`end` gather a slice of
    moves when indexed; :meth:`arrays` stores them all.
    """

    def __init__(self, columns: tuple[np.ndarray, ...], idx: np.ndarray, is_chained: bool):
        self.columns = columns
        self.idx = idx
        self.chained = is_chained

    @property
    def start(self) -> "_Gathered":
        """The moves' start points, gathered when indexed (made on each read: no reference cycle, so the
        columns are freed as soon as the last view of them is)."""
        return _Gathered(self, "start")

    @property
    def end(self) -> "_Gathered":
        """The moves' end points, gathered when indexed."""
        return _Gathered(self, "end")

    def __len__(self) -> int:
        return int(self.idx.size)

    def _points(self, waypoints: np.ndarray, at_origin: np.ndarray | None = None) -> np.ndarray:
        out = np.empty((waypoints.size, 4))
        for k, col in enumerate(self.columns):
            out[:, k] = col[waypoints]
        if at_origin is not None:
            out[at_origin] = 0.0
        return out

    def ends(self, sl: slice) -> np.ndarray:
        return self._points(self.idx[sl])

    def starts(self, sl: slice) -> np.ndarray:
        lo, hi, _ = sl.indices(len(self))
        if hi <= lo:
            return np.empty((0, 4))
        if not self.chained:
            waypoints = self.idx[lo:hi]
            return self._points(np.maximum(waypoints - 1, 0), waypoints == 0)
        first = self.idx[0]
        if lo == 0:  # the first move starts at the waypoint before its own, the rest where the last ended
            waypoints = np.concatenate([[max(first - 1, 0)], self.idx[: hi - 1]])
            at_origin = np.zeros(hi, bool)
            at_origin[0] = first == 0
            return self._points(waypoints, at_origin)
        return self._points(self.idx[lo - 1 : hi - 1])

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """Every move's start and end: views of one array of ``n + 1`` points when chained (half the memory)."""
        every = slice(None)
        if not self.chained:
            return self.starts(every), self.ends(every)
        points = np.empty((len(self) + 1, 4))
        points[1:] = self.ends(every)
        if len(self):
            points[:1] = self.starts(slice(0, 1))
        return points[:-1], points[1:]


class _Gathered:
    """``MoveEnds.start`` or ``.end``: indexed by a slice of moves, the ``(m, 4)`` array of their points."""

    def __init__(self, ends: MoveEnds, which: str):
        self.ends = ends
        self._of = ends.starts if which == "start" else ends.ends
        self._n = len(ends)

    @property
    def shape(self) -> tuple[int, int]:
        return (self._n, 4)

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, sl: slice) -> np.ndarray:
        if not isinstance(sl, slice):
            raise TypeError("gathered move points are read by slices of moves")
        return self._of(sl)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        out = self._of(slice(None))
        return out if dtype is None else out.astype(dtype)
