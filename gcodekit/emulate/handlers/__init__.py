"""Emulate stage: the handlers of state-changing commands, one module per family.

Importing the package registers every handler in :data:`HANDLERS` (see
:mod:`.registry` for what a handler is given and returns).  Families:
:mod:`.modes` (units, distance modes, planes, feed modes, program end),
:mod:`.work_systems` (G54-G59.3, G92 family, G52, G10), :mod:`.tools`,
:mod:`.spindle` (spindle, coolant, laser, deposition), :mod:`.homing`
(G28/G30, G53), :mod:`.printer` (extrusion modes, flow, firmware
retraction), :mod:`.cycles` (canned cycles, G76, G33), :mod:`.lathe_cycles`
(G70-G72) and :mod:`.moves` (splines, polar coordinates).
"""

from . import cycles, homing, lathe_cycles, modes, moves, printer, spindle, tools, work_systems
from .registry import HANDLERS, Block, Context, Outcome, Waypoint, handles

__all__ = ["HANDLERS", "Block", "Context", "Outcome", "Waypoint", "handles", "cycles", "homing", "lathe_cycles",
           "modes", "moves", "printer", "spindle", "tools", "work_systems"]
