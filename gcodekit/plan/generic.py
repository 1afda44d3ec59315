"""Plan stage: the GRBL-style :class:`~gcodekit.plan.motion_profile.MotionProfile` as a planner.

For machines without a firmware model of their own (``generic``,
``linuxcnc``; planner name ``"motion_profile"``): a preset's ``[planner]`` table with ``name =
"motion_profile"`` and the settings of :class:`MotionProfileConfig`.

Each move keeps the speed the emulator gave it (its path length over its
time), so rapids, inverse-time and per-revolution feeds plan at the speed
the machine was asked for.  Arcs are cut into chords of at most
``arc_resolution`` mm (every turn of a multi-turn arc or helix), each
capped at the speed whose centripetal acceleration on the arc's radius is
``max_acceleration`` and measured as its share of the arc's length: the
machine follows the arc, not the chords.  The machine
comes to rest where LinuxCNC's task waits for motion to finish before the
next command (``emctaskmain.cc``, ``emcTaskCheckPreconditions``): dwells,
tool changes, spindle and coolant commands, program stops and ends,
homing, probing, and offset changes; and after every move in exact-stop
mode (G61, G61.1).  Steps without a planner move (rotary axes only; G28
and G30, which ``firmware_moves`` leaves out as homing; arcs too long to
cut into chords within ``max_motions``) keep the emulator's time and the
linear axes stop around them.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ConfigError, check_choice
from ..emulate import arcs
from ..parse.table import NAME_ID
from .motion_profile import BAAMMotionProfile, MotionProfile
from .moves import (PlannerMoves, PlanResult, command_rows, firmware_moves, follows_kept_step, happens_before,
                    in_force, with_kept_steps)

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

#: Commands before which the machine has come to rest.
STOP_NAMES = (
    "dwell", "tool_change", "spindle_cw", "spindle_ccw", "spindle_off", "coolant_flood", "coolant_mist",
    "coolant_off", "program_stop", "optional_stop", "program_end", "home", "home_secondary", "probe",
    "wait_moves", "motors_off", "tool_length_offset", "tool_length_offset_dynamic", "cancel_tool_length",
    "work_offset_1", "work_offset_2", "work_offset_3", "work_offset_4", "work_offset_5", "work_offset_6",
    "work_offset_7", "work_offset_8", "work_offset_9",
)
PROFILE_TYPES = ("trapezoid", "scurve")


@dataclass(frozen=True)
class MotionProfileConfig:
    """Settings of the ``motion_profile`` planner (a preset's ``[planner]`` table).

    Attributes
    ----------
    max_acceleration : float or None
        mm/s^2; None (key left out) plans without acceleration: every move
        at its own speed, no corner slow-downs.
    max_velocity : float or None
        mm/s; ceiling on every move's speed.
    junction_deviation : float
        mm, the corner model's deviation (GRBL's ``$11``).
    profile_type : {"trapezoid", "scurve"}
    max_jerk : float or None
        mm/s^3, for ``"scurve"``; None: full acceleration after 0.1 s.
    arc_resolution : float
        mm, longest chord an arc is cut into.
    machine_rules : {"", "baam"}
        ``"baam"`` plans with :class:`~gcodekit.plan.motion_profile.BAAMMotionProfile`
        (rest before and after each layer change, per-axis speed caps).
    axis_max_velocity : list of 3 floats or None
        mm/s, X, Y and Z speed caps for ``"baam"``.
    """

    max_acceleration: float | None = None
    max_velocity: float | None = None
    junction_deviation: float = 0.05
    profile_type: str = "trapezoid"
    max_jerk: float | None = None
    arc_resolution: float = 1.0
    machine_rules: str = ""
    axis_max_velocity: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        check_choice("profile_type", self.profile_type, PROFILE_TYPES)
        check_choice("machine_rules", self.machine_rules, ("", "baam"))
        for key in ("max_acceleration", "max_velocity", "max_jerk", "arc_resolution"):
            value = getattr(self, key)
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0):
                raise ConfigError(f"planner 'motion_profile': {key} must be a positive number, not {value!r}")
        jd = self.junction_deviation
        if isinstance(jd, bool) or not isinstance(jd, (int, float)) or jd < 0:
            raise ConfigError(f"planner 'motion_profile': junction_deviation must be 0 or more mm, not {jd!r}")

    @classmethod
    def from_config_file(cls, path: str | os.PathLike) -> "MotionProfileConfig":
        raise ConfigError(f"{os.fspath(path)}: the motion_profile planner reads no firmware file; "
                          "set its values in the machine preset's [planner] table")

    def motion_profile(self) -> MotionProfile:
        """The :class:`MotionProfile` these settings describe."""
        if self.machine_rules == "baam":
            profile = BAAMMotionProfile(self.max_acceleration, self.max_velocity, self.junction_deviation,
                                        max_jerk=self.max_jerk, axis_max_velocity=self.axis_max_velocity)
        else:
            profile = MotionProfile(self.max_acceleration, self.max_velocity, self.junction_deviation,
                                    max_jerk=self.max_jerk)
        profile.profile_type = self.profile_type
        return profile


def plan(op: "EmulatedProgram", config: MotionProfileConfig) -> tuple[PlannerMoves, PlanResult]:
    """Plan an emulated operation with a :class:`MotionProfile`; one result per move."""
    w = op.waypoints
    n_wp = w["x"].size
    if n_wp == 0:
        empty = np.zeros(0)
        return (PlannerMoves(np.zeros((0, 4)), np.zeros((0, 4)), empty, np.zeros(0, np.int64), np.zeros(0, np.int64)),
                PlanResult(empty, empty, empty, empty, empty, empty, empty))
    resolution = config.arc_resolution
    moves = firmware_moves(op, None, lambda mm, *_: np.maximum(np.ceil(mm / resolution), 1.0))
    distance = np.asarray(w["distance"], float)
    time = np.asarray(w["time"], float)
    with np.errstate(divide="ignore", invalid="ignore"):
        # the emulator's speed: rapid rate, F, inverse time or feed per revolution alike
        speed_v = np.where((distance > 0) & (time > 0), distance / time, np.nan)
    speed_v = speed_v[moves.waypoint]
    is_arc = w["motion"][moves.waypoint] >= 3
    if config.max_acceleration is not None and is_arc.any():
        radius = _arc_radius(w)[moves.waypoint[is_arc]]
        speed_v[is_arc] = np.minimum(speed_v[is_arc], np.sqrt(config.max_acceleration * radius))
    moves = PlannerMoves(moves.start, moves.end, speed_v, moves.row, moves.waypoint)

    # Steps with time but no planner move (rotary axes only, G28/G30 through stored points)
    # keep the emulator's time, and the linear axes stop around them.
    has_move = np.zeros(n_wp, bool)
    has_move[moves.waypoint] = True
    kept = np.flatnonzero((w["motion"] > 0) & ~has_move & (time != 0))

    stop_before = happens_before(moves, command_rows(op, names=STOP_NAMES))
    stop_before |= follows_kept_step(moves, kept)
    stop_before |= follows_kept_step(moves, np.flatnonzero((w["motion"] == 0) & (time > 0)))  # dwells in cycles
    exact_rows = command_rows(op, names=("exact_stop", "path_blending"))
    exact = in_force(moves, exact_rows, op.table.name[exact_rows] == NAME_ID["exact_stop"], 0.0) > 0
    last_of_step = np.append(moves.waypoint[1:] != moves.waypoint[:-1], True)[:len(moves)]
    stops = np.append(stop_before[1:], True)[:len(moves)] | (exact & last_of_step)
    result = config.motion_profile().plan(moves, stops=stops, length_d=_path_lengths(w, moves, is_arc))
    if kept.size:
        moves, result = with_kept_steps(w, moves, result, kept)
    return moves, result


def _path_lengths(w, moves: PlannerMoves, is_arc: np.ndarray) -> np.ndarray:
    """Per move: its length, an arc's chords each their share of the arc's length (the machine follows the
    arc, not its chords)."""
    axes_d = moves.axes_d[:, :3]
    length_d = np.sqrt(np.einsum("ij,ij->i", axes_d, axes_d))
    chords = np.bincount(moves.waypoint, minlength=w["x"].size)[moves.waypoint]
    arc_share = np.asarray(w["distance"], float)[moves.waypoint] / chords
    return np.where(is_arc, arc_share, length_d)


def _arc_radius(w) -> np.ndarray:
    """Per waypoint: distance from the arc's start to its centre in the arc's plane (NaN if not an arc)."""
    n = w["x"].size
    position = np.column_stack([w["x"], w["y"], w["z"]])
    start = np.vstack([np.zeros((1, 3)), position[:-1]])
    centre = np.column_stack([w["cx"], w["cy"], w["cz"]])
    plane = np.asarray(w["plane"])
    radius = np.full(n, np.nan)
    for code, ((f, g, _), _) in arcs.PLANES.items():
        sel = plane == code
        radius[sel] = np.hypot(start[sel, f] - centre[sel, f], start[sel, g] - centre[sel, g])
    return radius
