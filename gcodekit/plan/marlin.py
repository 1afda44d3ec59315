"""Plan stage: Marlin 2's lookahead, as array code.

Mirrors Marlin 2.1 ``module/planner.cpp`` (``_populate_block``: feed and
acceleration limits per axis, classic jerk or junction deviation at the
junctions; ``reverse_pass``/``forward_pass``/``recalculate_trapezoids``
with the ``nominal_length`` shortcut) and ``gcode/motion/G2_G3.cpp``
(``plan_arc``: chords of ``MAX_ARC_SEGMENT_MM``, at least
``MIN_CIRCLE_SEGMENTS`` per turn).  Marlin's variable names are kept.

The program sets the limits as it goes: M201 (max acceleration per axis,
mm/s^2), M203 (max feed rate per axis, mm/s), M204 (P print, R retract, T
travel acceleration; S sets print and travel), M205 (X/Y/Z/E jerk, J
junction deviation, S minimum feed rate, T minimum travel feed rate) and
M220 (speed factor); each applies to the moves after it.

Marlin comes to rest when its block buffer drains: G4, M400, G28, G29,
M109/M190 (the queue waits for the heaters), M0/M1, M84/M18 and the end of
the program.  The last block before a rest ends at
``MINIMUM_PLANNER_SPEED``.

Not modelled: the 16-block buffer (lookahead is unlimited), step rounding
and ``MIN_STEPS_PER_SEGMENT`` (no steps/mm), ``SLOWDOWN`` and the minimum
segment time (they depend on how full the buffer is), linear advance, and
the heating times.  ``S_CURVE_ACCELERATION`` replaces each linear speed
ramp by a Bezier ramp between the same speeds over the same time
(``calculate_trapezoid_for_block`` keeps ``acceleration_time``), so block
times do not change; the flag is accepted and only documents the machine.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Mapping

import numpy as np

from ..columns import GatheredColumn, stored
from ..errors import ConfigError
from ..memory import release_freed_memory
from .kernels import engine
from .lookahead import BLOCK, _trapezoid_block, empty_result, limit_by_axis_maximum, lookahead, unit_vectors
from .moves import (PlannedMoves, PlannerMoves, PlanResult, command_rows, firmware_moves, happens_before,
                    StepSetting, m204_in_force, settings_in_force, speed_factor)
from .scans import Increments
from .trapezoids import TrapezoidPlan

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

COS_REVERSAL = 0.999999  # planner.cpp: a junction_cos_theta above this is a full reversal
COS_OCTAGON = -0.7071067812  # JD_HANDLE_SMALL_SEGMENTS: junctions sharper than 135 degrees
#: Every move is timed by the plan: the emulator's times are read only where nothing moves (see
#: :func:`gcodekit.plan.times_to_plan`)
TIMES_EVERY_MOVE = True
AXES = "XYZE"

#: Commands after which Marlin's block buffer drains (planner.synchronize() or a blocking wait).
REST_NAMES = ("wait_moves", "dwell", "home", "mesh_level", "wait_hotend_temp", "wait_bed_temp",
              "program_stop", "motors_off")


@dataclass(frozen=True)
class MarlinConfig:
    """Marlin's motion settings (``Configuration.h``, ``Configuration_adv.h``, M201-M205).

    Defaults are Marlin 2.1's stock configuration.  Units: mm/s, mm/s^2, mm.

    Attributes
    ----------
    max_feedrate_x, max_feedrate_y, max_feedrate_z, max_feedrate_e : float
        ``DEFAULT_MAX_FEEDRATE`` / M203, mm/s.
    max_acceleration_x, ..., max_acceleration_e : float
        ``DEFAULT_MAX_ACCELERATION`` / M201, mm/s^2.
    acceleration, retract_acceleration, travel_acceleration : float
        ``DEFAULT_ACCELERATION`` (M204 P), ``DEFAULT_RETRACT_ACCELERATION``
        (M204 R, extruder-only moves), ``DEFAULT_TRAVEL_ACCELERATION``
        (M204 T, moves without extrusion), mm/s^2.
    classic_jerk : bool
        ``CLASSIC_JERK``: junctions limited by per-axis jerk (M205 X/Y/Z/E)
        instead of junction deviation (M205 J).
    max_jerk_x, ..., max_jerk_e : float
        ``DEFAULT_XJERK``.. ``DEFAULT_EJERK``, mm/s.
    junction_deviation : float
        ``JUNCTION_DEVIATION_MM``, mm.
    jd_handle_small_segments : bool
        ``JD_HANDLE_SMALL_SEGMENTS``: moves under 1 mm turning more than
        135 degrees corner at the speed of the arc they approximate.
    min_feedrate, min_travel_feedrate : float
        ``DEFAULT_MINIMUMFEEDRATE`` (M205 S) and
        ``DEFAULT_MINTRAVELFEEDRATE`` (M205 T), mm/s.
    minimum_planner_speed : float
        ``MINIMUM_PLANNER_SPEED``, mm/s: the speed at a stop.
    s_curve_acceleration : bool
        ``S_CURVE_ACCELERATION``; no effect on times (see the module notes).
    max_arc_segment_mm : float
        ``MAX_ARC_SEGMENT_MM``: arc chords are at most this long, mm.
    min_circle_segments : int
        ``MIN_CIRCLE_SEGMENTS``: chords in a full turn, at least.
    """

    max_feedrate_x: float = 300.0
    max_feedrate_y: float = 300.0
    max_feedrate_z: float = 5.0
    max_feedrate_e: float = 25.0
    max_acceleration_x: float = 3000.0
    max_acceleration_y: float = 3000.0
    max_acceleration_z: float = 100.0
    max_acceleration_e: float = 10000.0
    acceleration: float = 3000.0
    retract_acceleration: float = 3000.0
    travel_acceleration: float = 3000.0
    classic_jerk: bool = False
    max_jerk_x: float = 10.0
    max_jerk_y: float = 10.0
    max_jerk_z: float = 0.3
    max_jerk_e: float = 5.0
    junction_deviation: float = 0.013
    jd_handle_small_segments: bool = True
    min_feedrate: float = 0.0
    min_travel_feedrate: float = 0.0
    minimum_planner_speed: float = 0.05
    s_curve_acceleration: bool = False
    max_arc_segment_mm: float = 1.0
    min_circle_segments: int = 72

    def axes(self, name: str) -> tuple[float, float, float, float]:
        """The X, Y, Z, E values of ``max_feedrate``, ``max_acceleration`` or ``max_jerk``."""
        return tuple(float(getattr(self, f"{name}_{a.lower()}")) for a in AXES)

    @classmethod
    def from_m503(cls, path: str | os.PathLike) -> "MarlinConfig":
        """Read the settings Marlin reports with M503 (M201, M203, M204, M205 lines).

        ``echo:`` prefixes and comments are skipped; a later line overrides
        an earlier one.  An M205 with X (and no J) means a classic-jerk
        build, one with J a junction-deviation build.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "m503.txt"
        >>> _ = p.write_text("echo:  M204 P1250.00 R1250.00 T1500.00\\necho:  M205 B20000.00 S0.00 T0.00 J0.02\\n")
        >>> c = MarlinConfig.from_m503(p)
        >>> c.travel_acceleration, c.junction_deviation, c.classic_jerk
        (1500.0, 0.02, False)
        """
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read Marlin M503 report: {exc}") from exc
        values: dict[str, float | bool] = {}
        seen = False
        for line in text.splitlines():
            line = re.sub(r"^\s*(echo:)?\s*", "", line.split(";")[0])
            match = re.match(r"M(20[1345])\b(.*)", line, re.IGNORECASE)
            if not match:
                continue
            seen = True
            words = {k.upper(): float(v) for k, v in re.findall(r"([A-Za-z])\s*([-+]?[\d.]+)", match.group(2))}
            values.update(_m20x_settings(int(match.group(1)), words))
        if not seen:
            raise ConfigError(f"{path}: no M201/M203/M204/M205 lines (is this a Marlin M503 report?)")
        return cls(**values)


#: MarlinConfig fields from the machine limits the Slic3r family keeps in its configuration block
#: (PrusaSlicer and SuperSlicer ``machine_max_feedrate_x``; OrcaSlicer and Bambu Studio ``machine_max_speed_x``).
_SLICER_LIMITS = {
    **{f"machine_max_{kind}_{a}": f"max_{field}_{a}" for a in "xyze"
       for kind, field in (("acceleration", "acceleration"), ("feedrate", "feedrate"), ("speed", "feedrate"),
                           ("jerk", "jerk"))},
    "machine_max_acceleration_extruding": "acceleration",
    "machine_max_acceleration_retracting": "retract_acceleration",
    "machine_max_acceleration_travel": "travel_acceleration",
    "machine_min_extruding_rate": "min_feedrate",
    "machine_min_travel_rate": "min_travel_feedrate",
}


def limits_from_slicer(settings: "Mapping[str, str]") -> dict[str, float | bool]:
    """MarlinConfig values from a slicer's printer settings (``machine_max_acceleration_x = 1000,960``).

    The first value of each list is the normal mode's (the second is
    PrusaSlicer's silent mode).  Empty when the settings carry no limits or
    say the slicer ignored them (``machine_limits_usage = ignore``).  A
    travel acceleration of 0 (PrusaSlicer's "same as printing") is left out.
    The Slic3r family estimates with classic jerk; a junction deviation
    above 0 (OrcaSlicer's ``machine_max_junction_deviation``) switches to it.

    Examples
    --------
    >>> limits_from_slicer({"machine_max_acceleration_x": "1000,960", "machine_max_jerk_x": "8,8"})
    {'max_acceleration_x': 1000.0, 'max_jerk_x': 8.0, 'classic_jerk': True}
    """
    if settings.get("machine_limits_usage", "").strip() == "ignore":
        return {}
    out: dict[str, float | bool] = {}
    for key, field in _SLICER_LIMITS.items():
        value = re.match(r"\s*([-+]?\d*\.?\d+)", settings.get(key, ""))
        if value and not (field == "travel_acceleration" and float(value[1]) == 0):
            out[field] = float(value[1])
    if not out:
        return {}
    deviation = re.match(r"\s*(\d*\.?\d+)", settings.get("machine_max_junction_deviation", ""))
    if deviation and float(deviation[1]) > 0:
        out.update(classic_jerk=False, junction_deviation=float(deviation[1]))
    else:
        out["classic_jerk"] = True
    return out


def _m20x_settings(code: int, words: dict[str, float]) -> dict[str, float | bool]:
    """MarlinConfig fields set by one M201/M203/M204/M205 line (Marlin 2.1 gcode/config)."""
    out: dict[str, float | bool] = {}
    if code in (201, 203):
        name = "max_acceleration" if code == 201 else "max_feedrate"
        out.update({f"{name}_{a.lower()}": words[a] for a in AXES if a in words})
    elif code == 204:  # M204.cpp: S is the legacy print-and-travel acceleration
        if "S" in words:
            out["acceleration"] = out["travel_acceleration"] = words["S"]
        for letter, name in (("P", "acceleration"), ("R", "retract_acceleration"), ("T", "travel_acceleration")):
            if letter in words:
                out[name] = words[letter]
    elif code == 205:
        out.update({f"max_jerk_{a.lower()}": words[a] for a in AXES if a in words})
        for letter, name in (("S", "min_feedrate"), ("T", "min_travel_feedrate"), ("J", "junction_deviation")):
            if letter in words:
                out[name] = words[letter]
        if "J" in words or "X" in words:
            out["classic_jerk"] = "X" in words and "J" not in words
    return out


def arc_segments(travel_d: np.ndarray, angle: np.ndarray, radius: np.ndarray,
                 max_arc_segment_mm: float = 1.0, min_circle_segments: int = 72) -> np.ndarray:
    """Chords per arc as Marlin's ``plan_arc`` cuts them.

    ``floor(travel / MAX_ARC_SEGMENT_MM)``, but at least
    ``ceil(MIN_CIRCLE_SEGMENTS * angle / 2 pi)`` and at least one.

    Examples
    --------
    >>> arc_segments(np.array([31.4159]), np.array([np.pi]), np.array([10.0]))
    array([36.])
    """
    by_length = np.floor(travel_d / max_arc_segment_mm)
    by_angle = np.ceil(min_circle_segments * np.abs(angle) / (2.0 * np.pi) - 1e-9)
    return np.maximum(np.maximum(by_length, by_angle), 1.0)


def _program_limits(op: "EmulatedProgram", moves: PlannerMoves, config: MarlinConfig) -> dict:
    """Per move, the limits in force: the config's, then M201/M203/M204/M205 in the program.

    Per-axis limits are lists of four (X, Y, Z, E), each a number or an array.
    """
    m201 = command_rows(op, names=("set_max_accel",))
    m203 = command_rows(op, names=("set_max_feed",))
    m204 = command_rows(op, names=("set_accel",))
    m205 = command_rows(op, names=("set_jerk",))

    def per_axis(rows, name):
        return [settings_in_force(op, moves, rows, a, v) for a, v in zip(AXES, config.axes(name))]

    limits = {
        "max_acceleration": per_axis(m201, "max_acceleration"),
        "max_feedrate": per_axis(m203, "max_feedrate"),
        "max_jerk": per_axis(m205, "max_jerk"),
        "retract_acceleration": settings_in_force(op, moves, m204, "R", config.retract_acceleration),
        "junction_deviation": settings_in_force(op, moves, m205, "J", config.junction_deviation),
        "min_feedrate": settings_in_force(op, moves, m205, "S", config.min_feedrate),
        "min_travel_feedrate": settings_in_force(op, moves, m205, "T", config.min_travel_feedrate),
    }
    limits.update(m204_in_force(op, moves, m204, {"P": ("acceleration", config.acceleration),
                                                  "T": ("travel_acceleration", config.travel_acceleration)},
                                 steps=True))
    return limits


def plan(op: "EmulatedProgram", config: MarlinConfig) -> tuple[PlannerMoves | PlannedMoves, PlanResult | TrapezoidPlan]:
    """Plan an emulated operation as Marlin 2 would; one result per firmware move.

    Examples
    --------
    A 100 mm move at 50 mm/s, 1000 mm/s^2 and 10 mm/s jerk starts at 10 mm/s
    (the jerk) and brakes to a stop (``MINIMUM_PLANNER_SPEED``):

    >>> import gcodekit
    >>> op = gcodekit.gcode_to_operation("M204 P1000\\nG1 X100 E5 F3000\\n", "marlin", plan=False)
    >>> moves, result = plan(op, MarlinConfig(classic_jerk=True))
    >>> round(float(result.start_v[0]), 3), round(float(result.duration_t[0]), 4)
    (10.0, 2.041)
    """
    factor = speed_factor(op)
    moves = firmware_moves(op, factor, lambda travel, angle, radius, speed_v: arc_segments(
        travel, angle, radius, config.max_arc_segment_mm, config.min_circle_segments), gathered=True)
    n = len(moves)
    if n == 0:
        return moves, empty_result()
    lim = _program_limits(op, moves, config)
    rest_before = happens_before(moves, command_rows(op, names=REST_NAMES))
    rest_before[0] = True
    block = {name: np.empty(n) for name in ("millimeters", "acceleration", "nominal_speed", "max_entry_speed_sqr")}
    compiled = engine(n)
    for lo in range(0, n, BLOCK):
        _populate_blocks(moves, lim, rest_before, config, lo, min(lo + BLOCK, n), block, compiled)
    del lim
    millimeters, acceleration = block["millimeters"], block["acceleration"]
    planned = moves.planned(millimeters)  # the speeds and rows read again when asked: two arrays fewer
    del moves  # the end points are no longer needed: free them before the passes
    release_freed_memory()
    minimum_planner_speed_sqr = config.minimum_planner_speed**2
    delta_v2 = Increments(millimeters, acceleration)  # 2 * acceleration * millimeters, made where read
    nominal_speed_sqr = block.pop("nominal_speed")
    nominal_speed_sqr *= nominal_speed_sqr  # squared in place: one array fewer
    # "If a block can de/ac-celerate from nominal speed to zero within the length of the block, then the
    # current block and next block junction speeds are guaranteed to always be at their maximum"
    nominal_length = np.empty(n, bool)
    for lo in range(0, n, BLOCK):
        sl = slice(lo, min(lo + BLOCK, n))
        nominal_length[sl] = nominal_speed_sqr[sl] <= minimum_planner_speed_sqr + delta_v2.at(sl)
    rest_after = np.r_[rest_before[1:], True]
    del rest_before
    entry_speed_sqr, exit_speed_sqr = lookahead(block.pop("max_entry_speed_sqr"), delta_v2, rest_after,
                                                rest_v2=minimum_planner_speed_sqr, nominal_length=nominal_length,
                                                reuse=True)
    del block, delta_v2, nominal_length, rest_after
    # the lengths kept as the waypoints' distances they repeat (but arcs' chords, extruder-only moves)
    planned.length_d = millimeters = GatheredColumn.encode(millimeters, stored(op.waypoints, "distance"),
                                                           planned.waypoint)
    release_freed_memory()  # the passes' temporaries, before the trapezoids' arrays
    # the trapezoids are computed when read (TrapezoidPlan): three arrays fewer kept
    return planned, TrapezoidPlan(_trapezoid_block, millimeters, acceleration, entry_speed_sqr, nominal_speed_sqr,
                                  exit_speed_sqr, kernel="marlin_trapezoids")


def _populate_blocks(moves: PlannerMoves, lim: dict, rest_before: np.ndarray, config: MarlinConfig,
                     lo: int, hi: int, out: dict, kernels=None) -> None:
    """``_populate_block`` for moves ``lo:hi``: length, nominal speed, acceleration, junction speed
    (by the compiled loops of ``kernels`` when given, but for junction deviation's junctions)."""
    first = max(lo - 1, 0)  # the move before the block, for its junction
    sl = slice(first, hi)
    row = moves.rows(sl)
    lim = {k: [_at(a, sl, row) for a in v] if isinstance(v, list) else _at(v, sl, row) for k, v in lim.items()}
    axes_d = moves.end[sl] - moves.start[sl]
    dist_mm = [np.ascontiguousarray(axes_d[:, a]) for a in range(4)]  # X, Y, Z, E columns
    del axes_d

    xyz_moves = (dist_mm[0] != 0) | (dist_mm[1] != 0) | (dist_mm[2] != 0)
    esteps = dist_mm[3] != 0
    if kernels is not None:
        def each(value) -> np.ndarray:  # one value per move, or one for all
            return np.ascontiguousarray(value, dtype=float).reshape(-1)

        millimeters, nominal_speed, speed_per_mm, acceleration = kernels.marlin_blocks(
            *dist_mm, np.ascontiguousarray(moves.speeds(sl)), *map(each, lim["max_feedrate"]),
            *map(each, lim["max_acceleration"]), *(each(lim[k]) for k in ("min_feedrate", "min_travel_feedrate",
                                                                        "acceleration", "travel_acceleration",
                                                                        "retract_acceleration")),
            float(config.minimum_planner_speed))
        inverse_millimeters = 1.0 / millimeters
    else:
        millimeters, inverse_millimeters, nominal_speed, speed_per_mm, acceleration = _block_speeds(
            dist_mm, xyz_moves, esteps, moves.speeds(sl), lim, config)
    _junctions(dist_mm, esteps, millimeters, inverse_millimeters, nominal_speed, speed_per_mm, acceleration, lim,
               rest_before[sl], config, kernels, lo - first, lo, hi, out)


def _block_speeds(dist_mm, xyz_moves, esteps, speed_v, lim, config):
    """Length, its inverse, nominal speed, speed per mm and acceleration of a block's moves."""
    xyz_mm, _ = unit_vectors(dist_mm[:3])
    millimeters = np.where(xyz_moves, xyz_mm, np.abs(dist_mm[3]))
    fr_mm_s = np.maximum(np.nan_to_num(speed_v),
                         np.where(esteps, lim["min_feedrate"], lim["min_travel_feedrate"]))
    # no feed rate yet (F0 or none): Marlin only plans positive speeds, so crawl at the stop speed
    fr_mm_s = np.maximum(fr_mm_s, config.minimum_planner_speed)
    inverse_millimeters = 1.0 / millimeters
    # speed_factor: the largest fraction of fr_mm_s within every axis's max feed rate
    speed_factor = np.minimum(limit_by_axis_maximum(lim["max_feedrate"], dist_mm) * millimeters / fr_mm_s, 1.0)
    nominal_speed = fr_mm_s * speed_factor
    # current_speed[i] = dist_mm[i] * inverse_secs, after the speed factor
    speed_per_mm = nominal_speed * inverse_millimeters

    # acceleration: retract for extruder-only moves, else print or travel, capped per axis
    accel = np.where(esteps, lim["acceleration"], lim["travel_acceleration"])
    accel = np.minimum(accel, limit_by_axis_maximum(lim["max_acceleration"], dist_mm) * millimeters)
    acceleration = np.where(xyz_moves, accel, lim["retract_acceleration"])
    return millimeters, inverse_millimeters, nominal_speed, speed_per_mm, acceleration


def _junctions(dist_mm, esteps, millimeters, inverse_millimeters, nominal_speed, speed_per_mm, acceleration, lim,
               rest, config, kernels, k, lo, hi, out) -> None:
    """The junction speeds of a block's moves, and the block's columns into ``out`` (from its ``k``-th move)."""
    prev = np.r_[0, np.arange(millimeters.size - 1)]
    if config.classic_jerk and kernels is not None:
        max_jerk = [np.ascontiguousarray(j, dtype=float).reshape(-1) for j in lim["max_jerk"]]
        vmax_junction = kernels.classic_jerk(*dist_mm, speed_per_mm, nominal_speed, *max_jerk, rest)
        max_entry_speed_sqr = vmax_junction * vmax_junction
    elif config.classic_jerk:
        vmax_junction = _classic_jerk(dist_mm, speed_per_mm, nominal_speed, lim["max_jerk"], prev, rest)
        max_entry_speed_sqr = vmax_junction * vmax_junction
    else:
        max_entry_speed_sqr = _junction_deviation(dist_mm, esteps, inverse_millimeters, millimeters, nominal_speed,
                                                  acceleration, lim, prev, config)
        max_entry_speed_sqr[rest] = config.minimum_planner_speed**2
    out["millimeters"][lo:hi] = millimeters[k:]
    out["acceleration"][lo:hi] = acceleration[k:]
    out["nominal_speed"][lo:hi] = nominal_speed[k:]
    out["max_entry_speed_sqr"][lo:hi] = max_entry_speed_sqr[k:]


def _at(value, sl: slice, row: np.ndarray):
    """A limit for the moves in ``sl`` (their command rows ``row``): a number stays a number."""
    if isinstance(value, StepSetting):
        return value.at(row)
    return value[sl] if isinstance(value, np.ndarray) else value


def _classic_jerk(dist_mm, speed_per_mm, nominal_speed, max_jerk, prev, rest_before) -> np.ndarray:
    """``vmax_junction`` per move, Marlin 2.1 CLASSIC_JERK ("adapted from Prusa firmware").

    The per-axis loops keep their shape; only the moves are vectorized.
    For ``safe_speed`` the first limited axis scales the nominal speed by
    ``maxj / jerk`` and each later one only lowers it, so the result is the
    nominal speed times the smallest ``maxj / jerk``; at the junction each
    limiting axis sets ``v_factor = maxj / jerk`` (its jerk measured at the
    running ``v_factor``), so again the smallest ratio wins.
    """
    # The junction speed is shared: the smaller nominal speed, the previous block's axis speeds scaled to it.
    previous_nominal_speed = nominal_speed[prev]
    vmax_junction = np.minimum(nominal_speed, previous_nominal_speed)
    exit_scale = speed_per_mm[prev] * (vmax_junction / previous_nominal_speed)
    safe_factor = np.ones_like(nominal_speed)
    v_factor = np.ones_like(nominal_speed)
    for d, maxj in zip(dist_mm, max_jerk):
        v_entry = d * speed_per_mm  # current_speed[axis]
        v_exit = d[prev] * exit_scale  # previous_speed[axis], scaled to vmax_junction
        cs = np.abs(v_entry)
        np.minimum(safe_factor, np.divide(maxj, cs, out=np.ones_like(cs), where=cs > maxj), out=safe_factor)
        # coasting (same direction) or axis reversal
        jerk = np.where(v_exit > v_entry,
                        np.where((v_entry > 0) | (v_exit < 0), v_exit - v_entry, np.maximum(v_exit, -v_entry)),
                        np.where((v_entry < 0) | (v_exit > 0), v_entry - v_exit, np.maximum(-v_exit, v_entry)))
        np.minimum(v_factor, np.divide(maxj, jerk, out=np.ones_like(jerk), where=jerk > maxj), out=v_factor)
    safe_speed = nominal_speed * safe_factor
    vmax_junction *= v_factor
    # "Not coasting. The machine will stop and start the movements anyway, better to start the segment from start."
    vmax_junction_threshold = vmax_junction * 0.99
    restart = (safe_speed[prev] > vmax_junction_threshold) & (safe_speed > vmax_junction_threshold)
    return np.where(rest_before | restart, safe_speed, vmax_junction)


def _junction_deviation(dist_mm, esteps, inverse_millimeters, millimeters, nominal_speed, acceleration, lim, prev,
                        config: MarlinConfig) -> np.ndarray:
    """``vmax_junction_sqr`` per move, Marlin 2.1 junction deviation (with JD_HANDLE_SMALL_SEGMENTS)."""
    # unit vectors: XYZ over the XYZ length; with extrusion, normalised with E (normalize_junction_vector)
    _, with_e = unit_vectors(dist_mm)
    unit_vec = [np.where(esteps, u, d * inverse_millimeters) for u, d in zip(with_e[:3], dist_mm[:3])]
    unit_vec.append(with_e[3])
    junction_cos_theta = -sum(u[prev] * u for u in unit_vec)
    _, junction_unit_vec = unit_vectors([u - u[prev] for u in unit_vec])
    junction_acceleration = np.minimum(acceleration, limit_by_axis_maximum(lim["max_acceleration"], junction_unit_vec))
    cos_theta = np.maximum(junction_cos_theta, -COS_REVERSAL)  # round-off guard: no division by zero
    sin_theta_d2 = np.sqrt(0.5 * (1.0 - cos_theta))
    vmax_junction_sqr = junction_acceleration * lim["junction_deviation"] * sin_theta_d2 / (1.0 - sin_theta_d2)
    if config.jd_handle_small_segments:
        # "For small moves with >135deg junction (octagon) find speed for approximate arc"
        small = (millimeters < 1.0) & (junction_cos_theta < COS_OCTAGON)
        junction_theta = np.arccos(np.clip(-junction_cos_theta, -1.0, 1.0))
        arc_sqr = np.divide(millimeters * junction_acceleration, junction_theta,
                            out=np.full_like(millimeters, np.inf), where=small & (junction_theta > 0))
        vmax_junction_sqr = np.minimum(vmax_junction_sqr, arc_sqr)
    vmax_junction_sqr = np.where(junction_cos_theta > COS_REVERSAL, config.minimum_planner_speed**2, vmax_junction_sqr)
    return np.minimum(vmax_junction_sqr, np.minimum(nominal_speed, nominal_speed[prev]) ** 2)
