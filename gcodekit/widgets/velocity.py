"""Widgets stage: VelocityPlot, commanded feed against the planner's speed.

The profile (four corners per planned move, as
:func:`gcodekit.analysis.velocity_corners` lays them out) can hold 12 M
points on a 3 M-line print; the plot keeps one row per move
(:class:`gcodekit.view.velocity.VelocityMoves`) and the browser gets at most
a few thousand points for the range shown: every corner when they fit, made
for those moves only, else the lowest and highest speed per bin (a line plot
drawn at pixel density looks the same), from each move's extremes.
``link(viewer)`` follows a :class:`LayerViewer`'s range.
"""

from __future__ import annotations

import html
from pathlib import Path

import anywidget
import ipywidgets as widgets
import numpy as np
import traitlets

from ..view import Toolpath, ToolpathError, move_rows, source_lines
from .display import PictureDisplay, friendly, message_html
from .picture import import_in_background, message_figure, new_figure
from .toolpath import load_source

#: Bins of the envelope: about one per pixel of a notebook-wide plot.
BINS = 1200
X_LABELS = {"time": "time (s)", "distance": "distance (mm)"}


class VelocityView(anywidget.AnyWidget):
    """The canvas plot: the points of the range shown and how to draw them."""

    _esm = Path(__file__).parent / "static" / "velocity.js"
    x = traitlets.Bytes(b"").tag(sync=True)
    planned_lo = traitlets.Bytes(b"").tag(sync=True)
    planned_hi = traitlets.Bytes(b"").tag(sync=True)
    commanded = traitlets.Bytes(b"").tag(sync=True)
    line = traitlets.Bytes(b"").tag(sync=True)
    move = traitlets.Bytes(b"").tag(sync=True)
    mode = traitlets.Unicode("raw").tag(sync=True)
    corners = traitlets.Int(4).tag(sync=True)
    range = traitlets.List(traitlets.Float(), default_value=[0.0, 1.0]).tag(sync=True)
    ymax = traitlets.Float(1.0).tag(sync=True)
    x_label = traitlets.Unicode("time (s)").tag(sync=True)
    title = traitlets.Unicode("").tag(sync=True)
    picked = traitlets.List().tag(sync=True)
    height = traitlets.Int(300).tag(sync=True)


class VelocityPlot(PictureDisplay):
    """Planned speed (accelerating, cruising, decelerating) and commanded feed over time or distance.

    Parameters
    ----------
    op : Operation, AdditivePart or path
    layers : (int, int), default: None
        Layers (or Z levels) to show, both included; None shows the whole program.
    x : {"time", "distance"}, default: "time"
    height : int, default: 300

    Attributes
    ----------
    range : tuple of float
        The x range shown.
    picked : ipywidgets.HTML
        The move and source line of the point last clicked.

    Examples
    --------
    ::

        plot = VelocityPlot(op, layers=(3, 3))
        plot.link(viewer)   # follows viewer.layers and viewer.moves
    """

    def __init__(self, op, layers: tuple[int, int] | None = None, x: str = "time", *, height: int = 300):
        from ..errors import check_choice

        check_choice("x", x, tuple(X_LABELS))
        import_in_background()  # the display's PNG needs matplotlib: loaded while this widget is built
        self.x_name = x
        self.error: str | None = None
        self.source = None
        self._path: Toolpath | None = None
        self._linked = None
        self.view = VelocityView(height=height, x_label=X_LABELS[x], layout=widgets.Layout(width="100%"))
        self.picked = widgets.HTML()
        try:
            self.source = load_source(op)
            self._profile()
        except ToolpathError as exc:
            self.error = str(exc)
        except Exception as exc:  # a message in the widget, not a traceback
            self.error = friendly(exc)
        if self.error is not None:
            self.widget = widgets.VBox([widgets.HTML(message_html(self.error))])
            return
        self.view.observe(self._on_pick, "picked")
        self.widget = widgets.VBox([self.view, self.picked], layout=widgets.Layout(width="100%"))
        if layers is None:
            self.show(*self.x_extent)
        else:
            self.show_layers(*layers)

    # -- data ---------------------------------------------------------------------

    @property
    def path(self) -> Toolpath | None:
        """The toolpath whose moves the points name: a linked viewer's, else made when first needed."""
        if self._path is None and self.source is not None:
            self._path = Toolpath.of(self.source)
        return self._path

    def _profile(self) -> None:
        from ..view.velocity import VelocityMoves

        op = getattr(self.source, "operation", self.source)
        self._move_rows, _ = move_rows(op)  # the toolpath's moves (Toolpath.move_rows), or why there are none
        self.op = op
        self.profile = v = VelocityMoves(op)
        if len(v) == 0:
            raise ToolpathError(f"{op.file}: no moves to plot")
        self.corners = v.per_move
        self._waypoint = op.plan[0].waypoint if op.plan is not None else v.moved
        self._starts = v.start(self.x_name)
        # each move's extremes, and one more: reduceat's last index may be the end of the profile
        n = len(v)
        self._lo, self._hi, self._commanded = np.full(n + 1, np.inf), np.full(n + 1, -np.inf), np.full(n + 1, -np.inf)
        v.speed_range(out=(self._lo[:n], self._hi[:n]))
        self._commanded[:n] = v.commanded()
        self.ymax = float(np.fmax.reduce([np.fmax.reduce(self._hi), np.fmax.reduce(self._commanded), 1e-9])) * 1.05

    @property
    def x_extent(self) -> tuple[float, float]:
        """The first and last corner's x: the whole program."""
        last = self.profile.corners(len(self.profile) - 1, None, (self.x_name,))[self.x_name]
        return float(self._starts[0]), float(last[-1])

    def moves_of(self, points: np.ndarray) -> np.ndarray:
        """The toolpath move (index of ``path.move_rows``) of each of the profile's points ``points``."""
        rows = self._move_rows
        return np.clip(np.searchsorted(rows, self._waypoint[np.asarray(points) // self.corners]), 0, len(rows) - 1)

    def corner_index(self, x: np.ndarray, side: str = "left") -> np.ndarray:
        """``np.searchsorted`` of ``x`` in every corner's x, found from each move's first corner and one move's corners."""
        x = np.atleast_1d(np.asarray(x, float))
        m = np.searchsorted(self._starts, x, side=side) - 1  # the last move starting before x (at or before: right)
        inside = m >= 0
        own = self.profile.corners_of(np.maximum(m, 0), (self.x_name,))[self.x_name].reshape(-1, self.corners)
        count = (own < x[:, None]) if side == "left" else (own <= x[:, None])
        return np.where(inside, m * self.corners + count.sum(axis=1), 0)

    def points(self, x0: float, x1: float, bins: int = BINS) -> dict[str, np.ndarray]:
        """What is drawn for ``x0..x1``: every corner, or per-bin min/max when more than ``3 * bins``.

        Returns ``x, lo, hi, commanded, line, move`` and ``mode`` (``"raw"`` or ``"binned"``).
        """
        c = self.corners
        a, b = int(self.corner_index(x0, "left")[0]), int(self.corner_index(x1, "right")[0])
        a = max(a - 1, 0)  # the corner before the range starts its first line
        a -= a % c  # whole moves: corner k of the points is then corner k % corners of its move
        if b - a <= 3 * bins:
            got = self.profile.corners(a // c, -(-b // c), (self.x_name, "planned", "commanded", "line"))
            planned = got["planned"][:b - a]
            return {"x": got[self.x_name][:b - a], "lo": planned, "hi": planned,
                    "commanded": got["commanded"][:b - a], "line": got["line"][:b - a],
                    "move": self.moves_of(np.arange(a, b)), "mode": "raw"}
        edges = np.linspace(x0, x1, bins + 1)
        starts = np.unique(np.clip(self.corner_index(edges[:-1], "left") - a, 0, b - a))
        first = a + starts[starts < b - a]  # each bin's first corner; the last bin ends at b
        lo, hi, commanded = self._bins(first, b)
        x = self.profile.corners_of(first // c, (self.x_name,))[self.x_name].reshape(-1, c)
        return {"x": x[np.arange(first.size), first % c], "lo": lo, "hi": hi, "commanded": commanded,
                "line": self.profile.line[first // c], "move": self.moves_of(first), "mode": "binned"}

    def _bins(self, first: np.ndarray, end: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Lowest and highest planned and highest commanded speed over corners ``first[k]`` to ``first[k + 1]``.

        What ``minimum.reduceat`` over every corner gives, from each move's
        extremes for the moves a bin holds whole and the corners of the (at
        most two) moves it holds in part.
        """
        c, v = self.corners, self.profile
        lo_m, hi_m, cmd_m = self._lo, self._hi, self._commanded
        stop = np.r_[first[1:], end]
        whole0, whole1 = -(-first // c), stop // c  # the moves held whole: [whole0, whole1)
        has_whole = whole1 > whole0
        index = np.column_stack([whole0, np.maximum(whole1, whole0)]).ravel()
        out = []
        for per_move, ufunc, none in ((lo_m, np.minimum, np.inf), (hi_m, np.maximum, -np.inf)):
            value = np.where(has_whole, ufunc.reduceat(per_move, index)[::2], none)
            for move in (first // c, np.minimum(stop // c, len(v) - 1)):  # the first and last move, in part
                corner = move[:, None] * c + np.arange(c)
                held = (corner >= first[:, None]) & (corner < stop[:, None])
                planned = v.corners_of(move, ("planned",))["planned"].reshape(-1, c)
                value = ufunc(value, ufunc.reduce(np.where(held, planned, none), axis=1))
            out.append(value)
        # a move's commanded speed is one for all its corners: the moves the bin touches
        last = (stop - 1) // c
        commanded = np.maximum.reduceat(cmd_m, np.column_stack([first // c, last + 1]).ravel())[::2]
        return out[0], out[1], commanded

    # -- what is shown ---------------------------------------------------------------

    def show(self, x0: float, x1: float) -> None:
        """Show ``x0..x1`` (seconds or millimetres, as ``x``)."""
        if x1 <= x0:
            x1 = x0 + 1e-6
        if getattr(self, "range", None) == (float(x0), float(x1)):
            return  # a linked viewer reports one step through two controls
        self.range = (float(x0), float(x1))
        p = self.points(x0, x1)
        f32 = lambda v: np.asarray(v, np.float32).tobytes()  # noqa: E731
        with self.view.hold_sync():
            self.view.x, self.view.planned_lo, self.view.planned_hi = f32(p["x"]), f32(p["lo"]), f32(p["hi"])
            self.view.commanded = f32(p["commanded"])
            self.view.line = np.asarray(p["line"], np.int32).tobytes()
            self.view.move = np.asarray(p["move"], np.int32).tobytes()
            self.view.mode, self.view.corners = p["mode"], self.corners
            self.view.range, self.view.ymax = list(self.range), self.ymax
            self.view.title = f"{Path(self.op.file).name}: {x0:.6g}-{x1:.6g} {X_LABELS[self.x_name].split(' ')[1]}"

    def show_moves(self, first: int, last: int) -> None:
        """Show the moves ``first..last`` (indices of the toolpath's moves)."""
        start, end = self.path.times(np.array([first, last]))  # two moves' times, not every move's
        t0, t1 = start[0], end[1]
        if self.x_name == "distance":
            t0, t1 = self._distance_at(np.array([t0, t1]))
        self.show(t0, t1)

    def _distance_at(self, t: np.ndarray) -> np.ndarray:
        """Distance travelled at times ``t``: interpolated between the corners of the move around each."""
        v, c = self.profile, self.corners
        m = np.clip(np.searchsorted(v.start("time"), t, side="right") - 1, 0, len(v) - 1)
        got = v.corners_of(m, ("time", "distance"))
        times, dist = got["time"].reshape(-1, c), got["distance"].reshape(-1, c)
        return np.array([np.interp(t[k], times[k], dist[k]) for k in range(t.size)])

    def show_layers(self, lo: int, hi: int) -> None:
        """Show layers (or Z levels) ``lo..hi``."""
        gm = self.path.group_move
        first, last = int(gm[lo]), int(gm[hi + 1]) - 1
        self.show_moves(first, max(last, first))

    def link(self, viewer) -> "VelocityPlot":
        """Follow ``viewer``'s layer range and move slider (a :class:`LayerViewer`); returns self.

        A point clicked here then moves the viewer to that move.
        """
        if self.error is not None or viewer.error is not None:
            return self
        self._linked = viewer
        if viewer.path.op is self.op and self._path is None:
            self._path = viewer.path  # one toolpath for both (a large program's takes seconds to cut)

        def follow(change=None):
            lo, hi = viewer.layers.value
            first, current = int(viewer.path.group_move[lo]), viewer.current_move
            self.show_moves(first, max(current, first))

        viewer.layers.observe(follow, "value")
        viewer.moves.observe(follow, "value")
        follow()
        return self

    def _on_pick(self, change) -> None:
        picked = change["new"]
        if not picked:
            return
        move, line = int(picked[0]), int(picked[1])
        lines = source_lines(self.op) or []
        text = html.escape(lines[line - 1]) if 0 < line <= len(lines) else ""
        self.picked.value = (f'<div class="gcodekit-picked" style="font:12px monospace">move {move}, line {line}: '
                             f'<b>{text}</b></div>')
        if self._linked is not None:
            self._linked.show_move(move)

    def figure(self, size: tuple[int, int] = (900, 300)):
        """The current plot as a matplotlib Figure."""
        if self.error is not None:
            return message_figure(self.error)
        p = self.points(*self.range)
        fig = new_figure(size)
        ax = fig.add_axes([0.07, 0.17, 0.9, 0.72])
        x = p["x"]
        ax.step(x, p["commanded"], where="post", color="#555", linestyle="--", linewidth=1, label="commanded")
        if p["mode"] == "raw" and self.corners == 4:
            colors = np.array(["#2ca02c", "#1f77b4", "#d62728", "#bbbbbb"])
            from matplotlib.collections import LineCollection

            segs = np.stack([np.column_stack([x[:-1], p["hi"][:-1]]), np.column_stack([x[1:], p["hi"][1:]])], axis=1)
            phase = np.arange(x.size - 1) % 4  # the points start at a move's first corner
            ax.add_collection(LineCollection(segs, colors=colors[phase], linewidths=1.3))
            for name, c in zip(("accelerating", "cruising", "decelerating"), colors):
                ax.plot([], [], color=c, label=name)
        elif p["mode"] == "raw":
            ax.plot(x, p["hi"], color="#1f77b4", linewidth=1.2, label="planned")
        else:
            ax.vlines(x, p["lo"], p["hi"], color="#1f77b4", linewidth=0.8, label="planned (min-max per bin)")
        ax.set_xlim(*self.range)
        ax.set_ylim(0, self.ymax)
        ax.set_xlabel(X_LABELS[self.x_name])
        ax.set_ylabel("speed (mm/s)")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(0.0, 1.16), ncol=4, fontsize=8, frameon=False)
        return fig

    def __repr__(self) -> str:
        if self.error is not None:
            return f"<VelocityPlot: {self.error}>"
        return f"<VelocityPlot {Path(self.op.file).name!r}: {self.x_name} {self.range[0]:.6g}-{self.range[1]:.6g}>"
