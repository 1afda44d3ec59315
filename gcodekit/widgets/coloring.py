"""Widgets stage: what colours a toolpath's segments, and the colours.

Values are per segment (one per move, repeated over an arc's chords);
categorical ones (feature, tool) are indices into a list of names.  The
colour tables are plain RGB bytes so the browser view and the pictures
drawn in Python use the very same colours.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .toolpath import Toolpath

#: Titles of the named colourings (any other waypoint column is allowed too).
TITLES = {"feature": "feature", "speed": "planned speed (mm/s)", "feed": "commanded feed (mm/min)",
          "layer": "layer", "time": "elapsed time (s)", "tool": "tool", "flow": "flow (mm³/s)"}
#: Waypoint columns that make no sense as colours.
_HIDDEN = {"command", "motion", "plane", "units", "cx", "cy", "cz"}
#: matplotlib's tab10, then tab20's lighter half: one colour per category.
PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf", "#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7",
           "#dbdb8d", "#9edae5"]
TRAVEL_COLOR = "#9a9a9a"


@dataclass
class Coloring:
    """Per-segment values of one colouring.

    ``categories`` names the values ``0, 1, ...`` of a categorical colouring
    (None for a continuous one).
    """

    by: str
    values: np.ndarray
    categories: list[str] | None
    title: str

    def shown_range(self, values: np.ndarray) -> tuple[float, float]:
        """Lowest and highest finite value among ``values`` (0, 1 when none)."""
        finite = values[np.isfinite(values)]
        if finite.size == 0:
            return 0.0, 1.0
        return float(finite.min()), float(finite.max())

    def rgb(self, values: np.ndarray, vmin: float, vmax: float) -> np.ndarray:
        """RGB in 0-1 for ``values`` with the colour scale over ``vmin..vmax``."""
        if self.categories is not None:
            return palette_rgb(len(self.categories))[np.asarray(values, np.int64) % max(len(self.categories), 1)]
        span = vmax - vmin if vmax > vmin else 1.0
        k = np.clip(np.nan_to_num((values - vmin) / span), 0.0, 1.0)
        return colormap_table()[np.round(k * 255).astype(np.int64)] / 255.0


def choices(path: "Toolpath") -> list[str]:
    """The colourings a program offers: the named ones it has data for, then its waypoint columns."""
    op = path.op
    named = []
    if op.flavor is not None and op.flavor.feature_comment and (op.features != "").any():
        named.append("feature")
    named += ["speed", "feed"]
    if path.group_by == "layer":
        named.append("layer")
    named += ["time", "tool"]
    if hasattr(op, "deposited_volumes"):
        named.append("flow")
    rows = path.move_rows
    # a column that never changes over the moves would paint everything one colour
    columns = sorted(k for k, v in op.waypoints.items()
                     if k not in _HIDDEN and k not in named and np.ptp(np.asarray(v, float)[rows]) > 0)
    return named + columns


def coloring(path: "Toolpath", by: str) -> Coloring:
    """The per-segment values of colouring ``by`` (see :func:`choices`)."""
    from ..errors import check_choice
    from ..visualize import waypoint_scalars

    check_choice("color_by", by, choices(path))
    op, rows = path.op, path.move_rows
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
        used, per_move = np.unique(per_move.astype(np.int64), return_inverse=True)
        categories = [categories[k] for k in used]
    return Coloring(by, per_move.astype(np.float32)[path.move_of], categories, TITLES.get(by, by))


@lru_cache(maxsize=1)
def colormap_table() -> np.ndarray:
    """viridis as 256 x 3 uint8."""
    from matplotlib import colormaps

    return np.round(colormaps["viridis"](np.linspace(0.0, 1.0, 256))[:, :3] * 255).astype(np.uint8)


def palette_rgb(n: int) -> np.ndarray:
    """``n`` category colours (cycling after 20), RGB in 0-1."""
    table = np.array([[int(h[i:i + 2], 16) for i in (1, 3, 5)] for h in PALETTE], float) / 255.0
    return table[np.arange(max(n, 1)) % len(PALETTE)]
