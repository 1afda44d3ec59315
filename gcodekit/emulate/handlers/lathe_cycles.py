"""Emulate stage: LinuxCNC's lathe cycles (G70-G72) and the axis words alone that follow one."""

from __future__ import annotations

import numpy as np

from ...parse.table import MOTION_CCW, MOTION_CW, MOTION_LINEAR, MOTION_NONE, MOTION_RAPID
from ..arcs import PLANES, centres, reach_tolerance
from ..lathe import CycleBlock, LatheCycleError, Move, run_lathe_cycle
from ..state import AXES
from .registry import AFTER_LATHE_CYCLE, LATHE_CYCLE, Block, Context, Outcome, Waypoint, handles
from .words import move_to, program_target


@handles(LATHE_CYCLE)
def lathe_cycle(ctx: Context, block: Block) -> Outcome | None:
    """G70-G72: the moves of a lathe cycle (see :mod:`gcodekit.emulate.lathe`); axis words alone
    after it move in the mode of its last move."""
    ctx.cycle_mode.name = block.name
    outcome = _moves(ctx, block)
    ctx.cycle_mode.lathe_motion = MOTION_NONE if outcome is None else outcome.motion
    return outcome


def _moves(ctx: Context, block: Block) -> Outcome | None:
    """The cycle's moves as waypoints, the last one the block's own; None (reported) if it is refused."""
    s, line = ctx.state, block.line
    program = s.program_position()
    cycle = CycleBlock(block.name, block.params, block.command.profile, complex(program[2], program[0]),
                       s.units, s.incremental, s.arc_incremental, s.diameter, s.plane, s.compensating)
    try:
        point, moves, profile_end = run_lathe_cycle(cycle, ctx.budget)
    except LatheCycleError as exc:
        ctx.error(line, str(exc))
        return None
    if s.compensating:
        end = program.copy()
        end[[0, 2]] = profile_end.imag, profile_end.real
        ctx.comp_profile_ends.append((line, s.to_machine(end)[:3]))
    here = program.copy()
    steps = []
    kinds = {"rapid": MOTION_RAPID, "feed": MOTION_LINEAR}
    for move in [Move("rapid", point)] + moves:
        end = program.copy()
        end[[0, 2]] = move.end.imag, move.end.real
        values = dict(zip(AXES.lower(), s.to_machine(end)))
        if move.kind == "arc":
            if abs(end[0] - here[0]) < 1e-4 and abs(end[2] - here[2]) < 1e-4:
                continue  # rs274 skips an arc that ends where it starts
            centre = end.copy()
            centre[[0, 2]] = move.centre.imag, move.centre.real
            centre = s.to_machine(centre)
            values.update(motion=MOTION_CCW if move.ccw else MOTION_CW, cx=centre[0], cy=np.nan, cz=centre[2])
        else:
            values["motion"] = kinds[move.kind]
        steps.append(Waypoint(values))
        here = end
    last = steps[-1].values
    s.position = np.array([last[k] for k in AXES.lower()])
    return Outcome(int(last["motion"]), steps[:-1], centre=tuple(last.get(k, np.nan) for k in ("cx", "cy", "cz")))


@handles(AFTER_LATHE_CYCLE)
def after_lathe_cycle(ctx: Context, block: Block) -> Outcome | None:
    """Axis words alone after G70-G72: a move in the mode of the cycle's last move (rs274's
    ``motion_mode`` after the cycle ran its moves through ``convert_straight``/``convert_arc``)."""
    s, params = ctx.state, block.params
    motion = ctx.cycle_mode.lathe_motion
    arc = motion in (MOTION_CW, MOTION_CCW)
    if arc and not any(k in params for k in "IJKR"):
        ctx.error(block.line, "R i j k words all missing for arc")
        return None
    before = s.program_position()
    move_to(s, program_target(s, params), params)
    centre = _arc_centre(ctx, before, params, motion == MOTION_CW, block.line) if arc else (np.nan,) * 3
    return Outcome(motion or MOTION_LINEAR, centre=centre)


def _arc_centre(ctx: Context, before: np.ndarray, params: dict[str, float], clockwise: bool, line: int) -> tuple:
    """Centre (machine X Y Z, the plane's normal NaN) of an arc from program point ``before`` to the
    position, by I/J/K or R."""
    s = ctx.state
    (f, g, h), (l1, l2) = PLANES[s.plane]
    after = s.program_position()
    p0, p1 = before[[f, g]], after[[f, g]]
    words = np.array([[params.get(l1, np.nan), params.get(l2, np.nan)]]) * s.units
    radius = np.array([params.get("R", np.nan) * s.units])
    in_plane, short = centres(p0[None], p1[None], words, radius, np.array([clockwise]), s.arc_incremental)
    if short[0] > reach_tolerance(s.units):
        ctx.error(line, "arc radius too small to reach the end point")
    centre = after.copy()
    centre[[f, g]] = in_plane[0]
    centre = s.to_machine(centre)[:3]
    centre[h] = np.nan
    return tuple(centre)
