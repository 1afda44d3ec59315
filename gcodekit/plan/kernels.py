"""Plan stage, compiled: the planners' hot loops written as loops, with Numba.

The NumPy code of :mod:`.scans`, :mod:`.marlin` and :mod:`.klipper` does
each step in passes over whole arrays; here the same arithmetic, in the same
order, runs as one loop over the moves, compiled when Numba is installed
(``pip install 'gcodekit[fast]'``).  It makes no temporaries, so it is
faster and leaner.  The NumPy code stays the reference: the tests plan the
same programs with both engines and require identical arrays, bit for bit.

``np.minimum(a, b)`` is ``a if a < b or a != a else b`` (NaN wins, ``b`` on
a tie, so -0.0 against 0.0 picks ``b``); the loops write it so.

:func:`engine` chooses: the compiled loops for programs of at least
:data:`COMPILED_AFTER_MOVES` moves when Numba is installed (smaller ones
would spend more loading Numba than they save), NumPy otherwise;
:func:`using` forces one.
"""

from __future__ import annotations

import contextlib
import functools
from types import SimpleNamespace
from typing import Iterator

import numpy as np

from ..errors import MissingDependencyError, check_choice

__all__ = ["COMPILED_AFTER_MOVES", "ENGINES", "compiled", "engine", "using"]

#: Programs with at least this many moves are planned by the compiled loops when Numba is installed.
COMPILED_AFTER_MOVES = 300_000
ENGINES = ("auto", "numba", "numpy")
_chosen = "auto"


@functools.lru_cache(maxsize=1)
def compiled() -> SimpleNamespace | None:
    """The compiled loops, or None when Numba is not installed (compiled on first use, cached on disk)."""
    try:
        import numba
    except ImportError:
        return None
    jit = numba.njit(cache=True, nogil=True)
    return SimpleNamespace(forward_min=jit(_forward_min), backward_min=jit(_backward_min))


def engine(n_moves: int) -> SimpleNamespace | None:
    """The compiled loops to plan ``n_moves`` moves with, or None for the NumPy code."""
    if _chosen == "numpy" or (_chosen == "auto" and n_moves < COMPILED_AFTER_MOVES):
        return None
    kernels = compiled()
    if kernels is None and _chosen == "numba":
        raise MissingDependencyError("the compiled planner needs Numba: pip install 'gcodekit[fast]'")
    return kernels


@contextlib.contextmanager
def using(name: str) -> Iterator[None]:
    """Plan with engine ``name`` inside the block: ``"numba"``, ``"numpy"`` or ``"auto"`` (the default).

    Examples
    --------
    >>> import gcodekit
    >>> with using("numpy"):
    ...     op = gcodekit.gcode_to_operation("G1 X10 E1 F600\\n", "marlin")
    """
    global _chosen
    check_choice("engine", name, ENGINES)
    previous, _chosen = _chosen, name
    try:
        yield
    finally:
        _chosen = previous


def _forward_min(cap, inc, first, block):
    """:func:`.scans.forward_min` (see it for the rule), block by block with its very roundings."""
    n = cap.size
    out = np.empty(n)
    carry = first
    for start in range(0, n, block):
        stop = min(start + block, n)
        s = 0.0  # increments from the block's first move up to move k (exclusive): np.cumsum's sums
        acc = 0.0  # running minimum of cap - s
        last = -1  # the last move whose cap binds
        base = 0.0  # its cap - s
        s_prev = 0.0
        for k in range(start, stop):
            if k == start:
                bound = cap[k] - s
                if not (bound < carry or bound != bound):
                    bound = carry
                acc = bound
                reach = carry
            else:
                s = inc[start] if k == start + 1 else s + inc[k - 1]
                reach = (acc + s_prev) + inc[k - 1]
                bound = cap[k] - s
                if not (acc < bound or acc != acc):
                    acc = bound
            s_prev = s
            if cap[k] <= reach:
                last = k
                base = cap[k] - s
                out[k] = cap[k]
            elif last >= 0:
                out[k] = base + s
            else:
                out[k] = carry + s
        carry = out[stop - 1] + inc[stop - 1]
    return out


def _backward_min(cap, inc, last, block):
    """:func:`.scans.backward_min` (see it for the rule), block by block with its very roundings."""
    n = cap.size
    out = np.empty(n)
    carry = last
    for stop in range(n, 0, -block):
        start = max(stop - block, 0)
        s = 0.0  # increments from the block's end back to move k (inclusive): np.cumsum's sums
        acc = 0.0
        binding = False  # a cap has bound since the block's end
        base = 0.0
        seed = 0.0
        for k in range(stop - 1, start - 1, -1):
            if k == stop - 1:
                s = inc[k]
                bound = cap[k] - s
                if carry < bound:  # Python's min(bound, carry)
                    bound = carry
                acc = bound
                reach = carry + inc[k]
                seed = (carry + inc[k]) - s
            else:
                reach = (acc + s) + inc[k]
                s = s + inc[k]
                bound = cap[k] - s
                if not (acc < bound or acc != acc):
                    acc = bound
            if cap[k] <= reach:
                binding = True
                base = cap[k] - s
                out[k] = cap[k]
            elif binding:
                out[k] = base + s
            else:
                out[k] = seed + s
        carry = out[start]
    return out
