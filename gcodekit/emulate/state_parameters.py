"""Emulate stage: LinuxCNC's parameters that report the machine's state.

A program may read where the tool is and which modes are in force:
``#5420``-``#5428`` and ``#<_x>`` .. ``#<_w>`` (position in program units,
every offset applied), ``#5220`` and ``#<_coord_system>`` (the work
coordinate system), ``#5400`` (the tool in the spindle), ``#5401``-``#5409``
(its length offsets) and the predefined named parameters of LinuxCNC 2.9
(``#<_imperial>``, ``#<_plane>``, ``#<_feed>``, ``#<_rpm>``, ...).  Their
values are those before the reading line runs, as rs274 gives them.

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

from typing import TYPE_CHECKING, Callable

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


def _tool_offset(axis: int) -> Callable[["Machine"], float]:
    # rs274 gives these in machine units (the tool table's), not the program's
    def read(m: "Machine") -> float:
        per_unit = 25.4 if m.config.tool_table_units == "inch" and axis < 3 else 1.0
        return float(m.state.tool_offset[axis] / per_unit) if axis < 6 else 0.0
    return read


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
}


#: Parameters that need the machine's configuration as well as its state.
_MACHINE_READERS: dict[int | str, Callable[["Machine"], float]] = {5401 + k: _tool_offset(k) for k in range(9)}


def is_state_parameter(key: int | str) -> bool:
    """Whether ``key`` (a number, or a normalized name) reports the machine's state."""
    return key in _READERS or key in _MACHINE_READERS


def machine_parameter(machine: "Machine", key: int | str) -> float | None:
    """The value of state parameter ``key`` on ``machine`` now; None for any other parameter."""
    if key in _MACHINE_READERS:
        return _MACHINE_READERS[key](machine)
    reader = _READERS.get(key)
    return None if reader is None else reader(machine.state)
