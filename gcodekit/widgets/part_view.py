"""Front end: the cut part in a live 3D view (PyVista's trame backend, vtk.js in the browser), with a move slider.

The view renders in the browser: PyVista's ``client`` trame mode sends the
part's mesh to vtk.js, which the user rotates and zooms without the kernel.
The slider re-cuts up to the chosen move: forward it cuts only the new
moves, backward it restores the height field kept at the nearest block of
moves before (:class:`gcodekit.cut.CutSimulation` with ``keep_states``).

Every VTK and trame call (making the plotter, each update and screenshot)
runs on the thread of the trame server's event loop
(:mod:`gcodekit.widgets.trame_view`, which says why).  The display also
carries a PNG of the part, so a notebook exported to HTML keeps the
picture.

Examples
--------
::

    view = gcodekit.widgets.PartView(op, tools=ToolLibrary.read("TOOLS.toml"))
    view            # in JupyterLab: the part, a slider over the moves
    view.show_move(120)
"""

from __future__ import annotations

from ..cut import CutSimulation
from ..cut.path import moving_rows
from ..cut.result import PICTURE_CELLS, part_mesh, style_part_view
from .trame_view import TrameView


class PartView(TrameView):
    """The part a mill program cuts, in a 3D view the user rotates, and a slider over its moves.

    Parameters
    ----------
    op : Operation
        An emulated mill operation.
    stock, tools, resolution
        As for :class:`gcodekit.cut.CutSimulation`.
    size : (int, int), default: (800, 520)
        The view's width and height, pixels.
    """

    def __init__(self, op, *, stock=None, tools=None, resolution: float | None = None,
                 size: tuple[int, int] = (800, 520)):
        self.sim = CutSimulation(op, stock=stock, tools=tools, resolution=resolution, keep_states=True)
        self.rows = moving_rows(op.waypoints)
        if self.rows.size == 0:
            raise ValueError(f"{op.file}: no moves to cut")
        self.sim.cut_to(int(self.rows[-1]))
        super().__init__(int(self.rows.size), size, "part")

    def __repr__(self) -> str:
        return f"PartView of {self.sim.op.file}"

    def _mesh(self):
        return part_mesh(self.sim.stock, self.sim.top, PICTURE_CELLS)

    def _scene(self, plotter) -> None:
        style_part_view(plotter, self._mesh())

    def _update(self, move: int) -> None:
        # the cut runs here too: it is quick next to the mesh, and keeps every step's work on one thread
        self.sim.cut_to(int(self.rows[move - 1]))
        mesh = self._mesh()
        part = self.plotter.actors.get("part")
        if part is not None and mesh.n_points:
            part.mapper.dataset.copy_from(mesh)
        else:
            style_part_view(self.plotter, mesh)

    def _status(self, move: int) -> str:
        row = int(self.rows[move - 1])
        op = self.sim.op
        line = int(op.table.line[op.waypoints["command"][row]] if "command" in op.waypoints else op.table.line[row])
        removed = self.sim.stock.volume() - self.sim.stock.volume(self.sim.top)
        return f"line {line} · removed {removed:,.1f} mm³"
