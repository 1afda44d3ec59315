"""Plan stage: RepRapFirmware 3's lookahead, as array code.

Mirrors RepRapFirmware 3.4 ``Movement/DDA.cpp`` (``InitStandardMove``: the
direction vector normalised on XYZ, acceleration and speed by
``VectorBoxIntersection``, M204 for XY moves; ``MatchSpeeds``: the
junction speed at which no drive changes speed by more than its M566
"instantaneous speed change"; ``DoLookahead``/``RecalculateMove``:
trapezoids) and ``GCodes/GCodes.cpp`` (``DoArcMove``: chords within
``MaxArcDeviation``).  RRF's names are kept (``instantDv``,
``requestedSpeed``).

RRF joins two moves only when both are printing moves (XY with forward
extrusion) or both are not, with the same XY and extruder-only character
(unless ``M566 P1``); elsewhere the machine stops.  It also stops for G4,
M400, G28, G29, M109/M190, M0/M1, M18/M84, tool changes and at the end of
the program.

The program sets the limits as it goes: M201 (mm/s^2), M203 (mm/min),
M204 (P printing, T travel; S both), M566 (mm/min, P jerk policy), M205
(mm/s, RRF 3.3+) and M220.  Not modelled: dynamic ringing cancellation
and input shaping (off by default), pressure advance's acceleration limit,
and the finite move queue.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ConfigError
from .caps import report_feed_caps
from .lookahead import empty_result, limit_by_axis_maximum, lookahead, trapezoid, unit_vectors
from .moves import (PlannerMoves, PlanResult, command_rows, firmware_moves, happens_before, m204_in_force,
                    settings_in_force, speed_factor)


if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

#: Every move is timed by the plan: the emulator's times are read only where nothing moves (see
#: :func:`gcodekit.plan.times_to_plan`)
TIMES_EVERY_MOVE = True
AXES = "XYZE"
#: Commands RRF runs only once the moves before them are done (LockMovementAndWaitForStandstill).
REST_NAMES = ("wait_moves", "dwell", "home", "mesh_level", "wait_hotend_temp", "wait_bed_temp",
              "program_stop", "motors_off", "tool_change")


@dataclass(frozen=True)
class RrfConfig:
    """RepRapFirmware's motion settings, in the units ``config.g`` uses.

    Defaults are RRF 3.4's (``Configuration.h``: ``DefaultXYMaxFeedrate``,
    ``DefaultXYAcceleration``, ``DefaultXYInstantDv`` ...; ``Move.cpp``: M204
    10000 mm/s^2).

    Attributes
    ----------
    max_feedrate_x, max_feedrate_y, max_feedrate_z, max_feedrate_e : float
        M203, mm/min.
    max_acceleration_x, ..., max_acceleration_e : float
        M201, mm/s^2.
    instant_dv_x, ..., instant_dv_e : float
        M566 "jerk": the speed change a drive makes without accelerating, mm/min.
    max_printing_acceleration, max_travel_acceleration : float
        M204 P and T, mm/s^2: caps for moves with XY motion.
    minimum_movement_speed : float
        M203 I, mm/min: slower requested speeds are raised to this.
    jerk_policy : int
        M566 P: 1 joins printing and travel moves too.
    max_arc_deviation, min_arc_segment_mm, max_arc_segment_mm : float
        Arc chords: at most ``max_arc_deviation`` from the arc, within these lengths, mm.
    min_arc_segments_per_sec : float
        Arc chords are at most a 1/200 s of travel long.
    """

    max_feedrate_x: float = 6000.0
    max_feedrate_y: float = 6000.0
    max_feedrate_z: float = 300.0
    max_feedrate_e: float = 1200.0
    max_acceleration_x: float = 500.0
    max_acceleration_y: float = 500.0
    max_acceleration_z: float = 20.0
    max_acceleration_e: float = 250.0
    instant_dv_x: float = 900.0
    instant_dv_y: float = 900.0
    instant_dv_z: float = 12.0
    instant_dv_e: float = 120.0
    max_printing_acceleration: float = 10000.0
    max_travel_acceleration: float = 10000.0
    minimum_movement_speed: float = 30.0
    jerk_policy: int = 0
    max_arc_deviation: float = 0.005
    min_arc_segment_mm: float = 0.1
    max_arc_segment_mm: float = 1.0
    min_arc_segments_per_sec: float = 200.0

    def axes(self, name: str) -> tuple[float, float, float, float]:
        """The X, Y, Z, E values of ``max_feedrate``, ``max_acceleration`` or ``instant_dv``."""
        return tuple(float(getattr(self, f"{name}_{a.lower()}")) for a in AXES)

    @classmethod
    def from_config_g(cls, path: str | os.PathLike) -> "RrfConfig":
        """Read M201, M203, M204, M205 and M566 from a ``config.g``.

        Comments (``;``) are skipped and a later line overrides an earlier
        one; of a per-extruder list (``E120:120``) the first value is used.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "config.g"
        >>> _ = p.write_text("M566 X900 Y900 Z60 E120:120 P1 ; jerk\\nM204 P2000 T3000\\n")
        >>> c = RrfConfig.from_config_g(p)
        >>> c.instant_dv_z, c.jerk_policy, c.max_travel_acceleration
        (60.0, 1, 3000.0)
        """
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read RepRapFirmware config.g: {exc}") from exc
        values: dict[str, float] = {}
        seen = False
        for line in text.splitlines():
            match = re.match(r"\s*M(201|203|204|205|566)\b(.*)", line.split(";")[0], re.IGNORECASE)
            if not match:
                continue
            seen = True
            words = {k.upper(): float(v) for k, v in re.findall(r"([A-Za-z])\s*([-+]?[\d.]+)", match.group(2))}
            values.update(_config_settings(int(match.group(1)), words))
        if not seen:
            raise ConfigError(f"{path}: no M201/M203/M204/M566 lines (is this a RepRapFirmware config.g?)")
        return cls(**values)


def _config_settings(code: int, words: dict[str, float]) -> dict[str, float]:
    """RrfConfig fields set by one config.g line (RRF 3.4 GCodes2.cpp, Move::ConfigureAccelerations)."""
    out: dict[str, float] = {}
    axes = {201: ("max_acceleration", 1.0), 203: ("max_feedrate", 1.0), 566: ("instant_dv", 1.0),
            205: ("instant_dv", 60.0)}  # M205 is M566 in mm/s
    if code in axes:
        name, scale = axes[code]
        out.update({f"{name}_{a.lower()}": words[a] * scale for a in AXES if a in words})
    if code == 203 and "I" in words:
        out["minimum_movement_speed"] = words["I"]
    if code in (205, 566) and "P" in words:
        out["jerk_policy"] = int(words["P"])
    if code == 204:
        if "S" in words:
            out["max_printing_acceleration"] = out["max_travel_acceleration"] = words["S"]
        if "P" in words:
            out["max_printing_acceleration"] = words["P"]
        if "T" in words:
            out["max_travel_acceleration"] = words["T"]
    return out


def arc_segments(travel_d: np.ndarray, angle: np.ndarray, radius: np.ndarray, speed_v: np.ndarray,
                 config: RrfConfig = RrfConfig()) -> np.ndarray:
    """Chords per arc as RRF 3.4's ``DoArcMove`` cuts them.

    The chord length ``sqrt(8 r MaxArcDeviation)`` (a chord that far from
    the arc), shortened to 1/200 s of travel, kept within 0.1-1 mm; then
    ``int(r * angle / length + 0.8)`` chords, at least one.

    Examples
    --------
    A half turn of radius 10 mm at 50 mm/s: chords of 0.25 mm, 126 of them.

    >>> arc_segments(np.array([31.4]), np.array([np.pi]), np.array([10.0]), np.array([50.0]))
    array([126.])
    """
    length = np.minimum(np.sqrt(8.0 * radius * config.max_arc_deviation), speed_v / config.min_arc_segments_per_sec)
    length = np.clip(length, config.min_arc_segment_mm, config.max_arc_segment_mm)
    return np.maximum(np.floor(radius * np.abs(angle) / length + 0.8), 1.0)


def _program_limits(op: "EmulatedProgram", moves: PlannerMoves, config: RrfConfig) -> dict:
    """Per move, the limits in force, in mm/s and mm/s^2: the config's, then the program's."""
    m201 = command_rows(op, names=("set_max_accel",))
    m203 = command_rows(op, names=("set_max_feed",))
    m204 = command_rows(op, names=("set_accel",))
    m566 = command_rows(op, codes=("M566",))  # mm/min
    m205 = command_rows(op, codes=("M205",))  # mm/s

    def per_axis(rows, name, scale):
        return [settings_in_force(op, moves, rows, a, v * scale, scale) for a, v in zip(AXES, config.axes(name))]

    # M566 (mm/min) and M205 (mm/s) set the same limits: take them in program order
    jerk_rows = np.union1d(m566, m205)
    jerk_scale = np.where(np.isin(jerk_rows, m566), 1.0 / 60.0, 1.0)
    instant_dv = [settings_in_force(op, moves, jerk_rows, a, v / 60.0, jerk_scale)
                  for a, v in zip(AXES, config.axes("instant_dv"))]
    limits = {
        "max_acceleration": per_axis(m201, "max_acceleration", 1.0),
        "max_feedrate": per_axis(m203, "max_feedrate", 1.0 / 60.0),
        "instant_dv": instant_dv,
        "minimum_movement_speed": settings_in_force(op, moves, m203, "I", config.minimum_movement_speed / 60.0,
                                                    1.0 / 60.0),
    }
    limits.update(m204_in_force(op, moves, m204, {
        "P": ("max_printing_acceleration", config.max_printing_acceleration),
        "T": ("max_travel_acceleration", config.max_travel_acceleration)}))
    return limits


def _speed_factor(op: "EmulatedProgram") -> np.ndarray | None:
    """M220's factor per waypoint as RepRapFirmware applies it: to moves that name an axis, not to
    extruder-only ones such as retractions (``applyM220M221`` in ``GCodes::LoadFeedrateFromGCode``)."""
    factor = speed_factor(op)
    if factor is None:
        return None
    rows = op.waypoints["command"]
    names_an_axis = np.zeros(np.shape(rows), bool)
    for letter in "XYZUVWABC":
        names_an_axis |= ~np.isnan(op.table.param_at(letter, rows))
    return np.where(names_an_axis, factor, 1.0)


def plan(op: "EmulatedProgram", config: RrfConfig) -> tuple[PlannerMoves, PlanResult]:
    """Plan an emulated operation as RepRapFirmware 3 would; one result per firmware move.

    Examples
    --------
    A 10 mm printing move at 20 mm/s with 500 mm/s^2 starts and ends at rest:
    0.04 s up, 0.46 s cruising, 0.04 s down:

    >>> import gcodekit
    >>> op = gcodekit.gcode_to_operation("G1 X10 E1 F1200\\n", "reprapfirmware", plan=False)
    >>> moves, result = plan(op, RrfConfig())
    >>> round(float(result.duration_t[0]), 3)
    0.54
    """
    factor = _speed_factor(op)
    moves = firmware_moves(op, factor, lambda travel, angle, radius, speed_v: arc_segments(
        travel, angle, radius, speed_v, config))
    n = len(moves)
    if n == 0:
        return moves, empty_result()
    lim = _program_limits(op, moves, config)
    axes_d = moves.axes_d
    d = [np.ascontiguousarray(axes_d[:, a]) for a in range(4)]
    del axes_d

    # InitStandardMove: normalise on XYZ when an axis moves, else on the extrusion
    xy_moving = (d[0] != 0) | (d[1] != 0)
    axes_moving = xy_moving | (d[2] != 0)
    xyz_d, _ = unit_vectors(d[:3])
    total_distance = np.where(axes_moving, xyz_d, np.abs(d[3]))
    direction_vector = [c / total_distance for c in d]
    forward_extruding = d[3] > 0
    is_printing_move = xy_moving & forward_extruding
    is_non_printing_extruder_move = (d[3] != 0) & ~is_printing_move

    # 5. the acceleration available along the direction; M204 for XY moves
    acceleration = limit_by_axis_maximum(lim["max_acceleration"], direction_vector)
    m204 = np.where(is_printing_move, lim["max_printing_acceleration"], lim["max_travel_acceleration"])
    acceleration = np.where(xy_moving, np.minimum(acceleration, m204), acceleration)
    # 6. requested speed: at least the minimum movement speed, then within the axis limits
    allowed_speed = limit_by_axis_maximum(lim["max_feedrate"], direction_vector)
    # M203 is mm/min here and mm/s on Marlin: a Marlin program's M203 X200 caps its moves at 3.3 mm/s
    report_feed_caps(op, moves, allowed_speed, "M203, in mm/min on RepRapFirmware")
    requested_speed = np.minimum(np.maximum(np.nan_to_num(moves.speed_v), lim["minimum_movement_speed"]),
                                 allowed_speed)
    del allowed_speed

    # 7. "Try to meld this move to the previous move to avoid stop/start"
    prev = np.r_[0, np.arange(n - 1)]
    same_kind = ((is_printing_move == is_printing_move[prev]) & (xy_moving == xy_moving[prev])
                 & (is_non_printing_extruder_move == is_non_printing_extruder_move[prev]))
    rest_before = happens_before(moves, command_rows(op, names=REST_NAMES))
    if config.jerk_policy == 0:
        rest_before |= ~same_kind
    rest_before[0] = True

    # MatchSpeeds: no drive's speed may jump by more than its instantDv at the junction
    target_next_speed = np.minimum(requested_speed, requested_speed[prev])
    for u, instant_dv in zip(direction_vector, lim["instant_dv"]):
        total_fraction = np.abs(u[prev] - u)
        np.minimum(target_next_speed, np.divide(instant_dv, total_fraction, out=np.full(n, np.inf),
                                                where=total_fraction > 0), out=target_next_speed)
    max_entry_v2 = np.where(rest_before, 0.0, target_next_speed * target_next_speed)

    rest_after = np.r_[rest_before[1:], True]
    entry_v2, exit_v2 = lookahead(max_entry_v2, 2.0 * acceleration * total_distance, rest_after)
    return moves, trapezoid(total_distance, acceleration, entry_v2, requested_speed * requested_speed, exit_v2)
