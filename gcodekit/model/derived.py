"""Model: the columns derived from the waypoints, computed once -- layer, feature, depositing.

These are the one definition gcodekit uses everywhere (statistics,
additive parts, pictures, reports, widgets):

* a waypoint **deposits** when filament is pushed on a move (FFF), when a
  feed move runs with the heat source on (DED, whose wire or powder has no
  E), or on a screw extruder (BAAM, CEAD) when a feed move runs while the
  screw turns;
* its **feature** is the slicer's region (``;TYPE:`` comment) or DED
  fraction in force, ``""`` before the first;
* its **layer** counts from 0: the flavor's layer-change comments when the
  program has them, else a new layer starts at each new height a depositing
  move reaches (heights already printed are not new); -1 before the first.
  The number of layers is the last layer plus one.

:class:`~gcodekit.model.operation.Operation` keeps them (``op.depositing``,
``op.features``, ``op.layers``), so comments are scanned once per program.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .operation import Operation

__all__ = ["moving", "depositing", "depositing_of", "screw_extruder", "features", "layers", "waypoint_rows", "row_labels",
           "laser_power"]


def moving(w: dict) -> np.ndarray:
    """Waypoints that move the tool: a motion of some length (a move to where the tool already is does not)."""
    return (np.asarray(w["motion"]) > 0) & (np.asarray(w["distance"]) > 0)


def depositing(w: dict, screw: bool = False) -> np.ndarray:
    """Waypoints that lay material: filament pushed on a move (FFF), a feed
    move with the heat source on (DED, where the wire or powder has no E), or
    with ``screw``, a feed move while the screw extruder turns (BAAM, CEAD)."""
    feeding = np.asarray(w["motion"]) >= 2
    welding = (np.asarray(w["laser"]) == 1) & feeding if "laser" in w else False
    turning = (np.asarray(w["spindle"]) > 0) & feeding if screw else False
    return moving(w) & ((np.asarray(w["de"]) > 0) | welding | turning)


def laser_power(w: dict) -> np.ndarray:
    """Beam power of each waypoint on a laser in GRBL's laser mode, in S units (full power at ``$30``).

    The programmed S while M3 or M4 is on, on feed moves (G1-G3) only: G0
    moves with the beam off.  Under M3 the power is constant; under M4
    (dynamic, the spindle column negative) GRBL scales it with the actual
    speed over the programmed one, here the move's average: length over
    planned time against its feed.

    Examples
    --------
    >>> import numpy as np
    >>> w = {"motion": np.array([1, 2, 2, 2]), "spindle": np.array([0.0, 255.0, -255.0, 0.0]),
    ...      "distance": np.array([5.0, 10.0, 10.0, 10.0]), "time": np.array([0.1, 1.0, 2.0, 1.0]),
    ...      "feed": np.array([600.0, 600.0, 600.0, 600.0])}
    >>> laser_power(w).tolist()  # rapid unlit, M3 full S, M4 at half the programmed speed, beam off
    [0.0, 255.0, 127.5, 0.0]
    """
    spindle = np.asarray(w["spindle"], float)
    burning = (np.asarray(w["motion"]) >= 2) & (spindle != 0)
    distance, time = np.asarray(w["distance"], float), np.asarray(w["time"], float)
    programmed = np.asarray(w["feed"], float) / 60.0
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.clip(np.where((time > 0) & (programmed > 0), distance / time / programmed, 1.0), 0.0, 1.0)
    dynamic = np.where(spindle < 0, np.nan_to_num(ratio, nan=1.0), 1.0)
    return np.where(burning, np.abs(spindle) * dynamic, 0.0)


def screw_extruder(op: "Operation") -> bool:
    """Whether the operation's machine deposits with a screw extruder."""
    return op.machine is not None and op.machine.extruder_type == "screw"


def depositing_of(op: "Operation") -> np.ndarray:
    """:func:`depositing` for an emulated operation, with its machine's kind of extruder."""
    return depositing(op.waypoints, screw_extruder(op))


def waypoint_rows(op: "Operation") -> np.ndarray:
    """The command row of each waypoint."""
    w = op.waypoints
    return w["command"]


def row_labels(op: "Operation", pattern: str) -> tuple[np.ndarray, list[str]]:
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


def features(op: "Operation") -> np.ndarray:
    """Feature name (slicer ``;TYPE:`` comment) of each waypoint; ``""`` before the first."""
    codes, names = feature_codes(op)
    return np.array(names, dtype=object)[codes]


def feature_codes(op: "Operation") -> tuple[np.ndarray, list[str]]:
    """:func:`features` as an index per waypoint into a list of names (``""``, then each comment's in order).

    Colourings and checks use these: millions of strings cost seconds to compare or sort.
    """
    marks, labels = row_labels(op, op.flavor.feature_comment if op.flavor else "")
    return marks[waypoint_rows(op)] + 1, [""] + labels


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
            found, labels = row_labels(op, f"({pattern})")
            if labels:
                marks = found
                break
        if (marks >= 0).any():
            return marks[waypoint_rows(op)]
        heights = op.waypoints["z"]
    extruding = np.flatnonzero(op.depositing)
    z = np.round(np.asarray(heights, float), 4)
    at = z[extruding]
    starts = extruding[np.r_[True, at[1:] != at[:-1]]] if extruding.size else extruding
    # a layer begins at its first extruding move; heights already printed are not new
    seen = np.unique(z[starts], return_index=True)[1]
    first = np.zeros(z.size, bool)
    first[starts[np.sort(seen)]] = True
    return np.cumsum(first) - 1
