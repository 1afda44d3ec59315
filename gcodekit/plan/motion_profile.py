"""Plan stage: the generic planner, :class:`MotionProfile` (a GRBL-style lookahead) and :class:`BAAMMotionProfile`.

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

Each move is then shaped by a segment profile (:class:`~.shapes.Trapezoid`
by default, :class:`~.shapes.SCurve` for jerk-limited motion; see
:mod:`.shapes`).  Without
``max_acceleration`` the corner model is skipped: speed changes are
instantaneous and every move takes ``move_d / cruise_v``.

Both passes are cumulative minima on squared speeds
(:mod:`gcodekit.plan.scans`), so no Python loop runs per move.
Names follow Klipper's suffixes: ``_d`` mm, ``_v`` mm/s, ``_v2`` mm^2/s^2,
``_t`` s.

Examples
--------
A 100 mm move at 100 mm/s with 1000 mm/s^2 spends 0.1 s accelerating and
0.1 s braking, so it takes ``d / v + v / a``:

>>> import numpy as np
>>> from gcodekit.plan.moves import PlannerMoves
>>> moves = PlannerMoves(np.zeros((1, 4)), np.array([[100.0, 0, 0, 0]]), np.array([100.0]),
...                      np.zeros(1, np.int64), np.zeros(1, np.int64))
>>> float(MotionProfile(max_acceleration=1000.0).plan(moves).duration_t[0])
1.1
"""

from __future__ import annotations

import sys
import warnings
from typing import Sequence

import numpy as np

from ..errors import did_you_mean
from .moves import PlannerMoves, PlanResult
from .scans import backward_min, forward_min
from .shapes import PROFILE_TYPES, ConstantVelocity, SCurve, SegmentProfile, Trapezoid

__all__ = ["MotionProfile", "BAAMMotionProfile", "SegmentProfile", "Trapezoid", "SCurve", "ConstantVelocity"]

#: Moves shorter than this in X, Y and Z (mm) are extruder-only moves
#: (Klipper's ``move_d < .000000001`` test).
MIN_MOVE_D = 1e-9


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
    >>> from gcodekit.plan.moves import PlannerMoves
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
            if value not in PROFILE_TYPES:
                raise ValueError(f"profile_type={value!r} is not one of {', '.join(map(repr, PROFILE_TYPES))}"
                                 + did_you_mean(value, PROFILE_TYPES))
            value = PROFILE_TYPES[value]
        allowed = tuple(PROFILE_TYPES.values())
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

    def plan(self, moves: PlannerMoves, *, stops: np.ndarray | None = None,
             length_d: np.ndarray | None = None) -> PlanResult:
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
        length_d : ndarray, default: None
            Path length of each move (mm), for moves along a curve (the
            chords of an arc, each its share of the arc's length); None: the
            straight distance between its ends.

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
        if length_d is not None:
            move_d = np.where(is_kinematic, np.asarray(length_d, float), move_d)
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
    >>> from gcodekit.plan.moves import PlannerMoves
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
