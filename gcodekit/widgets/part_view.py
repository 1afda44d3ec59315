"""Front end: the cut part in a live 3D view (PyVista's trame backend, vtk.js in the browser), with a move slider.

The view renders in the browser: PyVista's ``client`` trame mode sends the
part's mesh to vtk.js, which the user rotates and zooms without the kernel.
The slider re-cuts up to the chosen move: forward it cuts only the new
moves, backward it restores the height field kept at the nearest block of
moves before (:class:`gcodekit.cut.CutSimulation` with ``keep_states``).

Every VTK and trame call (making the plotter, starting the server, each
update and screenshot) runs on the thread of trame's server event loop:
ipykernel 7 runs widget callbacks on other threads than the cell's, and
trame schedules its messages on the calling thread's loop (see
``../shared/WIDGETS.md``).  The display also carries a PNG of the part,
so a notebook exported to HTML keeps the picture.

Examples
--------
::

    view = gcodekit.widgets.PartView(op, tools=ToolLibrary.read("TOOLS.toml"))
    view            # in JupyterLab: the part, a slider over the moves
    view.show_move(120)
"""

from __future__ import annotations

import asyncio
import html
import os
import tempfile
import time
from typing import Any

import numpy as np

from ..cut import CutSimulation
from ..cut.path import moving_rows
from ..cut.result import PICTURE_CELLS, part_mesh, render_part, style_part_view
from ..errors import MissingDependencyError


def _trame():
    try:
        from trame_pyvista import jupyter
    except ImportError as exc:
        raise MissingDependencyError("the live part view needs trame: pip install 'gcodekit[widgets]'") from exc
    return jupyter


class PartView:
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
        import ipywidgets as widgets

        self.sim = CutSimulation(op, stock=stock, tools=tools, resolution=resolution, keep_states=True)
        self.rows = moving_rows(op.waypoints)
        if self.rows.size == 0:
            raise ValueError(f"{op.file}: no moves to cut")
        self.sim.cut_to(int(self.rows[-1]))
        self.size = size
        self.timings: list[float] = []
        self._jupyter = _trame()
        # trame-vtklocal, when installed, fetches its WebAssembly bundle at start: point it at a local folder
        os.environ.setdefault("VTK_WASM_DIR_OVERRIDE", tempfile.mkdtemp(prefix="gcodekit-vtk-wasm-"))
        self._loop = self._jupyter._server_loop()
        self.plotter = self.viewer = None
        src = self._on_loop(self._start)
        self.view = widgets.HTML(f'<iframe class="gcodekit-part-frame" src="{html.escape(src)}" '
                                 f'style="width:{size[0]}px;height:{size[1]}px;border:0"></iframe>')
        self.slider = widgets.IntSlider(min=1, max=int(self.rows.size), value=int(self.rows.size),
                                        description="move", continuous_update=False,
                                        layout=widgets.Layout(width=f"{size[0]}px"))
        self.status = widgets.HTML()
        self.slider.observe(lambda change: self.show_move(change["new"]), names="value")
        self.widget = widgets.VBox([self.view, self.slider, self.status])
        self.widget.add_class("gcodekit-part-view")
        self._say(int(self.rows.size))

    # -- on trame's loop ------------------------------------------------------------------

    def _on_loop(self, fn, *args):
        async def run():
            return await fn(*args) if asyncio.iscoroutinefunction(fn) else fn(*args)

        return asyncio.run_coroutine_threadsafe(run(), self._loop).result()

    async def _start(self) -> str:
        from ..export.vtk import import_pyvista

        pv = import_pyvista()
        jupyter = self._jupyter
        server = jupyter.get_server(name=pv.global_theme.trame.jupyter_server_name)
        if not server.running:
            await jupyter.launch_server(server).ready
        self.plotter = pv.Plotter(off_screen=True, window_size=list(self.size))
        style_part_view(self.plotter, self._mesh())

        def keep(viewer, src, **_):
            self.viewer = viewer
            return src

        return jupyter.show_trame(self.plotter, mode="client", handler=keep)

    def _mesh(self):
        return part_mesh(self.sim.stock, self.sim.top, PICTURE_CELLS)

    def _redraw(self) -> None:
        mesh = self._mesh()
        part = self.plotter.actors.get("part")
        if part is not None and mesh.n_points:
            part.mapper.dataset.copy_from(mesh)
        else:
            style_part_view(self.plotter, mesh)
        self.plotter.render()
        self.viewer.update()

    # -- public ---------------------------------------------------------------------------

    def show_move(self, move: int) -> None:
        """Show the part as it is after move ``move`` (1 = the first move cut)."""
        move = int(np.clip(move, 1, self.rows.size))
        start = time.perf_counter()
        self.sim.cut_to(int(self.rows[move - 1]))
        self._on_loop(self._redraw)
        self.timings.append(time.perf_counter() - start)
        self._say(move)

    def _say(self, move: int) -> None:
        row = int(self.rows[move - 1])
        line = int(self.sim.op.table.line[self.sim.op.waypoints["command"][row]]
                   if "command" in self.sim.op.waypoints else self.sim.op.table.line[row])
        removed = self.sim.stock.volume() - self.sim.stock.volume(self.sim.top)
        self.status.value = (f'<span class="gcodekit-part-status" data-move="{move}">move {move} of '
                             f"{self.rows.size} · line {line} · removed {removed:,.1f} mm³</span>")

    def screenshot(self) -> np.ndarray:
        """The view's picture as an (height, width, 3) array, rendered off-screen."""
        # a plotter of its own (the live one renders in the browser), made on the same thread as every VTK call
        return self._on_loop(lambda: render_part(self._mesh(), window_size=self.size))

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict[str, Any]:
        import base64
        import io

        from PIL import Image

        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude) or {}
        buf = io.BytesIO()
        Image.fromarray(np.asarray(self.screenshot(), np.uint8)).save(buf, format="PNG")
        bundle["image/png"] = base64.b64encode(buf.getvalue()).decode("ascii")
        bundle.setdefault("text/plain", f"PartView of {self.sim.op.file}")
        return bundle
