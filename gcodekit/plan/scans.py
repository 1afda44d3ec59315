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

import numpy as np

from .kernels import engine

BLOCK = 4096


def forward_min(cap: np.ndarray, inc: np.ndarray, first: float = 0.0, *, out: np.ndarray | None = None) -> np.ndarray:
    """``m[0] = min(cap[0], first)``; ``m[i] = min(cap[i], m[i-1] + inc[i-1])``.

    ``out`` (a float64 array of ``cap``'s size, which may be ``cap`` itself:
    each cap is read before its move's value is written) receives ``m``.
    """
    out = _output(out, cap)
    kernels = engine(cap.size)
    if kernels is not None:
        kernels.forward_min(_floats(cap), _floats(inc), float(first), BLOCK, out)
        return out
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


def backward_min(cap: np.ndarray, inc: np.ndarray, last: float = 0.0, *, out: np.ndarray | None = None) -> np.ndarray:
    """``s[n-1] = min(cap[n-1], last + inc[n-1])``; ``s[i] = min(cap[i], s[i+1] + inc[i])``.

    ``out`` as in :func:`forward_min` (``cap`` itself allowed).
    """
    out = _output(out, cap)
    kernels = engine(cap.size)
    if kernels is not None:
        kernels.backward_min(_floats(cap), _floats(inc), float(last), BLOCK, out)
        return out
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
