"""Widgets stage: pictures of the widgets' current state, drawn in Python.

The browser view draws with WebGL; these functions draw the same segments,
colours and camera with matplotlib's Agg canvas (no display, no GPU, no
thread of its own), for ``screenshot()`` and for the PNG every widget puts
in its rich display so an exported notebook shows it offline.  The camera
is orthographic with Z up: ``azimuth`` turns about Z, ``elevation`` lifts
the eye from the XY plane, as in the browser's ``viewer.js``.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from .coloring import Coloring
    from .toolpath import Toolpath

DPI = 100


@dataclass
class Camera:
    """An orthographic orbit camera: angles in degrees, ``zoom`` 1 fits the part."""

    azimuth: float = -60.0
    elevation: float = 30.0
    zoom: float = 1.0
    #: where the camera looks, mm from the middle of the part (moved by panning)
    target: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Screen right, screen up and towards-the-eye unit vectors."""
        az, el = np.radians(self.azimuth), np.radians(np.clip(self.elevation, -89.9, 89.9))
        eye = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        right = np.array([-np.sin(az), np.cos(az), 0.0])
        return right, np.cross(eye, right), eye

    def as_dict(self) -> dict:
        return {"azimuth": self.azimuth, "elevation": self.elevation, "zoom": self.zoom, "target": list(self.target)}


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
    """Segments ``span`` of ``path`` as the camera sees them, with their legend.

    Far segments are drawn first (a painter's order), so nearer ones cover them.
    """
    from matplotlib.collections import LineCollection

    a, b = span
    fig = new_figure(size)
    ax = fig.add_axes([0.0, 0.0, 0.78, 0.94] if title else [0.0, 0.0, 0.78, 1.0])
    ax.set_axis_off()
    right, up, eye = camera.axes()
    middle, radius = path.frame()
    centre = middle + np.asarray(camera.target, float)  # the target is kept relative to the part's middle
    half = radius / max(camera.zoom, 1e-6)
    aspect = (0.78 * size[0]) / ((0.94 if title else 1.0) * size[1])
    ax.set_xlim(-half * aspect, half * aspect)
    ax.set_ylim(-half, half)
    keep = np.arange(a, b)
    if not show_travel:
        keep = keep[path.kind[keep] == 0]
    work = keep[path.kind[keep] == 0]
    values = color.values[work]
    vmin, vmax = color.shown_range(values)
    rgb = np.full((keep.size, 3), 0.6)
    rgb[path.kind[keep] == 0] = color.rgb(values, vmin, vmax)
    p0, p1 = path.start[keep] - centre, path.end[keep] - centre
    depth = (p0 + p1) @ eye
    order = np.argsort(depth, kind="stable")
    segs = np.stack([np.column_stack([p0 @ right, p0 @ up]), np.column_stack([p1 @ right, p1 @ up])], axis=1)
    widths = np.where(path.kind[keep] == 0, 1.0, 0.5)[order]
    ax.add_collection(LineCollection(segs[order], colors=rgb[order], linewidths=widths))
    if current_move >= 0:
        s = path.move_seg[current_move + 1] - 1
        tip = path.end[s] - centre
        ax.plot([tip @ right], [tip @ up], "o", color="#e4002b", markersize=6)
    if title:
        fig.text(0.01, 0.97, title, fontsize=10, va="center")
    _legend(fig, color, values, vmin, vmax)
    return fig


def _legend(fig: "Figure", color: "Coloring", values: np.ndarray, vmin: float, vmax: float) -> None:
    """Colour bar or category swatches for the values shown."""
    if color.categories is not None:
        import matplotlib.patches as mpatches

        used = np.unique(values.astype(np.int64)) if values.size else np.zeros(0, np.int64)
        rgb = color.rgb(used, 0, 1)
        handles = [mpatches.Patch(color=rgb[k], label=color.categories[c]) for k, c in enumerate(used.tolist())]
        fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.78, 0.95), fontsize=8, frameon=False,
                   title=color.title, title_fontsize=9)
        return
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import ListedColormap, Normalize

    from .coloring import colormap_table

    cax = fig.add_axes([0.82, 0.1, 0.03, 0.8])
    cmap = ListedColormap(colormap_table() / 255.0)
    bar = fig.colorbar(ScalarMappable(Normalize(vmin, vmax if vmax > vmin else vmin + 1), cmap), cax=cax)
    bar.set_label(color.title, fontsize=9)
    bar.ax.tick_params(labelsize=8)
