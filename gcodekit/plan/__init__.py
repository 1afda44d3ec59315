"""Plan stage: firmware motion planners, chosen by name.

A machine preset names its planner (``planner = "klipper"``); each planner
module has a settings class built from the preset's ``[planner]`` table or
from the firmware's own configuration file, and a ``plan(op, settings)``
function returning the firmware's moves and their planned velocities.
:func:`apply_plan` sums the moves back onto the operation's waypoints.
"""

from __future__ import annotations

import dataclasses
import importlib
import os
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from ..errors import ConfigError, did_you_mean
from .moves import PlannedMoves, PlannerMoves, PlanResult

if TYPE_CHECKING:
    from ..model.operation import Operation

#: Planner name -> (module, settings class, reader of the firmware's own config file)
PLANNERS = {
    "klipper": ("gcodekit.plan.klipper", "KlipperConfig", "from_printer_cfg"),
    "marlin": ("gcodekit.plan.marlin", "MarlinConfig", "from_m503"),
    "grbl": ("gcodekit.plan.grbl", "GrblConfig", "from_settings"),
    "reprapfirmware": ("gcodekit.plan.reprapfirmware", "RrfConfig", "from_config_g"),
    "motion_profile": ("gcodekit.plan.motion_profile", "MotionProfileConfig", "from_config_file"),
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


def run_planner(op: "Operation", name: str, settings) -> "Operation":
    """Plan ``op`` with planner ``name`` and write the planned times into it."""
    module = importlib.import_module(PLANNERS[name][0])
    moves, result = module.plan(op, settings)
    apply_plan(op, moves, result)
    return op


def apply_plan(op: "Operation", moves: PlannerMoves | PlannedMoves, result: PlanResult) -> None:
    """Per-waypoint planned time from per-move results.

    A waypoint's ``time`` becomes the sum of its moves' durations (dwells
    keep theirs); the per-move plan stays in ``op.plan`` and
    :func:`waypoint_speeds` gives each waypoint's entry, cruise and exit speed.
    """
    w = op.waypoints
    n = w["x"].size
    planned = np.bincount(moves.waypoint, weights=result.duration_t, minlength=n)
    has_moves = np.bincount(moves.waypoint, minlength=n) > 0
    w["time"] = np.where(has_moves, planned, np.where(w["motion"] > 0, 0.0, w["time"]))
    # a feed move with no feed in force has no time a planner could know (its minimum speed is no answer)
    unknown = (np.asarray(w["motion"]) >= 2) & ~(np.asarray(w["feed"], float) > 0) & (np.asarray(w["distance"]) > 0)
    w["time"] = np.where(unknown, np.nan, w["time"])
    op.plan = (moves.planned() if isinstance(moves, PlannerMoves) else moves, result)
    op._elapsed = None


def waypoint_speeds(op: "Operation") -> dict[str, np.ndarray]:
    """Planned ``start_v`` (first move's entry), ``cruise_v`` (fastest cruise),
    ``end_v`` (last move's exit) and ``accel`` of every waypoint, mm/s and mm/s^2."""
    moves, result = op.plan
    n = op.waypoints["x"].size
    out = {k: np.zeros(n) for k in ("start_v", "cruise_v", "end_v", "accel")}
    if len(moves):
        first = np.r_[True, moves.waypoint[1:] != moves.waypoint[:-1]]
        last = np.r_[moves.waypoint[1:] != moves.waypoint[:-1], True]
        out["start_v"][moves.waypoint[first]] = result.start_v[first]
        out["end_v"][moves.waypoint[last]] = result.end_v[last]
        np.maximum.at(out["cruise_v"], moves.waypoint, result.cruise_v)
        out["accel"][moves.waypoint[first]] = result.accel[first]
    return out
