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
from typing import TYPE_CHECKING, Any, Iterator, Mapping

import numpy as np

from ..columns import Column, RunColumn, stored
from ..errors import ConfigError, did_you_mean
from .moves import PlannedMoves, PlannerMoves, PlanResult
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
    ``time`` replaces the waypoints' ``time`` column and ``moves``/``result``
    stay as ``op.plan``, from which :func:`waypoint_speeds` reads each
    waypoint's entry, cruise and exit speed.
    """

    time: np.ndarray
    moves: PlannedMoves
    result: PlanResult | TrapezoidPlan


def run_planner(program: "EmulatedProgram", name: str, settings) -> Plan:
    """Plan an emulated program with planner ``name``; the program is not changed."""
    module = importlib.import_module(PLANNERS[name][0])
    moves, result = module.plan(program, settings)
    return Plan(waypoint_times(program.waypoints, moves, result),
                moves.planned() if isinstance(moves, PlannerMoves) else moves, result)


def waypoint_times(w: Mapping[str, np.ndarray], moves: PlannerMoves | PlannedMoves,
                   result: PlanResult | TrapezoidPlan) -> np.ndarray:
    """Per-waypoint planned time from per-move results.

    A waypoint's time is the sum of its moves' durations; a waypoint that
    moves without a planned move (a move to where the tool already is) takes
    none, and one that does not move (a dwell) keeps its own.  A feed move
    with no feed rate in force gets NaN: its time is unknown, not the
    planner's crawl at its minimum speed, unless the emulator timed it too
    (RepRapFirmware takes F0 as written and does crawl at M203 I); a move
    planned at no speed (an infinite time) gets NaN as well.
    """
    n = len(stored(w, "x"))
    times = np.zeros(n)
    waypoint = moves.waypoint
    for sel in _whole_waypoints(waypoint):  # a block of moves at a time: no array of every move's duration
        first = int(waypoint[sel].min())
        summed = np.bincount(waypoint[sel] - first, weights=result.durations(sel))  # each in move order
        times[first:first + summed.size] = summed
    has_moves = np.zeros(n, bool)
    has_moves[moves.waypoint] = True
    # the columns read a block of waypoints at a time: those kept as runs stay so, no column is copied whole
    motion, distance, time, feed = (stored(w, k) for k in ("motion", "distance", "time", "feed"))
    for lo in range(0, n, 1 << 16):
        sl = slice(lo, min(lo + (1 << 16), n))
        block_motion, block_time, block_times = np.asarray(motion[sl]), np.asarray(time[sl], float), times[sl]
        idle = ~has_moves[sl]
        block_times[idle] = np.where(block_motion[idle] > 0, 0.0, block_time[idle])
        # a feed move with no feed in force has no time a planner could know (its minimum speed is no
        # answer) where the emulator knew none either; nor has a move a planner gave no speed at all (a
        # printer's G0 at F0): unknown, as the emulator has it.  The emulator times F0 where the firmware
        # moves at a minimum speed it knows (RepRapFirmware's M203 I), and then the planner's crawl is the
        # firmware's.
        unknown = (block_motion >= 2) & ~(np.asarray(feed[sl], float) > 0) & (np.asarray(distance[sl]) > 0)
        unknown &= ~np.isfinite(block_time)
        block_times[unknown] = np.nan
    times[np.isinf(times)] = np.nan
    return times


def times_every_move(name: str) -> bool:
    """Whether planner ``name`` times every move itself, reading the emulator's times only where nothing
    moves and where they are unknown (its module's ``TIMES_EVERY_MOVE``; see :func:`times_to_plan`)."""
    return bool(getattr(importlib.import_module(PLANNERS[name][0]), "TIMES_EVERY_MOVE", False))


def times_to_plan(w: Mapping[str, np.ndarray]) -> Column:
    """The emulator's ``time`` column as a planner that times every move reads it (:func:`times_every_move`).

    Such a plan gives every moving waypoint its time (:func:`waypoint_times`),
    so the emulator's finite times of moves are dropped (as 0) and what stays
    is the time of each waypoint that does not move (a dwell) and the NaN of
    each move the emulator could not time: on a print, a few runs instead of
    25 MB of times the plan replaces, freed before the planner's own arrays.
    """
    time = np.asarray(w["time"], float)
    replaced = (np.asarray(w["motion"]) > 0) & np.isfinite(time)
    return RunColumn.encode(np.where(replaced, 0.0, time))


def _whole_waypoints(waypoint: np.ndarray, size: int = 1 << 16) -> Iterator[slice]:
    """Blocks of about ``size`` moves, each holding all the moves of its waypoints (one block when the
    moves are not in waypoint order)."""
    m = waypoint.size
    if m and not (waypoint[1:] >= waypoint[:-1]).all():
        yield slice(0, m)
        return
    lo = 0
    while lo < m:
        hi = min(lo + size, m)
        if hi < m:  # cut before the waypoint the block would split, or after it when it fills the block
            cut = int(np.searchsorted(waypoint, waypoint[hi], "left"))
            hi = cut if cut > lo else int(np.searchsorted(waypoint, waypoint[hi], "right"))
        yield slice(lo, hi)
        lo = hi


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
