"""Plan stage: the planner passes as array scans.

Every lookahead planner has two recurrences of the same shape, on squared
velocities ``v2``:

* forward (what can be reached accelerating from the previous junction)::

      for i in range(n):  m[i] = min(cap[i], m[i-1] + inc[i-1])

* backward (what still allows braking for the next junction)::

      for i in reversed(range(n)):  s[i] = min(cap[i], s[i+1] + inc[i])

With ``S`` the running sum of ``inc``, ``m[i] - S[i] = min(cap[i] - S[i],
m[i-1] - S[i-1])``: a running minimum, ``np.minimum.accumulate``.

``cap - S`` rounds away the last digits of small caps (a near-reversal
corner allows 1e-7 mm^2/s^2), so the scan only decides *which* bound holds
at each move; the values are then rebuilt: a move bound by its cap takes
the cap itself, a move bound by its predecessor the last cap plus the
increments since, as ``(cap - S[k]) + S[i]``.  That is the firmware's
loop's value up to the last bits (its increments are added one at a time:
0.0075 here can be 0.00749999999999984); the compiled loops do the same
arithmetic as this code.  Sums restart every :data:`BLOCK` moves so that
their size never costs precision.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..columns import Column
from .kernels import NO_RUNS, engine, runs_of

BLOCK = 4096


@dataclass(eq=False)
class Increments:
    """A scan's increments, made where the compiled scans read them instead of stored (an array fewer).

    Each move's ``2 * move_d * accel`` (what it adds to or sheds from v^2),
    or the least of that and ``2 * move_d * pseudo_accel`` (Klipper's
    minimum cruise ratio) when ``pseudo_accel`` is given; where ``free``,
    the scan's own cap instead: the move's own, scanning backward, the next
    move's, scanning forward (a stop cuts the recurrence, see
    :func:`.lookahead.lookahead`).  ``accel`` and ``pseudo_accel`` may be
    runs (:class:`~gcodekit.columns.RunColumn`).  Doubling is exact, so
    ``2 * move_d * accel`` is ``2 * accel * move_d`` to the last bit.
    """

    move_d: np.ndarray
    accel: Column
    pseudo_accel: Column | None = None
    free: np.ndarray | None = None

    def at(self, moves: np.ndarray) -> np.ndarray:
        """The increments (``free`` aside) of the moves ``moves``."""
        delta = 2.0 * np.asarray(self.move_d[moves], float) * np.asarray(self.accel[moves], float)
        if self.pseudo_accel is not None:
            least = 2.0 * np.asarray(self.move_d[moves], float) * np.asarray(self.pseudo_accel[moves], float)
            delta = np.where((least < delta) | (least != least), least, delta)
        return delta

    def array(self, cap: np.ndarray, forward: bool) -> np.ndarray:
        """Every increment, as the NumPy scans read them (``cap`` as the scan reads it, before it writes)."""
        out = self.at(slice(None))
        if self.free is not None and forward:
            np.copyto(out[:-1], cap[1:], where=self.free[:-1])
        elif self.free is not None:
            np.copyto(out, cap, where=self.free)
        return out

    def kernel_args(self) -> tuple:
        """What the compiled scans take after ``out``: move_d, accel and its runs, pseudo_accel and its runs, free."""
        pseudo = runs_of(self.pseudo_accel) if self.pseudo_accel is not None else (np.zeros(0), NO_RUNS)
        free = np.zeros(0, np.bool_) if self.free is None else np.ascontiguousarray(self.free, np.bool_)
        return np.ascontiguousarray(self.move_d, float), *runs_of(self.accel), *pseudo, free


def _stored_args() -> tuple:
    """:meth:`Increments.kernel_args` when the increments are an array."""
    none = np.zeros(0)
    return none, none, NO_RUNS, none, NO_RUNS, np.zeros(0, np.bool_)


def forward_min(cap: np.ndarray, inc: np.ndarray | Increments, first: float = 0.0, *,
                out: np.ndarray | None = None) -> np.ndarray:
    """``m[0] = min(cap[0], first)``; ``m[i] = min(cap[i], m[i-1] + inc[i-1])``.

    ``out`` (a float64 array of ``cap``'s size, which may be ``cap`` itself:
    each cap is read before its move's value is written) receives ``m``.
    ``inc`` may be :class:`Increments`, made where read.
    """
    out = _output(out, cap)
    kernels = engine(cap.size)
    if kernels is not None:
        made = isinstance(inc, Increments)
        kernels.forward_min(_floats(cap), np.zeros(0) if made else _floats(inc), float(first), BLOCK, out,
                            *(inc.kernel_args() if made else _stored_args()))
        return out
    if isinstance(inc, Increments):
        inc = inc.array(cap, forward=True)
    n = cap.size
    carry = first  # what the move before the block allows at the block's first junction
    for start in range(0, n, BLOCK):
        stop = min(start + BLOCK, n)
        c = cap[start:stop]
        # s[k]: increments from the block's first move up to move k (exclusive)
        s = np.concatenate([[0.0], np.cumsum(inc[start:stop - 1])])
        bound = np.minimum(c - s, np.r_[carry, np.full(stop - start - 1, np.inf)])
        approx = np.minimum.accumulate(bound) + s
        reach = np.r_[carry, approx[:-1] + inc[start:stop - 1]]
        m = _rebuild(c, s, c <= reach, carry)
        out[start:stop] = m
        carry = m[-1] + inc[stop - 1]
    return out


def backward_min(cap: np.ndarray, inc: np.ndarray | Increments, last: float = 0.0, *,
                 out: np.ndarray | None = None) -> np.ndarray:
    """``s[n-1] = min(cap[n-1], last + inc[n-1])``; ``s[i] = min(cap[i], s[i+1] + inc[i])``.

    ``out`` as in :func:`forward_min` (``cap`` itself allowed); ``inc`` as there.
    """
    out = _output(out, cap)
    kernels = engine(cap.size)
    if kernels is not None:
        made = isinstance(inc, Increments)
        kernels.backward_min(_floats(cap), np.zeros(0) if made else _floats(inc), float(last), BLOCK, out,
                             *(inc.kernel_args() if made else _stored_args()))
        return out
    if isinstance(inc, Increments):
        inc = inc.array(cap, forward=False)
    n = cap.size
    carry = last  # s of the move after the block
    for stop in range(n, 0, -BLOCK):
        start = max(stop - BLOCK, 0)
        c = cap[start:stop][::-1]
        d = inc[start:stop][::-1]
        s = np.cumsum(d)  # s[k]: increments from the block's end back to move k (inclusive)
        bound = c - s
        bound[0] = min(bound[0], carry)
        approx = np.minimum.accumulate(bound) + s
        reach = np.r_[carry, approx[:-1]] + d
        r = _rebuild(c, s, c <= reach, carry + d[0] - s[0])
        out[start:stop] = r[::-1]
        carry = out[start]
    return out


def _output(out: np.ndarray | None, cap: np.ndarray) -> np.ndarray:
    """Where a scan writes: ``out`` when given (checked), else a new array."""
    if out is None:
        return np.empty(cap.size)
    if out.dtype != np.float64 or out.shape != (cap.size,) or not out.flags.c_contiguous or not out.flags.writeable:
        raise ValueError(f"a scan writes into a writable contiguous float64 array of {cap.size} values")
    return out


def _floats(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def _rebuild(cap: np.ndarray, s: np.ndarray, binds: np.ndarray, seed: float) -> np.ndarray:
    """The values: ``cap[k]`` where the cap binds, else the last bound value
    plus the increments since (``s`` are running sums, ``seed + s`` before any cap)."""
    k = np.where(binds, np.arange(cap.size), -1)
    np.maximum.accumulate(k, out=k)
    base = np.where(k >= 0, cap[np.maximum(k, 0)] - s[np.maximum(k, 0)], seed)
    out = base + s
    out[binds] = cap[binds]
    return out


def segmented_cummin(values: np.ndarray, segment: np.ndarray) -> np.ndarray:
    """Running minimum that restarts where ``segment`` changes (a doubling scan)."""
    out = values.copy()
    shift = 1
    n = values.size
    while shift < n:
        same = segment[shift:] == segment[:-shift]
        if not same.any():
            break
        np.copyto(out[shift:], np.minimum(out[shift:], out[:-shift]), where=same)
        shift *= 2
    return out


def next_marked(marked: np.ndarray) -> np.ndarray:
    """For each index, the smallest marked index at or after it (n if none)."""
    n = marked.size
    idx = np.where(marked, np.arange(n), n)
    return np.minimum.accumulate(idx[::-1])[::-1]
