"""Widgets stage: pictures of the widgets' current state, drawn in Python.

The browser view draws with WebGL; these functions draw the same segments,
colours and camera (:mod:`gcodekit.view`) with matplotlib's Agg canvas
(no display, no GPU, no thread of its own) through
:func:`gcodekit.visualize.draw_toolpath`, for ``screenshot()`` and for the
PNG every widget puts in its rich display so an exported notebook shows it
offline.  matplotlib draws about ten thousand segments a second here, so
more than :data:`RASTER_FROM` segments are drawn as the WebGL view draws
them, one pixel wide with a depth buffer, by :func:`raster_toolpath` in
NumPy (its pixel loop compiled when Numba is installed:
:mod:`.raster_kernel`), and shown as an image in the same figure.
"""

from __future__ import annotations

import io
import sys
import threading
from typing import TYPE_CHECKING

import numpy as np

from ..view import Camera
from . import raster_kernel

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..view import Coloring, Toolpath

DPI = 100
#: Segments from which a picture's toolpath is rasterised in NumPy rather than drawn by matplotlib.
RASTER_FROM = 20_000
#: Segments rasterised at a time (bounds the memory of the samples along them).
RASTER_CHUNK = 400_000


def import_in_background() -> None:
    """Start importing matplotlib's figure and Agg canvas on a thread, if not imported yet.

    A widget's display draws its PNG with them (importing them costs about
    0.7 CPU-s); a widget starts this when it is made, so the import runs
    beside the NumPy work that builds the widget (which releases the GIL)
    rather than after it.  Python's import lock makes a later ``import``
    wait for this one to finish.
    """
    if "matplotlib.backends.backend_agg" in sys.modules:
        return

    def load() -> None:
        import matplotlib.backends.backend_agg  # noqa: F401
        import matplotlib.figure  # noqa: F401

    threading.Thread(target=load, name="gcodekit-matplotlib-import", daemon=True).start()


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
    draw = raster_toolpath if keep.size > RASTER_FROM else draw_toolpath
    vmin, vmax = draw(ax, path, color, camera, keep)
    if current_move >= 0:
        right, up, _ = camera.axes()
        centre, _ = camera.view(*path.frame())
        tip = path.end[path.move_seg[current_move + 1] - 1] - centre
        ax.plot([tip @ right], [tip @ up], "o", color="#e4002b", markersize=6)
    if title:
        fig.text(0.01, 0.97, title, fontsize=10, va="center")
    add_legend(fig, color, path, keep, vmin, vmax)
    return fig


def raster_toolpath(ax, path: "Toolpath", color: "Coloring", camera: Camera,
                    segments: np.ndarray) -> tuple[float, float]:
    """:func:`~gcodekit.visualize.draw_toolpath`'s picture as an image: lines one pixel wide, the nearest in front.

    Each segment is sampled at every pixel it crosses; a depth buffer keeps
    the sample nearest the eye per pixel (``np.maximum.at``), in chunks of
    :data:`RASTER_CHUNK` segments.  The Axes are framed as ``draw_toolpath``
    frames them; returns the colour scale.
    """
    right, up, eye = camera.axes()
    centre, half = camera.view(*path.frame())
    box = ax.get_position()
    fig_w, fig_h = ax.figure.get_size_inches()
    width, height = max(int(round(box.width * fig_w * DPI)), 1), max(int(round(box.height * fig_h * DPI)), 1)
    half_w = half * width / height
    rgb, vmin, vmax = color.segment_rgb(path, segments)
    image = np.ones((height, width, 3))
    depth = np.full(height * width, -np.inf)
    kernel = raster_kernel.engine(segments.size)
    for c in range(0, segments.size, RASTER_CHUNK):
        keep = segments[c:c + RASTER_CHUNK]
        ends = [(path.start[keep] - centre), (path.end[keep] - centre)]
        # pixel column, row (0 at the top) and nearness of each end
        cols = [(p @ right + half_w) / (2 * half_w) * width for p in ends]
        rows = [(half - p @ up) / (2 * half) * height for p in ends]
        near = [p @ eye for p in ends]
        count = np.clip(np.ceil(np.maximum(np.abs(cols[1] - cols[0]), np.abs(rows[1] - rows[0]))), 1, 4 * width) + 1
        count = count.astype(np.int64)
        if kernel is not None:  # the same samples as below, as one compiled loop
            kernel(*cols, *rows, *near, count, np.ascontiguousarray(rgb[c:c + RASTER_CHUNK]), width, height,
                   image.reshape(-1, 3), depth)
            continue
        seg = np.repeat(np.arange(keep.size), count)
        t = (np.arange(seg.size) - np.repeat(np.cumsum(count) - count, count)) / (count - 1)[seg]
        x = np.floor(cols[0][seg] + t * (cols[1] - cols[0])[seg]).astype(np.int64)
        y = np.floor(rows[0][seg] + t * (rows[1] - rows[0])[seg]).astype(np.int64)
        z = near[0][seg] + t * (near[1] - near[0])[seg]
        inside = (x >= 0) & (x < width) & (y >= 0) & (y < height)
        pixel, z, seg = y[inside] * width + x[inside], z[inside], seg[inside]
        np.maximum.at(depth, pixel, z)
        front = z >= depth[pixel]  # the nearest so far: a later chunk's nearer sample overwrites it
        image.reshape(-1, 3)[pixel[front]] = rgb[c:c + RASTER_CHUNK][seg[front]]
    x0, y0 = 0.0, 0.0  # the Axes' coordinates are mm from the point looked at, as draw_toolpath's
    ax.imshow(image, extent=(x0 - half_w, x0 + half_w, y0 - half, y0 + half), interpolation="nearest",
              aspect="auto")
    ax.set_xlim(x0 - half_w, x0 + half_w)
    ax.set_ylim(y0 - half, y0 + half)
    return vmin, vmax
