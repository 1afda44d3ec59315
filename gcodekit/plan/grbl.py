"""Plan stage: GRBL 1.1's lookahead, as array code.

Mirrors grbl 1.1h ``planner.c`` (``plan_buffer_line``: junction deviation
and per-axis limits along the move's unit vector; ``planner_recalculate``:
the reverse and forward passes), ``motion_control.c`` (``mc_arc``: arcs cut
into chords within ``$12`` of the circle) and the ``protocol_buffer_synchronize``
calls that bring the machine to rest.  GRBL's planner is the ancestor of
Marlin's: the two passes and the trapezoid they share are in :mod:`.lookahead`.

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

from ..errors import ConfigError
from ..parse.table import MOTION_RAPID
from .caps import report_feed_caps
from .lookahead import empty_result, limit_by_axis_maximum, lookahead, trapezoid, unit_vectors
from .moves import (PlannerMoves, PlanResult, command_rows, firmware_moves, follows_kept_step, happens_before,
                    with_kept_steps)

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

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


def machine_options(path: str | os.PathLike) -> dict[str, bool]:
    """What the emulator needs from a ``$$`` dump: ``$32`` (laser mode) makes the machine a laser.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "laser.txt"
    >>> _ = p.write_text("$30=1000\\n$32=1\\n$110=6000\\n")
    >>> machine_options(p)
    {'laser': True}
    """
    return {"laser": GrblConfig.from_settings(path).laser_mode}


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


# -- grbl ---------------------------------------------------------------------------

#: Commands GRBL executes only once the planner buffer is empty (protocol_buffer_synchronize).
REST_NAMES = (
    "dwell", "program_stop", "program_end", "probe", "home", "home_secondary", "store_home", "store_home_secondary",
    "coolant_flood", "coolant_mist", "coolant_off", "set_position", "clear_position_offset",
    "tool_length_offset_dynamic", "cancel_tool_length",
    "work_offset_1", "work_offset_2", "work_offset_3", "work_offset_4", "work_offset_5", "work_offset_6",
)
SPINDLE_NAMES = ("spindle_cw", "spindle_ccw", "spindle_off")


def plan(op: "EmulatedProgram", config: GrblConfig) -> tuple[PlannerMoves, PlanResult]:
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
    moves = _with_steps(op, moves)
    w = op.waypoints
    # arcs too long to cut into chords within max_motions keep the emulator's time, at rest around them
    has_move = np.zeros(w["x"].size, bool)
    has_move[moves.waypoint] = True
    unplanned = np.flatnonzero((w["motion"] >= 3) & ~has_move & (w["distance"] > 0))
    if len(moves) == 0:
        return with_kept_steps(w, moves, empty_result(), unplanned) if unplanned.size else (moves, empty_result())
    dwells = np.flatnonzero((w["motion"] == 0) & (np.asarray(w["time"], float) > 0))  # G4, and dwells in cycles
    rest_before = follows_kept_step(moves, unplanned) | follows_kept_step(moves, dwells)
    moves, result = _plan_moves(op, moves, config, rest_before)
    return with_kept_steps(w, moves, result, unplanned) if unplanned.size else (moves, result)


def _with_steps(op: "EmulatedProgram", moves: PlannerMoves) -> PlannerMoves:
    """The moves that step X, Y or Z: GRBL has no extruder, and its ``plan_buffer_line`` drops a block
    without steps (``PLAN_EMPTY_BLOCK``), so an extruder-only move takes no time and is no junction.

    Said once, at the first such move's line, when a program has any (a 3D printer's program planned as
    a GRBL machine's).
    """
    travel = np.asarray(moves.axes_d)[:, :3]
    stepping = (travel != 0).any(axis=1)
    if stepping.all():
        return moves
    dropped = np.flatnonzero(~stepping)
    op.diagnostics.report(int(op.table.line[moves.row[dropped[0]]]), 1,
                          f"GRBL moves X, Y and Z only: the {dropped.size:,} extruder-only "
                          + ("move takes" if dropped.size == 1 else "moves take") + " no time",
                          severity="info")
    return moves.select(np.flatnonzero(stepping))


def _plan_moves(op: "EmulatedProgram", moves: PlannerMoves, config: GrblConfig,
                rest_before: np.ndarray) -> tuple[PlannerMoves, PlanResult]:
    """GRBL's lookahead over the firmware moves; ``rest_before``: moves that start from rest."""
    n = len(moves)
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
    report_feed_caps(op, moves, rapid_rate, "$110-$112")

    rest_before = rest_before | happens_before(moves, command_rows(op, names=REST_NAMES))
    rest_before |= _spindle_syncs(op, moves, config)
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


def _spindle_syncs(op: "EmulatedProgram", moves: PlannerMoves, config: GrblConfig) -> np.ndarray:
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
