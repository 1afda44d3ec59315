"""Widgets stage: an emulated program as line segments grouped for stepping.

A :class:`Toolpath` is what the viewers draw: every move of the program as
straight segments (arcs split into chords), in program order, each with its
move, its kind (work or travel) and a group to step through (an additive
program's layers, a mill program's Z levels or its source lines).  Groups
never go back along the program, so a range of groups is one contiguous
slice of segments and a front end redraws a range without rebuilding
anything.  Only NumPy here: the widgets and the pictures read these arrays.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("M83\\nG1 X10 E1 F600\\nG1 Z0.2\\nG1 X0 E1\\n", "marlin", plan=False)
>>> path = Toolpath.of(op)
>>> path.group_by, path.n_groups, path.group_slice(1, 1)
('layer', 2, (2, 3))
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import GcodeError

if TYPE_CHECKING:
    from ..model.operation import Operation

#: How a program is stepped through: layers (additive), Z levels or source lines (mill).
GROUP_BY = ("layer", "z", "line")
#: Segment kinds.
WORK, TRAVEL = 0, 1


class ToolpathError(GcodeError, ValueError):
    """A program the viewers cannot draw (no file, no motions, nothing readable)."""


@dataclass
class Toolpath:
    """Segments of an emulated operation, in program order.

    Attributes
    ----------
    op : Operation
    start, end : ndarray (n, 3) float64
        Segment end points, machine coordinates, mm.
    move_of : ndarray (n,) int
        Index into :attr:`move_rows` of the move each segment belongs to.
    kind : ndarray (n,) uint8
        ``WORK`` (deposition, or a mill's feed moves) or ``TRAVEL``.
    move_rows : ndarray (m,) int
        Waypoint row of each move.
    move_seg : ndarray (m + 1,) int
        Move ``k`` is segments ``move_seg[k]:move_seg[k + 1]``.
    group_move : ndarray (g + 1,) int
        Group ``j`` is moves ``group_move[j]:group_move[j + 1]``.
    group_labels : list of str
        What each group is (``"layer 3"``, ``"Z -2"``, ``"line 41"``).
    group_by : str
        ``"layer"``, ``"z"`` or ``"line"``.
    """

    op: "Operation"
    start: np.ndarray
    end: np.ndarray
    move_of: np.ndarray
    kind: np.ndarray
    move_rows: np.ndarray
    move_seg: np.ndarray
    group_move: np.ndarray
    group_labels: list[str]
    group_by: str

    # -- construction --------------------------------------------------------

    @classmethod
    def of(cls, source, group_by: str | None = None, *, waypoint_layer: np.ndarray | None = None) -> "Toolpath":
        """The toolpath of an Operation, an AdditivePart or a program path.

        Parameters
        ----------
        source : Operation, AdditivePart, path or program text
        group_by : {"layer", "z", "line"}, default: None
            None steps by layer for additive programs, by Z level otherwise.

        Raises
        ------
        ToolpathError
            When the source cannot be read or has no motion to draw.
        """
        from ..errors import check_choice
        from ..visualize import move_masks

        op, waypoint_layer = _operation(source, waypoint_layer)
        w = op.waypoints
        if w is None or len(w["x"]) == 0:
            raise ToolpathError(f"{op.file}: the program is empty (no commands to run)")
        work, travel = move_masks(op)
        moving = work | travel
        if not moving.any():
            raise ToolpathError(f"{op.file}: the program has no motions to draw")
        additive = op.process == "additive"
        group_by = group_by or ("layer" if additive else "z")
        check_choice("group_by", group_by, GROUP_BY)
        rows = np.flatnonzero(moving)
        key, labels = _group_keys(op, rows, work[rows], group_by, waypoint_layer)
        start, end, move_of = _segments(w, rows)
        group_move = np.searchsorted(key, np.arange(len(labels) + 1))
        move_seg = np.searchsorted(move_of, np.arange(rows.size + 1))
        return cls(op, start, end, move_of, np.where(work[rows], WORK, TRAVEL).astype(np.uint8)[move_of], rows,
                   move_seg, group_move, labels, group_by)

    # -- questions -----------------------------------------------------------

    @property
    def n_groups(self) -> int:
        return len(self.group_labels)

    @property
    def n_segments(self) -> int:
        return self.start.shape[0]

    def moves_in(self, group: int) -> int:
        """How many moves group ``group`` has."""
        return int(self.group_move[group + 1] - self.group_move[group])

    def group_slice(self, lo: int, hi: int, move: int | None = None) -> tuple[int, int]:
        """Segments ``[a, b)`` of groups ``lo..hi``, the top one up to its move ``move`` (all when None)."""
        first = int(self.move_seg[self.group_move[lo]])
        top = self.group_move[hi + 1] if move is None else min(self.group_move[hi] + move + 1, self.group_move[hi + 1])
        return first, int(self.move_seg[top])

    def current_move(self, hi: int, move: int | None = None) -> int:
        """Index of the last move shown when groups up to ``hi`` are drawn up to ``move``; -1 if none."""
        count = self.moves_in(hi)
        if count == 0:
            return -1
        return int(self.group_move[hi] + (count - 1 if move is None else min(max(move, 0), count - 1)))

    def line_of(self, move: int) -> int:
        """Source line of a move."""
        return int(self.op.table.line[_command_rows(self.op)[self.move_rows[move]]])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner of the work segments (of all when none is work), mm.

        Travel to a parking or home position would otherwise shrink the part to a dot.
        """
        keep = self.kind == WORK if (self.kind == WORK).any() else slice(None)
        both = np.vstack([self.start[keep], self.end[keep]])
        return both.min(axis=0), both.max(axis=0)

    def frame(self) -> tuple[np.ndarray, float]:
        """Centre of :meth:`bounds` and the radius of the sphere around them, mm."""
        lo, hi = self.bounds()
        return (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)

    def times(self) -> tuple[np.ndarray, np.ndarray]:
        """Start and end time (s) of every move."""
        w = self.op.waypoints
        end = self.op.elapsed_time()[self.move_rows]
        return end - np.nan_to_num(np.asarray(w["time"], float)[self.move_rows]), end


def _operation(source, waypoint_layer):
    """The emulated operation of ``source`` and its waypoint layers (None: derive)."""
    from ..model.operation import Operation
    from ..errors import GcodeError

    if hasattr(source, "operation") and hasattr(source, "waypoint_layer"):  # an AdditivePart
        return source.operation, source.waypoint_layer
    if isinstance(source, Operation):
        if source.waypoints is None:
            raise ToolpathError(f"{source.file}: the operation is not emulated (use gcode_to_operation)")
        return source, waypoint_layer
    if not isinstance(source, (str, os.PathLike)):
        raise ToolpathError(f"cannot draw a {type(source).__name__}: give an Operation, an AdditivePart or a path")
    from ..pipeline import gcode_to_operation

    if isinstance(source, str) and not source.strip():
        raise ToolpathError("the program is empty (no text)")
    try:
        return gcode_to_operation(source), None  # a path, or the program's text
    except (GcodeError, OSError, ValueError) as exc:
        raise ToolpathError(str(exc)) from exc


def _command_rows(op: "Operation") -> np.ndarray:
    w = op.waypoints
    return w["command"]


def _group_keys(op, rows, work, group_by, waypoint_layer) -> tuple[np.ndarray, list[str]]:
    """Group of each move (non-decreasing) and the group labels."""
    if group_by == "layer":
        layer = (op.layers if waypoint_layer is None else np.asarray(waypoint_layer))[rows]
        # start code before the first layer is drawn with layer 0; layers never go back
        key = np.maximum.accumulate(np.maximum(layer, 0))
        return key, [f"layer {k}" for k in range(int(key[-1]) + 1)]
    if group_by == "line":
        line = op.table.line[_command_rows(op)[rows]]
        new = np.r_[True, line[1:] != line[:-1]]
        return np.cumsum(new) - 1, [f"line {v}" for v in line[new].tolist()]
    # Z levels: a level starts where a work move runs at a new height; the moves
    # leading to a level (rapids, plunges) belong to it
    z = np.round(np.asarray(op.waypoints["z"], float)[rows], 3)
    cut = np.flatnonzero(work)
    if cut.size == 0:
        return np.zeros(rows.size, np.int64), ["all moves"]
    new = np.r_[True, z[cut][1:] != z[cut][:-1]]
    level_of_cut = np.cumsum(new) - 1
    level = np.full(rows.size, -1, np.int64)
    level[cut] = level_of_cut
    # each move takes the level of the next work move (the last ones the last level)
    after = np.searchsorted(cut, np.arange(rows.size))
    key = level_of_cut[np.minimum(after, cut.size - 1)]
    return key, [f"Z {v:g}" for v in z[cut][new].tolist()]


def _segments(w: dict, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Straight segments of the moves ending at waypoints ``rows`` (arcs in 5-degree chords)."""
    from ..emulate.arcs import waypoint_arc_points

    xyz = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
    interior, counts = waypoint_arc_points(w, rows)
    points_per_move = counts + 2  # its start, the arc's interior points, its end
    offsets = np.r_[0, np.cumsum(points_per_move)]
    points = np.empty((int(offsets[-1]), 3))
    points[offsets[:-1]] = xyz[rows - 1]
    points[offsets[1:] - 1] = xyz[rows]
    inside = np.ones(points.shape[0], bool)
    inside[offsets[:-1]] = inside[offsets[1:] - 1] = False
    points[inside] = interior
    # a segment joins each point to the next one of the same move
    joins = np.ones(points.shape[0], bool)
    joins[offsets[1:] - 1] = False
    seg_start = np.flatnonzero(joins)
    move_of = np.repeat(np.arange(rows.size), points_per_move - 1)
    return points[seg_start], points[seg_start + 1], move_of


def source_lines(op: "Operation") -> list[str] | None:
    """The program's text lines (None when it came from text that was not kept)."""
    path = Path(op.file)
    if not path.is_file():
        return None
    import gzip

    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt", encoding="utf-8", errors="replace") as f:
        return f.read().splitlines()
