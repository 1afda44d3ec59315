"""Emulate stage: the compensated waypoints as the compensation pass writes them.

Each written waypoint is a copy of one of the machine's, with the columns
compensation changes (the point in the plane, an arc's centre, for the
corner moves it adds also motion, distance and time).  Lathe tools are
compensated about their nose centre; the shift to their control point is
added to the rows written while it is in force, once the whole path is known
(rs274 does it when it flushes its queue).
"""

from __future__ import annotations

import numpy as np

from ...parse.table import MOTION_CCW, MOTION_CW, MOTION_LINEAR
from ..arcs import PLANES, single_turn_lengths


class ToolPath:
    """The compensated waypoints written so far, column by column.

    Parameters
    ----------
    waypoints : dict of ndarray
        The machine's waypoint columns (read, not changed).
    rows : ndarray of int
        The command of each waypoint: corner moves are added, so every
        written waypoint names its command.
    """

    def __init__(self, waypoints: dict[str, np.ndarray], rows: np.ndarray):
        self.columns = {k: np.array(v, copy=True) for k, v in waypoints.items()}
        self.columns["command"] = np.asarray(rows)
        self.out: dict[str, list] = {k: [] for k in self.columns}
        #: shift of a lathe tool's control point from its nose centre (along the plane's axes) for rows written now
        self.shift = (0.0, 0.0)
        self._shifted: list[tuple[int, float, float, int]] = []  # (row, along a, along b, plane)

    def __bool__(self) -> bool:
        return bool(self.out["x"])

    def emit(self, k: int, **changes) -> int:
        """Write a copy of the machine's waypoint ``k`` with ``changes`` (column -> value); its row."""
        for key in self.columns:
            self.out[key].append(changes.get(key, self.columns[key][k]))
        if self.shift != (0.0, 0.0):
            self._shifted.append((len(self.out["x"]) - 1, *self.shift, int(self.columns["plane"][k])))
        return len(self.out["x"]) - 1

    def last(self, axis: str):
        """The coordinate ``axis`` of the last written waypoint."""
        return self.out[axis][-1]

    def point(self, row: int, a: str, b: str) -> np.ndarray:
        """Waypoint ``row``'s point in the plane of axes ``a`` and ``b`` (row -1: the last one)."""
        return np.array([self.out[a][row], self.out[b][row]])

    def motion(self, row: int) -> int:
        return self.out["motion"][row]

    def move_ends(self, rows: list[int], a: str, b: str, point: np.ndarray) -> None:
        """Move the point in the plane of the waypoints ``rows`` to ``point``."""
        for row in rows:
            self.out[a][row], self.out[b][row] = point[0], point[1]

    def finish(self, waypoints: dict[str, np.ndarray]) -> None:
        """Replace ``waypoints``' columns with the written ones: lathe rows shifted, lengths recomputed."""
        for i, da, db, plane in self._shifted:
            (f, g, _), _ = PLANES[plane]
            for axis, shift in (("xyz"[f], da), ("xyz"[g], db)):
                self.out[axis][i] += shift
                self.out["c" + axis][i] += shift  # NaN off arcs stays NaN
        for key, column in self.columns.items():
            waypoints[key] = np.asarray(self.out[key], dtype=column.dtype)
        _recompute_lengths(waypoints)


def _recompute_lengths(w: dict) -> None:
    """Move lengths after the path moved: straight moves and arcs in their plane."""
    points = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
    centers = np.column_stack([np.asarray(w["c" + k], float) for k in "xyz"])
    previous = np.vstack([np.zeros(3), points[:-1]])
    motion = np.asarray(w["motion"])
    distance = np.array(w["distance"], float)
    straight = motion <= MOTION_LINEAR
    distance[straight] = np.linalg.norm(points - previous, axis=1)[straight]
    plane = np.asarray(w["plane"])
    arcs = np.isin(motion, (MOTION_CW, MOTION_CCW))
    for code in np.unique(plane[arcs]):
        (f, g, h), _ = PLANES[int(code)]
        idx = np.flatnonzero(arcs & (plane == code))
        p0, p1, c = previous[idx][:, [f, g]], points[idx][:, [f, g]], centers[idx][:, [f, g]]
        distance[idx] = single_turn_lengths(p0, p1, c, motion[idx] == MOTION_CW, points[idx, h] - previous[idx, h])
    w["distance"] = distance
