"""Plan stage: the shape of one move -- how its speed changes from entry to exit.

A planner decides each move's entry, cruise and exit speeds; a segment
profile says how the speed gets from one to the next and so how long the
move takes: :class:`Trapezoid` (constant acceleration, most firmware),
:class:`SCurve` (limited jerk), :class:`LinearRamp` and
:class:`ConstantVelocity`.  Every method takes arrays, one value per move.

Examples
--------
>>> float(Trapezoid().duration(100.0, 0.0, 100.0, 0.0, 1000.0))
1.1
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["SegmentTiming", "SegmentProfile", "ConstantVelocity", "LinearRamp", "Trapezoid", "SCurve",
           "PROFILE_TYPES", "DEFAULT_JERK_T"]

#: Time an :class:`SCurve` without ``max_jerk`` takes to build up full
#: acceleration, s (its jerk is ``accel / DEFAULT_JERK_T``).
DEFAULT_JERK_T = 0.1
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


#: ``profile_type`` names of the shapes
PROFILE_TYPES = {"trapezoid": Trapezoid, "scurve": SCurve, "constant": ConstantVelocity}
