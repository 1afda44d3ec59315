"""Plan stage: Klipper's lookahead, as array code.

Mirrors klippy's ``toolhead.py`` (Move, LookAheadQueue.flush; Klipper
v0.12+, with ``minimum_cruise_ratio``), ``kinematics/cartesian.py`` (Z
limits), ``kinematics/extruder.py`` (extrude-only limits and the
instantaneous corner velocity) and ``extras/gcode_arcs.py`` (arcs cut into
chords of at most ``resolution`` mm).  Klipper's variable names are kept.

Klipper comes to rest (flushes its lookahead) at G4, M400, G28, M84,
SET_KINEMATIC_POSITION and the end of the program; everything else, M204
and SET_VELOCITY_LIMIT included, only changes the moves that follow.
"""

from __future__ import annotations

import configparser
import math
import os
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..columns import Column, GatheredColumn, GrowingRuns, RunColumn, stored
from ..errors import ConfigError
from ..memory import release_freed_memory
from .kernels import NO_RUNS, engine, runs_of, units_of
from .moves import (PlannedMoves, PlannerMoves, PlanResult, StepSetting, command_rows, firmware_moves, happens_before,
                    in_force, speed_factor)
from .points import RunningSum
from .scans import Increments, backward_min, forward_min, next_marked, segmented_cummin
from .trapezoids import NextEntry, TrapezoidPlan

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

EXTRUDE_ONLY_ACCEL = 99999999.9  # klippy: "self.accel = 99999999.9" for extrude-only moves
NO_LIMIT_V2 = 999999999.9  # klippy's next_junction_v2 default
#: Every move is timed by the plan: the emulator's times are read only where nothing moves (see
#: :func:`gcodekit.plan.times_to_plan`)
TIMES_EVERY_MOVE = True
TIE = 1e-9  # relative: squared speeds this close count as equal (see flush)


@dataclass(frozen=True)
class KlipperConfig:
    """The ``[printer]``, ``[extruder]`` and ``[gcode_arcs]`` options the planner reads.

    Units: mm/s, mm/s^2, mm; ratios 0..1.  Defaults are Klipper's.
    """

    max_velocity: float = 300.0
    max_accel: float = 3000.0
    square_corner_velocity: float = 5.0
    minimum_cruise_ratio: float = 0.5
    max_z_velocity: float | None = None  # default: max_velocity
    max_z_accel: float | None = None  # default: max_accel
    nozzle_diameter: float = 0.4
    filament_diameter: float = 1.75
    max_extrude_only_velocity: float | None = None
    max_extrude_only_accel: float | None = None
    instantaneous_corner_velocity: float = 1.0
    arc_resolution: float = 1.0
    temperature_waits_flush: bool = False  # M109/M190 wait for the heater (a full stop)

    @property
    def max_e_velocity(self) -> float:
        # klippy extruder.py: max_velocity * def_max_cross_section / filament_area
        return self.max_extrude_only_velocity or self.max_velocity * self._cross_ratio

    @property
    def max_e_accel(self) -> float:
        return self.max_extrude_only_accel or self.max_accel * self._cross_ratio

    @property
    def _cross_ratio(self) -> float:
        area = math.pi * (self.filament_diameter * 0.5) ** 2
        return 4.0 * self.nozzle_diameter**2 / area

    @classmethod
    def from_printer_cfg(cls, path: str | os.PathLike) -> "KlipperConfig":
        """Read the planner's options from a Klipper ``printer.cfg``."""
        get = _cfg_reader(path)

        values = {
            "max_velocity": get("printer", "max_velocity"),
            "max_accel": get("printer", "max_accel"),
            "square_corner_velocity": get("printer", "square_corner_velocity", 5.0),
            "max_z_velocity": get("printer", "max_z_velocity"),
            "max_z_accel": get("printer", "max_z_accel"),
            "nozzle_diameter": get("extruder", "nozzle_diameter", 0.4),
            "filament_diameter": get("extruder", "filament_diameter", 1.75),
            "max_extrude_only_velocity": get("extruder", "max_extrude_only_velocity"),
            "max_extrude_only_accel": get("extruder", "max_extrude_only_accel"),
            "instantaneous_corner_velocity": get("extruder", "instantaneous_corner_velocity", 1.0),
            "arc_resolution": get("gcode_arcs", "resolution", 1.0),
        }
        for key in ("max_velocity", "max_accel"):
            if values[key] is None:
                raise ConfigError(f"{path}: [printer] needs {key}")
        mcr = get("printer", "minimum_cruise_ratio")
        atd = get("printer", "max_accel_to_decel")
        if mcr is None:  # the older option: max_accel_to_decel (default max_accel / 2)
            mcr = 1.0 - min(atd, values["max_accel"]) / values["max_accel"] if atd is not None else 0.5
        values["minimum_cruise_ratio"] = mcr
        return cls(**values)


def _cfg_reader(path: str | os.PathLike):
    """A ``get(section, key, default)`` for the numbers of a Klipper config file."""
    parser = configparser.RawConfigParser(inline_comment_prefixes=("#", ";"), strict=False, delimiters=(":", "="))
    try:
        with open(path, encoding="utf-8") as f:
            parser.read_file(f)
    except (OSError, configparser.Error) as exc:
        raise ConfigError(f"{path}: cannot read Klipper config: {exc}") from exc
    if not parser.has_section("printer"):
        raise ConfigError(f"{path}: no [printer] section (is this a Klipper printer.cfg?)")

    def get(section: str, key: str, default=None):
        if parser.has_option(section, key):
            raw = parser.get(section, key)
            try:
                return float(raw)
            except ValueError:
                raise ConfigError(f"{path}: [{section}] {key} = {raw!r} is not a number") from None
        return default

    return get


def machine_options(path: str | os.PathLike) -> dict[str, float]:
    """What the emulator (not the planner) needs from ``printer.cfg``: filament and retraction."""
    get = _cfg_reader(path)
    return {
        "filament_diameter": get("extruder", "filament_diameter", 1.75),
        # klippy extras/firmware_retraction.py defaults
        "retract_length": get("firmware_retraction", "retract_length", 0.0),
        "retract_speed": get("firmware_retraction", "retract_speed", 20.0),
        "unretract_extra_length": get("firmware_retraction", "unretract_extra_length", 0.0),
        "unretract_speed": get("firmware_retraction", "unretract_speed", 10.0),
    }


def _named_args(text: str) -> dict[str, float]:
    out = {}
    for key, value in re.findall(r"([A-Za-z_]+)\s*=\s*(\S+)", text):
        try:
            out[key.upper()] = float(value)
        except ValueError:
            continue
    return out


def _velocity_limits(op: "EmulatedProgram", config: KlipperConfig):
    """Rows where the toolhead limits change, and the limits after each.

    M204 rows are read as columns (a sliced print has one per feature);
    SET_VELOCITY_LIMIT rows are few and parsed one by one.
    """
    t = op.table
    m204 = command_rows(op, codes=("M204",))
    s_word, p_word, t_word = (t.param_at(k, m204) for k in "SPT")
    accel = np.where(np.isnan(s_word), np.fmin(p_word, t_word) * (~np.isnan(p_word) & ~np.isnan(t_word)), s_word)
    accel[~(accel > 0)] = np.nan  # Klipper ignores M204 without S (or P and T together)
    ignored = m204[np.isnan(accel)]
    if ignored.size:
        first = t.command(int(ignored[0]))
        more = f" ({ignored.size} such lines)" if ignored.size > 1 else ""
        op.diagnostics.warn(first.line, 1, f"Klipper ignores M204 without S (or P and T together){more}", str(first))
    events = {int(r): ("M204", float(a)) for r, a in zip(m204, accel) if a == a}
    for row in command_rows(op, codes=("SET_VELOCITY_LIMIT",)).tolist():
        events[row] = ("SET_VELOCITY_LIMIT", _named_args(t.command(row).text))
    rows = np.array(sorted(events), np.int64)
    columns = {name: np.empty(rows.size) for name in ("max_velocity", "max_accel", "square_corner_velocity",
                                                     "minimum_cruise_ratio")}
    state = {name: getattr(config, name) for name in columns}
    only_m204 = all(kind == "M204" for kind, _ in events.values())
    if only_m204:  # the common case: the acceleration alone changes
        for name in columns:
            columns[name][:] = state[name]
        columns["max_accel"][:] = [events[r][1] for r in rows.tolist()]
        return rows, columns
    for k, row in enumerate(rows.tolist()):
        kind, value = events[row]
        if kind == "M204":
            state["max_accel"] = value
        else:
            for key, name in (("VELOCITY", "max_velocity"), ("ACCEL", "max_accel"),
                              ("SQUARE_CORNER_VELOCITY", "square_corner_velocity"),
                              ("MINIMUM_CRUISE_RATIO", "minimum_cruise_ratio")):
                if key in value:
                    state[name] = value[key]
            if "ACCEL_TO_DECEL" in value and "MINIMUM_CRUISE_RATIO" not in value:
                state["minimum_cruise_ratio"] = 1.0 - min(value["ACCEL_TO_DECEL"], state["max_accel"]) / state["max_accel"]
        for name in columns:
            columns[name][k] = state[name]
    return rows, columns


#: Moves handled at once by the element-wise steps: small blocks reuse
#: memory instead of touching fresh pages for every temporary array.
BLOCK = 1 << 14


def plan(op: "EmulatedProgram", config: KlipperConfig) -> tuple[PlannerMoves | PlannedMoves,
                                                              PlanResult | TrapezoidPlan]:
    """Plan an emulated operation as Klipper would; one result per firmware move."""
    factor = speed_factor(op)
    # gcode_arcs.py: chords of at most `resolution` mm
    moves = firmware_moves(op, factor, lambda mm, *_: np.maximum(np.floor(mm / config.arc_resolution), 1.0),
                           gathered=True)
    n = len(moves)
    if n == 0:
        empty = np.zeros(0)
        return moves, PlanResult(empty, empty, empty, empty, empty, empty, empty)
    rows, limits = _velocity_limits(op, config)
    flush_names = ("wait_moves", "dwell", "home", "motors_off", "set_kinematic_position")
    if config.temperature_waits_flush:
        flush_names += ("wait_hotend_temp", "wait_bed_temp")
    # Full stops: a flush empties the lookahead queue, so the next move
    # starts from rest (the first move of a queue gets no junction).
    flush = happens_before(moves, command_rows(op, names=flush_names, codes=("SET_KINEMATIC_POSITION",)))
    flush[0] = True

    compiled = engine(n)
    if compiled is not None:
        m, junction = _compiled_moves(compiled, moves, rows, limits, config, flush)
    else:
        m = {k: np.empty(n) for k in ("move_d", "accel", "max_cruise_v2", "delta_v2", "mcr_delta_v2", "cap")}
        junction = np.empty(n, bool)
        for lo in range(0, n, BLOCK):
            hi = min(lo + BLOCK, n)
            _move_block(moves, rows, limits, config, flush, lo, hi, m, junction)
    planned = moves.planned(m["move_d"])  # the speeds and rows read again when asked: two arrays fewer
    del moves  # the end points are no longer needed: free them before the passes
    release_freed_memory()

    # max_start_v2 = min(cap, prev.max_start_v2 + prev.delta_v2): forward scans
    # (each scan writes over the array it scans, which nothing reads after it: two arrays fewer at the peak)
    cap = m.pop("cap")
    max_start_v2 = forward_min(cap, m["delta_v2"], out=cap)
    mcr_cap = np.where(junction, max_start_v2, 0.0)
    max_mcr_start_v2 = forward_min(mcr_cap, m["mcr_delta_v2"], out=mcr_cap)
    # LookAheadQueue.flush, backward: assume a stop after the last move of each flush
    start_v2 = backward_min(max_start_v2, m["delta_v2"], out=max_start_v2)
    mcr_start_v2 = backward_min(max_mcr_start_v2, m["mcr_delta_v2"], out=max_mcr_start_v2)
    del cap, mcr_cap, max_start_v2, max_mcr_start_v2
    max_cruise_v2 = m.pop("max_cruise_v2")  # the cruise speeds are written over their caps
    if compiled is not None:  # the increments made as the loop goes
        cruise_v2 = compiled.klipper_cruise(start_v2, mcr_start_v2, np.zeros(0), np.zeros(0), max_cruise_v2,
                                            flush, TIE, max_cruise_v2, *m["mcr_delta_v2"].kernel_args()[:5])
    else:
        cruise_v2 = _cruise(start_v2, mcr_start_v2, m, max_cruise_v2, flush)
    del mcr_start_v2, max_cruise_v2, m["delta_v2"], m["mcr_delta_v2"]  # free before the trapezoids
    # the lengths kept as the waypoints' distances they repeat (but arcs' chords, extruder-only moves)
    planned.length_d = m["move_d"] = GatheredColumn.encode(m["move_d"], stored(op.waypoints, "distance"),
                                                           planned.waypoint)
    release_freed_memory()
    # a move ends at the next one's start, but at rest before a flush and after the last move (not stored)
    next_start_v2 = NextEntry(start_v2, np.flatnonzero(flush[1:]), 0.0)
    return planned, _set_junction(start_v2, cruise_v2, next_start_v2, m)


def _compiled_moves(compiled, moves, rows, limits, config, flush) -> tuple[dict, np.ndarray]:
    """What :func:`_move_block` computes, for all moves in one compiled loop."""
    names = ("max_velocity", "max_accel", "square_corner_velocity", "minimum_cruise_ratio")
    ends = getattr(moves.start, "ends", None)  # a MoveEnds when the points are gathered from the waypoints
    if ends is None:
        points = (np.ascontiguousarray(moves.start, float), np.ascontiguousarray(moves.end, float), False,
                  *([np.zeros(0)] * 3), NO_RUNS, np.zeros(0), np.zeros(3), False, np.zeros(0, np.int32), False)
    else:  # the extruder's running sum made as the loop goes, when it is not made already
        x, y, z, e = ends.columns
        summing = isinstance(e, RunningSum)
        (x, x_scale), (y, y_scale), (e, e_scale) = (units_of(c) for c in (x, y, e.deltas if summing else e))
        points = (np.zeros((0, 4)), np.zeros((0, 4)), True, x, y, *runs_of(z), e, np.array([x_scale, y_scale, e_scale]),
                  summing, ends.idx, ends.chained)
    if ends is not None and moves.read_from_source:  # each move's speed and row read at its waypoint, in the loop
        src = moves.source
        speeds_and_rows = (np.zeros(0), np.zeros(0, np.int32), True, *runs_of(src.feed), src.command,
                           src.motion, np.nan if src.rapid_v is None else float(src.rapid_v),
                           np.zeros(0) if src.factor is None else np.asarray(src.factor, float))
    else:
        speeds_and_rows = (np.ascontiguousarray(moves.speed_v, float), np.ascontiguousarray(moves.row), False,
                           np.zeros(0), NO_RUNS, np.zeros(0, np.int32), np.zeros(0, np.uint8), np.nan, np.zeros(0))
    out = compiled.klipper_moves(
        *points, *speeds_and_rows, flush,
        np.ascontiguousarray(rows, np.int64), *(np.ascontiguousarray(limits[k], float) for k in names),
        np.array([float(getattr(config, k)) for k in names]), float(config.max_z_velocity or config.max_velocity),
        float(config.max_z_accel or config.max_accel), float(config.max_e_velocity), float(config.max_e_accel),
        float(config.instantaneous_corner_velocity), EXTRUDE_ONLY_ACCEL, NO_LIMIT_V2)
    m = dict(zip(("move_d", "accel", "max_cruise_v2", "cap"), out[:4]))
    # the accelerations as runs (a print's few settings), the increments made where the scans read them
    m["accel"] = RunColumn.encode(m["accel"])
    m["delta_v2"] = Increments(m["move_d"], m["accel"])
    m["mcr_delta_v2"] = Increments(m["move_d"], m["accel"], _pseudo_accel(moves, rows, limits, config))
    return m, out[4]


def _pseudo_accel(moves: PlannerMoves, rows: np.ndarray, limits: dict, config: KlipperConfig) -> Column:
    """Each move's minimum cruise ratio pseudo acceleration, ``max_accel * (1 - minimum_cruise_ratio)`` in
    force (as :func:`_move_block` has it), a block of moves at a time: runs, where a print changes its
    limits a few times."""
    max_accel = StepSetting(rows, limits["max_accel"], config.max_accel)
    ratio = StepSetting(rows, limits["minimum_cruise_ratio"], config.minimum_cruise_ratio)
    n, runs, blocks = len(moves), GrowingRuns(np.float64), []
    for lo in range(0, n, BLOCK):
        move_rows = moves.rows(slice(lo, min(lo + BLOCK, n)))
        values = max_accel.at(move_rows) * (1.0 - ratio.at(move_rows))
        if runs is not None and not runs.add(values):  # too many changes: an array
            blocks, runs = [np.asarray(runs.finish())], None
        if runs is None:
            blocks.append(values)
    return runs.finish() if runs is not None else np.concatenate(blocks)


def _move_block(moves, rows, limits, config, flush, lo, hi, m, junction) -> None:
    """Move.__init__, limit_speed and calc_junction for moves ``lo:hi``."""
    first = max(lo - 1, 0)  # the move before the block, for its junction
    sl = slice(first, hi)
    block = moves.select(sl)

    def limit(name: str) -> np.ndarray:
        return in_force(block, rows, limits[name], getattr(config, name))

    max_velocity, max_accel = limit("max_velocity"), limit("max_accel")
    scv, mcr = limit("square_corner_velocity"), limit("minimum_cruise_ratio")
    junction_deviation = scv**2 * (math.sqrt(2.0) - 1.0) / max_accel
    mcr_pseudo_accel = max_accel * (1.0 - mcr)

    # Move.__init__, with klippy's order of floating-point operations: corner
    # speeds at near-reversals depend on the last bits of axes_r.
    axes_d = block.axes_d
    dx, dy, dz = axes_d[:, 0], axes_d[:, 1], axes_d[:, 2]
    move_d = np.sqrt((dx * dx + dy * dy) + dz * dz)
    is_kinematic = move_d >= 1e-9
    axes_d[~is_kinematic, :3] = 0.0
    move_d = np.where(is_kinematic, move_d, np.abs(axes_d[:, 3]))
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_move_d = np.where(move_d > 0, 1.0 / move_d, 0.0)
    axes_r = axes_d * inv_move_d[:, None]
    velocity = np.where(is_kinematic, np.minimum(block.speed_v, max_velocity), block.speed_v)
    accel = np.where(is_kinematic, max_accel, EXTRUDE_ONLY_ACCEL)
    max_cruise_v2 = velocity**2
    mcr_delta_v2 = 2.0 * move_d * mcr_pseudo_accel

    # limit_speed(): cartesian Z, then the extruder's extrude-only limits
    abs_dz = np.abs(axes_d[:, 2])
    z_move = is_kinematic & (abs_dz > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        z_ratio = np.where(z_move, move_d / abs_dz, np.inf)
        e_r = axes_r[:, 3]
        e_limited = (axes_d[:, 3] != 0) & (((axes_d[:, 0] == 0) & (axes_d[:, 1] == 0)) | (e_r < 0))
        inv_extrude_r = np.where(e_limited, 1.0 / np.abs(e_r), np.inf)
    speed_cap = _minimum(np.where(z_move, (config.max_z_velocity or config.max_velocity) * z_ratio, np.inf),
                         np.where(e_limited, config.max_e_velocity * inv_extrude_r, np.inf))
    np.minimum(max_cruise_v2, speed_cap**2, out=max_cruise_v2)
    accel = _minimum(accel, np.where(z_move, (config.max_z_accel or config.max_accel) * z_ratio, np.inf),
                     np.where(e_limited, config.max_e_accel * inv_extrude_r, np.inf))
    delta_v2 = 2.0 * move_d * accel
    np.minimum(mcr_delta_v2, delta_v2, out=mcr_delta_v2)

    # Move.calc_junction: caps on the squared speed at the start of each move
    # (index k of the block against k - 1; the first is the move before lo).
    cur, prv = slice(1, None), slice(0, -1)
    ea_v2 = np.empty(hi - first - 1)
    diff_r = e_r[cur] - e_r[prv]
    with np.errstate(divide="ignore"):
        ea_v2 = np.where(diff_r != 0, (config.instantaneous_corner_velocity / np.abs(diff_r)) ** 2,
                         max_cruise_v2[cur])
    cap = _minimum(max_cruise_v2[cur], max_cruise_v2[prv], ea_v2)
    np.minimum(cap, NO_LIMIT_V2, out=cap)
    junction_cos_theta = -((axes_r[cur, 0] * axes_r[prv, 0] + axes_r[cur, 1] * axes_r[prv, 1])
                           + axes_r[cur, 2] * axes_r[prv, 2])
    sin_theta_d2 = np.sqrt(np.maximum(0.5 * (1.0 - junction_cos_theta), 0.0))
    cos_theta_d2 = np.sqrt(np.maximum(0.5 * (1.0 + junction_cos_theta), 0.0))
    one_minus_sin_theta_d2 = 1.0 - sin_theta_d2
    corner = (one_minus_sin_theta_d2 > 0) & (cos_theta_d2 > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        R_jd = sin_theta_d2 / one_minus_sin_theta_d2
        quarter_tan_theta_d2 = 0.25 * sin_theta_d2 / cos_theta_d2
        corner_caps = _minimum(
            R_jd * junction_deviation[cur] * accel[cur],
            R_jd * junction_deviation[prv] * accel[prv],
            delta_v2[cur] * quarter_tan_theta_d2,
            delta_v2[prv] * quarter_tan_theta_d2,
        )
    cap = np.where(corner, np.minimum(cap, corner_caps), cap)
    joins = is_kinematic[cur] & is_kinematic[prv]

    skip = lo - first  # 1 except for the very first block
    out = slice(lo, hi)
    m["move_d"][out] = move_d[skip:]
    m["accel"][out] = accel[skip:]
    m["max_cruise_v2"][out] = max_cruise_v2[skip:]
    m["delta_v2"][out] = delta_v2[skip:]
    m["mcr_delta_v2"][out] = mcr_delta_v2[skip:]
    if skip:
        junction[out] = joins & ~flush[out]
        m["cap"][out] = np.where(junction[out], cap, 0.0)
    else:  # the first move of the program has no junction
        junction[lo] = False
        m["cap"][lo] = 0.0
        junction[lo + 1:hi] = joins & ~flush[lo + 1:hi]
        m["cap"][lo + 1:hi] = np.where(junction[lo + 1:hi], cap, 0.0)


def _cruise(start_v2, mcr_start_v2, m, max_cruise_v2, flush):
    """LookAheadQueue.flush: each move's cruise speed (at most ``max_cruise_v2``)."""
    n = start_v2.size
    segment = np.cumsum(flush, dtype=np.int32)
    last_of_segment = np.r_[segment[1:] != segment[:-1], True]
    next_start_v2 = np.r_[start_v2[1:], 0.0]
    next_start_v2[last_of_segment] = 0.0
    next_mcr_start_v2 = np.r_[mcr_start_v2[1:], 0.0]
    next_mcr_start_v2[last_of_segment] = 0.0
    reach_mcr_start_v2 = next_mcr_start_v2 + m["mcr_delta_v2"]
    # Klipper compares values its sequential loop made equal on purpose (a
    # move whose start is limited by braking for the next); the scans round
    # differently in the last bits, so equal means equal within TIE.
    tie = TIE * np.maximum(reach_mcr_start_v2, 1.0)
    can_accel = mcr_start_v2 < reach_mcr_start_v2 - tie
    # pending_cv2_assign > 1: the move after this one (same flush) could not accelerate
    pending = ~last_of_segment & ~np.r_[can_accel[1:], True]
    update = can_accel & ((mcr_start_v2 + m["mcr_delta_v2"] > next_mcr_start_v2 + tie) | pending)
    del tie, pending, next_mcr_start_v2
    nearest = np.minimum(next_marked(update), n - 1)
    has_peak = update[nearest] & (segment[nearest] == segment)
    peak_cruise_v2 = mcr_start_v2 + reach_mcr_start_v2  # twice the peak; halved below
    del reach_mcr_start_v2
    peak_cruise_v2 = peak_cruise_v2[nearest]
    peak_cruise_v2 *= 0.5
    peak_cruise_v2[~has_peak] = 0.0
    del nearest, has_peak, update
    cruise_v2 = next_start_v2 + m["delta_v2"]  # reachable_start_v2
    cruise_v2 += start_v2
    cruise_v2 *= 0.5
    np.minimum(cruise_v2, max_cruise_v2, out=cruise_v2)
    np.minimum(cruise_v2, peak_cruise_v2, out=cruise_v2)
    del peak_cruise_v2
    # forward: a move that cannot accelerate keeps min(previous cruise, its start)
    chain = np.cumsum(can_accel | flush, dtype=np.int32)
    seed = np.where(can_accel, cruise_v2, np.where(flush, 0.0, start_v2))
    return segmented_cummin(seed, chain)


def _set_junction(start_v2, cruise_v2, next_start_v2, m) -> TrapezoidPlan:
    """Move.set_junction: the trapezoid of each move, computed when read (:class:`.trapezoids.TrapezoidPlan`)."""
    return TrapezoidPlan(_set_junction_block, m["move_d"], m["accel"], start_v2, cruise_v2, next_start_v2,
                         kernel="klipper_trapezoids")


def _set_junction_block(move_d, accel, start_v2, cruise_v2, next_start_v2, result: PlanResult, sl: slice) -> None:
    """Move.set_junction for one block of moves, into ``result``'s arrays at ``sl``."""
    start_v2 = np.minimum(start_v2, cruise_v2)
    end_v2 = np.minimum(next_start_v2, cruise_v2)
    half_inv_accel = 0.5 / accel
    accel_d = (cruise_v2 - start_v2) * half_inv_accel
    decel_d = (cruise_v2 - end_v2) * half_inv_accel
    cruise_d = move_d - accel_d - decel_d
    start_v, cruise_v, end_v = np.sqrt(start_v2), np.sqrt(cruise_v2), np.sqrt(end_v2)
    with np.errstate(divide="ignore", invalid="ignore"):
        result.accel_t[sl] = np.where(accel_d > 0, accel_d / ((start_v + cruise_v) * 0.5), 0.0)
        result.cruise_t[sl] = np.where(cruise_d != 0, cruise_d / cruise_v, 0.0)
        result.decel_t[sl] = np.where(decel_d > 0, decel_d / ((end_v + cruise_v) * 0.5), 0.0)
    result.start_v[sl], result.cruise_v[sl], result.end_v[sl] = start_v, cruise_v, end_v


def _minimum(first: np.ndarray, *others: np.ndarray) -> np.ndarray:
    """Element-wise minimum of several arrays (np.minimum.reduce on a list copies them all)."""
    out = np.array(first, dtype=float)
    for other in others:
        np.minimum(out, other, out=out)
    return out


