"""Outputs: the stock as a height field, the material of each grid cell between a bottom and a top.

The stock is sampled on a square grid of ``resolution`` mm in X and Y.  Each
cell holds the material of a vertical column through its centre, from
``bottom`` up to ``top`` (mm); a cell with ``top <= bottom`` holds none.  A
tool cutting from above lowers the tops; nothing it does can raise one.
A box, an upright cylinder, or any closed mesh (an STL) can be the stock; a
mesh with overhangs keeps only its outer vertical extent in each column
(the height field has no undercuts).

Examples
--------
>>> stock = Stock.box(0, 0, -10, 20, 10, 0, resolution=0.5)
>>> stock.shape, round(stock.volume(), 6)
((20, 40), 2000.0)
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError

#: Bytes each grid cell costs while cutting: top, bottom and the stock's first top (float64), and a
#: per-cell share of the cutting kernel's work arrays.
BYTES_PER_CELL = 40


def available_memory() -> int:
    """Memory the machine can still give, bytes (``MemAvailable``; the physical memory elsewhere)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 1 << 62


def check_grid(width: float, depth: float, resolution: float) -> tuple[int, int]:
    """Cells ``(ny, nx)`` of a ``width`` x ``depth`` mm grid; a clear error when it cannot fit in memory.

    Raises
    ------
    ConfigError
        A resolution that is not a positive number, a stock without area, or
        a grid that would need more memory than the machine has available.
    """
    if not (math.isfinite(resolution) and resolution > 0):
        raise ConfigError(f"the resolution must be a positive number of mm, not {resolution!r}")
    if not (math.isfinite(width) and math.isfinite(depth) and width > 0 and depth > 0):
        raise ConfigError(f"the stock must have a positive width and depth in X and Y, not {width!r} x {depth!r} mm")
    nx, ny = max(1, math.ceil(width / resolution - 1e-9)), max(1, math.ceil(depth / resolution - 1e-9))
    need, have = nx * ny * BYTES_PER_CELL, available_memory()
    if need > have:
        raise ConfigError(
            f"a {resolution:g} mm grid over {width:g} x {depth:g} mm is {nx:,} x {ny:,} cells and needs about "
            f"{need / 2**30:,.1f} GiB; this machine has {have / 2**30:,.1f} GiB available: give a coarser resolution")
    return ny, nx


@dataclass
class Stock:
    """Material as a height field: per cell, the column from ``bottom`` to ``top`` (mm).

    Parameters
    ----------
    x0, y0 : float
        The grid's lower-left corner, mm; cell ``(j, i)`` is centred at
        ``(x0 + (i + 0.5) * resolution, y0 + (j + 0.5) * resolution)``.
    resolution : float
        Cell size, mm.
    top, bottom : ndarray, shape (ny, nx)
        The column of material in each cell, mm (none where ``top <= bottom``).
    """

    x0: float
    y0: float
    resolution: float
    top: np.ndarray
    bottom: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """Cells ``(ny, nx)``."""
        return self.top.shape

    @property
    def cell_area(self) -> float:
        """Area of one cell, mm^2."""
        return self.resolution * self.resolution

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """X of each column and Y of each row of cells, mm."""
        ny, nx = self.shape
        return (self.x0 + (np.arange(nx) + 0.5) * self.resolution,
                self.y0 + (np.arange(ny) + 0.5) * self.resolution)

    def thickness(self, top: np.ndarray | None = None) -> np.ndarray:
        """Material in each cell's column, mm (of ``top``, default the stock's own)."""
        return np.maximum((self.top if top is None else top) - self.bottom, 0.0)

    def volume(self, top: np.ndarray | None = None) -> float:
        """Volume of material, mm^3 (with the tops ``top``, default the stock's own)."""
        return float(self.thickness(top).sum() * self.cell_area)

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        """``(x0, y0, z0, x1, y1, z1)`` of the grid and of the material in it, mm."""
        ny, nx = self.shape
        solid = self.top > self.bottom
        z0 = float(self.bottom[solid].min()) if solid.any() else 0.0
        z1 = float(self.top[solid].max()) if solid.any() else 0.0
        return (self.x0, self.y0, z0, self.x0 + nx * self.resolution, self.y0 + ny * self.resolution, z1)

    def copy(self) -> "Stock":
        return Stock(self.x0, self.y0, self.resolution, self.top.copy(), self.bottom.copy())

    @classmethod
    def box(cls, x0: float, y0: float, z0: float, x1: float, y1: float, z1: float, *,
            resolution: float = 0.1) -> "Stock":
        """A rectangular block from corner ``(x0, y0, z0)`` to ``(x1, y1, z1)``, mm.

        Raises
        ------
        ConfigError
            Corners that do not span a box, or a grid too large for memory.
        """
        values = (x0, y0, z0, x1, y1, z1)
        if not all(math.isfinite(v) for v in values) or not (x1 > x0 and y1 > y0 and z1 > z0):
            raise ConfigError(f"a stock box needs X0 < X1, Y0 < Y1 and Z0 < Z1, not {','.join(f'{v:g}' for v in values)}")
        ny, nx = check_grid(x1 - x0, y1 - y0, resolution)
        return cls(float(x0), float(y0), float(resolution), np.full((ny, nx), float(z1)), np.full((ny, nx), float(z0)))

    @classmethod
    def cylinder(cls, x: float, y: float, radius: float, z0: float, z1: float, *,
                 resolution: float = 0.1) -> "Stock":
        """An upright round bar: axis along Z through ``(x, y)``, from ``z0`` to ``z1``, mm.

        Cells whose centre lies outside the circle hold no material.
        """
        if not (math.isfinite(radius) and radius > 0 and math.isfinite(z0) and math.isfinite(z1) and z1 > z0):
            raise ConfigError(f"a stock cylinder needs a positive radius and Z0 < Z1, not r={radius!r}, "
                              f"z {z0!r}..{z1!r}")
        ny, nx = check_grid(2 * radius, 2 * radius, resolution)
        stock = cls(x - radius, y - radius, float(resolution), np.full((ny, nx), float(z1)),
                    np.full((ny, nx), float(z0)))
        cx, cy = stock.centres()
        outside = np.hypot(cx[None, :] - x, cy[:, None] - y) > radius
        stock.top[outside] = z0
        return stock

    @classmethod
    def from_mesh(cls, mesh, *, resolution: float = 0.1) -> "Stock":
        """The vertical extent of a closed triangle mesh (a PyVista mesh or an STL/PLY/VTP path), per cell.

        Each cell's column runs from the lowest to the highest point where
        the vertical line through its centre meets the surface.
        """
        from ..export.vtk import import_pyvista

        pv = import_pyvista()
        if isinstance(mesh, (str, os.PathLike)):
            if not os.path.isfile(mesh):
                raise FileNotFoundError(f"no such stock file: {mesh}")
            try:
                mesh = pv.read(mesh)
            except (ValueError, OSError, RuntimeError) as exc:
                raise ConfigError(f"{mesh}: cannot be read as a mesh: {exc}") from None
        surface = mesh.extract_surface(algorithm="dataset_surface").triangulate()
        if surface.n_cells == 0:
            raise ConfigError("the stock mesh has no faces")
        tri = surface.points[surface.faces.reshape(-1, 4)[:, 1:]].astype(float)  # (n, 3 corners, xyz)
        lo, hi = surface.points.min(axis=0), surface.points.max(axis=0)
        ny, nx = check_grid(hi[0] - lo[0], hi[1] - lo[1], resolution)
        stock = cls(float(lo[0]), float(lo[1]), float(resolution), np.full((ny, nx), -np.inf),
                    np.full((ny, nx), np.inf))
        _rasterize(stock, tri)
        empty = ~np.isfinite(stock.top)
        stock.top[empty] = stock.bottom[empty] = lo[2]
        return stock


def box_cells(stock: Stock, x_lo: np.ndarray, x_hi: np.ndarray, y_lo: np.ndarray, y_hi: np.ndarray):
    """The cells whose centres lie in each of several rectangles, as flat arrays.

    Returns
    -------
    owner : ndarray of int
        Which rectangle each cell belongs to (a cell in two rectangles
        appears twice), in rectangle order.
    i, j : ndarray of int
        The cell's column and row.
    """
    ny, nx = stock.shape
    res = stock.resolution
    i0 = np.clip(np.ceil((x_lo - stock.x0) / res - 0.5), 0, nx).astype(np.int64)
    i1 = np.clip(np.floor((x_hi - stock.x0) / res - 0.5), -1, nx - 1).astype(np.int64)
    j0 = np.clip(np.ceil((y_lo - stock.y0) / res - 0.5), 0, ny).astype(np.int64)
    j1 = np.clip(np.floor((y_hi - stock.y0) / res - 0.5), -1, ny - 1).astype(np.int64)
    ni, nj = np.maximum(i1 - i0 + 1, 0), np.maximum(j1 - j0 + 1, 0)
    count = ni * nj
    owner = np.repeat(np.arange(count.size), count)
    local = np.arange(owner.size) - np.repeat(np.cumsum(count) - count, count)
    ni_o = ni[owner]
    return owner, i0[owner] + local % np.maximum(ni_o, 1), j0[owner] + local // np.maximum(ni_o, 1)


def box_counts(stock: Stock, x_lo, x_hi, y_lo, y_hi) -> np.ndarray:
    """How many cells :func:`box_cells` gives for each rectangle (to size batches before making them)."""
    ny, nx = stock.shape
    res = stock.resolution
    ni = np.clip(np.floor((x_hi - stock.x0) / res - 0.5), -1, nx - 1) - np.clip(
        np.ceil((x_lo - stock.x0) / res - 0.5), 0, nx) + 1
    nj = np.clip(np.floor((y_hi - stock.y0) / res - 0.5), -1, ny - 1) - np.clip(
        np.ceil((y_lo - stock.y0) / res - 0.5), 0, ny) + 1
    return (np.maximum(ni, 0) * np.maximum(nj, 0)).astype(np.int64)


def _rasterize(stock: Stock, tri: np.ndarray, batch_cells: int = 2_000_000) -> None:
    """Lower ``stock.bottom`` and raise ``stock.top`` to every triangle's height over each cell centre."""
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    counts = box_counts(stock, lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1])
    start = 0
    while start < len(tri):
        stop = start + max(1, int(np.searchsorted(np.cumsum(counts[start:]), batch_cells)))
        part = tri[start:stop]
        owner, i, j = box_cells(stock, lo[start:stop, 0], hi[start:stop, 0], lo[start:stop, 1], hi[start:stop, 1])
        start = stop
        if owner.size == 0:
            continue
        px = stock.x0 + (i + 0.5) * stock.resolution
        py = stock.y0 + (j + 0.5) * stock.resolution
        a, b, c = part[owner, 0], part[owner, 1], part[owner, 2]
        # barycentric coordinates of the cell centre in the triangle's XY projection
        det = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
        ok = np.abs(det) > 1e-15
        det = np.where(ok, det, 1.0)
        la = ((b[:, 1] - c[:, 1]) * (px - c[:, 0]) + (c[:, 0] - b[:, 0]) * (py - c[:, 1])) / det
        lb = ((c[:, 1] - a[:, 1]) * (px - c[:, 0]) + (a[:, 0] - c[:, 0]) * (py - c[:, 1])) / det
        lc = 1.0 - la - lb
        eps = -1e-12
        inside = ok & (la >= eps) & (lb >= eps) & (lc >= eps)
        z = la * a[:, 2] + lb * b[:, 2] + lc * c[:, 2]
        np.maximum.at(stock.top, (j[inside], i[inside]), z[inside])
        np.minimum.at(stock.bottom, (j[inside], i[inside]), z[inside])
