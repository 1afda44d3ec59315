"""Report stage: the pictures of a report, drawn off-screen with matplotlib.

Each function returns a matplotlib Figure; :func:`report_figures` draws them
all and returns them as ``data:`` URIs so a page embeds them and works
offline.  The toolpath pictures draw the one :class:`~gcodekit.view.Toolpath`
with the one :class:`~gcodekit.view.Coloring` through
:func:`gcodekit.visualize.draw_toolpath`, as the notebook viewer and the
PyVista pictures do, every segment of the program but only those the
picture's pixels show (:mod:`gcodekit.view.lod`), joined into polylines: a
3 M-line print draws in seconds and looks as its full drawing does.  The
speed plot bins the program's speeds.
"""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Collection

import numpy as np

from ..view import TRAVEL_COLOR, WORK, Coloring, Toolpath, ToolpathError, coloring, default_coloring
from ..view.coloring import hex_rgb

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..model.operation import Operation

THUMBNAILS = 12
#: The pictures of a report page.
FIGURES = ("iso", "top", "layer_times", "thumbnails", "velocity", "breakdown", "part")
#: Those drawn from the operation alone, before its numbers are computed.
OP_FIGURES = ("iso", "top", "thumbnails", "velocity")
DPI = 100
#: Layers per step outline of the layer-time chart: 2 vertices a layer, under Agg's 1024 for snapping.
STEPS = 500
WIDTH_IN = 8.0


@dataclass
class Drawing:
    """What a report draws of a toolpath: the toolpath, its colouring and which of its segments.

    A print shows its deposition only; a mill program every move, rapids grey.
    """

    path: Toolpath
    color: Coloring
    segments: np.ndarray

    @property
    def layer(self) -> np.ndarray:
        """Layer of each segment drawn (-1 for a program without layers)."""
        if self.path.group_by != "layer":
            return np.full(self.segments.size, -1)
        return self.path.segment_group[self.segments]

    @property
    def start(self) -> np.ndarray:
        """First end of each segment drawn, (n, 3) mm."""
        return self.path.start[self.segments]

    @property
    def end(self) -> np.ndarray:
        """Second end of each segment drawn, (n, 3) mm."""
        return self.path.end[self.segments]


def toolpath_drawing(op: "Operation", color_by: str | None = None) -> Drawing | None:
    """The report's drawing of ``op``, coloured by ``color_by`` (default: features, layers or feed); None
    when nothing moves."""
    try:
        path = Toolpath.of(op)
    except ToolpathError:
        return None
    color = coloring(path, color_by or default_coloring(op))
    keep = path.kind == WORK if op.process == "additive" else np.ones(path.n_segments, bool)
    return Drawing(path, color, np.flatnonzero(keep))


def _figure(height: float, **margins: float) -> "Figure":
    """A figure of the report's width with fixed margins (fractions of the figure).

    Fixed margins instead of matplotlib's constrained layout, which draws
    every figure twice more and took 40 % of a report's drawing time.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(WIDTH_IN, height), dpi=DPI)
    fig.subplots_adjust(**margins)
    return fig


def toolpath_iso(drawing: Drawing) -> "Figure":
    """The toolpath seen by the ``iso`` camera (orthographic, from +X, -Y, +Z), as the viewer shows it."""
    from ..visualize import add_legend, draw_toolpath, fitted_camera

    fig = _figure(5.0)
    ax = fig.add_axes((0.0, 0.0, 0.78, 1.0))
    ax.set_axis_off()
    camera = fitted_camera("iso", drawing.path, 0.78 * WIDTH_IN / 5.0)
    vmin, vmax = draw_toolpath(ax, drawing.path, drawing.color, camera, drawing.segments,
                               work_width=0.6, travel_width=0.5, lod=True)
    add_legend(fig, drawing.color, drawing.path, drawing.segments, vmin, vmax)
    return fig


def toolpath_top(drawing: Drawing) -> "Figure":
    """Top view (XY) of the whole toolpath, axes in machine millimetres."""
    from ..visualize import add_legend, draw_toolpath, fitted_camera

    fig = _figure(4.6)
    ax = fig.add_axes((0.09, 0.1, 0.69, 0.83))
    camera = fitted_camera("top", drawing.path, 0.69 * WIDTH_IN / (0.83 * 4.6))
    vmin, vmax = draw_toolpath(ax, drawing.path, drawing.color, camera, drawing.segments,
                               work_width=0.5, travel_width=0.5, absolute=True, lod=True)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("X, mm")
    ax.set_ylabel("Y, mm")
    ax.set_title("Top view", fontsize=10)
    add_legend(fig, drawing.color, drawing.path, drawing.segments, vmin, vmax)
    return fig


def layer_thumbnails(drawing: Drawing, count: int = THUMBNAILS) -> "Figure | None":
    """Small XY views of ``count`` layers spread over the height, on the part's extents."""
    from matplotlib.collections import LineCollection

    from ..view.lod import polylines

    layer = drawing.layer
    ids = np.unique(layer[layer >= 0])
    if ids.size == 0:
        return None
    chosen = ids[np.unique(np.linspace(0, ids.size - 1, min(count, ids.size)).round().astype(int))]
    cols = 6
    rows = int(np.ceil(chosen.size / cols))
    fig = _figure(1.45 * rows + 0.2, left=0.01, right=0.99, bottom=0.02, top=0.92, wspace=0.08, hspace=0.25)
    layered = layer >= 0  # the extents of the layers, not of a purge line drawn before them
    lo = drawing.path.start[drawing.segments[layered], :2].min(axis=0)
    hi = drawing.path.start[drawing.segments[layered], :2].max(axis=0)
    pad = 0.03 * max(float((hi - lo).max()), 1.0)
    lo, hi = lo - pad, hi + pad
    # colours of the chosen layers only, on the colour scale of the whole drawing
    shown = np.flatnonzero(np.isin(layer, chosen))
    colours = _colours(drawing, shown)
    picked = drawing.segments[shown]
    start, end, layer = drawing.path.start[picked, :2], drawing.path.end[picked, :2], layer[shown]
    for k, one in enumerate(chosen):
        ax = fig.add_subplot(rows, cols, k + 1)
        sel = layer == one
        runs = polylines(start[sel], end[sel], colours[sel])  # one path per run of joined moves
        ax.add_collection(LineCollection(runs.runs(), colors=colours[sel][runs.first], linewidths=0.4))
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"layer {int(one)}", fontsize=7)
    return fig


def _colours(drawing: Drawing, shown: np.ndarray) -> np.ndarray:
    """RGB of the drawing's segments ``shown`` (indices into it), on the colour scale of all its segments."""
    path, color, segments = drawing.path, drawing.color, drawing.segments
    work = path.kind[segments] == WORK
    vmin, vmax = color.value_range(segments[work])
    rgb = np.tile(hex_rgb(TRAVEL_COLOR), (shown.size, 1))
    shown_work = work[shown]
    rgb[shown_work] = color.rgb(color.values[segments[shown][shown_work]], vmin, vmax)
    return rgb


def layer_times(rows: list[dict[str, Any]], slicer_rows: list[dict[str, Any]] = ()) -> "Figure | None":
    """Planned time of each layer (as bars) and, when the file has progress marks, the slicer's (a step line).

    The slicer's time between two marks is spread evenly over the layers
    between them (Cura marks every layer; PrusaSlicer's M73 only where its
    minutes left change).
    """
    if not rows:
        return None
    from matplotlib.ticker import MaxNLocator

    fig = _figure(2.8, left=0.08, right=0.98, bottom=0.16, top=0.9)
    ax = fig.add_subplot()
    # filled step outlines, not a bar per layer: the same pixels (bars one layer wide touch, and both are
    # snapped to the pixel grid, which Agg does for paths of at most 1024 vertices: hence outlines of at most
    # STEPS layers) in a sixth of the time; a layer without a row is a step of height 0
    first, last = rows[0]["layer"], rows[-1]["layer"]
    times = np.zeros(last - first + 1)
    times[[r["layer"] - first for r in rows]] = [r["time_s"] for r in rows]
    edges = np.arange(first, last + 2) - 0.5
    planned = [ax.stairs(times[k:k + STEPS], edges[k:k + STEPS + 1], fill=True, baseline=0, color="#3b6ea8",
                         label="gcodekit (planned)") for k in range(0, times.size, STEPS)][0]
    if slicer_rows:
        edges = [slicer_rows[0]["layer"] - slicer_rows[0]["layers"] + 0.5] + [r["layer"] + 0.5 for r in slicer_rows]
        per_layer = [r["slicer_time_s"] / r["layers"] for r in slicer_rows]
        marks = ax.stairs(per_layer, edges, color="#d9822b", linewidth=1.2, label="slicer's marks")
        ax.legend(handles=[marks, planned], fontsize=7, loc="upper right")
    ax.set_xlabel("layer")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("time, s")
    ax.set_title("Time per layer", fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    return fig


def velocity(op: "Operation", bins: int = 1500, window_s: float = 20.0) -> "Figure | None":
    """Commanded and planned speed over time: the whole program binned, and a window at full detail.

    The binned view shows each bin's highest speeds, so the plateaus stay
    visible; the window (``window_s`` around the middle of the program)
    shows the planner's trapezoids.
    """
    from ..analysis import velocity_corners  # arrays: a DataFrame of a 3 M-line print's corners costs seconds

    v = velocity_corners(op, columns=("time", "distance", "planned", "commanded"))  # not the source lines
    if v["time"].size == 0:
        return None
    t, planned, commanded = (np.asarray(v[c], float) for c in ("time", "planned", "commanded"))
    fig = _figure(4.4, left=0.08, right=0.98, bottom=0.1, top=0.94, hspace=0.42)
    top, bottom = fig.subplots(2, 1)
    # mean speed per bin from the running integrals: planned distance, and commanded speed times time
    edges = np.linspace(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0, bins + 1)
    dt = np.diff(t)
    commanded_d = np.r_[0.0, np.cumsum(commanded[:-1] * dt)]
    for running, label, colour in ((commanded_d, "commanded", "#c44e52"),
                                   (np.asarray(v["distance"], float), "planned", "#3b6ea8")):
        mean = np.diff(np.interp(edges, t, running)) / np.diff(edges)
        top.plot((edges[:-1] + edges[1:]) / 2, mean, color=colour, lw=0.8, label=label)
    top.set_title(f"Mean speed over the whole program ({bins} time bins)", fontsize=10)
    top.set_ylabel("mm/s")
    top.legend(fontsize=8, loc="upper right")
    mid = (t[0] + t[-1]) / 2
    lo, hi = np.searchsorted(t, [mid - window_s / 2, mid + window_s / 2])
    lo, hi = max(lo - 1, 0), min(max(hi, lo + 2), t.size)
    bottom.plot(t[lo:hi], commanded[lo:hi], color="#c44e52", lw=0.8, label="commanded", drawstyle="steps-post")
    bottom.plot(t[lo:hi], planned[lo:hi], color="#3b6ea8", lw=0.8, label="planned")
    bottom.set_title(f"Detail: {t[lo]:.0f}-{t[hi - 1]:.0f} s", fontsize=10)
    bottom.set_xlabel("time, s")
    bottom.set_ylabel("mm/s")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    return fig


def breakdown_chart(breakdown: dict[str, Any]) -> "Figure | None":
    """Horizontal bars of time and distance per feature or tool."""
    rows = breakdown["rows"]
    if not rows:
        return None
    labels = [r["label"] for r in rows]
    height = 0.3 * len(rows) + 1.3
    label_in = 0.07 * max(len(label) for label in labels) + 0.15  # 8-point labels, about 0.07 in a character
    fig = _figure(height, left=min(label_in / WIDTH_IN, 0.4), right=0.98, bottom=0.55 / height, top=1 - 0.3 / height,
                  wspace=0.05)
    left, right = fig.subplots(1, 2, sharey=True)
    y = np.arange(len(rows))
    left.barh(y, [r["time_s"] / 60 for r in rows], color="#3b6ea8")
    right.barh(y, [r["distance_mm"] / 1000 for r in rows], color="#55a868")
    left.set_yticks(y, labels, fontsize=8)
    left.invert_yaxis()
    left.set_xlabel("time, min")
    right.set_xlabel("distance, m")
    left.set_title(f"Time by {breakdown['by']}", fontsize=10)
    right.set_title(f"Distance by {breakdown['by']}", fontsize=10)
    for ax in (left, right):
        ax.grid(axis="x", alpha=0.3)
    return fig


def data_uri(fig: "Figure") -> str:
    """A PNG ``data:`` URI of a figure."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def report_figures(op: "Operation", data: dict[str, Any] | None,
                   only: Collection[str] = FIGURES) -> dict[str, str | None]:
    """The pictures ``only`` of a report as ``data:`` URIs, keyed by their names in :data:`FIGURES` (None
    when absent).

    ``data`` (from :func:`~gcodekit.report.build.report_data`) is needed for
    the pictures not in :data:`OP_FIGURES`; with it None, ``only`` names
    some of those.
    """
    load_drawing_modules()
    drawing = toolpath_drawing(op) if {"iso", "top", "thumbnails"} & set(only) else None
    drawn = drawing is not None and drawing.segments.size > 0
    figures: dict[str, Any] = dict.fromkeys(only)
    if drawn and "iso" in only:
        figures["iso"] = toolpath_iso(drawing)
    if drawn and "top" in only:
        figures["top"] = toolpath_top(drawing)
    if drawn and "thumbnails" in only and op.process == "additive" and np.any(op.layers >= 0):  # data["layers"]
        figures["thumbnails"] = layer_thumbnails(drawing)
    if "velocity" in only:
        figures["velocity"] = velocity(op)
    if "layer_times" in only and data["layers"]:
        figures["layer_times"] = layer_times(data["layers"], data.get("slicer_layers") or [])
    if "breakdown" in only:
        figures["breakdown"] = breakdown_chart(data["breakdown"])
    uris = {name: None if fig is None else data_uri(fig) for name, fig in figures.items()}
    if "part" in only and data.get("cut"):
        uris["part"] = png_uri(data["cut"]["result"].picture(window_size=(1000, 700)))
    return uris


def load_drawing_modules() -> None:
    """Import what drawing the pictures needs (matplotlib off-screen, PIL's PNG writer): once, before a
    fork, rather than in both processes."""
    import matplotlib

    matplotlib.use("Agg", force=False)  # off-screen even when a display is set
    import matplotlib.collections  # noqa: F401
    import matplotlib.figure  # noqa: F401
    from PIL import Image

    from .. import analysis, visualize  # noqa: F401

    Image.preinit()


def png_uri(image: np.ndarray) -> str:
    """A PNG ``data:`` URI of an image array (height, width, 3)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.asarray(image, np.uint8)).save(buf, format="PNG", optimize=True)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
