"""Plan stage: firmware motion planners, chosen by name.

A machine preset names its planner (``planner = "klipper"``); each planner
module has a settings class built from the preset's ``[planner]`` table or
from the firmware's own configuration file, and a ``plan(op, settings)``
function returning the firmware's moves and their planned velocities.
:func:`run_planner` sums them into each waypoint's time and returns a
:class:`Plan`, which the pipeline attaches to the Operation.
"""

from __future__ import annotations

import dataclasses
import importlib
import os
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from ..errors import ConfigError, did_you_mean
from .moves import PlannedMoves, PlannerMoves, PlanResult
from .times import PlannedTimes, times_to_plan, waypoint_times
from .trapezoids import TrapezoidPlan

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

#: Planner name -> (module, settings class, reader of the firmware's own config file)
PLANNERS = {
    "klipper": ("gcodekit.plan.klipper", "KlipperConfig", "from_printer_cfg"),
    "marlin": ("gcodekit.plan.marlin", "MarlinConfig", "from_m503"),
    "grbl": ("gcodekit.plan.grbl", "GrblConfig", "from_settings"),
    "reprapfirmware": ("gcodekit.plan.reprapfirmware", "RrfConfig", "from_config_g"),
    "motion_profile": ("gcodekit.plan.generic", "MotionProfileConfig", "from_config_file"),
}


def machine_options(name: str, config_file: str | os.PathLike) -> dict[str, Any]:
    """Emulator settings (filament, firmware retraction) found in a firmware config file."""
    module = importlib.import_module(PLANNERS[name][0])
    reader = getattr(module, "machine_options", None)
    return reader(config_file) if reader else {}


def planner_settings(name: str, preset: Mapping[str, Any], config_file: str | os.PathLike | None = None):
    """Settings for planner ``name``: its defaults, the preset's values, then the firmware file."""
    if name not in PLANNERS:
        raise ConfigError(f"unknown planner {name!r}; choose one of {', '.join(PLANNERS)}" + did_you_mean(name, PLANNERS))
    module_name, class_name, reader = PLANNERS[name]
    cls = getattr(importlib.import_module(module_name), class_name)
    if config_file is not None:
        settings = getattr(cls, reader)(config_file)
    else:
        settings = cls()
    known = {f.name for f in dataclasses.fields(cls)}
    for key in preset:
        if key not in known:
            raise ConfigError(f"planner {name!r} has no setting {key!r}" + did_you_mean(key, known))
    if config_file is None and preset:
        settings = dataclasses.replace(settings, **dict(preset))
    return settings


@dataclasses.dataclass(frozen=True)
class Plan:
    """What a planner gives back: the planned time of every waypoint and the per-move plan.

    The pipeline attaches it to the Operation (``Operation.attach_plan``):
    ``time`` (computed when read) replaces the waypoints' ``time`` column and ``moves``/``result``
    stay as ``op.plan``, from which :func:`waypoint_speeds` reads each
    waypoint's entry, cruise and exit speed.
    """

    time: PlannedTimes
    moves: PlannedMoves
    result: PlanResult | TrapezoidPlan


def run_planner(program: "EmulatedProgram", name: str, settings) -> Plan:
    """Plan an emulated program with planner ``name``; the program is not changed."""
    module = importlib.import_module(PLANNERS[name][0])
    moves, result = module.plan(program, settings)
    return Plan(PlannedTimes(program.waypoints, moves, result),
                moves.planned() if isinstance(moves, PlannerMoves) else moves, result)


def times_every_move(name: str) -> bool:
    """Whether planner ``name`` times every move itself, reading the emulator's times only where nothing
    moves and where they are unknown (its module's ``TIMES_EVERY_MOVE``; see :func:`.times.times_to_plan`)."""
    return bool(getattr(importlib.import_module(PLANNERS[name][0]), "TIMES_EVERY_MOVE", False))




def waypoint_speeds(plan: tuple[PlannedMoves, PlanResult], n: int) -> dict[str, np.ndarray]:
    """Planned ``start_v`` (first move's entry), ``cruise_v`` (fastest cruise),
    ``end_v`` (last move's exit) and ``accel`` of each of ``n`` waypoints, mm/s and mm/s^2."""
    moves, result = plan
    out = {k: np.zeros(n) for k in ("start_v", "cruise_v", "end_v", "accel")}
    if len(moves):
        result = result.phases()  # every field in one computation
        first = np.r_[True, moves.waypoint[1:] != moves.waypoint[:-1]]
        last = np.r_[moves.waypoint[1:] != moves.waypoint[:-1], True]
        out["start_v"][moves.waypoint[first]] = result.start_v[first]
        out["end_v"][moves.waypoint[last]] = result.end_v[last]
        np.maximum.at(out["cruise_v"], moves.waypoint, result.cruise_v)
        out["accel"][moves.waypoint[first]] = result.accel[first]
    return out
