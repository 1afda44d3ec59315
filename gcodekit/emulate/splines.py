"""Emulate stage: the curves of LinuxCNC's spline moves, as chords.

G5 (cubic Bézier), G5.1 (quadratic Bézier) and G5.2/G5.3 (NURBS) move the
tool along a curve in the XY plane.  A controller interpolates the curve;
gcodekit follows it with straight chords that stay within
``spline_tolerance`` (mm, from the machine preset) of it, so distances,
times, pictures and the transpiler's plain G1 output all use the real path.

Every curve is cut into (rational) Bézier pieces and each piece is halved
(de Casteljau) until its control points lie within the tolerance of the
chord between its ends.  A piece lies inside the convex hull of its
control points, and the points within the tolerance of a segment form a
convex set, so the whole curve is within the tolerance of its chords, even
where it turns back on itself, which checking sampled curve points cannot
promise.

The NURBS knot vector is the clamped uniform one LinuxCNC builds from the
number of control points and the order L (``knot_vector_creator`` in
``nurbs_additional_functions.cc``): the curve starts at the first control
point and ends at the last.

Examples
--------
>>> import numpy as np
>>> chords = bezier_chords(np.array([[0, 0], [5, 5], [10, 0]], float), 0.01)
>>> chords[0].tolist(), chords[-1].tolist()
([0.0, 0.0], [10.0, 0.0])
"""

from __future__ import annotations

import numpy as np

_MAX_CHORDS = 1 << 16  # a curve is never cut into more chords than this


def clamped_knots(n_points: int, order: int) -> np.ndarray:
    """LinuxCNC's knot vector for ``n_points`` control points of order ``order``, scaled to [0, 1]."""
    n = n_points - 1
    i = np.arange(n + order + 1)
    knots = np.clip(i - order + 1, 0, n - order + 2).astype(float)
    return knots / knots[-1]


def bezier_chords(points: np.ndarray, tolerance: float, weights: np.ndarray | None = None) -> np.ndarray:
    """Chord end points (m, 2) of the Bézier curve with control ``points`` (n, 2), each chord within ``tolerance``.

    ``weights`` (n,), all positive, make it a rational Bézier; None is all ones.
    """
    weights = np.ones(len(points)) if weights is None else np.asarray(weights, float)
    return _chords(_homogeneous(points, weights)[None], tolerance)


def nurbs_chords(points: np.ndarray, weights: np.ndarray, order: int, tolerance: float) -> np.ndarray:
    """Chord end points (m, 2) of LinuxCNC's NURBS (control ``points`` (n, 2), positive ``weights``, order L)."""
    return _chords(_bezier_pieces(_homogeneous(points, weights), order), tolerance)


def _homogeneous(points: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Control points as (w x, w y, w): the rational curve is the projection of a polynomial one."""
    return np.column_stack([np.asarray(points, float) * weights[:, None], weights])


def _bezier_pieces(control: np.ndarray, order: int) -> np.ndarray:
    """The NURBS's homogeneous ``control`` points (n, 3) as Bézier pieces (k, order, 3), in curve order.

    Boehm's knot insertion raises every inner knot to the multiplicity of
    the degree; then each knot span is one Bézier piece, sharing its end
    points with its neighbours.
    """
    degree = order - 1
    knots = list(clamped_knots(len(control), order))
    control = list(control)
    for u in sorted(set(knots[order:-order])):
        for _ in range(degree - knots.count(u)):
            span = max(i for i, k in enumerate(knots) if k <= u)
            inserted = []
            for i in range(span - degree + 1, span + 1):
                alpha = (u - knots[i]) / (knots[i + degree] - knots[i])
                inserted.append(alpha * control[i] + (1.0 - alpha) * control[i - 1])
            control[span - degree + 1:span] = inserted
            knots.insert(span + 1, u)
    control = np.array(control)
    starts = np.arange(0, len(control) - 1, degree)
    return control[starts[:, None] + np.arange(order)[None, :]]


def _chords(pieces: np.ndarray, tolerance: float) -> np.ndarray:
    """Chord end points through the homogeneous Bézier ``pieces`` (k, n, 3), halving each until it is flat."""
    start = pieces[0, 0, :2] / pieces[0, 0, 2]
    place = np.arange(len(pieces), dtype=float)  # where a piece starts along the curve, in whole pieces
    width = np.ones(len(pieces))
    ends, end_places = [], []
    while len(pieces):
        xy = pieces[..., :2] / pieces[..., 2:]
        flat = _within(xy, tolerance)
        if sum(map(len, ends)) + len(pieces) + int(np.count_nonzero(~flat)) > _MAX_CHORDS:
            flat[:] = True
        ends.append(xy[flat, -1])
        end_places.append(place[flat])
        pieces, place, width = pieces[~flat], place[~flat], width[~flat] / 2
        pieces = np.concatenate(_halves(pieces))
        place, width = np.concatenate([place, place + width]), np.concatenate([width, width])
    order = np.argsort(np.concatenate(end_places), kind="stable")
    return np.vstack([start, np.concatenate(ends)[order]])


def _within(xy: np.ndarray, tolerance: float) -> np.ndarray:
    """Whether each piece's control points (k, n, 2) lie within ``tolerance`` of the segment between its ends."""
    a, chord = xy[:, :1], xy[:, -1:] - xy[:, :1]
    off = xy[:, 1:-1] - a
    chord2 = np.maximum(np.sum(chord * chord, axis=2), 1e-300)
    along = np.clip(np.sum(off * chord, axis=2) / chord2, 0.0, 1.0)
    gap = off - along[..., None] * chord
    return np.all(np.sum(gap * gap, axis=2) <= tolerance * tolerance, axis=1)


def _halves(pieces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each piece (k, n, 3) cut at its middle parameter (de Casteljau): the first halves and the second halves."""
    left, right = [pieces[:, 0]], [pieces[:, -1]]
    level = pieces
    while level.shape[1] > 1:
        level = 0.5 * (level[:, :-1] + level[:, 1:])
        left.append(level[:, 0])
        right.append(level[:, -1])
    return np.stack(left, axis=1), np.stack(right[::-1], axis=1)


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
            return bezier_chords(points, self.tolerance)
        if name == "spline_cubic":
            if "P" not in params or "Q" not in params:
                raise ValueError("Must specify both P and Q with G5")
            if ("I" in params) != ("J" in params):
                raise ValueError("Must specify both I and J, or neither, with G5")
            first = np.array([params["I"], params["J"]]) * scale if "I" in params else -self._handle
            self._handle = np.array([params["P"], params["Q"]]) * scale
            points = np.array([start, start + first, end + self._handle, end])
            return bezier_chords(points, self.tolerance)
        return self._add_control_point(name, params, start, end)

    def discard(self) -> None:
        """Forget an open NURBS (another motion mode ended it)."""
        self._order, self._points, self._weights = 0, [], []

    def _add_control_point(self, name: str, params: dict, start: np.ndarray, end: np.ndarray) -> None:
        if name == "nurbs_start":
            self._order = int(params.get("L", 3))
            self._points, self._weights = [start], [1.0]
            if "X" not in params and "Y" not in params:  # the block only opens the curve
                self._weights[0] = float(params.get("P", 1.0))  # rs274 takes 0 or less here too: see G5.3
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
        if not weights[0] > 0:  # no curve to follow (the handler warns at G5.2): a line to its end
            return points[[0, -1]]
        return nurbs_chords(points, weights, order, self.tolerance)
