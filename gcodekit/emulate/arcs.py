"""Emulate stage: circular and helical arc geometry, for many arcs at once.

Arcs are given in a plane: G17 (X, Y | Z), G18 (Z, X | Y), G19 (Y, Z | X),
the axis after the bar being the helix axis.  Centers come from the I/J/K
offsets or from a radius R, with LinuxCNC's rules (RS274NGC, interp_arc.cc):
a positive R takes the shorter arc, a negative R the longer one; a P word
adds full turns; start equal to end with I/J/K is a full circle.
"""

from __future__ import annotations

import numpy as np

from ..units import MM_PER_INCH

#: (first, second, helix) axis indices and the I/J/K letters of each plane.
PLANES = {
    17: ((0, 1, 2), ("I", "J")),
    18: ((2, 0, 1), ("K", "I")),
    19: ((1, 2, 0), ("J", "K")),
}
PLANE_CODES = (17, 18, 19)
PLANE_NAMES = {17: "xy", 18: "xz", 19: "yz"}  # as rs274's messages name them
TWO_PI = 2.0 * np.pi


def reach_tolerance(units: float) -> float:
    """How far (mm) an R-form arc may fall short of its end point before LinuxCNC refuses it
    (0.005 mm in G21, 0.0005 in in G20; ``units`` is mm per program unit)."""
    return 0.005 if units == 1.0 else 0.0005 * MM_PER_INCH


def center_from_radius(start: np.ndarray, end: np.ndarray, radius: np.ndarray, clockwise: np.ndarray):
    """In-plane centers of arcs given by radius (LinuxCNC ``arc_data_r``).

    Parameters
    ----------
    start, end : ndarray, shape (n, 2)
        In-plane start and end points.
    radius : ndarray, shape (n,)
        Signed radius: positive for the arc of at most 180 degrees.
    clockwise : ndarray of bool, shape (n,)

    Returns
    -------
    center : ndarray, shape (n, 2)
    reach : ndarray of float, shape (n,)
        How far the end point lies beyond the radius (> 0 is an error).
    """
    mid = (start + end) / 2.0
    chord = end - start
    half = np.hypot(chord[:, 0], chord[:, 1]) / 2.0
    r = np.abs(radius)
    reach = half - r
    half = np.minimum(half, r)  # a semicircle within rounding is allowed
    right = clockwise == (radius > 0)
    theta = np.arctan2(chord[:, 1], chord[:, 0]) + np.where(right, -np.pi / 2, np.pi / 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = r * np.cos(np.arcsin(np.where(r > 0, half / r, 0.0)))
    center = mid + offset[:, None] * np.column_stack([np.cos(theta), np.sin(theta)])
    return center, reach


def centres(start: np.ndarray, end: np.ndarray, offsets: np.ndarray, radius: np.ndarray, clockwise: np.ndarray,
            incremental: bool) -> tuple[np.ndarray, np.ndarray]:
    """In-plane centres of arcs given by I/J/K offsets or by R, as the program gives them.

    ``offsets`` (n, 2) are the two centre words (NaN: not given, taken as 0),
    from the start (``incremental``, G91.1) or absolute (G90.1); a radius
    (NaN where none) overrides them.  Also returns how far each R-form arc
    falls short of its end (see :func:`reach_tolerance`; 0 for the others).
    """
    centre = np.nan_to_num(offsets) + (start if incremental else 0.0)
    short = np.zeros(len(start))
    by_radius = ~np.isnan(radius)
    if by_radius.any():
        centre[by_radius], short[by_radius] = center_from_radius(start[by_radius], end[by_radius], radius[by_radius],
                                                                 clockwise[by_radius])
    return centre, short


def sweep(start: np.ndarray, end: np.ndarray, center: np.ndarray, clockwise: np.ndarray,
          turns: np.ndarray, full_circle_tolerance: float = 1e-9) -> np.ndarray:
    """Swept angle of each arc in radians (positive, includes extra turns).

    ``turns`` is the P word (1 when absent): P2 adds one full turn.
    """
    a0 = np.arctan2(start[:, 1] - center[:, 1], start[:, 0] - center[:, 0])
    a1 = np.arctan2(end[:, 1] - center[:, 1], end[:, 0] - center[:, 0])
    delta = np.where(clockwise, a0 - a1, a1 - a0)
    delta = np.mod(delta, TWO_PI)
    same = np.hypot(*(end - start).T) <= full_circle_tolerance
    delta = np.where(same | (delta <= 1e-12), TWO_PI, delta)
    return delta + TWO_PI * (np.maximum(turns, 1) - 1)


def arc_length(radius: np.ndarray, angle: np.ndarray, helix: np.ndarray) -> np.ndarray:
    """Length of a helical arc: hypotenuse of the unrolled arc and its rise."""
    return np.hypot(radius * angle, helix)


def single_turn_lengths(start: np.ndarray, end: np.ndarray, center: np.ndarray, clockwise: np.ndarray,
                        helix: np.ndarray) -> np.ndarray:
    """Lengths of arcs of less than a turn (in-plane points, shape (n, 2)) rising by ``helix``."""
    angle = sweep(start, end, center, clockwise, np.ones(len(start)))
    return arc_length(np.hypot(*(start - center).T), angle, helix)


def interior_points(start: np.ndarray, end: np.ndarray, center: np.ndarray, plane: np.ndarray,
                    clockwise: np.ndarray, length: np.ndarray, max_angle: float = np.radians(5.0)):
    """Points inside arcs, for drawing them as poly-lines.

    Parameters
    ----------
    start, end, center : ndarray, shape (n, 3)
        X, Y, Z of each arc's start, end and centre (the helix-axis
        coordinate of the centre is not used).
    plane : ndarray of int, shape (n,)
        17, 18 or 19.
    clockwise : ndarray of bool, shape (n,)
    length : ndarray, shape (n,)
        Path length of each arc; with the rise along the helix axis it gives
        the swept angle, full turns included.
    max_angle : float, default: 5 degrees
        Largest angle between two points, radians.

    Returns
    -------
    points : ndarray, shape (m, 3)
        The interior points of every arc in order, neither start nor end.
    counts : ndarray of int, shape (n,)
        How many of them each arc has.
    """
    n = start.shape[0]
    if n == 0:
        return np.zeros((0, 3)), np.zeros(0, np.int64)
    axes = np.array([PLANES[p][0] for p in PLANE_CODES])[np.asarray(plane, np.int64) - 17]
    arc = np.arange(n)
    f, g, h = axes[:, 0], axes[:, 1], axes[:, 2]
    d_f, d_g = start[arc, f] - center[arc, f], start[arc, g] - center[arc, g]
    radius = np.hypot(d_f, d_g)
    rise = end[arc, h] - start[arc, h]
    with np.errstate(invalid="ignore", divide="ignore"):
        angle = np.sqrt(np.maximum(np.asarray(length, float) ** 2 - rise**2, 0.0)) / radius
    angle = np.where(np.isfinite(angle) & (radius > 0), angle, 0.0)
    steps = np.clip(np.ceil(angle / max_angle), 1, 2000).astype(np.int64)
    counts = steps - 1
    which = np.repeat(arc, counts)
    # j = 1 .. steps-1 within each arc
    j = np.arange(which.size) - np.repeat(np.cumsum(counts) - counts, counts) + 1
    t = j / steps[which]
    theta = np.arctan2(d_g, d_f)[which] + np.where(clockwise[which], -1.0, 1.0) * t * angle[which]
    points = np.empty((which.size, 3))
    rows = np.arange(which.size)
    points[rows, f[which]] = center[which, f[which]] + radius[which] * np.cos(theta)
    points[rows, g[which]] = center[which, g[which]] + radius[which] * np.sin(theta)
    points[rows, h[which]] = start[which, h[which]] + t * rise[which]
    return points, counts


def waypoint_arc_points(w: dict, rows: np.ndarray, max_angle: float = np.radians(5.0)):
    """:func:`interior_points` of the waypoints ``rows`` (each a move from the waypoint before it).

    Returns the points and, per row, how many (0 for straight moves).
    """
    motion = np.asarray(w["motion"])[rows]
    arc = np.flatnonzero((motion == 3) | (motion == 4))
    counts = np.zeros(rows.size, np.int64)
    if arc.size == 0:
        return np.zeros((0, 3)), counts
    end_rows = rows[arc]
    xyz = lambda r: np.column_stack([np.asarray(w[k], float)[r] for k in "xyz"])  # noqa: E731
    center = np.column_stack([np.asarray(w[k], float)[end_rows] for k in ("cx", "cy", "cz")])
    points, counts[arc] = interior_points(xyz(end_rows - 1), xyz(end_rows), center, np.asarray(w["plane"])[end_rows],
                                          motion[arc] == 3, np.asarray(w["distance"], float)[end_rows], max_angle)
    return points, counts
