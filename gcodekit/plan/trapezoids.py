"""Plan stage: a plan's per-move speeds and phase times, computed when read.

A planner's passes decide three squared speeds per move (entry, the speed
it may cruise at, exit); each move's trapezoid then follows from them, its
length and its acceleration.  :class:`TrapezoidPlan` keeps those inputs
and computes the speeds and phase times (:class:`.moves.PlanResult`'s
fields) a block at a time when they are read, with the planner's own block
function, so they come out the same to the last bit: a planned program
keeps three arrays per move besides its lengths (the acceleration, the
entry and the cruise speed: the exit is the next entry, :class:`NextEntry`)
instead of seven.  Read several fields at once
with :meth:`TrapezoidPlan.phases` (each field read alone computes the
trapezoids again).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..columns import Column
from .kernels import engine
from .moves import PlanResult

__all__ = ["TrapezoidPlan", "NextEntry", "FIELDS"]

#: The fields computed on reading (``accel`` is kept).
FIELDS = ("start_v", "cruise_v", "end_v", "accel_t", "cruise_t", "decel_t")
BLOCK = 1 << 14  # moves computed at once: small temporaries

#: ``shape(move_d, accel, a_v2, b_v2, c_v2, out, sl)`` writes ``out.<field>[sl]`` for one block of moves.
Shape = Callable[..., None]


class _Discard:
    """Where a block's unwanted fields go."""

    def __setitem__(self, key, value) -> None:
        pass


def _computed(field: str) -> property:
    """The property reading ``field`` of every move, computed on each read (:meth:`TrapezoidPlan.phases`
    computes several at once)."""

    def read(self: "TrapezoidPlan") -> np.ndarray:
        return getattr(self._compute((field,)), field)

    read.__name__ = field
    read.__doc__ = f"Each move's ``{field}`` (see :class:`.moves.PlanResult`), computed when read."
    return property(read)


class NextEntry:
    """Each move's exit speed squared, kept as the entries it repeats: the next move's entry, or ``rest_v2``
    where the machine stops after the move (and after the last one).

    A lookahead planner ends each move at the speed the next one enters at,
    so a plan need not store the exits: indexed (by a slice, indices or a
    mask), this gives them, bit for bit the entries they copy.

    Parameters
    ----------
    entry_v2 : ndarray
        Each move's entry speed squared.
    stops : ndarray of int
        The moves after which the machine stops, sorted.
    rest_v2 : float
        The speed squared at a stop.
    """

    def __init__(self, entry_v2: np.ndarray, stops: np.ndarray, rest_v2: float):
        self.entry_v2, self.stops, self.rest_v2 = entry_v2, stops, float(rest_v2)

    def __len__(self) -> int:
        return int(self.entry_v2.size)

    @property
    def shape(self) -> tuple[int]:
        return (len(self),)

    def __getitem__(self, sel) -> np.ndarray:
        n = len(self)
        if isinstance(sel, slice) and sel.indices(n)[2] == 1:
            lo, hi, _ = sel.indices(n)
            hi = max(hi, lo)
            out = np.empty(hi - lo)
            inner = min(hi, n - 1)  # the moves whose next move exists
            out[:max(inner - lo, 0)] = self.entry_v2[lo + 1:inner + 1]
            out[max(inner - lo, 0):] = self.rest_v2  # the last move
            stops = self.stops[np.searchsorted(self.stops, lo):np.searchsorted(self.stops, hi)]
            out[stops - lo] = self.rest_v2
            return out
        moves = np.arange(n)[sel]
        if moves.ndim == 0:  # one move: a number
            return self[int(moves):int(moves) + 1][0]
        following = moves + 1
        out = self.entry_v2[np.minimum(following, n - 1)]
        at = np.minimum(np.searchsorted(self.stops, moves), max(self.stops.size - 1, 0))
        stopped = (following >= n) | ((self.stops[at] == moves) if self.stops.size else False)
        out[stopped] = self.rest_v2
        return out

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        out = self[:]
        return out if dtype is None else out.astype(dtype)


class TrapezoidPlan:
    """:class:`.moves.PlanResult`'s arrays, computed from the squared speeds when read.

    Parameters
    ----------
    shape : callable
        The planner's block function (see :data:`Shape`).
    move_d, accel : ndarray
        Each move's length (mm) and acceleration (mm/s^2); the accelerations
        may be a :class:`~gcodekit.columns.RunColumn` (read a block at a time).
    *v2 : ndarray or NextEntry
        The three squared speeds ``shape`` takes, mm^2/s^2 (the exits may be
        a :class:`NextEntry`).
    kernel : str, default: None
        The name of ``shape``'s compiled loop in :mod:`.kernels`, used when
        :func:`.kernels.engine` chooses it for a plan this size.
    """

    def __init__(self, shape: Shape, move_d: np.ndarray, accel: Column, *v2: np.ndarray,
                 kernel: str | None = None):
        self._shape, self._move_d, self._accel, self._v2, self._kernel = shape, move_d, accel, v2, kernel

    @property
    def accel(self) -> np.ndarray:
        """Each move's acceleration (mm/s^2), kept as its runs where it has few (a print's few settings)."""
        return np.asarray(self._accel)

    def _compiled(self, sel, fields: tuple[str, ...], duration: bool = False) -> tuple[PlanResult, np.ndarray] | None:
        """The fields (and the durations) by the compiled loop, or None when the NumPy code is to compute them."""
        compiled = engine(len(self)) if self._kernel else None
        if compiled is None:
            return None
        move_d, accel = self._move_d[sel], self._accel[sel]
        n, none = move_d.size, np.empty(0)
        speeds = [np.empty(n) if any(f in fields for f in FIELDS[:3]) else none for _ in range(3)]
        times = [np.empty(n) if any(f in fields for f in FIELDS[3:]) else none for _ in range(3)]
        duration_t = np.empty(n) if duration else none
        getattr(compiled, self._kernel)(np.ascontiguousarray(move_d), np.ascontiguousarray(accel),
                                        *(np.ascontiguousarray(a[sel]) for a in self._v2), *speeds, *times, duration_t)
        return PlanResult(*speeds, accel, *times), duration_t

    def __len__(self) -> int:
        return int(self._move_d.size)

    def phases(self, sel: slice | np.ndarray = slice(None)) -> PlanResult:
        """Every field of the moves ``sel`` (a slice or indices), computed once."""
        return self._compute(FIELDS, sel)

    def _compute(self, fields: tuple[str, ...], sel: slice | np.ndarray = slice(None)) -> PlanResult:
        compiled = self._compiled(sel, fields)
        if compiled is not None:
            return compiled[0]
        move_d, accel = self._move_d[sel], self._accel[sel]
        v2 = [a[sel] for a in self._v2]
        n = move_d.size
        out = PlanResult(**{f: np.empty(n) if f in fields else _Discard() for f in FIELDS}, accel=accel)
        for lo in range(0, n, BLOCK):
            s = slice(lo, min(lo + BLOCK, n))
            self._shape(move_d[s], accel[s], *(a[s] for a in v2), out, s)
        return out

    start_v = _computed("start_v")
    cruise_v = _computed("cruise_v")
    end_v = _computed("end_v")
    accel_t = _computed("accel_t")
    cruise_t = _computed("cruise_t")
    decel_t = _computed("decel_t")

    @property
    def duration_t(self) -> np.ndarray:
        """Each move's time, s: ``accel_t + cruise_t + decel_t``, summed a block at a time."""
        return self.durations()

    def durations(self, sel: slice = slice(None)) -> np.ndarray:
        """:attr:`duration_t` of the moves ``sel``, computed for them alone."""
        compiled = self._compiled(sel, (), duration=True)
        if compiled is not None:
            return compiled[1]
        first, stop, _ = sel.indices(len(self))
        out = np.empty(max(stop - first, 0))
        for lo in range(first, stop, BLOCK):
            s = slice(lo, min(lo + BLOCK, stop))
            r = self._compute(("accel_t", "cruise_t", "decel_t"), s)
            out[lo - first:s.stop - first] = r.accel_t + r.cruise_t + r.decel_t
        return out
