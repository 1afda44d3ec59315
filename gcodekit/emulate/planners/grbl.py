"""Emulate stage, planning: GRBL 1.1's lookahead, as array code.

Mirrors grbl 1.1h ``planner.c`` (``plan_buffer_line``: junction deviation
and per-axis limits along the move's unit vector; ``planner_recalculate``:
the reverse and forward passes), ``motion_control.c`` (``mc_arc``: arcs cut
into chords within ``$12`` of the circle) and the ``protocol_buffer_synchronize``
calls that bring the machine to rest.  GRBL's planner is the ancestor of
Marlin's, so the two passes and the trapezoid live here and the other
planners reuse them (:func:`lookahead`, :func:`trapezoid`).

GRBL works in mm/min internally; here speeds are mm/s and accelerations
mm/s^2 (``$120`` is already mm/s^2), which changes no result.

GRBL comes to rest before G4, M0, M2/M30, spindle and coolant changes
(``spindle_sync``/``coolant_sync``; spindle speed changes move on in laser
mode, ``$32=1``), work-offset and position-offset changes
(``FORCE_BUFFER_SYNC_DURING_WCO_CHANGE``), EEPROM writes (G28.1, G30.1),
probing, and at the end of the program.  M1 is ignored by GRBL 1.1.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...errors import ConfigError
from ...parse.table import MOTION_RAPID
from .base import PlannerMoves, PlanResult, command_rows, firmware_moves, happens_before
from .scans import backward_min, forward_min

if TYPE_CHECKING:
    from ..operation import Operation

BLOCK = 1 << 14  # element-wise steps run on this many moves at a time: less fresh memory
MINIMUM_FEED_RATE = 1.0 / 60.0  # grbl config.h: MINIMUM_FEED_RATE 1.0 mm/min
MINIMUM_JUNCTION_SPEED = 0.0  # grbl config.h, mm/s
COS_STRAIGHT = 0.999999  # planner.c: |junction_cos_theta| beyond this is a reversal or a straight line

#: ``$N`` numbers of the settings the planner reads, and their field names.
SETTINGS = {
    11: "junction_deviation", 12: "arc_tolerance", 32: "laser_mode",
    110: "max_rate_x", 111: "max_rate_y", 112: "max_rate_z",
    120: "acceleration_x", 121: "acceleration_y", 122: "acceleration_z",
}


@dataclass(frozen=True)
class GrblConfig:
    """The ``$`` settings GRBL's planner reads.

    Defaults are grbl 1.1's ``DEFAULTS_GENERIC`` (``defaults.h``).

    Attributes
    ----------
    max_rate_x, max_rate_y, max_rate_z : float
        ``$110``-``$112``, mm/min: per-axis speed limits, and the rapid rate.
    acceleration_x, acceleration_y, acceleration_z : float
        ``$120``-``$122``, mm/s^2.
    junction_deviation : float
        ``$11``, mm.
    arc_tolerance : float
        ``$12``, mm: the largest distance from a chord to its arc.
    laser_mode : bool
        ``$32``: spindle speed changes do not stop the motion.
    """

    max_rate_x: float = 500.0
    max_rate_y: float = 500.0
    max_rate_z: float = 500.0
    acceleration_x: float = 10.0
    acceleration_y: float = 10.0
    acceleration_z: float = 10.0
    junction_deviation: float = 0.010
    arc_tolerance: float = 0.002
    laser_mode: bool = False

    @property
    def max_rate_v(self) -> np.ndarray:
        """Per-axis speed limits, mm/s."""
        return np.array([self.max_rate_x, self.max_rate_y, self.max_rate_z]) / 60.0

    @property
    def acceleration(self) -> np.ndarray:
        return np.array([self.acceleration_x, self.acceleration_y, self.acceleration_z])

    @classmethod
    def from_settings(cls, path: str | os.PathLike) -> "GrblConfig":
        """Read a ``$$`` dump (lines like ``$110=500.000``); other lines are skipped.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "grbl.txt"
        >>> _ = p.write_text("$11=0.020\\n$110=3000.000 (x max rate, mm/min)\\nok\\n")
        >>> GrblConfig.from_settings(p).max_rate_x
        3000.0
        """
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read GRBL settings: {exc}") from exc
        values = {}
        for number, raw in re.findall(r"(?m)^\s*\$(\d+)\s*=\s*(\S+)", text):
            name = SETTINGS.get(int(number))
            if name is None:
                continue
            try:
                value = float(raw)
            except ValueError:
                raise ConfigError(f"{path}: ${number}={raw!r} is not a number") from None
            values[name] = bool(value) if name == "laser_mode" else value
        if not values:
            raise ConfigError(f"{path}: no $110-$122, $11 or $12 settings (is this a GRBL $$ dump?)")
        return cls(**values)


def arc_segments(travel_d: np.ndarray, angle: np.ndarray, radius: np.ndarray, arc_tolerance: float) -> np.ndarray:
    """Chords per arc as grbl's ``mc_arc`` cuts them.

    ``floor(|angle| * radius / 2 / sqrt(tol * (2 * radius - tol)))``, at
    least one: ``sqrt(tol * (2 r - tol))`` is half the chord whose sagitta
    is ``tol``.  ``travel_d`` (helix length) does not enter: GRBL cuts by
    the in-plane arc only.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        half_chord_d = np.sqrt(arc_tolerance * (2.0 * radius - arc_tolerance))
        segments = np.floor(np.abs(0.5 * angle * radius) / half_chord_d)
    return np.maximum(np.nan_to_num(segments, nan=1.0, posinf=1.0), 1.0)


def limit_by_axis_maximum(max_value, unit_vec) -> np.ndarray:
    """grbl's ``limit_value_by_axis_maximum``: per row, the largest value along
    ``unit_vec`` whose component on every axis stays within that axis's limit.

    ``max_value`` holds one limit per axis (a number, or an array with one
    value per row); ``unit_vec`` is a sequence of per-axis columns.
    """
    limit = np.full(np.shape(unit_vec[0]), np.inf)
    for cap, u in zip(max_value, unit_vec):
        u = np.abs(u)
        ratio = np.divide(cap, u, out=np.full(u.shape, np.inf), where=u > 0)
        np.minimum(limit, ratio, out=limit)
    return limit


# -- the passes and the trapezoid, shared with marlin.py and reprapfirmware.py ---------


def lookahead(max_entry_v2: np.ndarray, delta_v2: np.ndarray, rest_after: np.ndarray, *,
              rest_v2: float = 0.0, nominal_length: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit speeds (squared) after the reverse and forward passes.

    Parameters
    ----------
    max_entry_v2 : ndarray
        Cap on each move's entry speed (the junction limit; for the first
        move after a rest, the speed it may start at).
    delta_v2 : ndarray
        ``2 * accel * move_d``: what a move can add to (or shed from) v^2.
    rest_after : ndarray of bool
        The machine stops after this move (the last one is always a stop).
    rest_v2 : float, default: 0
        Speed squared at a stop (Marlin: ``MINIMUM_PLANNER_SPEED`` squared).
    nominal_length : ndarray of bool, optional
        Marlin's ``nominal_length`` flag: such a move always enters at its
        cap, and the next move's entry is not checked against it.

    Returns
    -------
    entry_v2, exit_v2 : ndarray

    Notes
    -----
    grbl ``planner_recalculate``, reverse then forward::

        for i in reversed(range(n)):   # next entry: rest_v2 after a stop
            entry[i] = min(max_entry[i], entry[i+1] + delta[i])
        for i in range(1, n):          # no limit across a stop
            entry[i] = min(entry[i], entry[i-1] + delta[i-1])

    Both are the scans of :mod:`.scans`.  A stop (or a ``nominal_length``
    move) cuts each recurrence: giving that move an increment equal to its
    own bound makes the minimum pick the bound whatever comes next.
    """
    n = max_entry_v2.size
    free = rest_after.copy()
    if nominal_length is not None:
        free |= nominal_length
    bound = np.where(rest_after, np.minimum(max_entry_v2, rest_v2 + delta_v2), max_entry_v2)
    if nominal_length is not None:
        bound = np.where(nominal_length, max_entry_v2, bound)
    reverse_v2 = backward_min(bound, np.where(free, bound, delta_v2))
    forward_inc = delta_v2.copy()
    cut = np.flatnonzero(free[:-1])
    forward_inc[cut] = reverse_v2[cut + 1]
    entry_v2 = forward_min(reverse_v2, forward_inc, first=float(reverse_v2[0])) if n else reverse_v2
    exit_v2 = np.where(rest_after, rest_v2, np.r_[entry_v2[1:], rest_v2])
    return entry_v2, exit_v2


def trapezoid(move_d: np.ndarray, accel: np.ndarray, entry_v2: np.ndarray, nominal_v2: np.ndarray,
              exit_v2: np.ndarray) -> PlanResult:
    """Phase speeds and durations of trapezoidal moves.

    Accelerate from the entry speed, cruise at the nominal speed, brake to
    the exit speed; a move too short to cruise peaks where accelerating and
    braking meet (Marlin's ``intersection_distance``, grbl's ``st_prep_buffer``
    ramp).  An entry above what the move can brake from is clipped, as the
    firmware's step generator does.
    """
    n = move_d.size
    result = PlanResult(np.empty(n), np.empty(n), np.empty(n), np.asarray(accel, float), np.empty(n), np.empty(n),
                        np.empty(n))
    for lo in range(0, n, BLOCK):
        sl = slice(lo, min(lo + BLOCK, n))
        _trapezoid_block(move_d[sl], accel[sl], entry_v2[sl], nominal_v2[sl], exit_v2[sl], result, sl)
    return result


def _trapezoid_block(move_d, accel, entry_v2, nominal_v2, exit_v2, result: PlanResult, sl: slice) -> None:
    half_inv_accel = 0.5 / accel
    accel_d = (nominal_v2 - entry_v2) * half_inv_accel
    decel_d = (nominal_v2 - exit_v2) * half_inv_accel
    short = accel_d + decel_d > move_d
    # where they meet: entry_v2 + 2 a x = exit_v2 + 2 a (d - x)
    meet_d = np.clip((move_d + (exit_v2 - entry_v2) * half_inv_accel) * 0.5, 0.0, move_d)
    accel_d = np.where(short, meet_d, np.maximum(accel_d, 0.0))
    cruise_v2 = np.where(short, entry_v2 + 2.0 * accel * meet_d, nominal_v2)
    start_v2 = np.minimum(np.minimum(entry_v2, nominal_v2), cruise_v2)
    decel_d = np.where(short, move_d - meet_d, np.clip(decel_d, 0.0, move_d - accel_d))
    end_v2 = np.maximum(cruise_v2 - 2.0 * accel * decel_d, 0.0)
    cruise_d = np.maximum(move_d - accel_d - decel_d, 0.0)
    start_v, cruise_v, end_v = np.sqrt(start_v2), np.sqrt(cruise_v2), np.sqrt(end_v2)
    with np.errstate(divide="ignore", invalid="ignore"):
        result.accel_t[sl] = np.where(accel_d > 0, (cruise_v - start_v) / accel, 0.0)
        result.cruise_t[sl] = np.where(cruise_d > 0, cruise_d / cruise_v, 0.0)
        result.decel_t[sl] = np.where(decel_d > 0, (cruise_v - end_v) / accel, 0.0)
    result.start_v[sl], result.cruise_v[sl], result.end_v[sl] = start_v, cruise_v, end_v


def empty_result() -> PlanResult:
    empty = np.zeros(0)
    return PlanResult(empty, empty, empty, empty, empty, empty, empty)


def unit_vectors(columns) -> tuple[np.ndarray, list[np.ndarray]]:
    """Length and unit-vector columns of the vectors given as per-axis columns (zero vectors stay zero)."""
    length = np.sqrt(sum(c * c for c in columns))
    inverse = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0)
    return length, [c * inverse for c in columns]


# -- grbl ---------------------------------------------------------------------------

#: Commands GRBL executes only once the planner buffer is empty (protocol_buffer_synchronize).
REST_NAMES = (
    "dwell", "program_stop", "program_end", "probe", "home", "home_secondary", "store_home", "store_home_secondary",
    "coolant_flood", "coolant_mist", "coolant_off", "set_position", "clear_position_offset",
    "tool_length_offset_dynamic", "cancel_tool_length",
    "work_offset_1", "work_offset_2", "work_offset_3", "work_offset_4", "work_offset_5", "work_offset_6",
)
SPINDLE_NAMES = ("spindle_cw", "spindle_ccw", "spindle_off")


def plan(op: "Operation", config: GrblConfig) -> tuple[PlannerMoves, PlanResult]:
    """Plan an emulated operation as GRBL 1.1 would; one result per firmware move.

    Examples
    --------
    A 10 mm move at 8 mm/s with 10 mm/s^2: 0.8 s up, 0.45 s cruising, 0.8 s down:

    >>> import gcodekit
    >>> op = gcodekit.gcode_to_operation("G21 G90\\nG1 X10 F480\\n", "grbl", plan=False)
    >>> moves, result = plan(op, GrblConfig())
    >>> round(float(result.duration_t.sum()), 3)
    2.05
    """
    moves = firmware_moves(op, None, lambda travel, angle, radius, speed_v: arc_segments(travel, angle, radius,
                                                                                 config.arc_tolerance))
    n = len(moves)
    if n == 0:
        return moves, empty_result()
    w = op.waypoints
    axes_d = moves.axes_d
    move_d, unit_vec = unit_vectors([axes_d[:, a] for a in range(3)])
    del axes_d

    # plan_buffer_line: the limits along the move's direction
    acceleration = limit_by_axis_maximum(config.acceleration, unit_vec)
    rapid_rate = limit_by_axis_maximum(config.max_rate_v, unit_vec)
    rapid = np.asarray(w["motion"])[moves.waypoint] == MOTION_RAPID
    # G93 needs nothing here: the emulator already turned "1/F minutes" into a speed
    programmed = moves.speed_v.copy()
    # plan_compute_profile_nominal_speed
    nominal = np.where(rapid, rapid_rate, np.minimum(programmed, rapid_rate))
    nominal = np.maximum(np.nan_to_num(nominal, nan=MINIMUM_FEED_RATE), MINIMUM_FEED_RATE)

    rest_before = happens_before(moves, command_rows(op, names=REST_NAMES)) | _spindle_syncs(op, moves, config)
    rest_before[0] = True

    # junction: grbl planner.c, "Compute maximum allowable entry speed at junction by centripetal acceleration"
    prev = np.r_[0, np.arange(n - 1)]
    junction_cos_theta = -sum(u[prev] * u for u in unit_vec)
    _, junction_unit_vec = unit_vectors([u - u[prev] for u in unit_vec])
    junction_acceleration = limit_by_axis_maximum(config.acceleration, junction_unit_vec)
    sin_theta_d2 = np.sqrt(np.clip(0.5 * (1.0 - junction_cos_theta), 0.0, 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        corner_v2 = junction_acceleration * config.junction_deviation * sin_theta_d2 / (1.0 - sin_theta_d2)
    max_junction_v2 = np.where(junction_cos_theta > COS_STRAIGHT, MINIMUM_JUNCTION_SPEED**2,
                               np.where(junction_cos_theta < -COS_STRAIGHT, np.inf,
                                        np.maximum(MINIMUM_JUNCTION_SPEED**2, corner_v2)))
    # plan_compute_profile_parameters: never above either nominal speed; from rest: 0
    max_entry_v2 = np.minimum(max_junction_v2, np.minimum(nominal, nominal[prev]) ** 2)
    max_entry_v2[rest_before] = 0.0

    rest_after = np.r_[rest_before[1:], True]
    entry_v2, exit_v2 = lookahead(max_entry_v2, 2.0 * acceleration * move_d, rest_after)
    return moves, trapezoid(move_d, acceleration, entry_v2, nominal**2, exit_v2)


def _spindle_syncs(op: "Operation", moves: PlannerMoves, config: GrblConfig) -> np.ndarray:
    """Per move: did a spindle change (M3/M4/M5, or a new S while on) stop the machine before it?

    grbl 1.1 ``gc_execute_line`` calls ``spindle_sync`` (a buffer sync) for
    both, except for speed changes in laser mode.
    """
    stops = happens_before(moves, command_rows(op, names=SPINDLE_NAMES))
    if config.laser_mode:
        return stops
    spindle = np.asarray(op.waypoints["spindle"])[moves.waypoint]
    changed = np.r_[False, spindle[1:] != spindle[:-1]]
    return stops | changed
