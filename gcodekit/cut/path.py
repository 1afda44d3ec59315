"""Outputs: a mill operation's moves as straight pieces of the tool tip's path, arcs cut into chords.

The first move is left out (it starts wherever the machine was).  The
waypoints are the spindle's controlled point in machine coordinates
with the program's tool length offsets applied (G43 adds the offset, G49
removes it).  The tool's tip is its table length below that point, so a
program that sets its offsets as the tool table says cuts where it means
to, and one that forgets G43 cuts where the machine would.  Arcs and
helices become chords no farther than ``tolerance`` from the true path.
"""

from __future__ import annotations

import math

import numpy as np

from ..emulate.arcs import waypoint_arc_points
from .sweep import Pieces

#: motion codes (see gcodekit.schema): rapid, feed, clockwise and counter-clockwise arcs
RAPID, FEED, ARC_CW, ARC_CCW = 1, 2, 3, 4


def moving_rows(w: dict) -> np.ndarray:
    """Waypoints that move (each from the waypoint before it), less the first move.

    The first move starts where the machine happened to be before the
    program, which the program does not say (the emulator's start is the
    machine's zero, often inside the stock's box): it is not cut.
    """
    rows = np.flatnonzero(np.asarray(w["motion"]) > 0)
    return rows[1:] if rows.size else rows


def chord_angle(w: dict, rows: np.ndarray, tolerance: float) -> float:
    """Largest angle between chord ends so that no chord of the arcs among ``rows`` strays more than ``tolerance``."""
    motion = np.asarray(w["motion"])[rows]
    arcs = rows[(motion == ARC_CW) | (motion == ARC_CCW)]
    if arcs.size == 0:
        return math.radians(5.0)
    start = np.column_stack([np.asarray(w[k], float)[arcs - 1] for k in "xyz"])
    centre = np.column_stack([np.asarray(w[k], float)[arcs] for k in ("cx", "cy", "cz")])
    offset = np.where(np.isnan(centre), 0.0, start - np.nan_to_num(centre))  # NaN: the helix axis' coordinate
    radius = float(np.linalg.norm(offset, axis=1).max())
    if radius <= tolerance:
        return math.radians(5.0)
    return min(math.radians(5.0), 2 * math.acos(1 - tolerance / radius))


def tool_tip_pieces(w: dict, lengths: dict[int, float], tolerance: float) -> Pieces:
    """The straight pieces of the tool tip's path, in program order, owned by their waypoints.

    Parameters
    ----------
    w : dict of ndarray
        The operation's waypoint columns (mm).
    lengths : dict of int to float
        Each tool's length, mm (its tip that far below the controlled point).
    tolerance : float
        Largest distance of an arc's chords from the arc, mm.
    """
    rows = moving_rows(w)
    if rows.size == 0:
        empty = np.zeros((0, 3))
        return Pieces(empty, empty, np.zeros(0, np.int64), np.zeros(0, np.int32))
    points, counts = waypoint_arc_points(w, rows, chord_angle(w, rows, tolerance))
    xyz = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
    n_vertices = counts + 2
    first = np.cumsum(n_vertices) - n_vertices
    vertices = np.empty((int(n_vertices.sum()), 3))
    vertices[first] = xyz[rows - 1]
    vertices[first + n_vertices - 1] = xyz[rows]
    if points.size:
        local = np.arange(points.shape[0]) - np.repeat(np.cumsum(counts) - counts, counts)
        vertices[np.repeat(first + 1, counts) + local] = points
    tool = np.asarray(w["tool"])[rows].astype(np.int32)
    length = np.array([lengths.get(int(t), 0.0) for t in np.unique(tool)])
    drop = length[np.searchsorted(np.unique(tool), tool)]
    vertices[:, 2] -= np.repeat(drop, n_vertices)
    keep = np.ones(len(vertices) - 1, bool)
    keep[(first + n_vertices - 1)[:-1]] = False  # no piece from one move's end to the next one's start
    owner = np.repeat(rows, n_vertices)[:-1][keep]
    return Pieces(vertices[:-1][keep], vertices[1:][keep], owner, np.repeat(tool, n_vertices)[:-1][keep])
