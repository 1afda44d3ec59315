"""Emulate stage: work coordinate systems and the G92/G52 offset, as LinuxCNC keeps them.

A program point reaches the machine as ``rotate(program + G92, R) + G5x +
tool`` (see :class:`~gcodekit.emulate.state.MachineState`).  Each work system G54..G59.3
has stored offsets and an XY rotation R (LinuxCNC's #5221-#5390); the one
selected brings its stored values into force.  The G92 offset (G52 writes
it too) is kept in force and stored (#5211..), so G92.2 can suspend it and
G92.3 bring it back.

When a frame changes, rs274 works out its new idea of the current point
itself, and that is what the next move starts from: these functions keep
that point as the program position (``keep_program_position``), so the
machine only moves on the next move, wherever rs274's arithmetic differs
from the machine's true position (a rotation change with a G92 offset on).

The frame arithmetic takes the state and values in mm (degrees for
rotations and rotary axes) by axis index; the handlers at the end read the
blocks (G54-G59.3, G92 family, G52, G10).
"""

from __future__ import annotations

from ..state import MachineState, rotate_xy
from .registry import Block, Context, handles
from .tools import set_tool_data
from .words import axis_values


def select(s: MachineState, index: int) -> None:
    """G54..G59.3: work system ``index`` (1..9) comes into force; the machine stays.

    Selecting the system in force changes nothing, as in rs274 (a stored
    offset written since then waits for another selection).
    """
    if index == s.work_offset:
        return
    believed = s.to_machine(s.program_position())  # where rs274 thinks the machine is
    s.select_work_system(index)
    s.keep_program_position(s.to_program(believed))


def set_offsets(s: MachineState, index: int, values: dict[int, float], rotation: float | None) -> None:
    """G10 L2: work system ``index`` stores offsets ``values`` and maybe a new rotation.

    In the system in force all its stored values come into force, and rs274
    turns its idea of the current point with the rotation, leaving out the
    G92 offset (LinuxCNC's tests/interp coord-rotation-xy keeps that too).
    """
    old_offset, old_rotation = s.frame.copy(), s.rotation
    program = s.program_position()
    for ax, value in values.items():
        s.work_offsets[index, ax] = value
    if rotation is not None:
        s.rotations[index] = rotation
    if index == s.work_offset:
        s.select_work_system(index)
        moved = old_offset - s.frame
        s.keep_program_position(rotate_xy(rotate_xy(program, old_rotation) + moved, -s.rotation))


def touch_off(s: MachineState, index: int, values: dict[int, float]) -> None:
    """G10 L20: work system ``index`` moves so the current point has coordinates ``values`` in it.

    Axes without a word keep their coordinate in that system, so under a
    rotation an X word alone moves the system's origin in X and Y.
    """
    believed = s.to_machine(s.program_position())
    rotation = float(s.rotations[index])
    program = rotate_xy(believed - s.work_offsets[index] - s.tool_offset, -rotation) - s.g92  # in that system
    for ax, value in values.items():
        program[ax] = value
    s.work_offsets[index] = believed - s.tool_offset - rotate_xy(program + s.g92, rotation)
    if index == s.work_offset:
        s.select_work_system(index)
        s.keep_program_position(program)


def set_axis_offset(s: MachineState, values: dict[int, float]) -> None:
    """G92: the G92 offset changes so the current point has coordinates ``values``.

    The offset sits before the rotation: it is worked out in the unturned
    frame, and the tool offset stays out of it.
    """
    program = s.program_position()
    for ax, value in values.items():
        s.g92[ax] = program[ax] + s.g92[ax] - value
    if values:
        s.g92_stored, s.g92_on = s.g92.copy(), True


def set_local_offset(s: MachineState, values: dict[int, float]) -> None:
    """G52: LinuxCNC keeps the local offset in the G92 offset, set outright."""
    for ax, value in values.items():
        s.g92[ax] = value
    s.g92_stored, s.g92_on = s.g92.copy(), True


def clear_axis_offset(s: MachineState) -> None:
    """G92.1: the G92 offset is zero, stored too."""
    s.g92[:] = 0.0
    s.g92_stored[:] = 0.0
    s.g92_on = False


def suspend_axis_offset(s: MachineState) -> None:
    """G92.2: the G92 offset is out of force; the stored one stays for G92.3."""
    s.g92[:] = 0.0
    s.g92_on = False


def restore_axis_offset(s: MachineState) -> None:
    """G92.3: the stored G92 offset (perhaps written as #5211..) comes into force."""
    s.g92, s.g92_on = s.g92_stored.copy(), True


# -- the blocks ----------------------------------------------------------------------


@handles(*(f"work_offset_{k}" for k in range(1, 10)))
def select_work_system(ctx: Context, block: Block) -> None:
    """G54..G59.3."""
    select(ctx.state, int(block.name.rsplit("_", 1)[1]))


@handles("set_position")
def set_position(ctx: Context, block: Block) -> None:
    """G92: offset the axes so the current point has the given coordinates (and E, on printers)."""
    s, params = ctx.state, block.params
    values = axis_values(s, params)
    if not values and "E" not in params and ctx.config.home_mode == "stored":
        ctx.error(block.line, "G92 needs at least one axis word")
    set_axis_offset(s, values)
    if "E" in params:
        s.e_program = params["E"] * s.units


@handles("clear_position_offset")
def clear_position_offset(ctx: Context, block: Block) -> None:
    """G92.1."""
    clear_axis_offset(ctx.state)


@handles("suspend_position_offset")
def suspend_position_offset(ctx: Context, block: Block) -> None:
    """G92.2."""
    suspend_axis_offset(ctx.state)


@handles("restore_position_offset")
def restore_position_offset(ctx: Context, block: Block) -> None:
    """G92.3."""
    restore_axis_offset(ctx.state)


@handles("local_offset")
def local_offset(ctx: Context, block: Block) -> None:
    """G52."""
    set_local_offset(ctx.state, axis_values(ctx.state, block.params))


@handles("coordinate_data")
def coordinate_data(ctx: Context, block: Block) -> None:
    """G10: L2/L20 set a work offset, L1/L10/L11 a tool's offsets (LinuxCNC 2.9)."""
    s, params, line = ctx.state, block.params, block.line
    mode = int(params.get("L", -1))
    if mode in (1, 10, 11):
        set_tool_data(ctx, mode, params)
        return
    if mode not in (2, 20):
        ctx.error(line, "G10 needs L1, L2, L10, L11 or L20")
        return
    index = int(params.get("P", 0)) or s.work_offset
    if not 1 <= index <= 9:
        ctx.error(line, f"G10 L{mode} P must be 0 to 9")
    elif mode == 20 and "R" in params:
        ctx.error(line, "R not allowed in G10 L20")
    elif mode == 2:
        set_offsets(s, index, axis_values(s, params), params.get("R"))
    else:
        touch_off(s, index, axis_values(s, params))
