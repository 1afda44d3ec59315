"""Widgets stage: a live 3D view through PyVista's trame backend (vtk.js in the browser), with a slider over moves.

The trame server and every VTK call of these views run on one thread of
gcodekit's own, with its own asyncio event loop (:func:`on_trame_loop`):
ipykernel 7 runs widget callbacks on other threads than the cell's, an EGL
context belongs to the thread that made it, and trame schedules its
messages on the calling thread's event loop, so calls from any other thread
go black after the first (see ``../shared/WIDGETS.md``).  The server is
started with trame-pyvista's public ``launch_server`` (awaiting its
``ready`` future) from a coroutine on that loop, under a name of its own
(:data:`SERVER_NAME`), and the views are made with the public ``show_trame``
naming it; nothing private of trame-pyvista is used.  (trame-pyvista keeps
a loop thread of its own for the servers it launches off the main thread,
but only as a private function; a server of our own on our loop needs
none.)

A subclass draws its scene (:meth:`TrameView._scene`), updates it to a move
(:meth:`TrameView._update`, on the loop) and says where it is
(:meth:`TrameView._status`).  The display also carries a PNG of the scene,
so a notebook exported to HTML keeps the picture.
"""

from __future__ import annotations

import asyncio
import html
import os
import tempfile
import threading
import time
from typing import Any, Callable

import numpy as np

from ..errors import MissingDependencyError

#: The trame server every gcodekit view is shown by (trame-pyvista's own is ``pyvista-jupyter``).
SERVER_NAME = "gcodekit-views"

_loop: asyncio.AbstractEventLoop | None = None
_loop_lock = threading.Lock()


def _trame_jupyter():
    try:
        from trame_pyvista import jupyter
    except ImportError as exc:
        raise MissingDependencyError("the live 3D views need trame: pip install 'gcodekit[widgets]'") from exc
    return jupyter


def trame_loop() -> asyncio.AbstractEventLoop:
    """The event loop (on a daemon thread of its own, started on first use) that runs the trame server."""
    global _loop
    with _loop_lock:
        if _loop is None:
            _loop = asyncio.new_event_loop()
            threading.Thread(target=_loop.run_forever, name="gcodekit-trame", daemon=True).start()
        return _loop


def on_trame_loop(fn: Callable, *args) -> Any:
    """Run ``fn(*args)`` (a function or a coroutine function) on :func:`trame_loop`'s thread; its result."""
    async def run():
        return await fn(*args) if asyncio.iscoroutinefunction(fn) else fn(*args)

    return asyncio.run_coroutine_threadsafe(run(), trame_loop()).result()


async def _server():
    """The view server, launched on first use (on the loop's thread)."""
    jupyter = _trame_jupyter()
    # trame-vtklocal, when installed, fetches its WebAssembly bundle at start: point it at a local folder
    os.environ.setdefault("VTK_WASM_DIR_OVERRIDE", tempfile.mkdtemp(prefix="gcodekit-vtk-wasm-"))
    server = jupyter.launch_server(SERVER_NAME)  # returns the running server when there is one
    await server.ready
    return server


class TrameView:
    """A scene in a live trame view (an iframe), a slider over ``n_moves`` moves and a status line.

    Parameters
    ----------
    n_moves : int
        The slider's range, 1..n_moves; the view starts at the last.
    size : (int, int)
        The view's width and height, pixels.
    kind : str
        The CSS names' middle word: ``gcodekit-<kind>-view`` (the box),
        ``gcodekit-<kind>-frame`` (the iframe), ``gcodekit-<kind>-status``.
    """

    def __init__(self, n_moves: int, size: tuple[int, int], kind: str):
        import ipywidgets as widgets

        _trame_jupyter()
        self.n_moves = int(n_moves)
        self.size = size
        self.kind = kind
        self.timings: list[float] = []
        self.plotter = self.viewer = None
        self.move = self.n_moves
        src = on_trame_loop(self._start)
        self.view = widgets.HTML(f'<iframe class="gcodekit-{kind}-frame" src="{html.escape(src)}" '
                                 f'style="width:{size[0]}px;height:{size[1]}px;border:0"></iframe>')
        self.slider = widgets.IntSlider(min=1, max=self.n_moves, value=self.n_moves, description="move",
                                        continuous_update=False, layout=widgets.Layout(width=f"{size[0]}px"))
        self.status = widgets.HTML()
        self.slider.observe(lambda change: self.show_move(change["new"]), names="value")
        self.widget = widgets.VBox([self.view, self.slider, self.status])
        self.widget.add_class(f"gcodekit-{kind}-view")
        self._say(self.n_moves)

    # -- what a subclass draws ----------------------------------------------------------------

    def _scene(self, plotter) -> None:  # pragma: no cover - each view draws its own
        """Put the scene of the current move on ``plotter`` (on the loop's thread)."""
        raise NotImplementedError

    def _update(self, move: int) -> None:  # pragma: no cover
        """Change the scene on :attr:`plotter` to move ``move`` (on the loop's thread)."""
        raise NotImplementedError

    def _status(self, move: int) -> str:  # pragma: no cover
        """The status line's text (HTML, escaped) after move ``move``."""
        raise NotImplementedError

    # -- on trame's loop -----------------------------------------------------------------------

    async def _start(self) -> str:
        from ..export.vtk import import_pyvista

        pv = import_pyvista()
        await _server()
        self.plotter = pv.Plotter(off_screen=True, window_size=list(self.size))
        self._scene(self.plotter)

        def keep(viewer, src, **_):
            self.viewer = viewer
            return src

        return _trame_jupyter().show_trame(self.plotter, mode="client", name=SERVER_NAME, handler=keep)

    def _redraw(self, move: int) -> None:
        self._update(move)
        self.plotter.render()
        self.viewer.update()

    # -- public ---------------------------------------------------------------------------------

    def show_move(self, move: int) -> None:
        """Show the scene as it is after move ``move`` (1 = the first)."""
        move = int(np.clip(move, 1, self.n_moves))
        start = time.perf_counter()
        self.move = move
        on_trame_loop(self._redraw, move)
        self.timings.append(time.perf_counter() - start)
        self._say(move)

    def _say(self, move: int) -> None:
        self.status.value = (f'<span class="gcodekit-{self.kind}-status" data-move="{move}">move {move} of '
                             f"{self.n_moves} · {self._status(move)}</span>")

    def screenshot(self) -> np.ndarray:
        """The view's picture as an (height, width, 3) array, rendered off-screen."""
        from ..export.vtk import import_pyvista

        def render():
            # a plotter of its own (the live one renders in the browser), made on the thread of every VTK call
            plotter = import_pyvista().Plotter(off_screen=True, window_size=list(self.size))
            self._scene(plotter)
            image = plotter.screenshot(None, return_img=True)
            plotter.close()
            return image

        return on_trame_loop(render)

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict[str, Any]:
        import base64
        import io

        from PIL import Image

        bundle = dict(self.widget._repr_mimebundle_(include=include, exclude=exclude) or {})
        buffer = io.BytesIO()
        Image.fromarray(np.asarray(self.screenshot(), np.uint8)).save(buffer, format="PNG")
        bundle["image/png"] = base64.b64encode(buffer.getvalue()).decode("ascii")
        bundle["text/plain"] = repr(self)
        return bundle
