"""Optional compiled loops: Numba's ``njit`` when it is installed, the NumPy code otherwise.

gcodekit's compiled kernels (the scanner, the parser's rows, the emulator's
forward fill, the planner's loops, the widgets' raster) are plain Python
functions over NumPy arrays, each beside the NumPy code that does the same
without Numba; ``pip install gcodekit[fast]`` adds Numba.  Each kernel
module compiles its functions once, on first use, through
:func:`compile_loops`, and the machine code is cached on disk beside the
module, so later processes load it instead of compiling again.
"""

from __future__ import annotations

import importlib.util
import sys
from typing import Any, Callable


def compile_loops(*functions: Callable, **options: Any) -> tuple[Callable, ...] | None:
    """The ``functions`` compiled by Numba, in order, or None when Numba is not installed.

    Compiled in ``nopython`` mode, cached on disk, releasing the GIL while
    they run; ``options`` are further ``numba.njit`` options (the planner's
    ``error_model="numpy"``, say, for NaN and inf instead of an exception on
    a division by zero, as NumPy gives).
    """
    try:
        import numba
    except ImportError:
        return None
    jit = numba.njit(cache=True, nogil=True, **options)
    return tuple(jit(f) for f in functions)


def numba_installed() -> bool:
    """Whether Numba can be imported (looked up, not imported: the look-up costs nothing at start-up)."""
    return importlib.util.find_spec("numba") is not None


def numba_loaded() -> bool:
    """Whether Numba is imported already: then a kernel costs only its cached load, not Numba's import
    (0.5 s and about 120 MB), which small inputs are cheaper without."""
    return sys.modules.get("numba") is not None
