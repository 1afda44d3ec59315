"""Emulate stage: forward fill, the modal rule of word columns (a value given stays in force until the next).

Absolute targets, the feed, the extruder position and the spindle speed of a
run of blocks are each the last word given at or before the row.  NumPy
does it in six passes (a running maximum of the given rows' indices, then a
gather); the same loop compiled with Numba is one pass, taken for long
columns once Numba is loaded (the reader loads it for large programs).
Both copy the words themselves, so they agree to the bit; the tests
compare them.
"""

from __future__ import annotations

import functools

import numpy as np

from ..jit import compile_loops, numba_loaded

__all__ = ["forward_fill", "forward_fill_numpy", "compiled", "COMPILED_FROM"]

#: Columns shorter than this are filled by NumPy (the compiled call's own cost is about a microsecond)
COMPILED_FROM = 2048


@functools.lru_cache(maxsize=1)
def compiled():
    """The compiled loop, or None when Numba is not installed (compiled on first use, cached on disk)."""
    loops = compile_loops(_fill)
    return loops and loops[0]


def forward_fill(values: np.ndarray, initial: float) -> np.ndarray:
    """Each NaN of the float column ``values`` replaced by the last number before it (``initial`` at the start)."""
    if values.size >= COMPILED_FROM and numba_loaded():
        kernel = compiled()
        if kernel is not None:
            return kernel(values, float(initial))
    return forward_fill_numpy(values, initial)


def forward_fill_numpy(values: np.ndarray, initial: float) -> np.ndarray:
    """:func:`forward_fill` by NumPy passes (the reference)."""
    idx = np.where(np.isnan(values), -1, np.arange(values.size))
    np.maximum.accumulate(idx, out=idx)
    return np.where(idx >= 0, values[np.maximum(idx, 0)], initial)


def _fill(values, initial):
    out = np.empty(values.size, np.float64)
    last = initial
    for i in range(values.size):
        v = values[i]
        if not np.isnan(v):
            last = v
        out[i] = last
    return out
