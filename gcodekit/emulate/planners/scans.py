"""Emulate stage, planning: the planner passes as array scans.

Every lookahead planner has two recurrences of the same shape, on squared
velocities ``v2``:

* forward (what can be reached accelerating from the previous junction)::

      for i in range(n):  m[i] = min(cap[i], m[i-1] + inc[i-1])

* backward (what still allows braking for the next junction)::

      for i in reversed(range(n)):  s[i] = min(cap[i], s[i+1] + inc[i])

With ``S`` the running sum of ``inc``, ``m[i] - S[i] = min(cap[i] - S[i],
m[i-1] - S[i-1])``: a running minimum, ``np.minimum.accumulate``.  The sums
restart every :data:`BLOCK` moves so that their size never costs precision.
"""

from __future__ import annotations

import numpy as np

BLOCK = 4096


def forward_min(cap: np.ndarray, inc: np.ndarray, first: float = 0.0) -> np.ndarray:
    """``m[0] = min(cap[0], first)``; ``m[i] = min(cap[i], m[i-1] + inc[i-1])``."""
    n = cap.size
    out = np.empty(n)
    carry = first  # value that m[start] may not exceed, from the block before
    for start in range(0, n, BLOCK):
        stop = min(start + BLOCK, n)
        c = cap[start:stop]
        # reach[k]: what the previous move allows at junction k of the block
        s = np.concatenate([[0.0], np.cumsum(inc[start:stop - 1])])
        bound = np.minimum(c - s, np.r_[carry, np.full(stop - start - 1, np.inf)])
        m = np.minimum.accumulate(bound) + s
        out[start:stop] = m
        carry = m[-1] + inc[stop - 1]
    return out


def backward_min(cap: np.ndarray, inc: np.ndarray, last: float = 0.0) -> np.ndarray:
    """``s[n-1] = min(cap[n-1], last + inc[n-1])``; ``s[i] = min(cap[i], s[i+1] + inc[i])``."""
    n = cap.size
    out = np.empty(n)
    carry = last  # s of the move after the block
    for stop in range(n, 0, -BLOCK):
        start = max(stop - BLOCK, 0)
        c = cap[start:stop][::-1]
        d = inc[start:stop][::-1]
        s = np.cumsum(d)  # s[k]: sum of inc from this move to the block's end
        bound = c - s
        bound[0] = min(bound[0], carry)
        r = np.minimum.accumulate(bound) + s
        out[start:stop] = r[::-1]
        carry = out[start]
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
