"""Emulate stage: stored positions and machine coordinates: G28/G30, G28.1/G30.1 and G53."""

from __future__ import annotations

import numpy as np

from ...parse.table import MOTION_LINEAR, MOTION_RAPID
from ..state import AXES, rotate_xy
from .registry import Block, Context, Outcome, Waypoint, handles
from .tools import held_tool_offset
from .words import program_target


@handles("home", "home_secondary")
def home(ctx: Context, block: Block) -> Outcome:
    """G28/G30: to the stored position, through the point the axis words give.

    With ``home_mode: select`` (printer firmware) the named axes, or X Y Z,
    are set to the stored position without a move through.
    """
    s, params = ctx.state, block.params
    # (a stale tool offset the interpreter holds shifts the machine point it aims at, see standalone_canon)
    stored = (s.home_secondary if block.name == "home_secondary" else s.home) + s.tool_offset - held_tool_offset(ctx)
    given = [ax for ax, letter in enumerate(AXES) if letter in params]
    if ctx.config.home_mode == "select":
        for ax in given or [0, 1, 2]:
            s.position[ax] = stored[ax]
        return Outcome(MOTION_RAPID)
    # rs274 goes through the given point; with no axis words through the current
    # one (a rapid of no length), then every axis goes to the stored position
    program = program_target(s, params, AXES)
    via = s.to_machine(program)
    # the given axes reach the stored position as program coordinates (a rotation mixes X and Y)
    s.position = s.to_machine(np.where(np.isin(np.arange(6), given), s.to_program(stored), program)) \
        if given else stored.copy()
    return Outcome(MOTION_RAPID, [Waypoint({k: v for k, v in zip(AXES.lower(), via)} | {"motion": MOTION_RAPID})])


@handles("store_home", "store_home_secondary")
def store_home(ctx: Context, block: Block) -> None:
    """G28.1/G30.1: the machine point as the interpreter works it out, with the tool offset it holds."""
    s = ctx.state
    stored = s.position + held_tool_offset(ctx) - s.tool_offset
    if block.name == "store_home":
        s.home = stored
    else:
        s.home_secondary = stored


@handles("machine_coordinates")
def machine_move(ctx: Context, block: Block) -> Outcome | None:
    """G53: move to machine coordinates in this block only."""
    s, params, line = ctx.state, block.params, block.line
    if block.motion not in (MOTION_RAPID, MOTION_LINEAR):
        ctx.error(line, "G53 needs G0 or G1 in force")
        return None
    if s.incremental:
        ctx.error(line, "G53 is not allowed in incremental mode (G91)")
    # rs274 (find_ends) works the target out in program coordinates from its own idea of the
    # current point: an axis without a word keeps that point's coordinate in the turned frame
    scale, held, program = s.scale(), held_tool_offset(ctx), s.program_position()
    target = program.copy()
    turned = rotate_xy(program + s.g92, s.rotation)
    for ax, letter in enumerate(AXES):
        if ax < 2:
            turned[ax] = params[letter] * scale[ax] - s.frame[ax] - held[ax] if letter in params else turned[ax]
        elif letter in params:
            target[ax] = params[letter] * scale[ax] - s.frame[ax] - s.g92[ax] - (held[ax] if ax == 2 else 0.0)
    target[:2] = rotate_xy(turned, -s.rotation)[:2] - s.g92[:2]
    s.position = s.to_machine(target)
    return Outcome(block.motion)
