"""Output stage: tables of an emulated operation -- time by layer, feature or tool, speed over time, DED moves.

The derived columns these build on (layer, feature, depositing) and the
statistics are the model's (:mod:`gcodekit.model.derived`,
:mod:`gcodekit.model.statistics`); their functions are re-exported here,
where users have looked for them.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("M83\\nG1 Z0.2 F600\\nG1 X10 E1\\nG1 Z0.4\\nG1 X0 E1\\n", "marlin", plan=False)
>>> time_by(op, "layer")["extrude_mm"].tolist()
[0.0, 10.0, 10.0]
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from .export.events import event_series, gcode_dataframe_to_event_series
from .model.derived import depositing, depositing_of, features, layers, row_labels, screw_extruder, waypoint_rows
from .model.statistics import operation_statistics
from .parse.table import NAME_ID as NAME_ID_LOOKUP, in_ids

__all__ = ["time_by", "slicer_layer_times", "velocity_profile", "velocity_corners", "part_name", "tool_vectors", "ded_moves", "depositing", "depositing_of",
           "features", "layers", "screw_extruder", "waypoint_rows", "operation_statistics", "event_series",
           "gcode_dataframe_to_event_series"]

if TYPE_CHECKING:
    import pandas as pd

    from .model.operation import Operation


def time_by(op: "Operation", key: str = "layer") -> "pd.DataFrame":
    """Time, distances and filament per layer, feature or tool.

    Parameters
    ----------
    key : {"layer", "feature", "tool"}, default: "layer"

    Returns
    -------
    DataFrame indexed by the key with ``time_s``, ``distance_mm``,
    ``extrude_mm`` (path length while extruding) and ``filament_mm``.
    """
    import pandas as pd

    from .errors import check_choice

    check_choice("key", key, ("layer", "feature", "tool"))
    w = op.waypoints
    labels = {"layer": op.layers, "feature": op.features, "tool": np.asarray(w["tool"])}[key]
    extruding = op.depositing
    frame = pd.DataFrame({
        key: labels,
        "time_s": np.nan_to_num(np.asarray(w["time"], float)),
        "distance_mm": np.asarray(w["distance"], float),
        "extrude_mm": np.where(extruding, w["distance"], 0.0),
        "filament_mm": np.asarray(w["de"], float),
    })
    return frame.groupby(key, sort=(key != "feature")).sum()


def slicer_layer_times(op: "Operation", mode: str = "normal") -> "pd.DataFrame":
    """Time by layer, gcodekit's planned time beside the slicer's own progress marks.

    A layer is compared at the last mark the slicer wrote inside it (Cura's
    ``;TIME_ELAPSED:`` closes every layer; PrusaSlicer's M73 falls where its
    percentage or whole minutes left change, so its elapsed time is exact
    only to the minute).  Layers without a mark are left out.

    Parameters
    ----------
    mode : {"normal", "silent"}, default: "normal"
        Which of PrusaSlicer's two series of marks (M73 P/R or Q/S).

    Returns
    -------
    DataFrame indexed by ``layer`` with ``line`` (the mark's), ``elapsed_s``
    (gcodekit's planned time from the start to the mark), ``slicer_elapsed_s``,
    ``layers`` (how many layers since the previous compared layer), ``time_s``
    and ``slicer_time_s`` (over those layers) and ``difference_s``
    (``elapsed_s - slicer_elapsed_s``).  Empty when the file has no marks.
    """
    import pandas as pd

    from .errors import check_choice

    check_choice("mode", mode, ("normal", "silent"))
    marks = [m for m in op.slicer_figures().marks if m.mode == mode]
    columns = ["line", "elapsed_s", "slicer_elapsed_s", "layers", "time_s", "slicer_time_s", "difference_s"]
    rows_of = waypoint_rows(op)
    elapsed, layer = op.elapsed_time(), op.layers
    # the last waypoint before each mark, searched for all marks at once in the column's own dtype (a Python
    # int per call made NumPy cast the 3 M commands of plate150 to int64 for each of its 1,431 marks)
    befores = np.searchsorted(rows_of, np.array([m.row for m in marks], rows_of.dtype), side="left") - 1
    by_layer: dict[int, tuple[int, float, float]] = {}
    for m, before in zip(marks, befores.tolist()):
        if before < 0 or layer[before] < 0:
            continue
        by_layer[int(layer[before])] = (m.line, float(elapsed[before]), m.elapsed_s)
    if not by_layer:
        return pd.DataFrame(columns=columns, index=pd.Index([], name="layer"))
    frame = pd.DataFrame.from_dict(by_layer, orient="index", columns=columns[:3]).sort_index()
    frame.index.name = "layer"
    frame["layers"] = np.diff(frame.index.to_numpy(), prepend=-1)
    frame["time_s"] = frame["elapsed_s"].diff().fillna(frame["elapsed_s"])
    frame["slicer_time_s"] = frame["slicer_elapsed_s"].diff().fillna(frame["slicer_elapsed_s"])
    frame["difference_s"] = frame["elapsed_s"] - frame["slicer_elapsed_s"]
    return frame


def velocity_profile(op: "Operation") -> "pd.DataFrame":
    """Speed over time, for plots: :func:`velocity_corners` as a DataFrame."""
    import pandas as pd

    return pd.DataFrame(velocity_corners(op))


def velocity_corners(op: "Operation", *, columns: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
    """Speed over time, for plots: planned (trapezoids) and commanded.

    One row per corner of each move's velocity trapezoid: ``time`` (s),
    ``distance`` (mm travelled so far), ``planned`` and ``commanded`` speed
    (mm/s), and the source ``line``.  Without a planner the planned speed is
    the commanded one, held for each move.  Columns as NumPy arrays (a
    DataFrame of a 3 M-line print's 12 M corners costs seconds to assemble);
    ``columns`` (default: all five) names those to compute.
    :class:`gcodekit.view.velocity.VelocityMoves` makes the corners of a
    range of moves only.
    """
    from .view.velocity import COLUMNS, VelocityMoves

    columns = COLUMNS if columns is None else tuple(columns)
    corners = VelocityMoves(op)
    if len(corners) == 0:  # nothing moved: no trapezoids to lay out
        return {c: np.zeros(0) for c in columns}
    return corners.corners(columns=columns)


_PART_NAME = re.compile(r"Part name:\s*(.+)")
_SLICE = re.compile(r"New Slice of body .*?No\.:\s*(\d+)")
_FRACTION = re.compile(r"Fraction\s+(\d+)")


def part_name(op: "Operation") -> str:
    """The DED part name from the ``(Part name: ...)`` header, else the file's stem."""
    t = op.table
    for k in range(min(t.comment_rows.size, 50)):
        m = _PART_NAME.search(t.comment(k))
        if m:
            return m.group(1).strip()
    from pathlib import Path

    return Path(op.file).stem


def tool_vectors(a_deg: np.ndarray, b_deg: np.ndarray) -> np.ndarray:
    """Unit tool directions (u, v, w) = (sin B, -sin A cos B, cos A cos B) of a 5-axis head.

    A and B in degrees; A = B = 0 points along +Z.
    """
    a, b = np.radians(a_deg), np.radians(b_deg)
    return np.column_stack([np.sin(b), -np.sin(a) * np.cos(b), np.cos(a) * np.cos(b)])


def ded_moves(op: "Operation") -> "pd.DataFrame":
    """One row per G0/G1 of a DED program, as the Beckhoff DED tooling reads it.

    Columns ``line_no, x, y, z, a, b, move_type ("rapid"/"cut"), weld_state
    ("on"/"off"), slice_no, fraction_no, u, v, w``.  Slice and fraction come
    from the ``(New Slice of body ... No.: n)`` and ``(... Fraction n ...)``
    comments; the weld state from M61 (on, also inline) and M62 (off).  A move
    missing X, Y or Z is left out (and reported when the program is read).
    """
    import pandas as pd

    t, w = op.table, op.waypoints
    rows = waypoint_rows(op)
    names = t.name[rows]
    straight = in_ids(names, [NAME_ID_LOOKUP["rapid"], NAME_ID_LOOKUP["linear"]])
    full = np.ones(rows.size, bool)
    for letter in "XYZ":
        full &= ~np.isnan(t.param(letter)[rows])
    keep = np.flatnonzero(straight & full)
    slice_marks, slices = row_labels(op, _SLICE.pattern)
    fraction_marks, fractions = row_labels(op, _FRACTION.pattern)
    slice_no = np.array([0] + [int(s) for s in slices])[slice_marks[rows[keep]] + 1]
    fraction_no = np.array([0] + [int(f) for f in fractions])[fraction_marks[rows[keep]] + 1]
    a = np.nan_to_num(t.param("A")[rows[keep]])
    b = np.nan_to_num(t.param("B")[rows[keep]])
    uvw = tool_vectors(a, b)
    return pd.DataFrame({
        "line_no": t.line[rows[keep]],
        "x": t.param("X")[rows[keep]], "y": t.param("Y")[rows[keep]], "z": t.param("Z")[rows[keep]],
        "a": a, "b": b,
        "move_type": np.where(names[keep] == NAME_ID_LOOKUP["rapid"], "rapid", "cut"),
        "weld_state": np.where(np.asarray(w["laser"])[keep] == 1, "on", "off"),
        "slice_no": slice_no, "fraction_no": fraction_no,
        "u": uvw[:, 0], "v": uvw[:, 1], "w": uvw[:, 2],
    })


