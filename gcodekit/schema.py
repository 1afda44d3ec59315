"""The waypoint table's columns: name, unit, dtype and meaning, in one place.

After emulation the truth about a program is a table of waypoints: one row
per command (its end state) plus the points commands pass through.  The
machine fills the :data:`WAYPOINT_COLUMNS` and ``command`` (which command
made each waypoint); the DataFrames add the :data:`COMMAND_COLUMNS` of that
command, and the planner and the operation the :data:`DERIVED_COLUMNS`.
``Operation.columns`` and the DataFrames show the same schema, so a user can
look up what a column is and in what unit.

Examples
--------
>>> COLUMNS["feed"].unit, COLUMNS["layer"].dtype
('mm/min', 'int32')
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Column", "COMMAND_COLUMNS", "WAYPOINT_COLUMNS", "DERIVED_COLUMNS", "COLUMNS", "allocate"]


@dataclass(frozen=True)
class Column:
    """One column of the waypoint table."""

    name: str
    unit: str  # "" when the column has no unit (codes, counts)
    dtype: str
    meaning: str


#: Columns that say which command made a waypoint; the machine writes ``command``, the DataFrames the rest.
COMMAND_COLUMNS: tuple[Column, ...] = (
    Column("line", "", "int32", "source line of the command (1-based, in the file the user gave)"),
    Column("command", "", "int32", "row in op.commands of the command that made the waypoint"),
    Column("code", "", "str", "the command's code as written (G1, M104, a named command's name)"),
    Column("kind", "", "category", "the command's kind (motion, setting, ...)"),
)

#: Columns the machine writes for every waypoint (machine coordinates, all offsets applied).
WAYPOINT_COLUMNS: tuple[Column, ...] = (
    Column("x", "mm", "float64", "X, machine coordinates"),
    Column("y", "mm", "float64", "Y, machine coordinates"),
    Column("z", "mm", "float64", "Z, machine coordinates"),
    Column("a", "deg", "float64", "A, machine coordinates"),
    Column("b", "deg", "float64", "B, machine coordinates"),
    Column("c", "deg", "float64", "C, machine coordinates"),
    Column("de", "mm", "float64", "filament (or wire, or screw travel) pushed by this step"),
    Column("feed", "mm/min", "float64", "feed rate in force"),
    Column("distance", "mm", "float64", "path length of this step"),
    Column("time", "s", "float64", "duration of this step (planned, when the machine has a planner)"),
    Column("cx", "mm", "float64", "arc centre X (NaN unless an arc; NaN on the helix axis)"),
    Column("cy", "mm", "float64", "arc centre Y"),
    Column("cz", "mm", "float64", "arc centre Z"),
    Column("spindle", "rpm", "float64", "spindle speed, negative when counter-clockwise"),
    Column("motion", "", "uint8", "0 none, 1 rapid, 2 feed, 3 arc clockwise, 4 arc counter-clockwise"),
    Column("plane", "", "uint8", "arc plane in force: 17 XY, 18 XZ, 19 YZ"),
    Column("units", "", "uint8", "program units in force: 0 mm, 1 inch"),
    Column("tool", "", "int32", "tool in the spindle, or the active extruder"),
    Column("coolant", "", "uint8", "bit 1 mist, bit 2 flood"),
    Column("laser", "", "uint8", "1 while the laser or weld heat source is on (DED: M61 on, M62 off)"),
    Column("work_offset", "", "uint8", "work system in force: 1..9 for G54..G59.3"),
    Column("flow", "ratio", "float32", "extrusion multiplier in force (M221): de is the programmed E times it"),
    Column("rotation", "deg", "float64", "XY rotation of the work system in force (G10 L2 R), counter-clockwise"),
)

#: Columns derived once from the waypoints and kept on the operation, or added by the planner.
DERIVED_COLUMNS: tuple[Column, ...] = (
    Column("layer", "", "int32", "layer of the waypoint, 0 first (-1 before the first); one definition, "
                                 "see gcodekit.model.derived"),
    Column("feature", "", "str", "slicer feature (;TYPE: comment) or DED fraction in force; '' when none"),
    Column("depositing", "", "bool", "the step lays material"),
    Column("elapsed_time", "s", "float64", "time from the program's start to the end of the step"),
    Column("start_time", "s", "float64", "time from the program's start to the start of the step"),
    Column("start_v", "mm/s", "float64", "planned speed entering the step (first firmware move)"),
    Column("cruise_v", "mm/s", "float64", "fastest planned cruise speed of the step"),
    Column("end_v", "mm/s", "float64", "planned speed leaving the step (last firmware move)"),
    Column("power", "S", "float64", "laser beam power in S units (full at GRBL's $30), 0 unlit; laser machines only"),
    Column("accel", "mm/s^2", "float64", "acceleration the planner used for the step's first move"),
    Column("deposited_volume", "mm^3", "float64", "material laid by the step (additive processes; NaN when "
                                                   "the machine does not say how much)"),
    Column("removed_volume", "mm^3", "float64", "material the step's move removed from the stock (once a cutting "
                                                 "simulation has run, gcodekit.cut; 0 for moves in the air)"),
    Column("removal_rate", "mm^3/min", "float64", "material removal rate: removed_volume over the step's planned "
                                                   "time (0 where the step takes no time; once a cut has run)"),
)

COLUMNS: dict[str, Column] = {c.name: c for c in COMMAND_COLUMNS + WAYPOINT_COLUMNS + DERIVED_COLUMNS}


def allocate(n: int) -> dict[str, np.ndarray]:
    """Empty arrays for ``n`` waypoints, one per :data:`WAYPOINT_COLUMNS` entry, in order, and
    ``command``: at first one waypoint per command."""
    out = {c.name: np.empty(n, c.dtype) for c in WAYPOINT_COLUMNS}
    out["command"] = np.arange(n, dtype=np.int32)
    return out
