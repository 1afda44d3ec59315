"""Emulate stage: canned cycles (G73, G74, G81-G89), the G76 threading cycle and spindle-synchronized
moves (G33, G33.1): blocks whose moves the machine works out, each move a waypoint."""

from __future__ import annotations

from ...parse.table import MOTION_CYCLE, MOTION_LINEAR, MOTION_RAPID
from ..cycles import CYCLES, TAPPING, run_cycle
from ..state import AXES
from ..threading import ThreadingError, check_words, threading_moves
from .registry import CANNED_CYCLE, SYNCHRONIZED, Block, Context, Outcome, Waypoint, handles
from .words import move_to, program_target

#: What a spindle-synchronized move at no speed does (rs274 accepts it; the machine waits forever).
STALLS = ": the tool waits on the spindle and the move never ends (a controller stalls); its time is unknown"

#: Canned cycles rs274 refuses with the spindle stopped (with its spelling of each code)
_SPINDLE_CYCLES = {"cycle_tap_left": "G74", "cycle_tap": "G84", "cycle_bore_stop": "g86", "cycle_back_bore": "g87",
                   "cycle_bore_manual": "g88"}


@handles(CANNED_CYCLE)
def canned_cycle(ctx: Context, block: Block) -> Outcome | None:
    """A block in a canned-cycle mode, named or axis words alone: its moves (see :mod:`gcodekit.emulate.cycles`)."""
    s, mode, name = ctx.state, ctx.cycle_mode, block.name
    in_mode = int(block.table.motion[block.row - 1]) == MOTION_CYCLE if block.row else mode.open
    if not in_mode:
        s.cycle.initial = None  # the cycle mode begins here
    same_mode = in_mode and name in ("", mode.name)  # rs274: motion_mode == motion
    mode.name = name or mode.name
    unit = 0.001 if ctx.config.dwell_p_unit == "ms" else 1.0
    try:
        if ctx.rs274_blocks:
            _check_cycle_conditions(ctx, mode.name)
        steps, end = run_cycle(name if name in CYCLES else "", block.params, s.cycle, program=s.program_position(),
                               to_machine=s.to_machine, scale=s.scale(), plane=s.plane, incremental=s.incremental,
                               dwell_unit=unit, same_mode=same_mode or not ctx.rs274_blocks, budget=ctx.budget)
    except ValueError as exc:
        ctx.error(block.line, str(exc))
        return None
    if not steps:
        return None
    if s.cycle.name in TAPPING and s.plane != 17:
        ctx.warn_once("tapping outside G17", block.line, f"G74/G84 in G{s.plane}: the feeds move as LinuxCNC 2.9 "
                      "sends them, with the axes mixed up (see gcodekit.emulate.cycles)")
    passed = [Waypoint({**dict(zip(AXES.lower(), st.point)), "motion": st.motion, "dwell": st.dwell})
              for st in steps[:-1]]
    s.position = steps[-1].point.copy()
    # rs274 takes the tool to end at `end` (see cycles.TAPPING): kept after the block
    return Outcome(steps[-1].motion, passed, dwell=steps[-1].dwell, believed=end)


def _check_cycle_conditions(ctx: Context, name: str) -> None:
    """rs274 2.9's conditions on the machine for a canned cycle (raises ValueError with its message)."""
    s = ctx.state
    if s.feed <= 0:
        raise ValueError("Cannot feed with zero feed rate")
    if s.feed_mode == "inverse_time":
        raise ValueError("Cannot use inverse time feed with canned cycles")
    if s.compensating:
        raise ValueError("Cannot use canned cycles with cutter compensation on")
    code = _SPINDLE_CYCLES.get(name)
    if code and s.spindle == 0:
        raise ValueError(f"Spindle not turning in {code}")
    if name == "cycle_tap" and s.spindle < 0:
        raise ValueError("Spindle turning counterclockwise in G84")
    if name == "cycle_tap_left" and s.spindle > 0:
        raise ValueError("Spindle turning clockwise in G74")


@handles("cycle_thread")
def threading_cycle(ctx: Context, block: Block) -> Outcome | None:
    """G76 (or axis words alone after one): the passes of a threading cycle (see :mod:`gcodekit.emulate.threading`)."""
    s, params = ctx.state, block.params
    ctx.cycle_mode.name = "cycle_thread"
    try:
        check_words(params, s.compensating)
    except ThreadingError as exc:
        ctx.error(block.line, str(exc))
        return None
    if ctx.rs274_blocks and (s.spindle == 0 or s.speed <= 0):
        ctx.error(block.line, "Chosen spindle (0) not turning in G76")
        return None
    if s.spindle == 0 or s.speed <= 0 or params["P"] == 0:
        ctx.diagnostics.warn(block.line, 1, ("G76 with a pitch of P0" if params["P"] == 0 else
                                             "G76 with the spindle stopped") + STALLS)
    k = s.units
    halve = 2.0 if s.diameter else 1.0  # I, J and K are diameters in G7 (X words are already radii)
    program = s.program_position()
    end = program_target(s, params, "XZ")
    moves = threading_moves((program[0], program[2]), end[2], p=params["P"] * k, i=params["I"] * k / halve,
                            j=params["J"] * k / halve, k=params["K"] * k / halve, q=params.get("Q", 0.0),
                            h=int(params.get("H", 0)), r=params.get("R", 1.0), e=params.get("E", 0.0) * k,
                            taper=int(params.get("L", 0)), budget=ctx.budget)
    steps = []
    for kind, x, z, pitch in moves + [("rapid", end[0], end[2], None)]:
        point = program.copy()
        point[0], point[2] = x, z
        values = {**dict(zip(AXES.lower(), s.to_machine(point))), "motion": MOTION_RAPID}
        if pitch is not None:  # synchronized with the spindle: pitch per revolution
            values.update(motion=MOTION_LINEAR, feed=pitch * s.speed)
        steps.append(Waypoint(values))
    s.position = s.to_machine(end)
    return Outcome(MOTION_RAPID, steps[:-1])


@handles(SYNCHRONIZED)
def synchronized_move(ctx: Context, block: Block) -> Outcome | None:
    """A block in G33 or G33.1 mode: a move at K units per spindle revolution.

    G33 is a straight move; G33.1 (a rigid tap) goes to the bottom and
    returns at the same pitch, so its waypoint is back where it started.
    """
    name = block.name
    rigid = name == "rigid_tap" or (not name and ctx.cycle_mode.thread == "rigid_tap")
    ctx.cycle_mode.thread = "rigid_tap" if rigid else "thread"
    rate = _synchronized_rate(ctx, block, "G33.1" if rigid else "G33")
    if rate is None:
        return None
    s = ctx.state
    if rigid:
        bottom = s.to_machine(program_target(s, block.params, "XYZ"))
        return Outcome(MOTION_LINEAR, [Waypoint({**dict(zip(AXES.lower(), bottom)), "motion": MOTION_LINEAR,
                                                 "feed": rate})], feed=rate)
    move_to(s, program_target(s, block.params), block.params)
    return Outcome(MOTION_LINEAR, feed=rate)


def _synchronized_rate(ctx: Context, block: Block, code: str) -> float | None:
    """Feed (mm/min) of a G33/G33.1 move, K units per spindle revolution; None (reported) if rs274 refuses it."""
    s, params = ctx.state, block.params
    problem = ("K word missing with g33/g33.1" if "K" not in params else
               "F word used with a g33/g33.1" if "F" in params else
               f"Spindle not turning in {code}" if s.spindle == 0 or s.speed <= 0 else "")
    if problem:
        ctx.error(block.line, problem)
        return None
    if params["K"] == 0:  # rs274 accepts it
        ctx.diagnostics.warn(block.line, 1, f"{code} with a pitch of K0" + STALLS)
    return params["K"] * s.scale()[2] * s.speed
