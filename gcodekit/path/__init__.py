"""Front end: FreeCAD's Path scripting API on gcodekit (``import gcodekit.path as Path``).

A FreeCAD Path script runs by changing its import: ``Command``, ``Path``,
``Tool``, ``Tooltable``, a ``Job`` (FreeCAD's compound and project),
``fromShape``, pre-processing (:func:`read`) and post-processing
(:func:`post_process`), with gcodekit's pipeline, planner and pictures
behind them.  The differences from FreeCAD 0.20, where it is wrong, are in
``docs/freecad.md``.

Examples
--------
>>> import gcodekit.path as Path
>>> c1 = Path.Command("g1x1")
>>> c2 = Path.Command("g1y4")
>>> c3 = Path.Command("g1 x2 y2")
>>> p = Path.Path([c1, c2, c3])
>>> print(p.toGCode(), end="")
G1 X1.000000
G1 Y4.000000
G1 X2.000000 Y2.000000
"""

from .command import Command
from .from_shape import from_shape, fromShape
from .geometry import BoundBox, Placement, Rotation, Vector
from .job import Compound, Job
from .processing import TARGETS, from_operation, post_process, read, to_operation, write_report
from .rules import FreeCADFormatError
from .toolpath import Path
from .tools import Tool, ToolBit, Tooltable
from .tooltable_files import read_tooltable, write_tooltable

__all__ = ["Command", "Path", "Tool", "Tooltable", "ToolBit", "Compound", "Job", "from_shape", "fromShape",
           "read", "post_process", "to_operation", "from_operation", "write_report", "read_tooltable", "write_tooltable",
           "Vector", "Placement", "Rotation", "BoundBox", "FreeCADFormatError", "TARGETS"]
