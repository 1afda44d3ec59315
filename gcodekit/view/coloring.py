"""Output stage: what colours a toolpath's segments, and the colours.

A :class:`Coloring` holds one value per segment of a
:class:`~gcodekit.view.toolpath.Toolpath`: a category index (feature, tool)
or a number (speed, feed, layer, time, flow, any waypoint column).  The
colours are two tables of RGB bytes, :data:`PALETTE` for categories and
viridis for numbers, and one rule for the colour scale (the lowest to the
highest value of the work drawn), so the WebGL viewer, the PyVista and
matplotlib pictures and the report paint a program the same way.

Examples
--------
>>> import gcodekit
>>> from gcodekit.view import Toolpath, coloring
>>> op = gcodekit.gcode_to_operation("G0 X0\\nG1 X10 F600\\nG1 Y10 F1200\\n", "linuxcnc", plan=False)
>>> c = coloring(Toolpath.of(op), "feed")
>>> c.values.tolist(), c.value_range(), c.categories is None
([600.0, 1200.0], (600.0, 1200.0), True)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from ..errors import check_choice
from .toolpath import WORK, Toolpath

if TYPE_CHECKING:
    from matplotlib.colors import ListedColormap

    from ..model.operation import Operation

#: Titles of the named colourings (any other waypoint column is allowed too, titled by its name).
TITLES = {"feature": "feature", "speed": "planned speed (mm/s)", "feed": "commanded feed (mm/min)",
          "layer": "layer", "time": "elapsed time (s)", "tool": "tool", "flow": "flow (mm³/s)",
          "laser": "heat source on"}
#: Waypoint columns that make no sense as colours.
HIDDEN = frozenset({"command", "motion", "plane", "units", "cx", "cy", "cz"})
#: One colour per category: matplotlib's tab10, then tab20's lighter half (cycling after 20).
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf", "#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7",
           "#dbdb8d", "#9edae5")
#: Travel (moves that lay no material, rapids) when drawn: one grey.
TRAVEL_COLOR = "#9a9a9a"
#: Moves looked at first to see whether a waypoint column varies (the whole column only when these do not).
VARIES_FROM = 64
#: Name of a category for waypoints before the first feature comment.
NO_FEATURE = "(none)"


def waypoint_scalars(op: "Operation", by: str) -> tuple[np.ndarray, list[str] | None]:
    """Values of colouring ``by`` at every waypoint, and category names for a categorical one.

    ``feature`` (slicer ``;TYPE:`` or DED fraction comments), ``speed`` (each
    move's length over its planned time, mm/s), ``layer``, ``time`` (elapsed,
    s), or any waypoint column (``feed``, ``tool``, ``laser``, ``z`` ...).
    """
    w = op.waypoints
    if by == "feature":
        # a few names over millions of waypoints: the comments' codes renumbered (strings took seconds)
        codes, labels = op.feature_codes
        present = np.flatnonzero(np.bincount(codes, minlength=len(labels)))
        names = sorted({labels[k] for k in present})
        index = {name: k for k, name in enumerate(names)}
        table = np.zeros(len(labels), np.int32)
        table[present] = [index[labels[k]] for k in present]
        return table[codes], [n or NO_FEATURE for n in names]
    if by == "speed":
        d, t = np.asarray(w["distance"], float), np.nan_to_num(np.asarray(w["time"], float))
        return np.divide(d, t, out=np.zeros_like(d), where=t > 0), None
    if by == "layer":
        return op.layers, None
    if by in ("time", "elapsed_time"):
        return op.elapsed_time(), None
    check_choice("color_by", by, [*TITLES, *sorted(k for k in w if k not in TITLES and k not in HIDDEN)])
    return np.asarray(w[by]), None


def has_features(op: "Operation") -> bool:
    """Whether the program names its features (slicer ``;TYPE:`` comments)."""
    if op.flavor is None or not op.flavor.feature_comment:
        return False
    codes, labels = op.feature_codes
    return any(labels[k] for k in np.flatnonzero(np.bincount(codes, minlength=len(labels))))


def default_coloring(op: "Operation") -> str:
    """``feature`` when the program names its features, else ``layer`` (additive) or ``feed``."""
    if has_features(op):
        return "feature"
    return "layer" if op.process == "additive" else "feed"


def choices(path: Toolpath) -> list[str]:
    """The colourings a program offers: the named ones it has data for, then its varying waypoint columns."""
    op = path.op
    named = ["feature"] if has_features(op) else []
    named += ["speed", "feed"]
    if path.group_by == "layer":
        named.append("layer")
    named += ["time", "tool"]
    if op.process == "additive":
        named.append("flow")
    moves = np.zeros(len(op.waypoints["x"]), bool)
    moves[path.move_rows] = True
    # a column that never changes over the moves would paint everything one colour
    columns = sorted(k for k, v in op.waypoints.items()
                     if k not in HIDDEN and k not in named and _varies(np.asarray(v), path.move_rows, moves))
    return named + columns


def _varies(values: np.ndarray, rows: np.ndarray, where: np.ndarray) -> bool:
    """Whether ``values`` differ among the waypoints ``rows`` (``where`` marks them), NaN counting as unknown."""
    head = values[rows[:VARIES_FROM]].astype(float)
    if head.min() < head.max() and (values.dtype.kind != "f" or not np.isnan(values).any()):
        return True  # seen among the first moves: most columns that vary do so at once
    if values.dtype.kind != "f":
        values = values.astype(float)
    # reduced in place (no copy of the selected values); a NaN among them gives False
    return bool(values.max(where=where, initial=-np.inf) > values.min(where=where, initial=np.inf))


@dataclass
class Coloring:
    """One value per segment of a toolpath, and how values become colours.

    Attributes
    ----------
    by : str
        The colouring's name (``feature``, ``speed``, a waypoint column ...).
    values : ndarray (n,) float32
        Per segment: a category index, or a number.
    categories : list of str or None
        Names of the values ``0, 1, ...`` of a categorical colouring; None for a continuous one.
    title : str
        What the legend or colour bar is titled.
    """

    by: str
    values: np.ndarray
    categories: list[str] | None
    title: str

    def value_range(self, segments: np.ndarray | slice = slice(None)) -> tuple[float, float]:
        """Lowest and highest finite value among ``segments`` (0, 1 when none): the colour scale's ends."""
        values = self.values[segments]
        finite = values[np.isfinite(values)]
        if finite.size == 0:
            return 0.0, 1.0
        return float(finite.min()), float(finite.max())

    def table(self) -> np.ndarray:
        """The colours as (k, 3) uint8: one per category, or viridis' 256 steps."""
        if self.categories is not None:
            return np.round(palette_rgb(len(self.categories)) * 255).astype(np.uint8)
        return colormap_table()

    def rgb(self, values: np.ndarray, vmin: float, vmax: float) -> np.ndarray:
        """RGB in 0-1 for ``values`` with the colour scale over ``vmin..vmax``."""
        if self.categories is not None:
            return palette_rgb(len(self.categories))[np.asarray(values, np.int64) % max(len(self.categories), 1)]
        span = vmax - vmin if vmax > vmin else 1.0
        k = np.clip(np.nan_to_num((np.asarray(values, float) - vmin) / span), 0.0, 1.0)
        return colormap_table()[np.round(k * 255).astype(np.int64)] / 255.0

    def segment_rgb(self, path: Toolpath, segments: np.ndarray) -> tuple[np.ndarray, float, float]:
        """RGB (0-1) of ``segments`` of ``path``: work by value, travel :data:`TRAVEL_COLOR`.

        The scale spans the work among ``segments``; returns the colours and its ends.
        """
        work = path.kind[segments] == WORK
        vmin, vmax = self.value_range(segments[work])
        rgb = np.tile(hex_rgb(TRAVEL_COLOR), (segments.size, 1))
        rgb[work] = self.rgb(self.values[segments[work]], vmin, vmax)
        return rgb, vmin, vmax

    def used(self, segments: np.ndarray) -> list[int]:
        """The categories among ``segments`` (all of them for a continuous colouring: none)."""
        if self.categories is None:
            return []
        return np.unique(self.values[segments].astype(np.int64)).tolist()

    def cmap(self) -> "ListedColormap":
        """:meth:`table` as a matplotlib colormap (for a colour bar, or PyVista's ``cmap``)."""
        from matplotlib.colors import ListedColormap

        return ListedColormap(self.table() / 255.0)


def coloring(path: Toolpath, by: str, offered: list[str] | None = None) -> Coloring:
    """The per-segment values of colouring ``by`` (see :func:`choices`; ``offered``: what it returned, if known).

    A categorical colouring keeps only the categories the moves have, in order.
    """
    op, rows = path.op, path.move_rows
    offered = choices(path) if offered is None else offered
    # what the program offers first; any named colouring or waypoint column is drawn when asked for
    check_choice("color_by", by, [*offered, *(k for k in [*TITLES, *sorted(op.waypoints)]
                                              if k not in offered and k not in HIDDEN and k != "flow")])
    categories = None
    if by == "flow":
        time = np.nan_to_num(np.asarray(op.waypoints["time"], float))
        volume = np.nan_to_num(op.deposited_volumes())
        per_move = np.divide(volume, time, out=np.zeros_like(time), where=time > 0)[rows]
    elif by == "layer" and path.group_by == "layer":
        per_move = np.searchsorted(path.group_move, np.arange(rows.size), side="right") - 1.0
    else:
        values, categories = waypoint_scalars(op, by)
        per_move = np.asarray(values, float)[rows]
        if by == "tool":  # a handful of tools: name them rather than scale them
            tools, per_move = np.unique(per_move, return_inverse=True)
            categories = [f"T{int(t)}" for t in tools]
    if categories is not None:
        codes = per_move.astype(np.int64)
        present = np.bincount(codes, minlength=len(categories)) > 0
        per_move = (np.cumsum(present) - 1)[codes]  # the categories renumbered in order, as np.unique would
        categories = [categories[k] for k in np.flatnonzero(present)]
    return Coloring(by, per_move.astype(np.float32)[path.move_of], categories, TITLES.get(by, by))


@lru_cache(maxsize=1)
def colormap_table() -> np.ndarray:
    """viridis as 256 x 3 uint8."""
    from matplotlib import colormaps

    return np.round(colormaps["viridis"](np.linspace(0.0, 1.0, 256))[:, :3] * 255).astype(np.uint8)


def hex_rgb(color: str) -> np.ndarray:
    """``"#rrggbb"`` as RGB in 0-1."""
    return np.array([int(color[i:i + 2], 16) for i in (1, 3, 5)], float) / 255.0


def palette_rgb(n: int) -> np.ndarray:
    """``n`` category colours (cycling after 20), RGB in 0-1."""
    table = np.array([hex_rgb(h) for h in PALETTE])
    return table[np.arange(max(n, 1)) % len(PALETTE)]
