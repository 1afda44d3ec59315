"""Outputs: what a cut made: volumes, removal per move, air cuts, rapids into stock, the part's mesh and picture.

Examples
--------
::

    result = gcodekit.cut.cut(op, tools=gcodekit.cut.ToolLibrary.read("TOOLS.toml"))
    result.removed_mm3, result.remaining_mm3, result.air_cut_s
    result.columns()            # per waypoint: removed volume and removal rate
    result.save("part.stl")     # or .vtp
    result.picture("part.png")
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import Diagnostic
from ..tool_shapes import ToolShape
from .path import ARC_CCW, ARC_CW, FEED, RAPID
from .stock import Stock

if TYPE_CHECKING:
    import pandas as pd
    import pyvista as pv

#: Depth (mm) over one cell below which a move counts as cutting nothing (rounding, not material).
CUT_DEPTH_EPS = 1e-4
#: Cells per side at most in pictures and the live view (block minima of the finer grid).
PICTURE_CELLS = 320


@dataclass
class CutResult:
    """The stock after a cut and what each move removed.

    Attributes
    ----------
    stock : Stock
        The stock before the cut.
    top : ndarray, shape (ny, nx)
        The tops after the cut, mm.
    removed : ndarray
        Volume each waypoint's move removed, mm^3 (0 for moves not cut yet).
    shapes : dict of int to ToolShape
        The shape each tool number was cut with.
    notes : list of Diagnostic
        What the cut has to say (tools without a shape, rotary moves, a stock
        the program never reaches), then the rapids into stock.
    cut_through : int
        The last waypoint cut (-1 before the first).
    """

    op: Any
    stock: Stock
    top: np.ndarray
    removed: np.ndarray
    shapes: dict[int, ToolShape]
    notes: list[Diagnostic]
    cut_through: int
    time: np.ndarray
    motion: np.ndarray
    lines: np.ndarray
    _mesh_cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        threshold = CUT_DEPTH_EPS * self.stock.cell_area
        self.cutting = self.removed > threshold
        rapid_cuts = np.flatnonzero(self.cutting & (self.motion == RAPID))
        for row in rapid_cuts[:100]:
            line = int(self.lines[row])
            file, line = self.op.diagnostics.elsewhere.get(line, (self.op.file, line))
            self.notes.append(Diagnostic(file, line, 1, "warning",
                                         f"rapid move cuts the stock: {self.removed[row]:.4g} mm^3 removed at "
                                         "rapid speed"))
        if rapid_cuts.size > 100:
            self.notes.append(Diagnostic(self.op.file, 0, 0, "warning",
                                         f"{rapid_cuts.size - 100} more rapid moves cut the stock"))
        self._rapid_rows = rapid_cuts
        if self.cut_through >= 0 and self.removed_mm3 <= threshold and not any(
                word in d.message for d in self.notes for word in ("never reaches", "no feed moves")):
            self.notes.append(Diagnostic(self.op.file, 0, 0, "warning", "the program removes no material from "
                                         "the stock (its tools never go below the stock's top where it is)"))

    # -- numbers ----------------------------------------------------------------------------

    @property
    def stock_mm3(self) -> float:
        """Volume of the stock before the cut, mm^3."""
        return self.stock.volume()

    @property
    def remaining_mm3(self) -> float:
        """Volume of the part after the cut, mm^3."""
        return self.stock.volume(self.top)

    @property
    def removed_mm3(self) -> float:
        """Volume the cut removed, mm^3 (the stock's less the part's)."""
        return self.stock_mm3 - self.remaining_mm3

    @property
    def removal_rate(self) -> np.ndarray:
        """Material removal rate of each waypoint's move, mm^3/min (0 where it takes no time)."""
        minutes = self.time / 60.0
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(minutes > 0, self.removed / np.where(minutes > 0, minutes, 1.0), 0.0)

    @property
    def air_cuts(self) -> np.ndarray:
        """Waypoints of feed moves (G1, G2, G3) that were cut and removed nothing."""
        feed = (self.motion == FEED) | (self.motion == ARC_CW) | (self.motion == ARC_CCW)
        feed[self.cut_through + 1:] = False
        return np.flatnonzero(feed & ~self.cutting)

    @property
    def air_cut_s(self) -> float:
        """Time the air cuts take, s."""
        return float(self.time[self.air_cuts].sum())

    @property
    def rapid_collisions(self) -> list[dict[str, float]]:
        """Rapid moves that cut the stock: ``{"line", "removed_mm3"}`` each."""
        return [{"line": int(self.lines[r]), "removed_mm3": float(self.removed[r])} for r in self._rapid_rows]

    def summary(self) -> dict[str, Any]:
        """The record ``gcodekit cut --json`` prints."""
        x0, y0, z0, x1, y1, z1 = self.stock.bounds()
        return {"file": self.op.file, "stock_mm3": self.stock_mm3, "removed_mm3": self.removed_mm3,
                "remaining_mm3": self.remaining_mm3, "air_cut_s": self.air_cut_s,
                "air_cuts": int(self.air_cuts.size), "rapid_collisions": self.rapid_collisions,
                "stock": [x0, y0, z0, x1, y1, z1], "resolution_mm": self.stock.resolution,
                "tools": {str(n): s.as_dict() for n, s in sorted(self.shapes.items())},
                "diagnostics": [str(d) for d in self.notes]}

    def columns(self) -> "pd.DataFrame":
        """Per waypoint: ``line``, ``motion``, ``removed_volume`` (mm^3), ``removal_rate`` (mm^3/min), ``air_cut``."""
        import pandas as pd

        air = np.zeros(len(self.removed), bool)
        air[self.air_cuts] = True
        return pd.DataFrame({"line": self.lines, "motion": self.motion, "removed_volume": self.removed,
                             "removal_rate": self.removal_rate, "air_cut": air})

    # -- the part as a mesh -----------------------------------------------------------------

    def mesh(self, max_cells: int | None = None) -> "pv.PolyData":
        """The machined part as a closed surface (a PyVista PolyData), with the cut depth as ``depth`` (mm).

        The surface passes through the cell centres' heights.  ``max_cells``
        per side coarsens the grid for pictures (each coarse cell keeps the
        lowest top of the cells it covers, so narrow cuts stay visible).
        """
        return part_mesh(self.stock, self.top, max_cells)

    def save(self, path: str | os.PathLike) -> None:
        """Write the part's mesh to ``path`` (.vtp, .stl, .ply, .vtk: by the ending)."""
        self.mesh().save(str(path))

    def picture(self, path: str | os.PathLike | None = None, *, window_size: tuple[int, int] = (1000, 750),
                camera: str = "iso") -> np.ndarray:
        """An off-screen picture of the part, coloured by cut depth; the image array (and a PNG at ``path``)."""
        return render_part(part_mesh(self.stock, self.top, PICTURE_CELLS), path, window_size=window_size,
                           camera=camera)


def _block_min(a: np.ndarray, step: int) -> np.ndarray:
    """The lowest value of each ``step`` x ``step`` block of ``a`` (the blocks at the far edges may be smaller).

    Reduced along one axis and then the other, without padding: a grid far
    longer than it is wide (a stock of 2 x 3.6 M cells) needs no more memory
    than it holds.
    """
    rows = np.minimum.reduceat(a, np.arange(0, a.shape[0], step), axis=0)
    return np.minimum.reduceat(rows, np.arange(0, a.shape[1], step), axis=1)


def part_mesh(stock: Stock, top: np.ndarray, max_cells: int | None = None) -> "pv.PolyData":
    """The closed surface of the material ``top`` leaves on ``stock`` (see :meth:`CutResult.mesh`)."""
    from ..export.vtk import import_pyvista

    pv = import_pyvista()
    first, bottom, res = stock.top, stock.bottom, stock.resolution
    if max_cells and max(top.shape) > max_cells:
        step = -(-max(top.shape) // max_cells)
        top, first = _block_min(top, step), _block_min(first, step)
        bottom = -_block_min(-stock.bottom, step)
        res = res * step
    ny, nx = top.shape
    x = stock.x0 + (np.arange(nx) + 0.5) * res
    y = stock.y0 + (np.arange(ny) + 0.5) * res
    X, Y = np.meshgrid(x, y)
    upper = np.maximum(top, bottom)
    points = np.vstack([np.column_stack([X.ravel(), Y.ravel(), bottom.ravel()]),
                        np.column_stack([X.ravel(), Y.ravel(), upper.ravel()])])
    grid = pv.StructuredGrid()
    grid.points = points
    grid.dimensions = (nx, ny, 2)
    grid.point_data["depth"] = np.concatenate([np.zeros(nx * ny), np.maximum(first - upper, 0).ravel()])
    solid = (upper > bottom)
    # a hexahedron between four neighbouring cell centres is material when all four are
    corners = solid[:-1, :-1] & solid[1:, :-1] & solid[:-1, 1:] & solid[1:, 1:]
    if ny < 2 or nx < 2 or not corners.any():
        return pv.PolyData()
    part = grid.extract_cells(np.flatnonzero(corners.ravel())).extract_surface(algorithm="dataset_surface")
    return part.triangulate().clean()


def render_part(mesh: "pv.PolyData", path: str | os.PathLike | None = None, *,
                window_size: tuple[int, int] = (1000, 750), camera: str = "iso",
                plotter: "pv.Plotter | None" = None) -> np.ndarray:
    """Draw a part mesh off-screen, coloured by cut depth; the image (and a PNG at ``path``)."""
    from ..export.vtk import import_pyvista

    pv = import_pyvista()
    own = plotter is None
    if own:
        plotter = pv.Plotter(off_screen=True, window_size=list(window_size))
    style_part_view(plotter, mesh, camera)
    image = plotter.screenshot(None if path is None else str(path), return_img=True)
    if own:
        plotter.close()
    return image


def style_part_view(plotter: "pv.Plotter", mesh: "pv.PolyData", camera: str = "iso") -> None:
    """Put the part on ``plotter`` as every part view shows it: grey stock, cuts coloured by depth."""
    plotter.set_background("white")
    if mesh.n_points:
        depth = mesh.point_data["depth"] if "depth" in mesh.point_data else None
        top = float(depth.max()) if depth is not None and depth.size else 0.0
        plotter.add_mesh(mesh, scalars="depth" if depth is not None else None, cmap="viridis_r",
                         clim=[0.0, max(top, 1e-6)], smooth_shading=False, show_scalar_bar=True,
                         scalar_bar_args=dict(title="cut depth (mm)", color="black", vertical=True,
                                              position_x=0.88, position_y=0.1, height=0.8, width=0.04),
                         name="part")
    {"iso": plotter.view_isometric, "top": plotter.view_xy, "front": plotter.view_xz,
     "side": plotter.view_yz}[camera]()
    plotter.reset_camera()
