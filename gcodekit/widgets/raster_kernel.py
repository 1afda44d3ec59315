"""Widgets stage, compiled: the pixel loop of :func:`gcodekit.widgets.picture.raster_toolpath`, with Numba.

The NumPy raster samples every segment at every pixel it crosses as arrays
(a sample's segment by ``np.repeat``, the nearest per pixel by
``np.maximum.at``, the colours by a masked assignment): millions of samples
for a large program's picture, each pass an array as long as them.  Here the
same samples, in the same order and with the same arithmetic, are one loop
that keeps a sample when it is at least as near as the pixel's nearest so
far, compiled when Numba is installed (``pip install 'gcodekit[fast]'``).
The last sample of the nearest ones wins in both, so the pictures are the
same to the bit; the NumPy path stays the reference and the fallback, and
the tests draw with both.
"""

from __future__ import annotations

import functools

import numpy as np

from ..jit import compile_loops, numba_loaded

__all__ = ["COMPILED_FROM", "compiled", "engine"]

#: Segments from which the compiled loop is used even when Numba is not loaded yet (its import costs more
#: than the NumPy raster of fewer segments saves).
COMPILED_FROM = 200_000


@functools.lru_cache(maxsize=1)
def compiled():
    """The compiled loop, or None when Numba is not installed (compiled on first use, cached on disk)."""
    loops = compile_loops(draw_samples)
    return loops and loops[0]


def engine(n_segments: int):
    """The compiled loop for this many segments, or None for NumPy: compiled when Numba is loaded already
    (reading a large program loads it) or the picture is large enough to pay for loading it."""
    if not numba_loaded() and n_segments < COMPILED_FROM:
        return None
    return compiled()


def draw_samples(cols0: np.ndarray, cols1: np.ndarray, rows0: np.ndarray, rows1: np.ndarray, near0: np.ndarray,
                 near1: np.ndarray, count: np.ndarray, rgb: np.ndarray, width: int, height: int, image: np.ndarray,
                 depth: np.ndarray) -> None:
    """Sample segment ``s`` at ``count[s]`` evenly spaced points from end 0 to end 1 (pixel column, row from
    the top, nearness); keep in ``image`` (pixels, 3) the colour of the nearest sample per pixel (``depth``)."""
    for s in range(count.size):
        n = count[s]
        c0, r0, z0 = cols0[s], rows0[s], near0[s]
        dc, dr, dz = cols1[s] - c0, rows1[s] - r0, near1[s] - z0
        for i in range(n):
            t = i / (n - 1)
            x = np.int64(np.floor(c0 + t * dc))
            y = np.int64(np.floor(r0 + t * dr))
            if x < 0 or x >= width or y < 0 or y >= height:
                continue
            z = z0 + t * dz
            p = y * width + x
            if z >= depth[p]:
                depth[p] = z
                image[p, 0] = rgb[s, 0]
                image[p, 1] = rgb[s, 1]
                image[p, 2] = rgb[s, 2]
