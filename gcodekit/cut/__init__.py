"""Outputs: material removal -- cut a stock with a mill program's tools and show the part it makes.

The method is a height field (:mod:`gcodekit.cut.stock`): the stock on a
square grid, each cell a column of material from a bottom to a top.  Each
move's tool envelope is computed exactly at every cell centre it passes
over (:mod:`gcodekit.cut.sweep`), so the part is exact at the cell centres
and its volume a midpoint sum over the cells; arcs and helices are cut into
chords within a tolerance (:mod:`gcodekit.cut.path`).  Undercuts cannot be
represented, and rotary (4/5-axis) moves are approximated by a vertical
tool at the controlled point.

Examples
--------
::

    import gcodekit
    from gcodekit.cut import CutSimulation, Stock, ToolLibrary, cut

    op = gcodekit.gcode_to_operation("part.ngc")
    result = cut(op, stock=Stock.box(0, 0, -10, 60, 40, 0), tools=ToolLibrary.read("TOOLS.toml"))
    result.removed_mm3, result.air_cut_s, result.rapid_collisions
    result.save("part.stl")
"""

from .result import CutResult
from .simulation import CutSimulation, cut
from .stock import Stock
from .tools import ToolLibrary

__all__ = ["CutResult", "CutSimulation", "Stock", "ToolLibrary", "cut"]
