"""Outputs: the cutting simulation of a mill operation, run to any move and back.

:class:`CutSimulation` turns an emulated operation into pieces of tool-tip
path (:mod:`gcodekit.cut.path`), chooses the stock and the tools, and cuts
(:mod:`gcodekit.cut.sweep`) up to the move asked for.  It keeps the height
field after every block of pieces, within a memory budget, so moving a
slider forward cuts only the new pieces and moving it back restores the
nearest block before and cuts forward from there -- never from the start.

Examples
--------
>>> import gcodekit
>>> from gcodekit.tool_shapes import ToolShape
>>> op = gcodekit.gcode_to_operation("G21 G90\\nG0 X0 Y0 Z1\\nG1 Z-1 F100\\nG1 X10\\nG0 Z5\\n", machine="linuxcnc")
>>> sim = CutSimulation(op, stock=Stock.box(-5, -5, -5, 15, 5, 0, resolution=0.1),
...                     tools=ToolLibrary({0: ToolShape("endmill", 4.0)}))
>>> round(sim.run().removed_mm3, 1)    # a 10 x 4 x 1 mm slot with round ends: 40 + pi * 4
52.6
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError, Diagnostic, check_choice
from ..tool_shapes import ToolShape
from .path import ARC_CCW, ARC_CW, FEED, RAPID, moving_rows, tool_tip_pieces
from .result import CutResult
from .stock import Stock, check_grid
from .sweep import ENGINES, Pieces, split_long, sweep
from .tools import ToolLibrary

#: What a tool with no definition is cut as (and said to be).
FALLBACK_TOOL = ToolShape("endmill", 6.0)
#: Finest default resolution, mm, and the cells at most the default gives (coarser beyond).
DEFAULT_RESOLUTION = 0.1
DEFAULT_MAX_CELLS = 16_000_000
#: Memory the states kept for going back may take, bytes.
STATE_BUDGET = 256 * 2**20
#: Space left under the deepest point cut in a stock made from the program, mm.
FLOOR_MARGIN = 1.0


@dataclass
class CutSettings:
    """What a cut was run with: the stock (None: from the program), tools and grid."""

    resolution: float | None = None
    tolerance: float | None = None
    notes: list[Diagnostic] = field(default_factory=list)


class CutSimulation:
    """Material removal of an emulated mill operation, cut up to any move.

    Parameters
    ----------
    op : Operation
        An emulated operation (mm; see :mod:`gcodekit.cut.path` for the tool tip).
    stock : Stock, default: None
        The material; None makes a box: the bounding box of the feed moves'
        tool envelopes, its top at the highest point where a feed move ends
        (a plunge's start is the rapid's end, above the work) and its
        bottom 1 mm below the deepest point.
    tools : ToolLibrary, default: None
        The shape of each tool number.  A tool the program uses that has no
        shape is cut as a 6 mm flat end mill, with a warning naming it.
    resolution : float, default: None
        Grid cell size, mm, for a stock made from the program; None: 0.1 mm,
        or a twentieth of the smallest tool's diameter if that is finer,
        coarser when the grid would pass ``max_cells``.
    tolerance : float, default: None
        Largest distance of arc chords from the arc, mm (default: a tenth of
        the resolution).
    engine : {"auto", "numba", "numpy"}, default: "auto"
        The cutting loop (see :func:`gcodekit.cut.sweep.sweep`).
    keep_states : bool, default: False
        Keep the height field every block of moves (within 256 MB), so that
        :meth:`cut_to` can go back without cutting from the start (the live
        view does; a single run does not need it).
    max_cells : int, default: 16 million
        The most cells the default resolution gives a stock made from the
        program (a coarser grid beyond, with a note).

    Raises
    ------
    ConfigError
        A resolution that is not positive or would need more memory than the
        machine has, or an operation that was not emulated.
    """

    def __init__(self, op, *, stock: Stock | None = None, tools: ToolLibrary | None = None,
                 resolution: float | None = None, tolerance: float | None = None, engine: str = "auto",
                 keep_states: bool = False, max_cells: int = DEFAULT_MAX_CELLS):
        self.max_cells = max_cells
        self.engine = check_choice("engine", engine, ENGINES)
        if getattr(op, "waypoints", None) is None:
            raise ConfigError(f"{op.file}: cutting needs an emulated operation (use gcode_to_operation)")
        self.op = op
        self.notes: list[Diagnostic] = []
        w = op.waypoints
        tools = tools if tools is not None else ToolLibrary()
        rows = moving_rows(w)
        self.shapes = self._shapes(tools, w, rows)
        if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
            raise ConfigError(f"the resolution must be a positive number of mm, not {resolution!r}")
        self._check_rotary(w, rows)
        default_res = min([DEFAULT_RESOLUTION] + [s.diameter / 20 for s in self.shapes.values()])
        res = stock.resolution if stock is not None else (resolution or default_res)
        self.tolerance = tolerance if tolerance is not None else res / 10
        if not (math.isfinite(self.tolerance) and self.tolerance > 0):
            raise ConfigError(f"the arc tolerance must be a positive number of mm, not {tolerance!r}")
        pieces = tool_tip_pieces(w, tools.offsets, self.tolerance)
        if stock is None:
            stock = self._stock_from_path(pieces, w, res, explicit=resolution is not None)
        else:
            self._check_meets(stock, pieces)
        self.stock = stock
        radius = np.array([self.shapes[int(t)].radius for t in pieces.tool]) if len(pieces) else np.zeros(0)
        self.pieces = split_long(pieces, np.maximum(2 * radius, 8 * stock.resolution))
        self.top = stock.top.copy()
        self.removed_per_piece = np.zeros(len(self.pieces))
        self.done = 0  # pieces cut into self.top
        n = len(self.pieces)
        state_bytes = stock.top.nbytes
        states = min(64, STATE_BUDGET // max(state_bytes, 1)) if keep_states else 0
        self._block = max(1, math.ceil(n / states)) if states else max(n, 1)
        self._states: dict[int, np.ndarray] = {0: stock.top.copy()}
        # the pieces of each waypoint end before this index
        self._piece_end = np.searchsorted(self.pieces.owner, np.arange(len(w["x"])), side="right")

    # -- setting up -------------------------------------------------------------------------

    def _line(self, row: int) -> int:
        w, table = self.op.waypoints, self.op.table
        command = w.get("command")
        return int(table.line[command[row] if command is not None else row])

    def _note(self, row: int, message: str, severity: str = "warning") -> None:
        line = self._line(row) if row >= 0 else 0
        file, line = self.op.diagnostics.elsewhere.get(line, (self.op.file, line))
        self.notes.append(Diagnostic(file, line, 1, severity, message))

    def _shapes(self, tools: ToolLibrary, w: dict, rows: np.ndarray) -> dict[int, ToolShape]:
        used = np.asarray(w["tool"])[rows]
        shapes = {}
        for number in dict.fromkeys(used.tolist()):
            if number in tools:
                shapes[number] = tools[number]
                continue
            first = int(rows[np.argmax(used == number)])
            what = "no tool in the spindle (tool 0)" if number == 0 else f"tool {number}"
            self._note(first, f"{what} has no shape in {tools.source if len(tools) else 'any tool file'}: cut as "
                              f"a {FALLBACK_TOOL.diameter:g} mm flat end mill (give its shape with --tools, or a "
                              "tool table with its diameter)")
            shapes[number] = FALLBACK_TOOL
        return shapes

    def _check_rotary(self, w: dict, rows: np.ndarray) -> None:
        if rows.size == 0:
            return
        for axis in "abc":
            values = np.asarray(w[axis])[np.r_[rows[0] - 1, rows]]
            changed = np.flatnonzero(np.abs(np.diff(values)) > 1e-9)
            if changed.size:
                self._note(int(rows[changed[0]]), f"the {axis.upper()} axis turns: the cut takes the tool as "
                           "vertical at the controlled point's X, Y, Z and the stock as fixed (rotary moves are "
                           "approximated, see the README)")
                return

    def _stock_from_path(self, pieces: Pieces, w: dict, resolution: float, explicit: bool) -> Stock:
        motion = np.asarray(w["motion"])[pieces.owner]
        cutting = (motion == FEED) | (motion == ARC_CW) | (motion == ARC_CCW)
        if not cutting.any():
            self.notes.append(Diagnostic(self.op.file, 0, 0, "warning", "the program has no feed moves (G1, G2, "
                                         "G3): nothing to cut, and no stock to make from it (give --stock)"))
            return Stock(0.0, 0.0, resolution, np.zeros((1, 1)), np.zeros((1, 1)))
        p = pieces.take(np.flatnonzero(cutting))
        radius = np.array([self.shapes[int(t)].radius for t in p.tool])
        both = np.concatenate([p.p0, p.p1])
        r2 = np.concatenate([radius, radius])
        x0, x1 = float((both[:, 0] - r2).min()), float((both[:, 0] + r2).max())
        y0, y1 = float((both[:, 1] - r2).min()), float((both[:, 1] + r2).max())
        # the top: the highest point a feed move ends at (a plunge's start is the rapid's end, above the work;
        # so is a helix's, and its chords' ends do not count either)
        ends = np.r_[p.owner[1:] != p.owner[:-1], True]
        z0, z1 = float(both[:, 2].min()) - FLOOR_MARGIN, float(p.p1[ends, 2].max())
        if not explicit and (x1 - x0) * (y1 - y0) / resolution**2 > self.max_cells:
            # cells as square as the area allows, but no fewer than one across a narrow side: the long side
            # alone must then fit (a 6 mm wide cut 8e11 mm long)
            coarser = max(math.sqrt((x1 - x0) * (y1 - y0) / self.max_cells), max(x1 - x0, y1 - y0) / self.max_cells)
            self.notes.append(Diagnostic(self.op.file, 0, 0, "info",
                                         f"a {resolution:g} mm grid over {x1 - x0:g} x {y1 - y0:g} mm would pass "
                                         f"{self.max_cells:,} cells: cut at {coarser:.3g} mm"))
            resolution = coarser
            self.tolerance = max(self.tolerance, resolution / 10)
        check_grid(x1 - x0, y1 - y0, resolution)
        return Stock.box(x0, y0, z0, x1, y1, z1, resolution=resolution)

    def _check_meets(self, stock: Stock, pieces: Pieces) -> None:
        if len(pieces) == 0:
            return
        sx0, sy0, sz0, sx1, sy1, sz1 = stock.bounds()
        radius = max(s.radius for s in self.shapes.values())
        lo = np.minimum(pieces.p0, pieces.p1).min(axis=0) - [radius, radius, 0]
        hi = np.maximum(pieces.p0, pieces.p1).max(axis=0) + [radius, radius, 0]
        if lo[0] > sx1 or hi[0] < sx0 or lo[1] > sy1 or hi[1] < sy0 or lo[2] >= sz1:
            self.notes.append(Diagnostic(self.op.file, 0, 0, "warning",
                                         f"the program never reaches the stock: its tool moves over X {lo[0]:g}.."
                                         f"{hi[0]:g}, Y {lo[1]:g}..{hi[1]:g}, Z down to {lo[2]:g} mm; the stock is "
                                         f"X {sx0:g}..{sx1:g}, Y {sy0:g}..{sy1:g}, Z {sz0:g}..{sz1:g} mm"))

    # -- cutting ----------------------------------------------------------------------------

    @property
    def n_waypoints(self) -> int:
        return len(self.op.waypoints["x"])

    def cut_to(self, waypoint: int) -> np.ndarray:
        """Cut every move up to and including waypoint ``waypoint``; the tops (ny, nx), mm.

        Forward it cuts only the pieces not yet cut; backward it restores
        the state kept at the nearest block before and cuts from there.
        """
        waypoint = int(np.clip(waypoint, -1, self.n_waypoints - 1))
        target = int(self._piece_end[waypoint]) if waypoint >= 0 else 0
        if target < self.done:
            block = max(k for k in self._states if k <= target)
            self.top = self._states[block].copy()
            self.done = block
        while self.done < target:
            stop = min(target, (self.done // self._block + 1) * self._block)
            rows = np.arange(self.done, stop)
            self.removed_per_piece[rows] = sweep(self.stock, self.top, self.pieces.take(rows), self.shapes,
                                                  engine=self.engine)
            self.done = stop
            if stop % self._block == 0 and stop not in self._states:
                self._states[stop] = self.top.copy()
        return self.top

    def run(self) -> CutResult:
        """Cut the whole program; the :class:`CutResult`.

        The operation gains the per-waypoint columns ``removed_volume``
        (mm^3) and ``removal_rate`` (mm^3/min) (see
        :meth:`~gcodekit.model.operation.Operation.attach_removal`), so that
        ``op.to_dataframe()`` and ``op.volumes()`` report them.
        """
        self.cut_to(self.n_waypoints - 1)
        result = self.result()
        self.op.attach_removal(result.removed, result.removal_rate)
        return result

    def result(self) -> CutResult:
        """What the cut so far has made (:meth:`cut_to` sets how far)."""
        w = self.op.waypoints
        done = self.pieces.owner[:self.done]
        removed = np.bincount(done, weights=self.removed_per_piece[:self.done], minlength=self.n_waypoints)
        return CutResult(self.op, self.stock, self.top.copy(), removed, self.shapes, list(self.notes),
                         cut_through=int(done[-1]) if done.size else -1,
                         time=np.nan_to_num(np.asarray(w["time"], float)), motion=np.asarray(w["motion"]),
                         lines=self._lines())

    def _lines(self) -> np.ndarray:
        w, table = self.op.waypoints, self.op.table
        command = w.get("command")
        return np.asarray(table.line)[command] if command is not None else np.asarray(table.line)


def cut(op, *, stock: Stock | None = None, tools: ToolLibrary | None = None, resolution: float | None = None,
        tolerance: float | None = None, engine: str = "auto") -> CutResult:
    """Cut the stock with the whole program; see :class:`CutSimulation` for the parameters.

    The operation gains the columns ``removed_volume`` and ``removal_rate`` (see :meth:`CutSimulation.run`).
    """
    return CutSimulation(op, stock=stock, tools=tools, resolution=resolution, tolerance=tolerance,
                         engine=engine).run()
