"""Emulate stage: what works on the part besides the tool's motion: spindle, coolant, laser and deposition."""

from __future__ import annotations

from ...parse.calls import call_bead_area
from .registry import Block, Context, handles

_DIRECTIONS = {"spindle_cw": 1, "spindle_ccw": -1, "spindle_off": 0}


@handles(*_DIRECTIONS)
def spindle(ctx: Context, block: Block) -> None:
    """M3/M4/M5, with the block's S as the speed."""
    ctx.state.spindle = _DIRECTIONS[block.name]
    ctx.state.speed = block.params.get("S", ctx.state.speed)


@handles("coolant_mist", "coolant_flood", "coolant_off")
def coolant(ctx: Context, block: Block) -> None:
    """M7/M8 switch mist and flood on (both may be on), M9 both off."""
    s = ctx.state
    s.coolant = {"coolant_mist": s.coolant | 1, "coolant_flood": s.coolant | 2, "coolant_off": 0}[block.name]


@handles("laser_on", "laser_off")
def laser(ctx: Context, block: Block) -> None:
    """The heat source of a DED machine (laser or weld arc) on or off."""
    ctx.state.laser = int(block.name == "laser_on")


@handles("deposition_switch")
def deposition_switch(ctx: Context, block: Block) -> None:
    """CEAD's ``EM=1`` / ``EM=0``: material on or off from here."""
    ctx.state.laser = int(block.params.get("value", 1.0) != 0.0)


@handles("set_bead")
def set_bead(ctx: Context, block: Block) -> None:
    """CEAD's ``EXTRUDERSPEED2(w, h, ..)``: a zero bead is the screw at 0 rpm, so no material."""
    area = call_bead_area(block.table.named.get(block.row, ("", ""))[1])
    if area == 0.0:
        ctx.state.laser = 0
