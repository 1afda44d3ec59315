"""Widgets stage: pictures of the widgets' current state, drawn in Python.

The browser view draws with WebGL; these functions draw the same segments,
colours and camera (:mod:`gcodekit.view`) with matplotlib's Agg canvas
(no display, no GPU, no thread of its own) through
:func:`gcodekit.visualize.draw_toolpath`, for ``screenshot()`` and for the
PNG every widget puts in its rich display so an exported notebook shows it
offline.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING

import numpy as np

from ..view import Camera

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..view import Coloring, Toolpath

DPI = 100


def new_figure(size: tuple[int, int]) -> "Figure":
    from matplotlib.figure import Figure

    return Figure(figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI)


def to_rgb(fig: "Figure") -> np.ndarray:
    """The figure drawn, as an (height, width, 3) uint8 array."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def to_png(fig: "Figure") -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    buffer = io.BytesIO()
    FigureCanvasAgg(fig).print_png(buffer)
    return buffer.getvalue()


def message_figure(text: str, size: tuple[int, int] = (640, 160)) -> "Figure":
    """A picture of a message, for a widget that has nothing else to show."""
    fig = new_figure(size)
    fig.text(0.03, 0.5, text, fontsize=11, color="#a30000", va="center", wrap=True)
    return fig


def toolpath_figure(path: "Toolpath", span: tuple[int, int], color: "Coloring", camera: Camera, *,
                    show_travel: bool = True, current_move: int = -1, size: tuple[int, int] = (800, 600),
                    title: str = "") -> "Figure":
    """Segments ``span`` of ``path`` as the camera sees them, with their legend and the current move's end."""
    from ..visualize import add_legend, draw_toolpath

    a, b = span
    fig = new_figure(size)
    # the view takes the whole height and the title is laid over it, as the browser lays its status over the canvas
    ax = fig.add_axes((0.0, 0.0, 0.78, 1.0))
    ax.set_axis_off()
    keep = np.arange(a, b)
    if not show_travel:
        keep = keep[path.kind[keep] == 0]
    vmin, vmax = draw_toolpath(ax, path, color, camera, keep)
    if current_move >= 0:
        right, up, _ = camera.axes()
        centre, _ = camera.view(*path.frame())
        tip = path.end[path.move_seg[current_move + 1] - 1] - centre
        ax.plot([tip @ right], [tip @ up], "o", color="#e4002b", markersize=6)
    if title:
        fig.text(0.01, 0.97, title, fontsize=10, va="center")
    add_legend(fig, color, path, keep, vmin, vmax)
    return fig
