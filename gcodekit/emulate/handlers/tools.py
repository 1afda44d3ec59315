"""Emulate stage: tools: selection (T), change (M6), length offsets (G43 family, G49), tool data (G10 L1/L10/L11)."""

from __future__ import annotations

import numpy as np

from ...syntax import load_flavor
from ..state import AXES, rotate_xy
from ..tooltable import Tool
from .registry import T_WORD, Block, Context, handles

#: Largest tool number: the tool column is 32-bit, as LinuxCNC's tool numbers are C ints.
MAX_TOOL = 2**31 - 1


def _in_range(ctx: Context, number: int, line: int) -> bool:
    """A tool number the machine can hold; else rs274's message (interp_read.cc read_t)."""
    if 0 <= number <= MAX_TOOL:
        return True
    ctx.error(line, "Negative tool id used" if number < 0 else
              f"Tool number {number} out of range (at most {MAX_TOOL})")
    return False


def check_tool(ctx: Context, number: int, line: int) -> None:
    """With a tool table, selecting a tool it lacks is LinuxCNC's error (T0, no tool, is fine);
    without one, a mill's tools have no length or diameter, which is said once."""
    config = ctx.config
    if number and config.tool_table and number not in ctx.tools:
        ctx.error(line, f"Requested tool {number} not found in the tool table")
    elif number and not config.tool_table and config.process != "additive" and _reads_tool_lengths(config.flavor):
        consequence = ("LinuxCNC refuses a tool its table lacks" if config.flavor == "rs274ngc"
                       else "the control's own offsets are not known here")
        ctx.warn_once("no tool table", line, f"no tool table: tool {number} (and every other) is taken to have no "
                      f"length or diameter; {consequence} (give the machine a tool_table)")


def _reads_tool_lengths(flavor: str) -> bool:
    """Whether the machine's dialect applies a tool table's lengths (G43); GRBL's has no table."""
    return "tool_length_offset" in load_flavor(flavor).codes.values()


@handles(T_WORD)
def select_tool(ctx: Context, block: Block) -> None:
    """A T word: the tool the next M6 changes to (on firmware with ``tool_change_on: T``, the change itself)."""
    s = ctx.state
    number = int(round(block.table.number[block.row] / 10))
    if not _in_range(ctx, number, block.line):
        return
    check_tool(ctx, number, block.line)
    if ctx.config.tool_change_on == "T":
        s.tool = number
    s.selected_tool = number


@handles("tool_change")
def change_tool(ctx: Context, block: Block) -> None:
    """M6: the selected tool (or the block's T: ``T1 M6``) goes into the spindle."""
    s, params = ctx.state, block.params
    ctx.tool_change_line = block.line
    if not _in_range(ctx, int(params.get("T", 0)), block.line):
        return
    if "T" in params:
        check_tool(ctx, int(params["T"]), block.line)
    s.selected_tool = int(params.get("T", s.selected_tool))
    s.tool = s.selected_tool
    if ctx.rs274_blocks:
        s.spindle = 0  # rs274 stops the spindle for the change (a G86 after M6 is refused)
        if ctx.config.standalone_canon:  # it re-reads its position (see standalone_canon)
            s.keep_program_position(s.canon_point - s.frame - s.g92)


def held_tool_offset(ctx: Context) -> np.ndarray:
    """The tool length offset (mm) the interpreter holds: with ``standalone_canon``, after G20/G21
    the numbers it was set with, read in the units now in force."""
    s = ctx.state
    if ctx.config.standalone_canon:
        return s.tool_offset * (s.units / s.tool_offset_units)
    return s.tool_offset


def change_tool_offset(ctx: Context, offset, keep_program_position: bool = False) -> None:
    """A new tool length offset; the program position moves by the held offset's change (rs274's
    ``current += old - new``, turned into the program frame), which the next move reaches when the
    held one was stale."""
    s = ctx.state
    held = held_tool_offset(ctx)
    if keep_program_position or not np.any(held != s.tool_offset):
        s.change_tool_offset(offset, keep_program_position)
        return
    believed = s.program_position() + rotate_xy(held - np.asarray(offset, float), -s.rotation)
    s.change_tool_offset(offset)
    s.keep_program_position(believed)


@handles("tool_length_offset", "tool_length_offset_add")
def tool_length_offset(ctx: Context, block: Block) -> None:
    """G43 (H's offsets, or the tool's) and G43.2 (added to those in force)."""
    s, line = ctx.state, block.line
    number = block.params.get("H", s.tool)
    if not 0 <= number <= MAX_TOOL:  # rs274: a negative H is refused too
        ctx.error(line, f"H word {number:.0f} out of range (0 to {MAX_TOOL})")
        return
    if not ctx.config.tool_table:
        check_tool(ctx, int(number), line)
    offset = ctx.tools.offset(int(number))
    # rs274 re-reads its position after a tool change, so a G43 in the
    # M6 block keeps the program position; elsewhere the machine stays.
    change_tool_offset(ctx, offset if block.name == "tool_length_offset" else held_tool_offset(ctx) + offset,
                       keep_program_position=line == ctx.tool_change_line)


@handles("tool_length_offset_dynamic")
def dynamic_tool_length_offset(ctx: Context, block: Block) -> None:
    """G43.1: the offsets of the axes it names; the others keep theirs."""
    scale, held = ctx.state.scale(), held_tool_offset(ctx)
    change_tool_offset(ctx, [block.params[letter] * scale[ax] if letter in block.params else held[ax]
                             for ax, letter in enumerate(AXES)])


@handles("cancel_tool_length")
def cancel_tool_length(ctx: Context, block: Block) -> None:
    """G49: no tool length offset."""
    change_tool_offset(ctx, np.zeros(6))


def set_tool_data(ctx: Context, mode: int, params: dict[str, float]) -> None:
    """G10 L1/L10/L11: tool P's offsets as given (L1), or so the current point has the given
    coordinates with them (L10 in the work system in force, L11 in G59.3); R and Q its radius and
    orientation."""
    s = ctx.state
    scale = s.scale()
    number = int(params.get("P", 0))
    tool = ctx.tools.setdefault(number, Tool(number))
    for ax, letter in enumerate(AXES):
        if letter not in params:
            continue
        value = params[letter] * scale[ax]
        if mode == 1:
            tool.offset[ax] = value
        else:  # the current point would have coordinate `value` with this tool's offset
            system = s.work_offsets[9] if mode == 11 else s.frame
            g92 = 0.0 if mode == 11 else s.g92[ax]
            tool.offset[ax] = s.position[ax] - system[ax] - g92 - value
    if "R" in params:
        tool.diameter = 2 * params["R"] * s.units
    if "Q" in params:
        tool.orientation = int(params["Q"])
