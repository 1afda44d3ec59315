"""Outputs: sweep tools along straight pieces of path and lower the stock's height field.

Where a tool moving in a straight line from ``p0`` to ``p1`` leaves the
material over a point ``q`` is the lowest point of its lower surface over
``q`` during the move:

    env(q) = min over s of  z(s) + h(|q - xy(s)|)

with ``h`` the tool's profile (:meth:`ToolShape.height_at`, defined up to
the radius R).  Write ``a`` for the distance of ``q``'s projection along the
move's XY direction, ``u`` for its distance from that line, ``w = s - a``,
and ``m`` for the move's slope dz/ds.  Then ``z(s) + h(...) = z0 + m (a + w)
+ h(sqrt(u^2 + w^2))``: a convex function of ``w`` on the interval where
the tool reaches ``q`` (``|w| <= sqrt(R^2 - u^2)``, ``0 <= a + w <= L``),
since ``h`` is convex and increasing.  Its minimum is in closed form for
the flat end (an end of the interval), the ball end (``w = -m rho /
sqrt(1 + m^2)``, ``rho^2 = R^2 - u^2``) and the cone of V-bits and drills
(``w = -m u / sqrt(k^2 - m^2)``, ``k`` the cone's slope); the bull nose and
the chamfer mill take a golden-section search.  Each cell centre gets this
value exactly (to rounding): the height field's only error is its sampling.

Every (piece, cell) pair of a batch is computed at once; the pieces of a
batch then apply in program order per cell -- a running minimum within each
cell -- so that each piece's removed volume counts only what the pieces
before it left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import MissingDependencyError, check_choice
from ..tool_shapes import ToolShape
from .kernel import compiled, sweep_compiled
from .stock import Stock, box_cells, box_counts

#: (piece, cell) pairs computed at once: about 150 bytes each while a batch is worked on.
BATCH_PAIRS = 1_000_000
_GOLDEN = (math.sqrt(5) - 1) / 2
#: A tool whose envelope is this close to a top (mm) leaves it as it is (rounding, not cutting).
HEIGHT_EPS = 1e-9


@dataclass
class Pieces:
    """Straight pieces of tool path, in program order.

    ``p0``, ``p1`` are the tool tip's start and end, shape (n, 3), mm;
    ``owner`` the waypoint each piece belongs to; ``tool`` the tool number.
    """

    p0: np.ndarray
    p1: np.ndarray
    owner: np.ndarray
    tool: np.ndarray

    def __len__(self) -> int:
        return len(self.owner)

    def take(self, rows) -> "Pieces":
        return Pieces(self.p0[rows], self.p1[rows], self.owner[rows], self.tool[rows])


def split_long(pieces: Pieces, max_length: np.ndarray) -> Pieces:
    """Cut each piece into equal parts at most ``max_length`` (per piece) long in XY.

    A straight move's envelope is the union of its parts' envelopes; short
    parts keep the cells each one is checked against near its path.
    """
    d = np.hypot(*(pieces.p1[:, :2] - pieces.p0[:, :2]).T)
    parts = np.maximum(np.ceil(d / max_length), 1).astype(np.int64)
    if np.all(parts == 1):
        return pieces
    which = np.repeat(np.arange(len(pieces)), parts)
    k = np.arange(which.size) - np.repeat(np.cumsum(parts) - parts, parts)
    t0, t1 = (k / parts[which])[:, None], ((k + 1) / parts[which])[:, None]
    step = pieces.p1[which] - pieces.p0[which]
    return Pieces(pieces.p0[which] + t0 * step, pieces.p0[which] + t1 * step, pieces.owner[which], pieces.tool[which])


def envelope(shape: ToolShape, qx: np.ndarray, qy: np.ndarray, p0: np.ndarray, p1: np.ndarray):
    """Lowest height of the tool's lower surface over points ``(qx, qy)`` as its tip moves ``p0`` -> ``p1``.

    ``qx``, ``qy`` are relative to ``p0``'s XY; ``p0``, ``p1`` are (n, 3), one
    per point.  Returns the heights (mm; +inf where the tool never reaches
    the point).
    """
    R = shape.radius
    dx, dy, dz = (p1 - p0).T
    L = np.hypot(dx, dy)
    moving = L > 1e-12
    Ls = np.where(moving, L, 1.0)
    ex, ey = np.where(moving, dx / Ls, 1.0), np.where(moving, dy / Ls, 0.0)
    m = np.where(moving, dz / Ls, 0.0)
    z0 = np.where(moving, p0[:, 2], np.minimum(p0[:, 2], p1[:, 2]))  # a plunge: its lowest point
    L = np.where(moving, L, 0.0)
    a = qx * ex + qy * ey
    u2 = np.maximum(qx * qx + qy * qy - a * a, 0.0)
    rho2 = R * R - u2
    rho = np.sqrt(np.maximum(rho2, 0.0))
    lo, hi = np.maximum(-rho, -a), np.minimum(rho, L - a)
    reach = (rho2 >= 0) & (lo <= hi)
    hi = np.maximum(hi, lo)
    down_end = np.where(m > 0, lo, hi)  # where a profile flat in w is lowest
    kind = shape.kind
    if kind == "endmill":
        w = down_end
    elif kind == "ballend":
        w = np.clip(-m * rho / np.sqrt(1 + m * m), lo, hi)
    elif kind in ("vbit", "drill"):
        k = 1.0 / math.tan(math.radians(shape.angle) / 2)
        steep = np.abs(m) >= k
        with np.errstate(invalid="ignore", divide="ignore"):
            w_stat = -m * np.sqrt(u2) / np.sqrt(np.where(steep, 1.0, k * k - m * m))
        w = np.where(steep, down_end, np.clip(w_stat, lo, hi))
    else:
        w = _golden(lambda w: m * w + _profile(shape, np.sqrt(u2 + w * w)), lo, hi)
    r = np.minimum(np.sqrt(u2 + w * w), R)
    value = z0 + m * (a + w) + _profile(shape, r)
    return np.where(reach, value, np.inf)


def _profile(shape: ToolShape, r: np.ndarray) -> np.ndarray:
    return shape.height_at(np.minimum(r, shape.radius))


def _golden(g, lo: np.ndarray, hi: np.ndarray, iterations: int = 40) -> np.ndarray:
    """Minimise the convex ``g`` on ``[lo, hi]`` elementwise (golden-section search)."""
    a, b = lo.copy(), hi.copy()
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    gc, gd = g(c), g(d)
    for _ in range(iterations):
        left = gc < gd
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        c_new, d_new = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
        c, d = c_new, d_new
        gc, gd = g(c), g(d)
    best = (a + b) / 2
    # the ends themselves (a linear g's minimum is there exactly)
    candidates = np.stack([best, lo, hi])
    values = np.stack([g(best), g(lo), g(hi)])
    return candidates[np.argmin(values, axis=0), np.arange(lo.size)]


ENGINES = ("auto", "numba", "numpy")


def sweep(stock: Stock, top: np.ndarray, pieces: Pieces, shapes: dict[int, ToolShape], *,
          engine: str = "auto") -> np.ndarray:
    """Cut ``top`` (the stock's tops, changed in place) with ``pieces``; the volume each piece removed, mm^3.

    Parameters
    ----------
    stock : Stock
        The grid and the material's bottoms.
    top : ndarray, shape (ny, nx)
        The current tops, lowered in place.
    pieces : Pieces
    shapes : dict of int to ToolShape
        The shape of every tool number in ``pieces``.
    engine : {"auto", "numba", "numpy"}, default: "auto"
        The compiled loop of :mod:`gcodekit.cut.kernel` when Numba is
        installed ("auto"), or the vectorized NumPy path (the reference).
    """
    check_choice("engine", engine, ENGINES)
    removed = np.zeros(len(pieces))
    if len(pieces) == 0:
        return removed
    run = compiled() if engine != "numpy" else None
    if engine == "numba" and run is None:
        raise MissingDependencyError("the compiled cutting loop needs Numba: pip install 'gcodekit[cut]'")
    if run is not None:
        change = np.flatnonzero(np.diff(pieces.tool)) + 1
        for lo, hi in zip(np.r_[0, change], np.r_[change, len(pieces)]):
            removed[lo:hi] = sweep_compiled(run, stock, top, pieces.p0[lo:hi], pieces.p1[lo:hi],
                                            shapes[int(pieces.tool[lo])], HEIGHT_EPS)
        return removed
    radius = np.array([shapes[t].radius for t in pieces.tool.tolist()]) if len(shapes) > 1 else np.full(
        len(pieces), next(iter(shapes.values())).radius)
    x_lo = np.minimum(pieces.p0[:, 0], pieces.p1[:, 0]) - radius
    x_hi = np.maximum(pieces.p0[:, 0], pieces.p1[:, 0]) + radius
    y_lo = np.minimum(pieces.p0[:, 1], pieces.p1[:, 1]) - radius
    y_hi = np.maximum(pieces.p0[:, 1], pieces.p1[:, 1]) + radius
    # pieces that stay above every top, or miss the grid, cannot cut
    live = np.minimum(pieces.p0[:, 2], pieces.p1[:, 2]) < float(top.max(initial=-np.inf)) - HEIGHT_EPS
    counts = np.where(live, box_counts(stock, x_lo, x_hi, y_lo, y_hi), 0)
    candidates = np.flatnonzero(counts)
    if candidates.size == 0:
        return removed
    # batches of whole pieces of one tool, each at most BATCH_PAIRS pairs (a larger piece alone)
    tool = pieces.tool[candidates]
    cum = np.cumsum(counts[candidates])
    start = 0
    while start < candidates.size:
        limit = (cum[start - 1] if start else 0) + BATCH_PAIRS
        stop = max(start + 1, int(np.searchsorted(cum, limit, side="right")))
        change = np.flatnonzero(tool[start:stop] != tool[start])
        if change.size:
            stop = start + int(change[0])
        rows = candidates[start:stop]
        removed[rows] = _cut_batch(stock, top, pieces.take(rows), shapes[int(tool[start])],
                                   x_lo[rows], x_hi[rows], y_lo[rows], y_hi[rows])
        start = stop
    return removed


def _cut_batch(stock: Stock, top: np.ndarray, pieces: Pieces, shape: ToolShape, x_lo, x_hi, y_lo, y_hi) -> np.ndarray:
    owner, i, j = box_cells(stock, x_lo, x_hi, y_lo, y_hi)
    nx = stock.shape[1]
    cell = j * nx + i
    flat_top, flat_bottom = top.reshape(-1), stock.bottom.reshape(-1)
    res = stock.resolution
    p0, p1 = pieces.p0[owner], pieces.p1[owner]
    qx = stock.x0 + (i + 0.5) * res - p0[:, 0]
    qy = stock.y0 + (j + 0.5) * res - p0[:, 1]
    value = envelope(shape, qx, qy, p0, p1)
    floor = flat_bottom[cell]
    before_all = flat_top[cell]
    cuts = value < before_all - HEIGHT_EPS
    cuts &= before_all > floor  # a cell with no material left cannot lose any
    if not cuts.any():
        return np.zeros(len(pieces))
    owner, cell, floor = owner[cuts], cell[cuts], floor[cuts]
    value = np.maximum(value[cuts], floor)  # nothing below the stock's bottom to remove
    # Program order within each cell: a stable sort by cell keeps the pieces' order.  The loop
    #   for each pair in order: removed[piece] += max(top[cell] - value, 0); top[cell] = min(top[cell], value)
    # is, per cell, a running minimum: top before a pair = min(first top, values of the pairs before it).
    order = np.argsort(cell, kind="stable")
    owner, cell, value = owner[order], cell[order], value[order]
    first = np.r_[True, cell[1:] != cell[:-1]]
    group = np.cumsum(first) - 1
    # one minimum.accumulate over all cells: shift each cell's values below every earlier cell's
    base = value.min()
    span = float(max(flat_top[cell].max() - base, value.max() - base)) + 1.0
    shifted = (value - base) - group * span
    running = np.minimum.accumulate(shifted) + group * span + base
    start_top = flat_top[cell]
    before = np.where(first, start_top, np.minimum(start_top, np.r_[np.inf, running[:-1]]))
    removed_pair = np.maximum(before - value, 0.0) * stock.cell_area
    last = np.r_[cell[1:] != cell[:-1], True]
    flat_top[cell[last]] = np.minimum(start_top[last], running[last])
    return np.bincount(owner, weights=removed_pair, minlength=len(pieces))
