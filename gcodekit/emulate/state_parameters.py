"""Emulate stage: LinuxCNC's parameters that report the machine's state.

A program may read where the tool is and which modes are in force:
``#5420``-``#5428`` and ``#<_x>`` .. ``#<_w>`` (position in program units,
every offset applied), ``#5220`` and ``#<_coord_system>`` (the work
coordinate system), ``#5400`` (the tool in the spindle), ``#5401``-``#5409``
(its length offsets), ``#5410``-``#5413`` (its diameter, front and back
angle, orientation) and the predefined named parameters of LinuxCNC 2.9
(``#<_imperial>``, ``#<_plane>``, ``#<_feed>``, ``#<_rpm>``, ``#<_ccomp>``, ...).  Their
values are those before the reading line runs, as rs274 gives them.

The stored positions and offsets are parameters a program may also write:
``#5161``-``#5166`` (G28's position), ``#5181``-``#5186`` (G30's),
``#5210`` (G92 offset on), ``#5211``-``#5216`` (the G92 offset G92.3 brings
back), and per work system ``#5221``-``#5226`` and ``#5230`` (G54's offsets
and XY rotation), ``#5241``.. (G55) up to ``#5381``.. (G59.3).  As in rs274,
a written work offset comes into force when its system is next selected (or
set by G10 L2), a written G28 position at the next G28.  Lengths are in the
machine's units (rs274's are inches; gcodekit takes the tool table's units),
the U V W slots are ordinary parameters.

With the machine option ``ini_file``, ``#<_ini[SECTION]NAME>`` reads the
INI file's value (read-only; see :mod:`.ini`).

The parameter stage asks :func:`machine_parameter` only after the machine
has run every line before the one reading (see ``gcodekit.pipeline``).

Examples
--------
>>> from gcodekit.emulate.machine import Machine
>>> from gcodekit.emulate.presets import load_machine
>>> m = Machine(load_machine("linuxcnc"))
>>> m.state.position[:3] = (10.0, 5.0, 2.0)
>>> machine_parameter(m, 5420), machine_parameter(m, "_y"), machine_parameter(m, "_metric")
(10.0, 5.0, 1.0)
>>> machine_parameter(m, 100) is None  # an ordinary parameter
True
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Callable

from ..units import MM_PER_INCH

if TYPE_CHECKING:
    from .machine import Machine
    from .state import MachineState

#: ``#<_coord_system>`` of G54 .. G59.3 (work offsets 1 .. 9)
_COORD_SYSTEMS = (540, 550, 560, 570, 580, 590, 591, 592, 593)
#: Axes of ``#5420``.. and ``#<_x>``..; U V W are not emulated and read 0.
_AXES = "xyzabcuvw"


def _position(axis: int) -> Callable[["MachineState"], float]:
    def read(s: "MachineState") -> float:
        return float(s.program_position()[axis] / s.scale()[axis]) if axis < 6 else 0.0
    return read


def _machine_unit(machine: "Machine", axis: int) -> float:
    """mm per machine unit on ``axis``: rs274 gives offsets in machine units (the tool table's), not the program's."""
    return MM_PER_INCH if machine.config.tool_table_units == "inch" and axis < 3 else 1.0


def _tool_offset(axis: int) -> Callable[["Machine"], float]:
    def read(m: "Machine") -> float:
        return float(m.state.tool_offset[axis] / _machine_unit(m, axis)) if axis < 6 else 0.0
    return read


def _stored_slot(key: int | str) -> tuple[str, int | tuple[int, int], int] | None:
    """Where stored parameter ``key`` lives: (state attribute, index, axis); axis -1 for a rotation."""
    if not isinstance(key, int):
        return None
    for first, attribute in ((5161, "home"), (5181, "home_secondary"), (5211, "g92_stored")):
        if first <= key < first + 6:
            return attribute, key - first, key - first
    system, slot = divmod(key - 5221, 20)
    if 0 <= system < 9 and slot < 6:
        return "work_offsets", (system + 1, slot), slot
    if 0 <= system < 9 and slot == 9:
        return "rotations", system + 1, -1
    return None


def _scale(machine: "Machine", axis: int) -> float:
    return _machine_unit(machine, axis) if axis >= 0 else 1.0


def _feed(s: "MachineState") -> float:
    if s.feed != s.feed:  # no F yet
        return 0.0
    return float(s.feed if s.feed_mode == "inverse_time" else s.feed / s.units)


_READERS: dict[int | str, Callable[["MachineState"], float]] = {
    **{5420 + k: _position(k) for k in range(9)},
    **{"_" + a: _position(k) for k, a in enumerate(_AXES)},
    5220: lambda s: float(s.work_offset),
    5400: lambda s: float(s.tool),
    "_coord_system": lambda s: float(_COORD_SYSTEMS[s.work_offset - 1]),
    "_imperial": lambda s: float(s.units != 1.0),
    "_metric": lambda s: float(s.units == 1.0),
    "_absolute": lambda s: float(not s.incremental),
    "_incremental": lambda s: float(s.incremental),
    "_inverse_time": lambda s: float(s.feed_mode == "inverse_time"),
    "_units_per_minute": lambda s: float(s.feed_mode == "per_minute"),
    "_units_per_rev": lambda s: float(s.feed_mode == "per_rev"),
    "_plane": lambda s: float(s.plane * 10),
    "_feed": _feed,
    "_rpm": lambda s: float(s.speed),
    "_spindle_on": lambda s: float(s.spindle != 0),
    "_spindle_cw": lambda s: float(s.spindle == 1),
    "_mist": lambda s: float(bool(s.coolant & 1)),
    "_flood": lambda s: float(bool(s.coolant & 2)),
    "_current_tool": lambda s: float(s.tool),
    "_selected_tool": lambda s: float(s.selected_tool),
    "_motion_mode": lambda s: float(s.motion_code),
    "_ccomp": lambda s: 410.0 if s.compensating and s.compensating_left else 420.0 if s.compensating else 400.0,
    "_tool_offset": lambda s: float(s.tool_offset.any()),
    "_lathe_diameter_mode": lambda s: float(s.diameter),
    "_ijk_absolute_mode": lambda s: float(not s.arc_incremental),
    # what rs274 run standalone gives: no task runs the machine, LinuxCNC 2.9
    "_task": lambda s: 0.0,
    "_vmajor": lambda s: 2.9,
    "_vminor": lambda s: 0.0,
}


#: Parameters that need the machine's configuration as well as its state.
def _tool_data(attribute: str, length: bool = False) -> Callable[["Machine"], float]:
    """#5410-#5413: a datum of the tool in the spindle (a length in machine units), 0 without one."""
    def read(m: "Machine") -> float:
        tool = m.tools.get(m.state.tool)
        value = float(getattr(tool, attribute)) if tool is not None else 0.0
        return value / _machine_unit(m, 0) if length else value
    return read


_MACHINE_READERS: dict[int | str, Callable[["Machine"], float]] = {
    **{5401 + k: _tool_offset(k) for k in range(9)},
    5410: _tool_data("diameter", length=True),
    5411: _tool_data("front_angle"),
    5412: _tool_data("back_angle"),
    5413: _tool_data("orientation"),
}


@functools.lru_cache(maxsize=4096)  # asked for every parameter read of a program's loops
def is_state_parameter(key: int | str) -> bool:
    """Whether ``key`` (a number, or a normalized name) reports the machine's state or configuration."""
    return (key in _READERS or key in _MACHINE_READERS or is_stored_parameter(key)
            or (isinstance(key, str) and key.startswith("_ini[")))


@functools.lru_cache(maxsize=4096)
def is_stored_parameter(key: int | str) -> bool:
    """Whether ``key`` is a stored position or offset a program may write (``#5221 = 1``)."""
    return key == 5210 or _stored_slot(key) is not None


def machine_parameter(machine: "Machine", key: int | str) -> float | None:
    """The value of state parameter ``key`` on ``machine`` now; None for any other parameter."""
    if key in _MACHINE_READERS:
        return _MACHINE_READERS[key](machine)
    if key == 5210:
        return float(machine.state.g92_on)
    if isinstance(key, str) and key.startswith("_ini["):  # an INI value: None when the file has none
        return machine.ini.parameter(key) if machine.ini is not None else None
    slot = _stored_slot(key)
    if slot is not None:
        attribute, index, axis = slot
        return float(getattr(machine.state, attribute)[index] / _scale(machine, axis))
    reader = _READERS.get(key)
    return None if reader is None else reader(machine.state)


def set_machine_parameter(machine: "Machine", key: int | str, value: float) -> None:
    """Write stored parameter ``key`` (see :func:`is_stored_parameter`) into the machine."""
    if key == 5210:
        machine.state.g92_on = value != 0.0
        return
    slot = _stored_slot(key)
    if slot is None:
        raise KeyError(key)
    attribute, index, axis = slot
    getattr(machine.state, attribute)[index] = value * _scale(machine, axis)
