"""Emulate stage: work coordinate systems and the G92/G52 offset, as LinuxCNC keeps them.

A program point reaches the machine as ``rotate(program + G92, R) + G5x +
tool`` (see :class:`~.state.MachineState`).  Each work system G54..G59.3
has stored offsets and an XY rotation R (LinuxCNC's #5221-#5390); the one
selected brings its stored values into force.  The G92 offset (G52 writes
it too) is kept in force and stored (#5211..), so G92.2 can suspend it and
G92.3 bring it back.

When a frame changes, rs274 works out its new idea of the current point
itself, and that is what the next move starts from: these functions keep
that point as the program position (``keep_program_position``), so the
machine only moves on the next move, wherever rs274's arithmetic differs
from the machine's true position (a rotation change with a G92 offset on).

All values are mm (degrees for rotations and rotary axes), by axis index.
"""

from __future__ import annotations

from .state import MachineState, rotate_xy


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
