"""Emulate stage: the modes a block switches: units, distance modes, planes, feed modes and the like.

None of these moves the tool; each sets how later words are read.
"""

from __future__ import annotations

from ...units import MM_PER_INCH
from .registry import Block, Context, handles

#: Said once where firmware that sets its feed only from an F above 0 (Marlin; Klipper outside G0-G3) meets
#: F0 or below.
FEED_AT_OR_BELOW_ZERO = "F at or below 0 sets no feed rate on this firmware: it keeps the one it had"
#: mm per program unit after G20 / G21
UNITS = {"units_inch": MM_PER_INCH, "units_mm": 1.0}
_FEED_MODES = {"feed_inverse_time": "inverse_time", "feed_per_minute": "per_minute", "feed_per_rev": "per_rev"}
#: Switches that only set one state attribute: name -> (attribute, value)
_SETTINGS = {
    "arc_distance_absolute": ("arc_incremental", False), "arc_distance_incremental": ("arc_incremental", True),
    "plane_xy": ("plane", 17), "plane_zx": ("plane", 18), "plane_yz": ("plane", 19),
    "polar_on": ("polar", True), "polar_off": ("polar", False),
    "diameter_mode": ("diameter", True), "radius_mode": ("diameter", False),
}


@handles(*UNITS)
def units(ctx: Context, block: Block) -> None:
    """G20/G21: program units from here."""
    s, value = ctx.state, UNITS[block.name]
    if ctx.config.units_keep_feed:
        s.feed *= value / s.units  # the same F number in the new units
    if ctx.rs274_blocks:
        s.cycle.keep_numbers(value / s.units)
    s.units = value


@handles("distance_absolute", "distance_incremental")
def distance_mode(ctx: Context, block: Block) -> None:
    """G90/G91, and on firmware that ties them (``distance_mode_sets_extrusion``) the extruder's mode too."""
    incremental = block.name == "distance_incremental"
    ctx.state.incremental = incremental
    if ctx.config.distance_mode_sets_extrusion:
        ctx.state.e_relative = incremental


@handles(*_FEED_MODES)
def feed_mode(ctx: Context, block: Block) -> None:
    """G93/G94/G95: how F is read."""
    ctx.state.feed_mode = _FEED_MODES[block.name]
    if ctx.rs274_blocks and "F" not in block.params:
        ctx.state.feed = 0.0  # rs274 2.9: G93, G94 and G95 zero the feed rate (an F in the block is set after)


@handles(*_SETTINGS)
def setting(ctx: Context, block: Block) -> None:
    """G90.1/G91.1, G17-G19, G15/G16, G7/G8: one state attribute each."""
    attribute, value = _SETTINGS[block.name]
    setattr(ctx.state, attribute, value)


@handles("retract_initial", "retract_r")
def cycle_retract(ctx: Context, block: Block) -> None:
    """G98/G99: canned cycles retract to the initial level or to R."""
    ctx.state.cycle.retract_to_r = block.name == "retract_r"


@handles("cutter_comp_off", "cutter_comp_left", "cutter_comp_right", "cutter_comp_left_dynamic",
         "cutter_comp_right_dynamic")
def cutter_compensation(ctx: Context, block: Block) -> None:
    """G40-G42.1: the side the path is offset to (a later pass offsets it, see ``compensation``)."""
    ctx.state.compensating = block.name != "cutter_comp_off"
    ctx.state.compensating_left = block.name.startswith("cutter_comp_left")


@handles("program_end")
def program_end(ctx: Context, block: Block) -> None:
    """M2/M30: LinuxCNC resets these modes and stops reading the program."""
    s = ctx.state
    s.select_work_system(1)
    s.plane, s.incremental, s.feed_mode = 17, False, "per_minute"
    s.spindle, s.coolant, s.compensating = 0, 0, False
    s.ended = True
