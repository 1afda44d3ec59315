"""Emulate stage: the curves of LinuxCNC's spline moves, as chords.

G5 (cubic Bézier), G5.1 (quadratic Bézier) and G5.2/G5.3 (NURBS) move the
tool along a curve in the XY plane.  A controller interpolates the curve;
gcodekit follows it with straight chords that stay within
``spline_tolerance`` (mm, from the machine preset) of it, so distances,
times, pictures and the transpiler's plain G1 output all use the real path.

The NURBS knot vector is the clamped uniform one LinuxCNC builds from the
number of control points and the order L (``knot_vector_creator`` in
``nurbs_additional_functions.cc``): the curve starts at the first control
point and ends at the last.

Examples
--------
>>> import numpy as np
>>> chords = polyline(lambda t: quadratic_bezier(np.array([[0, 0], [5, 5], [10, 0]], float), t), 0.01)
>>> chords[0].tolist(), chords[-1].tolist()
([0.0, 0.0], [10.0, 0.0])
"""

from __future__ import annotations

from typing import Callable

import numpy as np

#: Curve points (n, 2) at parameters t (n,) in [0, 1].
Curve = Callable[[np.ndarray], np.ndarray]

_MAX_CHORDS = 1 << 16  # a curve is never cut into more chords than this


def cubic_bezier(points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of the cubic Bézier with control points ``points`` (4, 2) at ``t``."""
    t = np.asarray(t, float)[:, None]
    s = 1.0 - t
    p0, p1, p2, p3 = points
    return s**3 * p0 + 3 * s * s * t * p1 + 3 * s * t * t * p2 + t**3 * p3


def quadratic_bezier(points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of the quadratic Bézier with control points ``points`` (3, 2) at ``t``."""
    t = np.asarray(t, float)[:, None]
    s = 1.0 - t
    p0, p1, p2 = points
    return s * s * p0 + 2 * s * t * p1 + t * t * p2


def clamped_knots(n_points: int, order: int) -> np.ndarray:
    """LinuxCNC's knot vector for ``n_points`` control points of order ``order``, scaled to [0, 1]."""
    n = n_points - 1
    i = np.arange(n + order + 1)
    knots = np.clip(i - order + 1, 0, n - order + 2).astype(float)
    return knots / knots[-1]


def nurbs(points: np.ndarray, weights: np.ndarray, order: int, t: np.ndarray) -> np.ndarray:
    """Points of the NURBS curve (control ``points`` (n, 2), ``weights`` (n,), order) at ``t``.

    Cox-de Boor recursion on all parameters at once.
    """
    t = np.asarray(t, float)
    knots = clamped_knots(len(points), order)
    # order-1 basis: the span holding t (the last span also holds t = 1)
    last = len(knots) - order - 1
    span = np.clip(np.searchsorted(knots, t, side="right") - 1, order - 1, last)
    basis = (np.arange(len(knots) - 1)[None, :] == span[:, None]).astype(float)
    for k in range(2, order + 1):
        new = np.zeros((t.size, len(knots) - k))
        for i in range(len(knots) - k):
            left = knots[i + k - 1] - knots[i]
            right = knots[i + k] - knots[i + 1]
            if left > 0:
                new[:, i] += (t - knots[i]) / left * basis[:, i]
            if right > 0:
                new[:, i] += (knots[i + k] - t) / right * basis[:, i + 1]
        basis = new
    weighted = basis * weights[None, :]
    return weighted @ points / weighted.sum(axis=1, keepdims=True)


def polyline(curve: Curve, tolerance: float) -> np.ndarray:
    """Chord end points (m, 2) from the curve's start to its end, each chord within ``tolerance``.

    Chords are halved until the curve's points a quarter, half and three
    quarters along each chord's parameter interval lie within the tolerance
    of the chord (the segment, so a curve that doubles back on itself is
    followed to its tip; at such a cusp the tip can still lie up to about
    twice the tolerance from the chords).
    """
    t = np.linspace(0.0, 1.0, 9)
    while True:
        points = curve(t)
        a, b = points[:-1], points[1:]
        chord = b - a
        chord2 = np.maximum(np.einsum("ij,ij->i", chord, chord), 1e-300)
        too_far = np.zeros(len(chord), bool)
        for f in (0.25, 0.5, 0.75):  # curve points inside each chord's parameter interval
            off = curve(t[:-1] + f * np.diff(t)) - a
            along = np.clip(np.einsum("ij,ij->i", off, chord) / chord2, 0.0, 1.0)
            gap = off - along[:, None] * chord  # from the nearest point of the chord (not of its line)
            too_far |= np.hypot(gap[:, 0], gap[:, 1]) > tolerance
        if not too_far.any() or t.size > _MAX_CHORDS:
            return points
        mid_t = 0.5 * (t[:-1] + t[1:])
        t = np.sort(np.r_[t, mid_t[too_far]])


#: Spline commands (names in :data:`gcodekit.syntax.flavor.COMMANDS`).
SPLINE_NAMES = frozenset({"spline_cubic", "spline_quadratic", "nurbs_start", "nurbs_end"})


class SplineBlocks:
    """The spline blocks of one program, with the memory they need between blocks.

    A G5 without I and J continues the previous cubic smoothly; G5.2 opens a
    NURBS whose control points are the tool's position and the X/Y of every
    block up to G5.3.  Errors are raised as ``ValueError`` with rs274's
    message.

    Parameters
    ----------
    tolerance : float
        Largest distance between a chord and the curve, mm.
    """

    def __init__(self, tolerance: float):
        self.tolerance = tolerance
        self._handle = np.zeros(2)  # P, Q of the last cubic: its end tangent
        self._order = 0  # order L of the open NURBS (0: none open)
        self._points: list[np.ndarray] = []
        self._weights: list[float] = []

    def block(self, name: str, params: dict[str, float], start: np.ndarray, scale: float,
              incremental: bool) -> np.ndarray | None:
        """Chord ends of a spline block (program XY, mm) from ``start``, or None if it only adds a control point.

        ``name`` is a :data:`SPLINE_NAMES` command or ``nurbs_point`` (a block
        of words inside G5.2 ... G5.3); ``params`` are its words, ``scale``
        mm per program unit.
        """
        if name == "nurbs_end":
            return self._close_nurbs()
        end = start.copy()
        for k, letter in enumerate("XY"):
            if letter in params:
                end[k] = (end[k] if incremental else 0.0) + params[letter] * scale
        if name == "spline_quadratic":
            if "I" not in params or "J" not in params:
                raise ValueError("Must specify both I and J with G5.1")
            control = start + np.array([params["I"], params["J"]]) * scale
            points = np.array([start, control, end])
            return polyline(lambda t: quadratic_bezier(points, t), self.tolerance)
        if name == "spline_cubic":
            if "P" not in params or "Q" not in params:
                raise ValueError("Must specify both P and Q with G5")
            if ("I" in params) != ("J" in params):
                raise ValueError("Must specify both I and J, or neither, with G5")
            first = np.array([params["I"], params["J"]]) * scale if "I" in params else -self._handle
            self._handle = np.array([params["P"], params["Q"]]) * scale
            points = np.array([start, start + first, end + self._handle, end])
            return polyline(lambda t: cubic_bezier(points, t), self.tolerance)
        return self._add_control_point(name, params, start, end)

    def discard(self) -> None:
        """Forget an open NURBS (another motion mode ended it)."""
        self._order, self._points, self._weights = 0, [], []

    def _add_control_point(self, name: str, params: dict, start: np.ndarray, end: np.ndarray) -> None:
        if name == "nurbs_start":
            self._order = int(params.get("L", 3))
            self._points, self._weights = [start], [1.0]
            if "X" not in params and "Y" not in params:  # the block only opens the curve
                self._weights[0] = float(params.get("P", 1.0))
                return None
        elif not self._order:
            raise ValueError("Cannot use a NURBS control point without G5.2 first")
        if "X" not in params or "Y" not in params:
            raise ValueError("You must specify both X and Y coordinates for Control Points")
        weight = params.get("P", 0.0)
        if not weight > 0:
            raise ValueError("Must specify positive weight P for every Control Point")
        self._points.append(end)
        self._weights.append(float(weight))
        return None

    def _close_nurbs(self) -> np.ndarray:
        if not self._order:
            raise ValueError("Cannot use G5.3 without G5.2 first")
        points, weights, order = np.array(self._points), np.array(self._weights), self._order
        self.discard()
        if len(points) < order:
            raise ValueError(f"You must specify a number of control points at least equal to the order L = {order}")
        if order < 2:
            raise ValueError(f"the order L of a NURBS must be at least 2, not {order}")
        return polyline(lambda t: nurbs(points, weights, order, t), self.tolerance)
