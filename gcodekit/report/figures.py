"""Report stage: the pictures of a report, drawn off-screen with matplotlib.

Each function returns a matplotlib Figure; :func:`report_figures` draws them
all and returns them as ``data:`` URIs so a page embeds them and works
offline.  Large programs are thinned before drawing (every k-th layer in 3D,
every k-th segment elsewhere, binned speeds) so a 150 k-line print draws in
about a second: a picture 800 pixels wide cannot show more anyway.
"""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..emulate.arcs import PLANES, sweep

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..model.operation import Operation

#: Segments drawn in the 3D view and the top view (beyond this they only add ink).
MAX_3D_SEGMENTS = 25_000
MAX_2D_SEGMENTS = 60_000
#: Chords per arc: 16 keeps a 100 mm arc within 0.5 mm of the circle at report scale.
ARC_CHORDS = 16
THUMBNAILS = 12
#: The pictures of a report page.
FIGURES = ("iso", "top", "layer_times", "thumbnails", "velocity", "breakdown", "part")
DPI = 100
WIDTH_IN = 8.0


@dataclass
class Segments:
    """Straight pieces of the toolpath, with what colours them.

    ``start``/``end`` (n, 3) mm; ``value`` a category index (``labels``) or a
    speed in mm/s (``labels`` None); ``layer`` per segment (-1 without layers);
    ``rapid`` True for rapid (or additive travel) moves.
    """

    start: np.ndarray
    end: np.ndarray
    value: np.ndarray
    layer: np.ndarray
    rapid: np.ndarray
    labels: list[str] | None

    def take(self, keep: np.ndarray) -> "Segments":
        return Segments(self.start[keep], self.end[keep], self.value[keep], self.layer[keep], self.rapid[keep],
                        self.labels)


def toolpath_segments(op: "Operation") -> Segments:
    """The moves of an operation as straight segments, arcs split into chords.

    Additive programs keep only the depositing moves, coloured by slicer
    feature when the program names them; others keep every move, coloured by
    commanded speed, with rapids flagged.
    """
    w = op.waypoints
    additive = op.process == "additive"
    xyz = np.column_stack([w["x"], w["y"], w["z"]]).astype(float)
    prev = np.vstack([xyz[:1], xyz[:-1]])
    keep = op.depositing if additive else op.moving
    idx = np.flatnonzero(keep)
    labels = None
    if additive:
        names = op.features
        if np.any(names != ""):
            labels, value = np.unique(names, return_inverse=True)
            labels = [str(x) or "(no feature)" for x in labels]
        else:
            value = np.asarray(w["feed"], float) / 60.0
        layer = op.layers
    else:
        value = np.asarray(w["feed"], float) / 60.0
        layer = np.full(xyz.shape[0], -1)
    start, end = prev[idx], xyz[idx]
    owner = idx
    arcs = np.isin(np.asarray(w["motion"])[idx], (3, 4))
    if arcs.any():
        a = idx[arcs]
        pts = _arc_points(w, a, prev[a], xyz[a])  # (m, ARC_CHORDS + 1, 3)
        arc_start = pts[:, :-1].reshape(-1, 3)
        arc_end = pts[:, 1:].reshape(-1, 3)
        straight = idx[~arcs]
        start = np.vstack([prev[straight], arc_start])
        end = np.vstack([xyz[straight], arc_end])
        owner = np.r_[straight, np.repeat(a, ARC_CHORDS)]
        order = np.argsort(owner, kind="stable")
        start, end, owner = start[order], end[order], owner[order]
    rapid = np.asarray(w["motion"])[owner] == 1
    return Segments(start, end, np.asarray(value)[owner], np.asarray(layer)[owner], rapid, labels)


def _arc_points(w: dict, rows: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Points along the arcs ending at waypoints ``rows`` (plane from ``plane``, centre
    ``cx, cy, cz``), the helix axis interpolated."""
    motion = np.asarray(w["motion"])
    center = np.column_stack([w["cx"], w["cy"], w["cz"]]).astype(float)[rows]
    plane = np.asarray(w["plane"])[rows]
    out = np.empty((rows.size, ARC_CHORDS + 1, 3))
    f = np.linspace(0.0, 1.0, ARC_CHORDS + 1)
    for code, ((i, j, h), _) in PLANES.items():
        sel = plane == code
        if not sel.any():
            continue
        s, e, c = start[sel], end[sel], center[sel]
        cw = motion[rows][sel] == 3
        angle = sweep(s[:, [i, j]], e[:, [i, j]], c[:, [i, j]], cw, np.ones(sel.sum()))
        a0 = np.arctan2(s[:, j] - c[:, j], s[:, i] - c[:, i])
        r = np.hypot(s[:, i] - c[:, i], s[:, j] - c[:, j])
        theta = a0[:, None] + np.where(cw, -1.0, 1.0)[:, None] * angle[:, None] * f
        out[sel, :, i] = c[:, i, None] + r[:, None] * np.cos(theta)
        out[sel, :, j] = c[:, j, None] + r[:, None] * np.sin(theta)
        out[sel, :, h] = s[:, h, None] + (e[:, h] - s[:, h])[:, None] * f
    return out


def _thin(seg: Segments, limit: int, by_layer: bool) -> Segments:
    """At most about ``limit`` segments: every k-th layer when layered, else every k-th segment."""
    n = seg.start.shape[0]
    if n <= limit:
        return seg
    if by_layer and (seg.layer >= 0).any():
        ids = np.unique(seg.layer[seg.layer >= 0])
        step = int(np.ceil(n / limit))
        chosen = ids[::step]
        if chosen[-1] != ids[-1]:
            chosen = np.r_[chosen, ids[-1]]  # keep the top layer: it is what the part looks like
        kept = seg.take(np.isin(seg.layer, chosen))
        if kept.start.shape[0] <= 2 * limit:
            return kept
        seg = kept
        n = seg.start.shape[0]
    return seg.take(np.arange(0, n, int(np.ceil(n / limit))))


def _colours(seg: Segments):
    """RGBA per segment and what to put in a legend or colour bar."""
    import matplotlib as mpl

    if seg.labels is not None:
        cmap = mpl.colormaps["tab10" if len(seg.labels) <= 10 else "tab20"]
        return cmap(seg.value.astype(int) % cmap.N), ("legend", [(lab, cmap(k % cmap.N))
                                                                 for k, lab in enumerate(seg.labels)])
    finite = seg.value[np.isfinite(seg.value) & ~seg.rapid]
    hi = float(np.percentile(finite, 99)) if finite.size else 1.0
    lo = float(finite.min()) if finite.size else 0.0
    norm = mpl.colors.Normalize(lo, hi if hi > lo else lo + 1.0)
    colours = mpl.colormaps["viridis"](norm(np.nan_to_num(seg.value)))
    colours[seg.rapid] = (0.6, 0.6, 0.6, 0.5)
    return colours, ("colorbar", mpl.cm.ScalarMappable(norm=norm, cmap="viridis"))


def _key(fig: "Figure", ax, key, seg: Segments) -> None:
    kind, what = key
    shown = set(np.unique(seg.value).astype(int).tolist()) if kind == "legend" else set()
    if kind == "legend":
        from matplotlib.lines import Line2D

        handles = [Line2D([], [], color=c, lw=3, label=lab) for k, (lab, c) in enumerate(what) if k in shown]
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    else:
        fig.colorbar(what, ax=ax, shrink=0.7, pad=0.08, label="commanded speed, mm/s")


def _figure(height: float, **margins: float) -> "Figure":
    """A figure of the report's width with fixed margins (fractions of the figure).

    Fixed margins instead of matplotlib's constrained layout, which draws
    every figure twice more and took 40 % of a report's drawing time.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(WIDTH_IN, height), dpi=DPI)
    fig.subplots_adjust(**margins)
    return fig


def toolpath_iso(seg: Segments) -> "Figure":
    """Isometric 3D view of the toolpath (orthographic, equal axes).

    A print shows its layers only: a purge line drawn before the first layer
    would otherwise shrink the part to a corner of the picture (the top view
    shows it).
    """
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    if (seg.layer >= 0).any():
        seg = seg.take(seg.layer >= 0)
    seg = _thin(seg, MAX_3D_SEGMENTS, by_layer=True)
    fig = _figure(5.0, left=0.0, right=0.8, bottom=0.02, top=1.0)
    ax = fig.add_subplot(projection="3d", proj_type="ortho")
    colours, key = _colours(seg)
    ax.add_collection3d(Line3DCollection(np.stack([seg.start, seg.end], axis=1), colors=colours, linewidths=0.6))
    lo = np.minimum(seg.start.min(axis=0), seg.end.min(axis=0)) if len(seg.start) else np.zeros(3)
    hi = np.maximum(seg.start.max(axis=0), seg.end.max(axis=0)) if len(seg.start) else np.ones(3)
    span = np.maximum(hi - lo, 1e-3 * max(float((hi - lo).max()), 1.0))
    ax.set_xlim(lo[0], lo[0] + span[0])
    ax.set_ylim(lo[1], lo[1] + span[1])
    ax.set_zlim(lo[2], lo[2] + span[2])
    # equal scales, except that a flat part (a mill pass, a first layer) keeps a readable height
    ax.set_box_aspect((span[0], span[1], max(span[2], 0.25 * max(span[0], span[1]))))
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(6))
    ax.view_init(elev=35.264, azim=-45)  # isometric: arctan(1/sqrt 2) above the XY diagonal
    ax.set_xlabel("X, mm")
    ax.set_ylabel("Y, mm")
    ax.set_zlabel("Z, mm")
    ax.tick_params(labelsize=7)
    _key(fig, ax, key, seg)
    return fig


def toolpath_top(seg: Segments) -> "Figure":
    """Top view (XY) of the whole toolpath."""
    from matplotlib.collections import LineCollection

    seg = _thin(seg, MAX_2D_SEGMENTS, by_layer=False)
    fig = _figure(4.6, left=0.09, right=0.8, bottom=0.1, top=0.93)
    ax = fig.add_subplot()
    colours, key = _colours(seg)
    ax.add_collection(LineCollection(np.stack([seg.start[:, :2], seg.end[:, :2]], axis=1), colors=colours,
                                     linewidths=0.5))
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("X, mm")
    ax.set_ylabel("Y, mm")
    ax.set_title("Top view", fontsize=10)
    _key(fig, ax, key, seg)
    return fig


def layer_thumbnails(seg: Segments, count: int = THUMBNAILS) -> "Figure | None":
    """Small XY views of ``count`` layers spread over the height, on the part's extents."""
    from matplotlib.collections import LineCollection

    ids = np.unique(seg.layer[seg.layer >= 0])
    if ids.size == 0:
        return None
    chosen = ids[np.unique(np.linspace(0, ids.size - 1, min(count, ids.size)).round().astype(int))]
    cols = 6
    rows = int(np.ceil(chosen.size / cols))
    fig = _figure(1.45 * rows + 0.2, left=0.01, right=0.99, bottom=0.02, top=0.92, wspace=0.08, hspace=0.25)
    colours, _ = _colours(seg)
    layered = seg.layer >= 0  # the extents of the layers, not of a purge line drawn before them
    lo, hi = seg.start[layered, :2].min(axis=0), seg.start[layered, :2].max(axis=0)
    pad = 0.03 * max(float((hi - lo).max()), 1.0)
    lo, hi = lo - pad, hi + pad
    for k, layer in enumerate(chosen):
        ax = fig.add_subplot(rows, cols, k + 1)
        sel = seg.layer == layer
        ax.add_collection(LineCollection(np.stack([seg.start[sel, :2], seg.end[sel, :2]], axis=1),
                                         colors=colours[sel], linewidths=0.4))
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"layer {int(layer)}", fontsize=7)
    return fig


def layer_times(rows: list[dict[str, Any]], slicer_rows: list[dict[str, Any]] = ()) -> "Figure | None":
    """Planned time of each layer (bars) and, when the file has progress marks, the slicer's (a step line).

    The slicer's time between two marks is spread evenly over the layers
    between them (Cura marks every layer; PrusaSlicer's M73 only where its
    minutes left change).
    """
    if not rows:
        return None
    from matplotlib.ticker import MaxNLocator

    fig = _figure(2.8, left=0.08, right=0.98, bottom=0.16, top=0.9)
    ax = fig.add_subplot()
    ax.bar([r["layer"] for r in rows], [r["time_s"] for r in rows], width=1.0, color="#3b6ea8",
           label="gcodekit (planned)")
    if slicer_rows:
        edges = [slicer_rows[0]["layer"] - slicer_rows[0]["layers"] + 0.5] + [r["layer"] + 0.5 for r in slicer_rows]
        per_layer = [r["slicer_time_s"] / r["layers"] for r in slicer_rows]
        ax.stairs(per_layer, edges, color="#d9822b", linewidth=1.2, label="slicer's marks")
        ax.legend(fontsize=7, loc="upper right")
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
    v = op.velocity_profile()
    if v.empty:
        return None
    t, planned, commanded = (v[c].to_numpy(float) for c in ("time", "planned", "commanded"))
    fig = _figure(4.4, left=0.08, right=0.98, bottom=0.1, top=0.94, hspace=0.42)
    top, bottom = fig.subplots(2, 1)
    # mean speed per bin from the running integrals: planned distance, and commanded speed times time
    edges = np.linspace(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0, bins + 1)
    dt = np.diff(t)
    commanded_d = np.r_[0.0, np.cumsum(commanded[:-1] * dt)]
    for running, label, colour in ((commanded_d, "commanded", "#c44e52"),
                                   (v["distance"].to_numpy(float), "planned", "#3b6ea8")):
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


def report_figures(op: "Operation", data: dict[str, Any]) -> dict[str, str]:
    """Every picture of a report as a ``data:`` URI, keyed by the names in :data:`FIGURES` (None when absent)."""
    import matplotlib

    matplotlib.use("Agg", force=False)  # off-screen even when a display is set
    seg = toolpath_segments(op)
    figures: dict[str, Any] = dict.fromkeys(FIGURES)
    if seg.start.shape[0]:
        figures["iso"] = toolpath_iso(seg)
        figures["top"] = toolpath_top(seg)
    if data["layers"]:
        figures["layer_times"] = layer_times(data["layers"], data.get("slicer_layers") or [])
        figures["thumbnails"] = layer_thumbnails(seg) if seg.start.shape[0] else None
    figures["velocity"] = velocity(op)
    figures["breakdown"] = breakdown_chart(data["breakdown"])
    uris = {name: None if fig is None else data_uri(fig) for name, fig in figures.items()}
    if data.get("cut"):
        uris["part"] = png_uri(data["cut"]["result"].picture(window_size=(1000, 700)))
    return uris


def png_uri(image: np.ndarray) -> str:
    """A PNG ``data:`` URI of an image array (height, width, 3)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.asarray(image, np.uint8)).save(buf, format="PNG", optimize=True)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
