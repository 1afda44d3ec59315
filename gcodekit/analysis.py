"""Output stage: statistics of an emulated operation.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G1 X3 Y4 F600\\nG0 X0 Y0\\n", machine="linuxcnc")
>>> stats = op.get_statistics()
>>> stats["distance_mm"]["feed"], stats["moves"]["rapid"]
(5.0, 1)
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

import numpy as np

from .parse.table import NAME_ID as NAME_ID_LOOKUP

if TYPE_CHECKING:
    import pandas as pd

    from .model.operation import Operation


def depositing(w: dict, screw: bool = False) -> np.ndarray:
    """Waypoints that lay material: filament pushed on a move (FFF), a feed
    move with the heat source on (DED, where the wire or powder has no E), or
    with ``screw``, a feed move while the screw extruder turns (BAAM, CEAD)."""
    moving = (np.asarray(w["motion"]) > 0) & (np.asarray(w["distance"]) > 0)
    feeding = np.asarray(w["motion"]) >= 2
    welding = (np.asarray(w["laser"]) == 1) & feeding if "laser" in w else False
    turning = (np.asarray(w["spindle"]) > 0) & feeding if screw else False
    return moving & ((np.asarray(w["de"]) > 0) | welding | turning)


def screw_extruder(op: "Operation") -> bool:
    """Whether the operation's machine deposits with a screw extruder."""
    return op.machine is not None and op.machine.extruder_type == "screw"


def depositing_of(op: "Operation") -> np.ndarray:
    """:func:`depositing` for an emulated operation, with its machine's kind of extruder."""
    return depositing(op.waypoints, screw_extruder(op))


def operation_statistics(op: "Operation") -> dict[str, Any]:
    """Counts, distances and time of an emulated operation (see ``get_statistics``)."""
    w = op.waypoints
    motion, distance, de = w["motion"], w["distance"], w["de"]
    moving = motion > 0
    extruding = depositing_of(op)
    stats: dict[str, Any] = {
        "lines": op.n_lines,
        "commands": len(op.table),
        "moves": {
            "rapid": int(np.count_nonzero(motion == 1)),
            "feed": int(np.count_nonzero(motion == 2)),
            "arc_cw": int(np.count_nonzero(motion == 3)),
            "arc_ccw": int(np.count_nonzero(motion == 4)),
            "extruding": int(np.count_nonzero(extruding)),
        },
        "distance_mm": {
            "feed": float(distance[motion >= 2].sum()),
            "rapid": float(distance[motion == 1].sum()),
            "extrude": float(distance[extruding].sum()),
        },
        "time_s": float(np.nansum(w["time"])),
        "tools": sorted(int(t) for t in np.unique(w["tool"][moving])) if moving.any() else [],
        "bounds": op.get_bounds(),
    }
    if op.machine is not None and op.machine.process == "additive":
        if screw_extruder(op):  # pellets: no filament
            stats["filament_mm"] = stats["filament_convention"] = stats["filament_pushed_mm"] = None
        else:
            from .model.filament import filament_used, slicer_convention

            stats["filament_mm"] = filament_used(op)
            stats["filament_convention"] = slicer_convention(op)
            stats["filament_pushed_mm"] = float(de.sum())
        stats["layers"] = count_layers(op)
    else:
        stats["filament_mm"] = stats["filament_convention"] = stats["filament_pushed_mm"] = None
        stats["layers"] = None
    return stats


def count_layers(op: "Operation") -> int:
    """Layers: the flavor's layer-change comments, or distinct extruding Z heights."""
    patterns = [re.compile(p) for p in (op.flavor.layer_comments if op.flavor else ())]
    t = op.table
    if patterns and t.comment_rows.size:
        text = t.comment_data.decode("utf-8", "replace")
        ascii_only = text.isascii()  # then byte offsets are character offsets
        offsets = t.comment_offsets
        count = 0
        for k in range(t.comment_rows.size):
            comment = text[offsets[k]:offsets[k + 1]].strip() if ascii_only else t.comment(k)
            if any(p.search(comment) for p in patterns):
                count += 1
        if count:
            return count
    w = op.waypoints
    extruding = depositing_of(op)
    return int(np.unique(np.round(w["z"][extruding], 4)).size)


def _row_labels(op: "Operation", pattern: str) -> tuple[np.ndarray, list[str]]:
    """Per command row, the index of the last comment matching ``pattern`` (-1 before any)."""
    t = op.table
    rows, labels = [], []
    if pattern and t.comment_rows.size:
        regex = re.compile(pattern)
        text = t.comment_data.decode("utf-8", "replace")
        ascii_only = text.isascii()
        offsets = t.comment_offsets
        for k in range(t.comment_rows.size):
            comment = text[offsets[k]:offsets[k + 1]].strip() if ascii_only else t.comment(k)
            m = regex.search(comment)
            if m:
                rows.append(int(t.comment_rows[k]))
                labels.append(m.group(1) if m.groups() else comment)
    n = len(t)
    marks = np.full(n, -1, np.int64)
    if rows:
        marks[np.array(rows)] = np.arange(len(rows))
    np.maximum.accumulate(marks, out=marks)
    return marks, labels


def waypoint_rows(op: "Operation") -> np.ndarray:
    w = op.waypoints
    return w["command"] if "command" in w else np.arange(len(op.table))


def features(op: "Operation") -> np.ndarray:
    """Feature name (slicer ``;TYPE:`` comment) of each waypoint; ``""`` before the first."""
    marks, labels = _row_labels(op, op.flavor.feature_comment if op.flavor else "")
    names = np.array([""] + labels, dtype=object)
    return names[marks[waypoint_rows(op)] + 1]


def layers(op: "Operation", heights: np.ndarray | None = None) -> np.ndarray:
    """Layer number (0-based) of each waypoint, -1 before the first layer.

    From the flavor's layer-change comments when the program has them and no
    ``heights`` are given; else a new layer starts at each new height reached
    by a depositing move.  ``heights`` (mm, one per waypoint) default to Z;
    pass the positions projected on another layer normal for tilted layers.
    """
    if heights is None:
        marks = np.full(len(op.table), -1, np.int64)
        for pattern in (op.flavor.layer_comments if op.flavor else ()):
            found, labels = _row_labels(op, f"({pattern})")
            if labels:
                marks = found
                break
        if (marks >= 0).any():
            return marks[waypoint_rows(op)]
        heights = op.waypoints["z"]
    extruding = np.flatnonzero(depositing_of(op))
    z = np.round(np.asarray(heights, float), 4)
    at = z[extruding]
    starts = extruding[np.r_[True, at[1:] != at[:-1]]] if extruding.size else extruding
    # a layer begins at its first extruding move; heights already printed are not new
    seen = np.unique(z[starts], return_index=True)[1]
    first = np.zeros(z.size, bool)
    first[starts[np.sort(seen)]] = True
    return np.cumsum(first) - 1


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
    labels = {"layer": layers, "feature": features, "tool": lambda o: np.asarray(o.waypoints["tool"])}[key](op)
    extruding = depositing_of(op)
    frame = pd.DataFrame({
        key: labels,
        "time_s": np.nan_to_num(np.asarray(w["time"], float)),
        "distance_mm": np.asarray(w["distance"], float),
        "extrude_mm": np.where(extruding, w["distance"], 0.0),
        "filament_mm": np.asarray(w["de"], float),
    })
    return frame.groupby(key, sort=(key != "feature")).sum()


def velocity_profile(op: "Operation") -> "pd.DataFrame":
    """Speed over time, for plots: planned (trapezoids) and commanded.

    One row per corner of each move's velocity trapezoid: ``time`` (s),
    ``distance`` (mm travelled so far), ``planned`` and ``commanded`` speed
    (mm/s), and the source ``line``.  Without a planner the planned speed is
    the commanded one, held for each move.
    """
    import pandas as pd

    plan = op.plan
    if plan is None:
        w = op.waypoints
        moved = np.flatnonzero(w["motion"] > 0)
        t_end = op.elapsed_time()[moved]
        dur = np.nan_to_num(np.asarray(w["time"], float)[moved])
        speed = np.asarray(w["feed"], float)[moved] / 60.0
        d_end = np.cumsum(np.asarray(w["distance"], float)[moved])
        d_start = d_end - np.asarray(w["distance"], float)[moved]
        line = op.table.line[waypoint_rows(op)[moved]]
        return pd.DataFrame({
            "time": np.column_stack([t_end - dur, t_end]).ravel(),
            "distance": np.column_stack([d_start, d_end]).ravel(),
            "planned": np.repeat(speed, 2), "commanded": np.repeat(speed, 2), "line": np.repeat(line, 2),
        })
    moves, r = plan
    if len(moves) == 0:  # nothing moved: no trapezoids to lay out
        return pd.DataFrame({c: np.zeros(0) for c in ("time", "distance", "planned", "commanded", "line")})
    w = op.waypoints
    # a move starts when its waypoint started plus the moves of that waypoint before it
    dur = r.duration_t
    t_end_wp = op.elapsed_time()
    t_start_wp = t_end_wp - np.nan_to_num(np.asarray(w["time"], float))
    within = np.cumsum(dur) - dur
    first = np.r_[0, np.flatnonzero(moves.waypoint[1:] != moves.waypoint[:-1]) + 1]
    offset = np.repeat(within[first], np.diff(np.r_[first, len(moves)]))
    t0 = t_start_wp[moves.waypoint] + (within - offset)
    d = moves.length_d
    d0 = np.cumsum(d) - d
    accel_d = (r.cruise_v**2 - r.start_v**2) / (2 * r.accel)
    decel_d = (r.cruise_v**2 - r.end_v**2) / (2 * r.accel)
    times = np.column_stack([t0, t0 + r.accel_t, t0 + r.accel_t + r.cruise_t, t0 + dur])
    dist = np.column_stack([d0, d0 + accel_d, d0 + d - decel_d, d0 + d])
    speed = np.column_stack([r.start_v, r.cruise_v, r.cruise_v, r.end_v])
    commanded = np.repeat(moves.speed_v, 4)
    return pd.DataFrame({
        "time": times.ravel(), "distance": dist.ravel(), "planned": speed.ravel(), "commanded": commanded,
        "line": np.repeat(op.table.line[moves.row], 4),
    })


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
    straight = np.isin(names, [NAME_ID_LOOKUP["rapid"], NAME_ID_LOOKUP["linear"]])
    full = np.ones(rows.size, bool)
    for letter in "XYZ":
        full &= ~np.isnan(t.param(letter)[rows])
    keep = np.flatnonzero(straight & full)
    slice_marks, slices = _row_labels(op, _SLICE.pattern)
    fraction_marks, fractions = _row_labels(op, _FRACTION.pattern)
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


def gcode_dataframe_to_event_series(df: "pd.DataFrame", source: str = "material") -> "pd.DataFrame":
    """An Abaqus AM event series from a waypoint DataFrame (``Operation.to_dataframe``).

    Parameters
    ----------
    df : DataFrame
        Needs ``x, y, z, de, distance, time, elapsed_time, motion`` (and
        ``laser`` for ``source="heat"``); an additive operation's frame also
        has ``deposited_volume``, which then decides where material is laid.
    source : {"material", "heat"}, default: "material"
        ``material``: 1 while material is deposited (filament pushed on a
        move, or for DED a feed move with the heat source on); ``heat``: 1 while the laser/weld heat source is on during a move
        (DED, M61/M62).

    Returns
    -------
    DataFrame with ``time, x, y, z, value``: at each time the source is at
    that point with that value until the next event, moving in a straight
    line between events (how Abaqus reads an event series).  The last event
    switches the source off.

    Examples
    --------
    >>> import gcodekit
    >>> df = gcodekit.gcode_file_to_dataframe("M83\\nG1 X10 E1 F600\\nG1 X20\\n", "marlin", plan=False)
    >>> gcode_dataframe_to_event_series(df).values.tolist()
    [[0.0, 0.0, 0.0, 0.0, 1.0], [1.0, 10.0, 0.0, 0.0, 0.0], [2.0, 20.0, 0.0, 0.0, 0.0]]
    """
    import pandas as pd

    from .errors import check_choice

    check_choice("source", source, ("material", "heat"))
    motion = np.asarray(df["motion"].cat.codes if hasattr(df["motion"], "cat") else df["motion"])
    moved = np.flatnonzero(motion > 0)
    if moved.size == 0:
        return pd.DataFrame(columns=["time", "x", "y", "z", "value"])
    xyz = df[["x", "y", "z"]].to_numpy(float)
    end_t = df["elapsed_time"].to_numpy(float)[moved]
    start_t = end_t - np.nan_to_num(df["time"].to_numpy(float)[moved])
    start_xyz = np.vstack([np.zeros((1, 3)), xyz[:-1]])[moved]
    if source == "material" and "deposited_volume" in df:  # an additive operation's frame: screws, beads too
        volume = df["deposited_volume"].to_numpy(float)[moved]
        value = ((volume > 0) | np.isnan(volume)) & (df["distance"].to_numpy(float)[moved] > 0)
    elif source == "material":  # filament pushed, or (DED, no E words) the heat source on during a feed move
        value = (df["de"].to_numpy(float)[moved] > 0) & (df["distance"].to_numpy(float)[moved] > 0)
        if "laser" in df:
            value |= (df["laser"].to_numpy()[moved] == 1) & (motion[moved] >= 2)
    else:
        value = (df["laser"].to_numpy()[moved] == 1) & (motion[moved] >= 2)
    events = pd.DataFrame({"time": np.r_[start_t, end_t[-1]],
                           "x": np.r_[start_xyz[:, 0], xyz[moved[-1], 0]],
                           "y": np.r_[start_xyz[:, 1], xyz[moved[-1], 1]],
                           "z": np.r_[start_xyz[:, 2], xyz[moved[-1], 2]],
                           "value": np.r_[value.astype(float), 0.0]})
    # a run of travel moves is one "off" event: the source is off wherever it is
    off = events["value"].to_numpy() == 0
    repeat = off & np.r_[False, off[:-1]]
    repeat[-1] = False
    return events[~repeat].reset_index(drop=True)


def export_event_series_from_gcode(path, output_path, *, source: str = "material", machine: str | None = None,
                                   **options) -> "pd.DataFrame":
    """Write the Abaqus event series of a program (``time, x, y, z, value`` lines, no header)."""
    from .pipeline import gcode_to_operation

    events = gcode_dataframe_to_event_series(gcode_to_operation(path, machine, **options).to_dataframe(), source)
    events.to_csv(output_path, header=False, index=False, float_format="%.6f")
    return events
