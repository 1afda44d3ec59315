"""The layer-time chart, drawn as step outlines, has the pixels of the bar chart it replaced (the oracle here)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from gcodekit.report import figures


def bars(rows, slicer_rows=()):
    """The chart as it was drawn before: one bar a layer."""
    fig = figures._figure(2.8, left=0.08, right=0.98, bottom=0.16, top=0.9)
    ax = fig.add_subplot()
    ax.bar([r["layer"] for r in rows], [r["time_s"] for r in rows], width=1.0, color="#3b6ea8",
           label="gcodekit (planned)")
    if slicer_rows:
        edges = [slicer_rows[0]["layer"] - slicer_rows[0]["layers"] + 0.5] + [r["layer"] + 0.5 for r in slicer_rows]
        ax.stairs([r["slicer_time_s"] / r["layers"] for r in slicer_rows], edges, color="#d9822b", linewidth=1.2,
                  label="slicer's marks")
        ax.legend(fontsize=7, loc="upper right")
    from matplotlib.ticker import MaxNLocator

    ax.set_xlabel("layer")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("time, s")
    ax.set_title("Time per layer", fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    return fig


def png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=figures.DPI)
    return buf.getvalue()


def rows_of(times, first: int = 0):
    return [{"layer": first + k, "time_s": float(t), "filament_mm": 0.0} for k, t in enumerate(times)]


@pytest.mark.parametrize("count", [1, 2, 7, 250, figures.STEPS + 1, 3000])
def test_steps_have_the_pixels_of_the_bars(count):
    rows = rows_of(np.random.default_rng(count).gamma(2.0, 10.0, count), first=3)
    assert png(figures.layer_times(rows)) == png(bars(rows))


def test_a_missing_layer_and_the_slicers_marks_too():
    rows = [r for r in rows_of([5, 3, 1, 1, 7, 0, 4, 4, 4, 2]) if r["layer"] not in (2, 3)]
    marks = [{"layer": 4, "layers": 5, "slicer_time_s": 30.0}, {"layer": 9, "layers": 5, "slicer_time_s": 12.0}]
    assert png(figures.layer_times(rows, marks)) == png(bars(rows, marks))
