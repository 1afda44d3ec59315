"""Emulate stage: printer firmware's own commands: extrusion modes, flow, firmware retraction and
Klipper's declared position."""

from __future__ import annotations

import re

from ...parse.table import MOTION_LINEAR
from .registry import Block, Context, Outcome, handles


@handles("extrude_absolute", "extrude_relative")
def extrusion_mode(ctx: Context, block: Block) -> None:
    """M82/M83: E words are positions or lengths."""
    ctx.state.e_relative = block.name == "extrude_relative"


@handles("set_flow")
def set_flow(ctx: Context, block: Block) -> None:
    """M221 S: the extrusion multiplier, in percent."""
    ctx.state.flow = block.params.get("S", 100.0) / 100.0


@handles("firmware_retract", "firmware_unretract")
def firmware_retraction(ctx: Context, block: Block) -> Outcome | None:
    """G10/G11 on a printer: an extruder-only move of the configured length.

    Nothing happens when the machine has no retraction configured or is
    already in that state.  The modal feed is kept (Klipper restores its
    G-code state after).
    """
    s, c = ctx.state, ctx.config
    retract = block.name == "firmware_retract"
    if c.retract_length <= 0 or s.retracted == retract:
        return None
    s.retracted = retract
    length = c.retract_length if retract else -(c.retract_length + c.unretract_extra_length)
    speed = c.retract_speed if retract else c.unretract_speed
    de = -length * s.flow
    s.e_total += de
    return Outcome(MOTION_LINEAR, de=de, feed=speed * 60.0, axes_move=False)


@handles("set_kinematic_position")
def set_kinematic_position(ctx: Context, block: Block) -> None:
    """Klipper's SET_KINEMATIC_POSITION X=.. Y=.. Z=..: the toolhead is declared there."""
    for key, value in re.findall(r"\b([XYZ])\s*=\s*([-+]?[0-9.]+)", block.command.text.upper()):
        ctx.state.position["XYZ".index(key)] = float(value)
