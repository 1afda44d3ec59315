"""Front end: the beads an additive program lays, as shaded tubes in a live 3D view (trame, vtk.js), with a slider.

The beads are :func:`gcodekit.additive.bead_tubes` of the program's
:class:`~gcodekit.additive.AdditivePart` (its bead geometry: width, height
and shape per deposition segment), built once in program order.  The
slider over the depositing moves shows the beads laid up to the chosen
move: a step hands vtk.js the first triangles of that mesh, never building
geometry again, and its points (which do not change) are not sent again
(trame sends an array only when its content changed).  Colours: the
slicer's features when the program names them, else the layers.

Every VTK and trame call runs on the thread of the trame server's loop
(:mod:`gcodekit.widgets.trame_view`); the display also carries a PNG.

Examples
--------
::

    view = gcodekit.widgets.BeadView(gcodekit.gcode_to_operation("part.gcode"))
    view            # in JupyterLab: the beads, a slider over the depositing moves
    view.show_move(500)
"""

from __future__ import annotations

import html

import numpy as np

from ..additive import AdditivePart, Bead, bead_tubes
from ..view.coloring import NO_FEATURE, PALETTE, has_features, waypoint_scalars
from .trame_view import TrameView

#: The view's background.
BACKGROUND = "white"
#: Triangles per block (about): a block is one actor, and a slider step sends vtk.js only the blocks whose
#: share of the beads changes (within a block: the block the move ends in).
BLOCK_TRIANGLES = 8_000


def _blocks(counts: np.ndarray, size: int) -> np.ndarray:
    """Triangle indices where blocks start (and the end): a block ends at the end of the first move that
    brings it to ``size`` triangles or more."""
    bounds = [0]
    for end in counts.tolist():
        if end - bounds[-1] >= size:
            bounds.append(end)
    if bounds[-1] != counts[-1]:
        bounds.append(int(counts[-1]))
    return np.asarray(bounds, np.int64)


class BeadView(TrameView):
    """The beads an additive program lays, in a 3D view the user rotates, and a slider over its depositing moves.

    Parameters
    ----------
    op : Operation
        An emulated additive operation.
    bead : Bead, default: None
        The cross-section (as for :class:`~gcodekit.additive.AdditivePart`);
        None: from the program (filament per mm and layer spacing).
    layers : (int, int), default: None
        Only these layers (first, last; both included); None: all.
    sides : int, default: 8
        Points on each bead's outline.
    size : (int, int), default: (800, 520)
        The view's width and height, pixels.
    """

    def __init__(self, op, *, bead: Bead | None = None, layers: tuple[int, int] | None = None, sides: int = 8,
                 size: tuple[int, int] = (800, 520)):
        self.op = op
        self.part = AdditivePart(op, bead)
        self.tubes = bead_tubes(self.part, sides=sides, layers=layers)
        if self.tubes.triangles.size == 0:
            raise ValueError(f"{op.file}: no beads to show (the program lays no material"
                             f"{' in those layers' if layers is not None else ''})")
        self.rows = np.unique(self.tubes.triangle_row)
        self._counts = np.searchsorted(self.tubes.triangle_row, self.rows, side="right")
        self._bounds = _blocks(self._counts, BLOCK_TRIANGLES)
        if has_features(op):
            self.color_by = "feature"
            codes, self.categories = waypoint_scalars(op, "feature")
            self._values = codes[self.tubes.point_row].astype(float)
        else:
            self.color_by, self.categories = "layer", None
            self._values = np.asarray(self.part.waypoint_layer, float)[self.tubes.point_row]
        volume = np.nan_to_num(np.asarray(op.volumes(), float))
        self._laid = np.cumsum(np.where(self.part.operation.work, volume, 0.0))
        self._shown: list[int] = []  # triangles each block's actor shows in the live view
        super().__init__(int(self.rows.size), size, "bead")

    def __repr__(self) -> str:
        return f"BeadView of {self.op.file}: {self.rows.size} depositing moves, {len(self.tubes.triangles):,} triangles"

    # -- the scene ----------------------------------------------------------------------------

    def _block_mesh(self, k: int):
        """Block ``k``'s triangles as a mesh of its own points (with their normals, colour values, waypoints)."""
        from ..additive.tubes import faces_array
        from ..export.vtk import import_pyvista

        pv = import_pyvista()
        lo, hi = self._bounds[k], self._bounds[k + 1]
        triangles = self.tubes.triangles[lo:hi]
        used, local = np.unique(triangles, return_inverse=True)
        mesh = pv.PolyData(self.tubes.points[used], faces=faces_array(local.reshape(-1, 3)))
        mesh.point_data["Normals"] = self.tubes.normals[used]
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["waypoint"] = self.tubes.point_row[used]
        mesh.point_data["color"] = self._values[used]
        return mesh

    def _scene(self, plotter) -> None:
        plotter.set_background(BACKGROUND)
        live = plotter is self.plotter
        count = int(self._counts[self.move - 1])
        if live:
            # each block's mesh (the actor's input: its mapper's own dataset may be a pipeline's copy) and
            # whole face list, which steps slice
            self._meshes: list = []
            self._faces: list[np.ndarray] = []
        for k in range(len(self._bounds) - 1):
            mesh = self._block_mesh(k)
            if self.categories is not None:
                n = len(self.categories)
                style = dict(cmap=[PALETTE[c % len(PALETTE)] for c in range(n)], clim=[-0.5, n - 0.5], n_colors=n,
                             show_scalar_bar=False)
            else:
                top = float(np.max(self._values)) if self._values.size else 0.0
                style = dict(cmap="viridis", clim=[0.0, max(top, 1.0)], show_scalar_bar=k == 0,
                             scalar_bar_args=dict(title="layer", color="black", vertical=True, position_x=0.88,
                                                  position_y=0.1, height=0.8, width=0.04))
            actor = plotter.add_mesh(mesh, scalars="color", name=f"beads{k}", **style)
            if live:
                self._meshes.append(mesh)
                self._faces.append(mesh.faces.copy())
            self._show_block(actor, mesh, k, count, mesh.faces.copy())
        if live:
            self._shown = [self._in_block(k, count) for k in range(len(self._bounds) - 1)]
        # the whole part framed, whatever move is shown; shaded smoothly by the tubes' own normals
        plotter.view_isometric()
        lo, hi = self.tubes.points.min(axis=0), self.tubes.points.max(axis=0)
        plotter.reset_camera(bounds=[lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]])
        plotter.camera_set = True  # PyVista would otherwise fit the first picture to the beads shown

    def _in_block(self, k: int, count: int) -> int:
        """How many of block ``k``'s triangles the first ``count`` triangles take."""
        return int(np.clip(count - self._bounds[k], 0, self._bounds[k + 1] - self._bounds[k]))

    def _show_block(self, actor, mesh, k: int, count: int, faces: np.ndarray) -> None:
        """Show block ``k``'s share of the first ``count`` triangles (``faces``: all of the block's)."""
        shown = self._in_block(k, count)
        actor.visibility = shown > 0
        if shown and mesh.n_cells != shown:
            mesh.faces = faces[:4 * shown]

    def _update(self, move: int) -> None:
        # only the blocks whose share changes are touched: those wholly before or after the move stay as they
        # are, and vtk.js is sent nothing for them but (at most) their visibility
        count = int(self._counts[move - 1])
        for k, before in enumerate(self._shown):
            if self._in_block(k, count) != before:
                self._show_block(self.plotter.actors[f"beads{k}"], self._meshes[k], k, count, self._faces[k])
                self._shown[k] = self._in_block(k, count)

    def _status(self, move: int) -> str:
        row = int(self.rows[move - 1])
        op = self.op
        line = int(op.table.line[op.waypoints["command"][row]])
        layer = int(self.part.waypoint_layer[row])
        legend = ""
        if self.categories is not None:
            shown = np.unique(self._values[:]).astype(int)
            legend = " · " + " ".join(
                f'<span style="color:{PALETTE[k % len(PALETTE)]}">■</span> {html.escape(self.categories[k])}'
                for k in shown if self.categories[k] != NO_FEATURE)
        return f"line {line} · layer {layer} · laid {self._laid[row]:,.1f} mm³{legend}"
