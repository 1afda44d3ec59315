"""Emulate stage: circular and helical arc geometry, for many arcs at once.

Arcs are given in a plane: G17 (X, Y | Z), G18 (Z, X | Y), G19 (Y, Z | X),
the axis after the bar being the helix axis.  Centers come from the I/J/K
offsets or from a radius R, with LinuxCNC's rules (RS274NGC, interp_arc.cc):
a positive R takes the shorter arc, a negative R the longer one; a P word
adds full turns; start equal to end with I/J/K is a full circle.
"""

from __future__ import annotations

import numpy as np

#: (first, second, helix) axis indices and the I/J/K letters of each plane.
PLANES = {
    17: ((0, 1, 2), ("I", "J")),
    18: ((2, 0, 1), ("K", "I")),
    19: ((1, 2, 0), ("J", "K")),
}
PLANE_CODES = (17, 18, 19)
TWO_PI = 2.0 * np.pi


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
