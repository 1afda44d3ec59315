"""Emulate stage, planning: motion profiles, a GRBL-style lookahead and the shape of one move.

:class:`MotionProfile` times a sequence of straight moves in three steps:

1. **Corner speeds** from the junction-deviation model (GRBL's
   ``planner.c``): the corner is rounded by an arc tangent to both moves
   whose closest point lies ``junction_deviation`` mm from the corner, and
   the speed through it is the one whose centripetal acceleration equals
   ``max_acceleration``.
2. **Forward pass** from rest: a move cannot end faster than it can
   accelerate to, ``end_v**2 <= start_v**2 + 2 * accel * move_d``.
3. **Backward pass** from the final stop: a move cannot start faster than
   it can brake from, so every move can reach the next junction's speed.

Each move is then shaped by a segment profile (:class:`Trapezoid` by
default, :class:`SCurve` for jerk-limited motion).  Without
``max_acceleration`` the corner model is skipped: speed changes are
instantaneous and every move takes ``move_d / cruise_v``.

Both passes are cumulative minima on squared speeds
(:mod:`gcodekit.emulate.planners.scans`), so no Python loop runs per move.
Names follow Klipper's suffixes: ``_d`` mm, ``_v`` mm/s, ``_v2`` mm^2/s^2,
``_t`` s.

Examples
--------
A 100 mm move at 100 mm/s with 1000 mm/s^2 spends 0.1 s accelerating and
0.1 s braking, so it takes ``d / v + v / a``:

>>> import numpy as np
>>> from gcodekit.emulate.planners.base import PlannerMoves
>>> moves = PlannerMoves(np.zeros((1, 4)), np.array([[100.0, 0, 0, 0]]), np.array([100.0]),
...                      np.zeros(1, np.int64), np.zeros(1, np.int64))
>>> float(MotionProfile(max_acceleration=1000.0).plan(moves).duration_t[0])
1.1
"""

from __future__ import annotations

import sys
import warnings
from typing import NamedTuple, Sequence

import numpy as np

from ..errors import did_you_mean
from .planners.base import PlannerMoves, PlanResult
from .planners.scans import backward_min, forward_min

#: Time an :class:`SCurve` without ``max_jerk`` takes to build up full
#: acceleration, s (its jerk is ``accel / DEFAULT_JERK_T``).
DEFAULT_JERK_T = 0.1
#: Moves shorter than this in X, Y and Z (mm) are extruder-only moves
#: (Klipper's ``move_d < .000000001`` test).
MIN_MOVE_D = 1e-9
#: Bisection steps that find an S-curve's peak speed: each halves the
#: interval, so 64 reach the last bit of a float.
_BISECT_STEPS = 64
#: Doublings of a trial peak speed from 1 mm/s: enough to pass the largest float.
_DOUBLING_STEPS = 1100


class SegmentTiming(NamedTuple):
    """Phase durations of moves and the highest speed each reaches."""

    accel_t: np.ndarray
    cruise_t: np.ndarray
    decel_t: np.ndarray
    cruise_v: np.ndarray

    @property
    def duration_t(self) -> np.ndarray:
        return self.accel_t + self.cruise_t + self.decel_t


def _arrays(*values) -> list[np.ndarray]:
    return [np.asarray(v, float) for v in np.broadcast_arrays(*values)]


class SegmentProfile:
    """How speed changes along one move; subclasses give the shape.

    Every method takes the move's length ``move_d`` (mm), its entry speed
    ``start_v``, the speed it may cruise at ``cruise_v``, its exit speed
    ``end_v`` (mm/s) and the acceleration limit ``accel`` (mm/s^2,
    ``np.inf`` for none).  :meth:`timing` and :meth:`duration` take arrays
    (one value per move); :meth:`velocity_at` and :meth:`sample` describe
    one move, for plots.
    """

    def timing(self, move_d, start_v, cruise_v, end_v, accel=np.inf) -> SegmentTiming:
        """Phase durations (s) and reached speed of each move."""
        raise NotImplementedError

    def duration(self, move_d, start_v, cruise_v, end_v, accel=np.inf) -> np.ndarray:
        """Time of each move, s (the sum of :meth:`timing`'s phases)."""
        return self.timing(move_d, start_v, cruise_v, end_v, accel).duration_t

    def _pieces(self, move_d, start_v, cruise_v, end_v, accel) -> list[tuple[float, float, float, float]]:
        """One move as pieces of constant jerk: (duration_t, start_v, start accel, jerk)."""
        raise NotImplementedError

    def velocity_at(self, t, move_d, start_v, cruise_v, end_v, accel=np.inf) -> np.ndarray:
        """Speed (mm/s) of one move ``t`` seconds after it starts (clipped to the move)."""
        pieces = self._pieces(float(move_d), float(start_v), float(cruise_v), float(end_v), float(accel))
        piece_t = np.array([p[0] for p in pieces])
        edges_t = np.concatenate([[0.0], np.cumsum(piece_t)])
        t = np.clip(np.asarray(t, float), 0.0, edges_t[-1])
        k = np.clip(np.searchsorted(edges_t, t, side="right") - 1, 0, len(pieces) - 1)
        v0, a0, jerk = (np.array([p[i] for p in pieces])[k] for i in (1, 2, 3))
        tau = t - edges_t[k]
        return v0 + a0 * tau + 0.5 * jerk * tau * tau

    def sample(self, move_d, start_v, cruise_v, end_v, accel=np.inf, *, num: int = 200):
        """Times (s) and speeds (mm/s) at ``num`` even steps through one move.

        Examples
        --------
        A 10 mm move from rest to rest at 20 mm/s with 100 mm/s^2:

        >>> t, v = Trapezoid().sample(10.0, 0.0, 20.0, 0.0, 100.0, num=5)
        >>> round(float(t[-1]), 3), float(v.max())
        (0.7, 20.0)
        """
        total_t = float(self.duration(move_d, start_v, cruise_v, end_v, accel))
        t = np.linspace(0.0, total_t, num)
        return t, self.velocity_at(t, move_d, start_v, cruise_v, end_v, accel)

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class ConstantVelocity(SegmentProfile):
    """The whole move at ``cruise_v``; entry and exit speeds are ignored.

    ``duration_t = move_d / cruise_v``.
    """

    def timing(self, move_d, start_v, cruise_v, end_v, accel=np.inf) -> SegmentTiming:
        move_d, cruise_v = _arrays(move_d, cruise_v)
        with np.errstate(divide="ignore", invalid="ignore"):
            cruise_t = np.where(move_d > 0, move_d / cruise_v, 0.0)
        zero = np.zeros_like(move_d)
        return SegmentTiming(zero, cruise_t, zero.copy(), cruise_v)

    def _pieces(self, move_d, start_v, cruise_v, end_v, accel):
        return [(float(self.duration(move_d, start_v, cruise_v, end_v)), cruise_v, 0.0, 0.0)]


class LinearRamp(SegmentProfile):
    """Constant acceleration from ``start_v`` to ``end_v`` over the whole move.

    The speed is linear in time, so the mean speed is the mean of the two
    ends: ``duration_t = 2 * move_d / (start_v + end_v)`` and the
    acceleration is ``(end_v**2 - start_v**2) / (2 * move_d)``.
    ``cruise_v`` and ``accel`` are ignored.
    """

    def timing(self, move_d, start_v, cruise_v, end_v, accel=np.inf) -> SegmentTiming:
        move_d, start_v, end_v = _arrays(move_d, start_v, end_v)
        with np.errstate(divide="ignore", invalid="ignore"):
            ramp_t = np.where(move_d > 0, 2.0 * move_d / (start_v + end_v), 0.0)
        zero = np.zeros_like(move_d)
        speeding_up = end_v >= start_v
        return SegmentTiming(np.where(speeding_up, ramp_t, 0.0), zero, np.where(speeding_up, 0.0, ramp_t),
                             np.maximum(start_v, end_v))

    def _pieces(self, move_d, start_v, cruise_v, end_v, accel):
        ramp_t = float(self.duration(move_d, start_v, cruise_v, end_v))
        return [(ramp_t, start_v, (end_v - start_v) / ramp_t if ramp_t > 0 else 0.0, 0.0)]


class Trapezoid(SegmentProfile):
    """Accelerate, cruise, decelerate: the usual firmware profile.

    Acceleration-limited (the default): the speed rises at ``accel`` from
    ``start_v``, cruises, and falls at ``accel`` to ``end_v``.  The highest
    speed is ``min(cruise_v, sqrt((start_v**2 + end_v**2) / 2 + accel *
    move_d))``; when the second term wins the cruise vanishes and the
    profile is a triangle.  Phase lengths are ``accel_d = (cruise_v2 -
    start_v2) / (2 * accel)``, likewise ``decel_d``, and ``accel_t =
    (cruise_v - start_v) / accel``.  From rest to rest at full speed a move
    takes ``move_d / cruise_v + cruise_v / accel``; a triangular one
    ``2 * sqrt(move_d / accel)``.

    Distance-limited (``ramp_fraction`` given): each ramp covers that
    fraction of the move at whatever acceleration it takes, ``accel`` is
    ignored: ``accel_t = 2 * ramp_fraction * move_d / (start_v + cruise_v)``,
    ``cruise_t = (1 - 2 * ramp_fraction) * move_d / cruise_v``.

    ``cruise_v`` is raised to ``max(start_v, end_v)`` if lower; entry and
    exit speeds must be reachable (``|end_v**2 - start_v**2| <= 2 * accel *
    move_d``), as :meth:`MotionProfile.plan` ensures.

    Parameters
    ----------
    ramp_fraction : float, default: None (acceleration-limited)
        Share of the move each ramp takes, 0 to 0.5.

    Examples
    --------
    >>> float(Trapezoid().duration(100.0, 0.0, 100.0, 0.0, 1000.0))
    1.1
    >>> float(Trapezoid(ramp_fraction=0.25).duration(100.0, 0.0, 100.0, 0.0))
    1.5
    """

    def __init__(self, *, ramp_fraction: float | None = None):
        if ramp_fraction is not None and not 0.0 <= ramp_fraction <= 0.5:
            raise ValueError(f"ramp_fraction must lie between 0 and 0.5, not {ramp_fraction!r}")
        self.ramp_fraction = ramp_fraction

    def __repr__(self) -> str:
        return "Trapezoid()" if self.ramp_fraction is None else f"Trapezoid(ramp_fraction={self.ramp_fraction!r})"

    def timing(self, move_d, start_v, cruise_v, end_v, accel=np.inf) -> SegmentTiming:
        move_d, start_v, cruise_v, end_v, accel = _arrays(move_d, start_v, cruise_v, end_v, accel)
        cruise_v = np.maximum.reduce([cruise_v, start_v, end_v])
        if self.ramp_fraction is not None:
            return self._distance_limited(move_d, start_v, cruise_v, end_v)
        start_v2, end_v2 = start_v * start_v, end_v * end_v
        # Highest speed from which the move can still brake to end_v:
        # (v2 - start_v2) + (v2 - end_v2) = 2 * accel * move_d.
        with np.errstate(invalid="ignore"):
            gain_v2 = np.where(move_d > 0, accel * move_d, 0.0)  # inf * 0 is no gain
        peak_v2 = np.minimum(cruise_v * cruise_v, 0.5 * (start_v2 + end_v2) + gain_v2)
        # rounding in the planner's passes can leave a reachable end a few ulps short
        peak_v2 = np.maximum(peak_v2, np.maximum(start_v2, end_v2))
        peak_v = np.sqrt(peak_v2)
        half_inv_accel = 0.5 / accel
        accel_d = (peak_v2 - start_v2) * half_inv_accel
        decel_d = (peak_v2 - end_v2) * half_inv_accel
        cruise_d = np.maximum(move_d - accel_d - decel_d, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            cruise_t = np.where(cruise_d > 0, cruise_d / peak_v, 0.0)
        return SegmentTiming((peak_v - start_v) / accel, cruise_t, (peak_v - end_v) / accel, peak_v)

    def _distance_limited(self, move_d, start_v, cruise_v, end_v) -> SegmentTiming:
        ramp_d = self.ramp_fraction * move_d
        with np.errstate(divide="ignore", invalid="ignore"):
            # a linear ramp covers its distance at the mean of its end speeds
            accel_t = np.where(ramp_d > 0, 2.0 * ramp_d / (start_v + cruise_v), 0.0)
            decel_t = np.where(ramp_d > 0, 2.0 * ramp_d / (cruise_v + end_v), 0.0)
            cruise_d = move_d - 2.0 * ramp_d
            cruise_t = np.where(cruise_d > 0, cruise_d / cruise_v, 0.0)
        return SegmentTiming(accel_t, cruise_t, decel_t, cruise_v)

    def _pieces(self, move_d, start_v, cruise_v, end_v, accel):
        accel_t, cruise_t, decel_t, peak_v = (float(x) for x in self.timing(move_d, start_v, cruise_v, end_v, accel))
        rise = (peak_v - start_v) / accel_t if accel_t > 0 else 0.0
        fall = (peak_v - end_v) / decel_t if decel_t > 0 else 0.0
        return [(accel_t, start_v, rise, 0.0), (cruise_t, peak_v, 0.0, 0.0), (decel_t, peak_v, -fall, 0.0)]


class SCurve(SegmentProfile):
    """Jerk-limited profile: acceleration itself ramps at ``max_jerk``.

    A speed change ``dv`` is an S-shaped ramp.  When ``dv >= accel**2 /
    jerk`` it has three phases (jerk up for ``accel / jerk``, constant
    ``accel``, jerk down) and takes ``dv / accel + accel / jerk``;
    otherwise acceleration never reaches ``accel`` and it takes ``2 *
    sqrt(dv / jerk)``.  Either ramp is symmetric, so it covers ``(v_lo +
    v_hi) / 2`` times its duration.  A move is ramp up, cruise, ramp down:
    seven phases when the ramps to ``cruise_v`` fit in ``move_d``; else the
    peak speed is lowered (found by bisection, vectorized) until they fit.
    If even a direct ramp from ``start_v`` to ``end_v`` does not fit (the
    planner's passes limit acceleration, not jerk), the move is that one
    ramp, taking ``2 * move_d / (start_v + end_v)`` with a steeper jerk.

    With ``jerk = inf`` every formula is the :class:`Trapezoid`'s, and an
    S-curve is never faster than the trapezoid with the same limits.

    Parameters
    ----------
    max_jerk : float, default: None
        mm/s^3; None uses ``accel / DEFAULT_JERK_T`` (full acceleration
        after 0.1 s).

    Examples
    --------
    >>> s = SCurve(max_jerk=10000.0).duration(100.0, 0.0, 100.0, 0.0, 1000.0)
    >>> t = Trapezoid().duration(100.0, 0.0, 100.0, 0.0, 1000.0)
    >>> round(float(s - t), 6)
    0.1
    """

    def __init__(self, max_jerk: float | None = None):
        if max_jerk is not None and not max_jerk > 0:
            raise ValueError(f"max_jerk must be positive, not {max_jerk!r}")
        self.max_jerk = max_jerk

    def __repr__(self) -> str:
        return f"SCurve(max_jerk={self.max_jerk!r})"

    def _jerk(self, accel: np.ndarray) -> np.ndarray:
        return accel / DEFAULT_JERK_T if self.max_jerk is None else np.full_like(accel, self.max_jerk)

    @staticmethod
    def _ramp(dv, accel, jerk):
        """(jerk_t, const_t) of an S-ramp changing speed by ``dv``: 2 jerk phases + 1 at constant accel."""
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            reaches = dv >= accel * accel / jerk  # NaN when both limits are infinite: instantaneous
            jerk_t = np.where(reaches, accel / jerk, np.sqrt(dv / jerk))
            const_t = np.where(reaches, np.maximum(dv / accel - accel / jerk, 0.0), 0.0)
        return jerk_t, const_t

    def _solve(self, move_d, start_v, cruise_v, end_v, accel):
        move_d, start_v, cruise_v, end_v, accel = _arrays(move_d, start_v, cruise_v, end_v, accel)
        shape = move_d.shape
        move_d, start_v, cruise_v, end_v, accel = (x.ravel() for x in (move_d, start_v, cruise_v, end_v, accel))
        jerk = self._jerk(accel)
        cruise_v = np.maximum.reduce([cruise_v, start_v, end_v])

        def ramps_d(peak_v, sel=slice(None)):
            up_j, up_c = self._ramp(peak_v - start_v[sel], accel[sel], jerk[sel])
            down_j, down_c = self._ramp(peak_v - end_v[sel], accel[sel], jerk[sel])
            return (0.5 * (start_v[sel] + peak_v) * (2 * up_j + up_c)
                    + 0.5 * (end_v[sel] + peak_v) * (2 * down_j + down_c))

        peak_v = cruise_v.copy()
        low_v = np.maximum(start_v, end_v)
        short = ramps_d(cruise_v) > move_d
        direct = short & (ramps_d(low_v) > move_d * (1 + 1e-12))
        lower = np.flatnonzero(short & ~direct)
        if lower.size:
            # ramps_d grows with the peak speed: bisect between max(start_v, end_v) and cruise_v,
            # or the trapezoid's peak (jerk limits only lengthen ramps) when cruise_v is unbounded
            lo = low_v[lower]
            hi = np.minimum(cruise_v[lower], Trapezoid().timing(move_d[lower], start_v[lower], cruise_v[lower],
                                                                 end_v[lower], accel[lower]).cruise_v)
            grow = ~np.isfinite(hi)
            hi[grow] = np.maximum(lo[grow], 1.0)
            for _ in range(_DOUBLING_STEPS):  # no acceleration limit: double until the ramps overshoot
                if not grow.any():
                    break
                grow[grow] = ramps_d(hi[grow], lower[grow]) <= move_d[lower[grow]]
                hi[grow] *= 2.0
            for _ in range(_BISECT_STEPS):
                mid = 0.5 * (lo + hi)
                fits = ramps_d(mid, lower) <= move_d[lower]
                lo, hi = np.where(fits, mid, lo), np.where(fits, hi, mid)
            peak_v[lower] = lo
        peak_v[direct] = low_v[direct]
        up_j, up_c = self._ramp(peak_v - start_v, accel, jerk)
        down_j, down_c = self._ramp(peak_v - end_v, accel, jerk)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            cruise_d = move_d - ramps_d(peak_v)
            cruise_t = np.where(~direct & (cruise_d > 0), cruise_d / peak_v, 0.0)
            # the one ramp that does not fit the jerk limit: pure jerk phases, no constant accel
            ramp_t = 2.0 * move_d / (start_v + end_v)
        rising = end_v > start_v
        up_j = np.where(direct, np.where(rising, 0.5 * ramp_t, 0.0), up_j)
        down_j = np.where(direct, np.where(rising, 0.0, 0.5 * ramp_t), down_j)
        up_c = np.where(direct, 0.0, up_c)
        down_c = np.where(direct, 0.0, down_c)
        up_j, up_c, down_j, down_c, peak_v, cruise_t = (
            x.reshape(shape) for x in (up_j, up_c, down_j, down_c, peak_v, cruise_t))
        return peak_v, (up_j, up_c), cruise_t, (down_j, down_c)

    def timing(self, move_d, start_v, cruise_v, end_v, accel=np.inf) -> SegmentTiming:
        peak_v, (up_j, up_c), cruise_t, (down_j, down_c) = self._solve(move_d, start_v, cruise_v, end_v, accel)
        return SegmentTiming(2 * up_j + up_c, cruise_t, 2 * down_j + down_c, peak_v)

    def _pieces(self, move_d, start_v, cruise_v, end_v, accel):
        peak_v, (up_j, up_c), cruise_t, (down_j, down_c) = self._solve(move_d, start_v, cruise_v, end_v, accel)
        peak_v, up_j, up_c, cruise_t, down_j, down_c = map(float, (peak_v, up_j, up_c, cruise_t, down_j, down_c))

        def ramp(v_from, v_to, jerk_t, const_t):
            # peak acceleration a_p: the two jerk phases and the flat one gain a_p * (jerk_t + const_t)
            span_t = jerk_t + const_t
            a_p = (v_to - v_from) / span_t if span_t > 0 else 0.0
            j = a_p / jerk_t if jerk_t > 0 else 0.0
            half = 0.5 * a_p * jerk_t
            return [(jerk_t, v_from, 0.0, j), (const_t, v_from + half, a_p, 0.0), (jerk_t, v_to - half, a_p, -j)]

        return ramp(start_v, peak_v, up_j, up_c) + [(cruise_t, peak_v, 0.0, 0.0)] + ramp(
            peak_v, end_v, down_j, down_c)


_PROFILE_TYPES = {"trapezoid": Trapezoid, "scurve": SCurve, "constant": ConstantVelocity}


def _outside_caller_level() -> int:
    """``stacklevel`` of the first frame outside this module (subclass constructors included)."""
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_code.co_filename == __file__:
        frame, level = frame.f_back, level + 1
    return level


class MotionProfile:
    """A GRBL-style lookahead planner: corner speeds, forward and backward passes.

    Parameters
    ----------
    max_acceleration : float, default: None
        mm/s^2.  None skips the corner model: speed changes are
        instantaneous and each move takes ``move_d / cruise_v``.
    max_velocity : float, default: None
        mm/s; ceiling on every move's requested speed.
    junction_deviation : float, default: 0.05
        mm; distance from the corner to the arc that rounds it.  Larger is
        faster through corners.
    max_jerk : float, default: None
        mm/s^3, for an :class:`SCurve` given as a class.

    Attributes
    ----------
    profile_type : SegmentProfile class or instance, default: Trapezoid
        Shape of each move: :class:`Trapezoid`, :class:`SCurve` or
        :class:`ConstantVelocity`, a class or a configured instance
        (``SCurve(max_jerk=5000)``), or its name (``"scurve"``).

    Notes
    -----
    The keyword ``max_accleration`` is accepted for ``max_acceleration``
    with a :class:`DeprecationWarning` (the spelling of an older user
    guide's example).

    Subclasses add machine rules by overriding
    :meth:`_apply_machine_constraints`; see :class:`BAAMMotionProfile`.

    Examples
    --------
    Two 10 mm moves meeting at a right angle slow to the corner speed
    ``sqrt(max_acceleration * junction_deviation * s / (1 - s))``, ``s =
    sin(45 deg)``:

    >>> import numpy as np
    >>> from gcodekit.emulate.planners.base import PlannerMoves
    >>> ends = np.array([[0, 0, 0, 0], [10, 0, 0, 0], [10, 10, 0, 0]], float)
    >>> moves = PlannerMoves(ends[:-1], ends[1:], np.full(2, 100.0), np.arange(2), np.arange(2))
    >>> result = MotionProfile(max_acceleration=1000.0).plan(moves)
    >>> round(float(result.end_v[0]), 3)
    10.987
    """

    def __init__(self, max_acceleration: float | None = None, max_velocity: float | None = None,
                 junction_deviation: float = 0.05, *, max_jerk: float | None = None, **deprecated):
        if "max_accleration" in deprecated:
            warnings.warn("MotionProfile(max_accleration=...) is misspelt; use max_acceleration",
                          DeprecationWarning, stacklevel=_outside_caller_level())
            value = deprecated.pop("max_accleration")
            if max_acceleration is not None:
                raise TypeError("give max_acceleration once (max_accleration is its misspelt alias)")
            max_acceleration = value
        if deprecated:
            key = next(iter(deprecated))
            known = ("max_acceleration", "max_velocity", "junction_deviation", "max_jerk")
            raise TypeError(f"{type(self).__name__}() got an unexpected keyword argument {key!r}"
                            + did_you_mean(key, known))
        for name, value in (("max_acceleration", max_acceleration), ("max_velocity", max_velocity),
                            ("max_jerk", max_jerk)):
            if value is not None and not value > 0:
                raise ValueError(f"{name} must be positive or None, not {value!r}")
        if not junction_deviation >= 0:
            raise ValueError(f"junction_deviation must be 0 or more, not {junction_deviation!r}")
        self.max_acceleration = max_acceleration
        self.max_velocity = max_velocity
        self.junction_deviation = junction_deviation
        self.max_jerk = max_jerk
        self._profile_type = Trapezoid

    @property
    def profile_type(self):
        return self._profile_type

    @profile_type.setter
    def profile_type(self, value) -> None:
        if isinstance(value, str):
            if value not in _PROFILE_TYPES:
                raise ValueError(f"profile_type={value!r} is not one of {', '.join(map(repr, _PROFILE_TYPES))}"
                                 + did_you_mean(value, _PROFILE_TYPES))
            value = _PROFILE_TYPES[value]
        allowed = tuple(_PROFILE_TYPES.values())
        if not (isinstance(value, allowed) or (isinstance(value, type) and issubclass(value, allowed))):
            raise TypeError(f"profile_type must be Trapezoid, SCurve or ConstantVelocity (a class, an "
                            f"instance or its name), not {value!r}")
        self._profile_type = value

    def segment_profile(self) -> SegmentProfile:
        """The :class:`SegmentProfile` instance :meth:`plan` shapes moves with."""
        p = self._profile_type
        if isinstance(p, SegmentProfile):
            return p
        return SCurve(self.max_jerk) if issubclass(p, SCurve) else p()

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(max_acceleration={self.max_acceleration!r}, "
                f"max_velocity={self.max_velocity!r}, junction_deviation={self.junction_deviation!r}, "
                f"profile_type={self.segment_profile()!r})")

    # -- planning ------------------------------------------------------------------

    def plan(self, moves: PlannerMoves, *, stops: np.ndarray | None = None) -> PlanResult:
        """Entry, cruise and exit speeds and phase times of each move.

        Parameters
        ----------
        moves : PlannerMoves
            Straight moves in order; ``speed_v`` is each one's requested
            speed (mm/s).  A move without X, Y or Z travel is measured along
            the extruder and comes to rest at both ends.
        stops : ndarray of bool, default: None
            Moves after which the machine comes to rest (dwells, tool
            changes, exact-stop mode).

        Returns
        -------
        PlanResult
            Per move.  Moves whose requested speed is not positive or NaN
            (no feed in force) get NaN times and zero speeds, and stop at
            both ends.
            ``accel`` is ``inf`` without ``max_acceleration``.
        """
        n = len(moves)
        if n == 0:
            empty = np.zeros(0)
            return PlanResult(empty, empty, empty, empty, empty, empty, empty)
        axes_d = moves.axes_d
        dx, dy, dz = axes_d[:, 0], axes_d[:, 1], axes_d[:, 2]
        move_d = np.sqrt(dx * dx + dy * dy + dz * dz)
        is_kinematic = move_d >= MIN_MOVE_D
        move_d = np.where(is_kinematic, move_d, np.abs(axes_d[:, 3]))
        with np.errstate(divide="ignore", invalid="ignore"):
            axes_r = np.where(is_kinematic[:, None], axes_d[:, :3] / move_d[:, None], 0.0)
        target_v = np.asarray(moves.speed_v, float)
        if self.max_velocity is not None:
            target_v = np.minimum(target_v, self.max_velocity)
        accel = self.max_acceleration
        if accel is None:
            junction_v = np.r_[np.minimum(target_v[:-1], target_v[1:]), 0.0]
        else:
            junction_v = self._corner_velocities(axes_r, is_kinematic & np.r_[is_kinematic[1:], False], accel)
        if stops is not None:
            junction_v = np.where(np.asarray(stops, bool), 0.0, junction_v)
        target_v, junction_v = self._apply_machine_constraints(
            moves.start[:, :3], moves.end[:, :3], np.array(target_v, float), np.array(junction_v, float))
        target_v = np.asarray(target_v, float)
        known = target_v > 0  # False for NaN: the emulator found no feed in force
        # any positive stand-in: such moves stop at both ends and their results become NaN
        cruise_v = np.where(known, target_v, 1.0)

        if accel is None:
            # no acceleration limit: every move runs at its own speed from start to end
            timing = ConstantVelocity().timing(move_d, cruise_v, cruise_v, cruise_v)
            start_v = end_v = cruise_v
            accel_a = np.full(n, np.inf)
        else:
            max_cruise_v2 = cruise_v * cruise_v
            next_cruise_v2 = np.r_[max_cruise_v2[1:], 0.0]
            junction_v2 = np.minimum.reduce([np.asarray(junction_v, float) ** 2, max_cruise_v2, next_cruise_v2])
            junction_v2 = np.where(known & np.r_[known[1:], False], junction_v2, 0.0)
            delta_v2 = 2.0 * accel * move_d
            # Junction k is the start of move k; junction n the end of the last move.
            cap_v2 = np.r_[0.0, junction_v2]
            inc_v2 = np.r_[delta_v2, 0.0]
            # Forward pass from rest, the loop
            #     v2[0] = 0; for i in range(n): v2[i + 1] = min(cap_v2[i + 1], v2[i] + delta_v2[i])
            # With S[k] = delta_v2[0] + ... + delta_v2[k - 1], v2[k] - S[k] = min(cap_v2[k] - S[k],
            # v2[k - 1] - S[k - 1]): a running minimum (scans.forward_min).
            reach_v2 = forward_min(cap_v2, inc_v2)
            # Backward pass from the final stop, the loop
            #     v2[n] = 0; for i in reversed(range(n)): v2[i] = min(reach_v2[i], v2[i + 1] + delta_v2[i])
            # is the same running minimum with sums taken from the end (scans.backward_min).
            v2 = backward_min(reach_v2, inc_v2, 0.0)
            start_v, end_v = np.sqrt(v2[:-1]), np.sqrt(v2[1:])
            timing = self.segment_profile().timing(move_d, start_v, cruise_v, end_v, accel)
            accel_a = np.full(n, float(accel))
        unknown = ~known
        out = [np.where(unknown, 0.0, x) for x in (start_v, timing.cruise_v, end_v)]
        phases = [np.where(unknown, np.nan, x) for x in (timing.accel_t, timing.cruise_t, timing.decel_t)]
        return PlanResult(out[0], out[1], out[2], accel_a, *phases)

    def _corner_velocities(self, axes_r: np.ndarray, corner: np.ndarray, accel: float) -> np.ndarray:
        """Speed limit at the end of each move from the junction-deviation model (GRBL ``planner.c``).

        The corner is replaced by an arc tangent to both moves whose
        closest point lies ``junction_deviation`` from the corner.  With
        ``theta`` the angle at the corner between the way back along the
        first move and the way on along the second (``cos(theta) =
        -u1 . u2``: pi going straight on, 0 reversing), that arc's radius
        is ``R = junction_deviation * sin(theta/2) / (1 - sin(theta/2))``
        and the speed whose centripetal acceleration is ``accel`` is
        ``v**2 = accel * R``: unlimited straight on, 0 on a reversal.
        ``corner[k]`` is False where move k or k+1 has no X/Y/Z direction
        (a stop there); the last move ends at rest.
        """
        n = axes_r.shape[0]
        junction_v = np.zeros(n)
        if n < 2:
            return junction_v
        junction_cos_theta = -np.einsum("ij,ij->i", axes_r[:-1], axes_r[1:])
        sin_theta_d2 = np.sqrt(np.maximum(0.5 * (1.0 - junction_cos_theta), 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            R_jd = np.where(sin_theta_d2 < 1.0, sin_theta_d2 / (1.0 - sin_theta_d2), np.inf)
        junction_v[:-1] = np.where(corner[:-1], np.sqrt(accel * self.junction_deviation * R_jd), 0.0)
        if self.junction_deviation == 0:  # 0 * inf: a straight continuation is still unlimited
            junction_v[:-1] = np.where(corner[:-1] & (sin_theta_d2 >= 1.0), np.inf, junction_v[:-1])
        return junction_v

    def _apply_machine_constraints(self, initial_positions: np.ndarray, final_positions: np.ndarray,
                                   target_velocities: np.ndarray, junction_velocities: np.ndarray):
        """Machine rules beyond the corner model; override in a subclass.

        Called by :meth:`plan` just before the forward and backward passes,
        which then carry whatever is imposed here through the whole path.

        Parameters
        ----------
        initial_positions, final_positions : ndarray, shape (n, 3)
            X, Y, Z at the start and end of each move, mm.
        target_velocities : ndarray, shape (n,)
            Requested speed of each move after ``max_velocity``, mm/s.
        junction_velocities : ndarray, shape (n,)
            Speed limit at the end of each move (the junction with the
            next), mm/s; the last entry is the final stop.  ``inf`` means
            no corner limit.

        Returns
        -------
        (target_velocities, junction_velocities)
            The arrays to plan with; junction speeds are capped again by
            the target speeds on both sides afterwards.
        """
        return target_velocities, junction_velocities


class BAAMMotionProfile(MotionProfile):
    """Cincinnati BAAM (Big Area Additive Manufacturing) rules on top of the corner model.

    * The machine stops before and after every layer change: a move along
      Z only ends at rest, and so does the move before it.
    * Per-axis speed limits: a move at speed ``v`` along unit direction
      ``u`` drives axis ``k`` at ``v * |u_k|``, so its speed is capped at
      ``min_k(axis_max_velocity[k] / |u_k|)``.

    Parameters
    ----------
    axis_max_velocity : sequence of 3 floats or None, default: None
        X, Y, Z limits in mm/s; None (or a None entry) leaves that axis
        unlimited.  Take them from the machine's documentation.
    **kwargs
        :class:`MotionProfile` parameters.

    Examples
    --------
    A 10 mm move along X and Y at 100 mm/s with X limited to 30 mm/s runs
    at ``30 / cos(45 deg)``:

    >>> import numpy as np
    >>> from gcodekit.emulate.planners.base import PlannerMoves
    >>> moves = PlannerMoves(np.zeros((1, 4)), np.array([[10.0, 10, 0, 0]]), np.array([100.0]),
    ...                      np.zeros(1, np.int64), np.zeros(1, np.int64))
    >>> baam = BAAMMotionProfile(axis_max_velocity=(30.0, None, None))
    >>> round(float(baam.plan(moves).cruise_v[0]), 3)
    42.426
    """

    #: X and Y travel (mm) below which a Z move counts as a layer change
    layer_change_tolerance_d = 1e-9

    def __init__(self, *args, axis_max_velocity: Sequence[float | None] | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        if axis_max_velocity is not None:
            axis_max_velocity = tuple(axis_max_velocity)
            if len(axis_max_velocity) != 3 or any(v is not None and not v > 0 for v in axis_max_velocity):
                raise ValueError(f"axis_max_velocity must be 3 positive speeds (X, Y, Z) or None, "
                                 f"not {axis_max_velocity!r}")
        self.axis_max_velocity = axis_max_velocity

    def _apply_machine_constraints(self, initial_positions, final_positions, target_velocities,
                                   junction_velocities):
        axes_d = np.asarray(final_positions, float) - np.asarray(initial_positions, float)
        tol = self.layer_change_tolerance_d
        layer_change = (np.abs(axes_d[:, 0]) <= tol) & (np.abs(axes_d[:, 1]) <= tol) & (np.abs(axes_d[:, 2]) > tol)
        # junction k is the end of move k: stop at the end of a layer change and of the move before it
        stop = layer_change | np.r_[layer_change[1:], False]
        junction_velocities = np.where(stop, 0.0, junction_velocities)
        if self.axis_max_velocity is not None:
            move_d = np.sqrt(np.einsum("ij,ij->i", axes_d, axes_d))
            limits = np.array([np.inf if v is None else v for v in self.axis_max_velocity])
            with np.errstate(divide="ignore", invalid="ignore"):
                axes_r = np.abs(axes_d) / move_d[:, None]
                axis_caps = np.where(axes_r > 0, limits / axes_r, np.inf)
            target_velocities = np.minimum(target_velocities, axis_caps.min(axis=1))
        return target_velocities, junction_velocities
