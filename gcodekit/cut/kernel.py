"""Outputs: the cutting loop compiled with Numba, when it is installed (``pip install 'gcodekit[cut]'``).

The same envelope as :func:`gcodekit.cut.sweep.envelope` (whose docstring
derives it), written as the plain loop the NumPy path vectorizes: for each
piece in program order, for each cell in its box, lower the cell's top to
the tool's envelope and count what that removed.  The NumPy path stays the
reference; the tests run both on the same programs.
"""

from __future__ import annotations

import functools
import math

import numpy as np

#: Shape codes of the compiled loop.
KIND_CODES = {"endmill": 0, "ballend": 1, "bullnose": 2, "vbit": 3, "drill": 3, "chamfer": 4}


@functools.lru_cache(maxsize=1)
def compiled():
    """The compiled loop, or None when Numba is not installed."""
    try:
        import numba
    except ImportError:
        return None

    jit = numba.njit(cache=True, nogil=True, fastmath=False)
    golden = (math.sqrt(5) - 1) / 2

    @jit
    def profile(kind, R, k, rc, flat, r):
        if r > R:
            r = R
        if kind == 0:
            return 0.0
        if kind == 1:
            return R - math.sqrt(max(R * R - r * r, 0.0))
        if kind == 2:
            d = max(r - (R - rc), 0.0)
            return rc - math.sqrt(max(rc * rc - d * d, 0.0))
        return max(r - flat, 0.0) * k

    @jit
    def best_w(kind, R, k, rc, flat, m, u2, rho, lo, hi):
        down_end = lo if m > 0 else hi
        if kind == 0:
            return down_end
        if kind == 1:
            return min(max(-m * rho / math.sqrt(1 + m * m), lo), hi)
        if kind == 3:
            if abs(m) >= k:
                return down_end
            return min(max(-m * math.sqrt(u2) / math.sqrt(k * k - m * m), lo), hi)
        a, b = lo, hi
        c, d = b - golden * (b - a), a + golden * (b - a)
        gc = m * c + profile(kind, R, k, rc, flat, math.sqrt(u2 + c * c))
        gd = m * d + profile(kind, R, k, rc, flat, math.sqrt(u2 + d * d))
        for _ in range(40):
            if gc < gd:
                b = d
            else:
                a = c
            c, d = b - golden * (b - a), a + golden * (b - a)
            gc = m * c + profile(kind, R, k, rc, flat, math.sqrt(u2 + c * c))
            gd = m * d + profile(kind, R, k, rc, flat, math.sqrt(u2 + d * d))
        best = 0.5 * (a + b)
        g_best = m * best + profile(kind, R, k, rc, flat, math.sqrt(u2 + best * best))
        for w in (lo, hi):
            g = m * w + profile(kind, R, k, rc, flat, math.sqrt(u2 + w * w))
            if g < g_best:
                best, g_best = w, g
        return best

    @jit
    def run(top, bottom, x0, y0, res, p0, p1, kind, R, k, rc, flat, eps, removed):
        ny, nx = top.shape
        for p in range(p0.shape[0]):
            ax, ay, az = p0[p, 0], p0[p, 1], p0[p, 2]
            dx, dy, dz = p1[p, 0] - ax, p1[p, 1] - ay, p1[p, 2] - az
            L = math.hypot(dx, dy)
            if L > 1e-12:
                ex, ey, m, z0 = dx / L, dy / L, dz / L, az
            else:
                ex, ey, m, z0, L = 1.0, 0.0, 0.0, min(az, az + dz), 0.0
            z_low = min(az, az + dz)
            i0 = max(int(math.ceil((min(ax, ax + dx) - R - x0) / res - 0.5)), 0)
            i1 = min(int(math.floor((max(ax, ax + dx) + R - x0) / res - 0.5)), nx - 1)
            j0 = max(int(math.ceil((min(ay, ay + dy) - R - y0) / res - 0.5)), 0)
            j1 = min(int(math.floor((max(ay, ay + dy) + R - y0) / res - 0.5)), ny - 1)
            total = 0.0
            for j in range(j0, j1 + 1):
                qy = y0 + (j + 0.5) * res - ay
                for i in range(i0, i1 + 1):
                    before = top[j, i]
                    floor = bottom[j, i]
                    if before <= floor or z_low >= before - eps:
                        continue
                    qx = x0 + (i + 0.5) * res - ax
                    a = qx * ex + qy * ey
                    u2 = max(qx * qx + qy * qy - a * a, 0.0)
                    rho2 = R * R - u2
                    if rho2 < 0:
                        continue
                    rho = math.sqrt(rho2)
                    lo, hi = max(-rho, -a), min(rho, L - a)
                    if lo > hi:
                        continue
                    w = best_w(kind, R, k, rc, flat, m, u2, rho, lo, hi)
                    value = z0 + m * (a + w) + profile(kind, R, k, rc, flat, math.sqrt(u2 + w * w))
                    if value < before - eps:
                        value = max(value, floor)
                        total += before - value
                        top[j, i] = value
            removed[p] = total * res * res

    return run


def shape_arguments(shape) -> tuple[int, float, float, float, float]:
    """``(kind code, R, cone slope k, corner radius, flat radius)`` of a ToolShape for the compiled loop."""
    k = 1.0 / math.tan(math.radians(shape.angle) / 2) if shape.kind in ("vbit", "drill", "chamfer") else 0.0
    flat = shape.tip_diameter / 2 if shape.kind == "chamfer" else 0.0
    return KIND_CODES[shape.kind], shape.radius, k, shape.corner_radius, flat


def sweep_compiled(run, stock, top: np.ndarray, p0: np.ndarray, p1: np.ndarray, shape, eps: float) -> np.ndarray:
    """Cut ``top`` in place with pieces ``p0 -> p1`` of one tool; the volume each removed, mm^3."""
    removed = np.zeros(len(p0))
    run(top, stock.bottom, float(stock.x0), float(stock.y0), float(stock.resolution),
        np.ascontiguousarray(p0, float), np.ascontiguousarray(p1, float), *shape_arguments(shape), eps, removed)
    return removed
