"""Output stage: a toolpath drawn with at most a given number of segments, for views of the whole of a large program.

A large print has millions of short segments, several times more than a
view has pixels.  :func:`overview` cuts the toolpath into runs (connected
segments of one key: group, kind and colour, combined by the caller, that
turn by at most :data:`CORNER_DEG` at each joint) and draws each run as
chords through every ``stride``-th point of it, the smallest stride that
fits the budget.  A run's chords start at its first point and end at its
last, so its ends and every sharper corner stay (an infill's zigzag keeps
its shape) and the chords cut only gentle curves shorter, such as a
perimeter's many short chords of a circle (a small circle then shows as a
polygon of a few chords: the top layer, drawn from its own segments, shows
it round); chords never join two runs, so the colours stay exact.  The chords are a partition of
the toolpath's segments in program order: a group range is still one
contiguous slice.  Only when the runs alone outnumber the budget are evenly
spaced chords left out.

Examples
--------
>>> import numpy as np
>>> p = np.column_stack([np.arange(9.0), np.zeros(9), np.zeros(9)])  # 8 segments along X
>>> first, last = chords(p[:-1], p[1:], np.r_[np.zeros(6, int), 1, 1], stride=4)
>>> first.tolist(), last.tolist()  # two runs: segments 0-5 (in chords of 4 and 2), 6-7
([0, 4, 6], [3, 5, 7])
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

#: A run of segments ends where the path turns by more than this (degrees): corners stay corners.
CORNER_DEG = 45.0


def runs(start: np.ndarray, end: np.ndarray, key: "np.ndarray | Sequence[np.ndarray]") -> np.ndarray:
    """First segment of each run: where the key (n,), (n, k) or k columns (n,) changes, the path turns by
    more than :data:`CORNER_DEG` or a segment does not start at the one before's end."""
    n = start.shape[0]
    if n == 0:
        return np.zeros(0, np.int64)
    if isinstance(key, np.ndarray):
        same = key[1:] == key[:-1]
        joined = np.all(same, axis=1) if same.ndim == 2 else same
    else:  # column by column: no (n, k) copy of them
        joined = np.ones(n - 1, bool)
        for column in key:
            joined &= column[1:] == column[:-1]
    joined &= np.all(end[:-1] == start[1:], axis=1)
    d = end - start
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    # cos(turn) * |a| |b| = a . b: no division (zero-length segments then end no run)
    joined &= np.einsum("ij,ij->i", d[:-1], d[1:]) >= np.cos(np.radians(CORNER_DEG)) * length[:-1] * length[1:]
    return np.flatnonzero(np.r_[True, ~joined])


def chords(start: np.ndarray, end: np.ndarray, key: "np.ndarray | Sequence[np.ndarray]", stride: int) -> tuple[np.ndarray, np.ndarray]:
    """Each run of segments in chords of ``stride`` segments (its last chord shorter): first and last segment of each."""
    n = start.shape[0]
    run_first = runs(start, end, key)
    return _chords(run_first, n, stride)


def _chords(run_first: np.ndarray, n: int, stride: int) -> tuple[np.ndarray, np.ndarray]:
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    run_of = np.repeat(np.arange(run_first.size), np.diff(np.r_[run_first, n]))
    rel = np.arange(n) - run_first[run_of]
    first = np.flatnonzero(rel % stride == 0)
    return first, np.r_[first[1:], n] - 1


def overview(start: np.ndarray, end: np.ndarray, key: "np.ndarray | Sequence[np.ndarray]", budget: int) -> tuple[np.ndarray, np.ndarray, int]:
    """At most ``budget`` chords standing for the segments: first and last segment of each, and the stride.

    Every segment when they fit (stride 1); else the smallest stride whose
    chords fit (:func:`chords`); else, when the runs alone are more than the
    budget, one chord per run, evenly spaced ones of them (stride 0).
    """
    n = start.shape[0]
    if n <= budget:
        every = np.arange(n)
        return every, every.copy(), 1
    run_first = runs(start, end, key)
    length = np.diff(np.r_[run_first, n])
    if run_first.size > budget:
        first, last = run_first, np.r_[run_first[1:], n] - 1
        pick = np.linspace(0, first.size - 1, budget).round().astype(np.int64)
        return first[pick], last[pick], 0
    # the chord count falls as the stride grows: the smallest stride that fits, by bisection
    lo, hi = 1, int(length.max())
    while lo < hi:
        mid = (lo + hi) // 2
        if int(np.sum(-(-length // mid))) <= budget:
            hi = mid
        else:
            lo = mid + 1
    first, last = _chords(run_first, n, lo)
    return first, last, lo
