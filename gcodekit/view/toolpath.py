"""Output stage: an emulated program as the line segments every picture draws.

A :class:`Toolpath` is every move of the program as straight segments (arcs
cut into chords of at most :data:`CHORD_ANGLE_DEG`), in program order, each
with its move, its kind (work or travel) and a group to step through (an
additive program's layers, a mill program's Z levels or its source lines).
Groups never go back along the program, so a range of groups is one
contiguous slice of segments.  The WebGL viewer, the PyVista pictures, the
matplotlib pictures and the report all draw these arrays, so one program
looks the same in each.  Only NumPy here.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("M83\\nG1 X10 E1 F600\\nG1 Z0.2\\nG1 X0 E1\\n", "marlin", plan=False)
>>> path = Toolpath.of(op)
>>> path.group_by, path.n_groups, path.group_slice(1, 1)
('layer', 2, (2, 3))
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import NothingToShowError, check_choice

if TYPE_CHECKING:
    from ..model.operation import Operation

#: How a program is stepped through: layers (additive), Z levels or source lines (mill).
GROUP_BY = ("layer", "z", "line")
#: Segment kinds.
WORK, TRAVEL = 0, 1
#: Largest angle an arc's chord spans: a chord then stays within r (1 - cos 2.5 deg), 0.1 % of the
#: arc's radius, of the circle -- below a pixel at any scale that shows the whole arc.
CHORD_ANGLE_DEG = 5.0


class ToolpathError(NothingToShowError):
    """A program the pictures cannot draw (not emulated, no motions)."""


def move_masks(op: "Operation") -> tuple[np.ndarray, np.ndarray]:
    """Waypoints that end a work move (``op.work``: what the process makes), and those that end any other move.

    A move runs from the waypoint before it, so the first waypoint ends none.
    """
    moving = op.moving.copy()
    moving[:1] = False
    work = op.work & moving
    return work, moving & ~work


def move_rows(op: "Operation") -> tuple[np.ndarray, np.ndarray]:
    """Waypoint rows that end a move (the moves every picture draws), and :func:`move_masks`' work mask.

    Raises
    ------
    ToolpathError
        When the operation is not emulated or has no motion to draw.
    """
    w = getattr(op, "waypoints", None)
    if w is None:
        raise ToolpathError(f"{op.file}: the operation is not emulated (use gcode_to_operation)")
    if len(w["x"]) == 0:
        raise ToolpathError(f"{op.file}: nothing to draw (the program is empty: no commands to run)")
    work, travel = move_masks(op)
    rows = np.flatnonzero(work | travel)
    if rows.size == 0:
        raise ToolpathError(f"{op.file}: nothing to draw (the program has no motions)")
    return rows, work


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

    @classmethod
    def of(cls, source, group_by: str | None = None) -> "Toolpath":
        """The toolpath of an emulated Operation or an AdditivePart.

        Parameters
        ----------
        source : Operation or AdditivePart
        group_by : {"layer", "z", "line"}, default: None
            None steps by layer for additive programs, by Z level otherwise.

        Raises
        ------
        ToolpathError
            When the operation is not emulated or has no motion to draw.
        """
        op = getattr(source, "operation", source)  # an AdditivePart draws its operation with its layers
        waypoint_layer = getattr(source, "waypoint_layer", None)
        w = getattr(op, "waypoints", None)
        rows, work = move_rows(op)
        group_by = group_by or ("layer" if op.process == "additive" else "z")
        check_choice("group_by", group_by, GROUP_BY)
        key, labels = _group_keys(op, rows, work[rows], group_by, waypoint_layer)
        start, end, move_of, move_seg = _move_segments(w, rows)
        group_move = np.searchsorted(key, np.arange(len(labels) + 1))
        return cls(op, start, end, move_of, np.where(work[rows], WORK, TRAVEL).astype(np.uint8)[move_of], rows,
                   move_seg, group_move, labels, group_by)

    # -- questions -----------------------------------------------------------

    @property
    def n_groups(self) -> int:
        return len(self.group_labels)

    @property
    def n_segments(self) -> int:
        return self.start.shape[0]

    @cached_property
    def segment_group(self) -> np.ndarray:
        """The group of each segment, (n,) int."""
        move_group = np.searchsorted(self.group_move, np.arange(self.move_rows.size), side="right") - 1
        return move_group[self.move_of]

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

    def bounds(self, keep: np.ndarray | slice | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner of segments ``keep`` (default: the work, or all when none is work), mm.

        Travel to a parking or home position would otherwise shrink the part to a dot.
        """
        if keep is None:
            return tuple(a.copy() for a in self._work_bounds)
        return _corners(self.start[keep], self.end[keep])

    @cached_property
    def _work_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`bounds` of the work, once: every picture and camera asks."""
        work = self.kind == WORK
        if not work.any():
            return _corners(self.start, self.end)
        # one coordinate at a time: a masked reduction over the (n, 3) arrays took ten times longer
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for p in (self.start, self.end):
            for k in range(3):
                picked = p[:, k][work]
                lo[k], hi[k] = np.minimum(lo[k], picked.min()), np.maximum(hi[k], picked.max())
        return lo, hi

    def frame(self) -> tuple[np.ndarray, float]:
        """Centre of :meth:`bounds` and the radius of the sphere around them, mm."""
        lo, hi = self.bounds()
        return (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)

    def times(self, moves: np.ndarray | slice = slice(None)) -> tuple[np.ndarray, np.ndarray]:
        """Start and end time (s) of every move, or of ``moves`` (indices of :attr:`move_rows`)."""
        rows = self.move_rows[moves]
        end = self.op.elapsed_time()[rows]
        return end - np.nan_to_num(np.asarray(self.op.waypoints["time"], float)[rows]), end


def _corners(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if start.shape[0] == 0:
        return np.zeros(3), np.zeros(3)
    return np.minimum(start.min(axis=0), end.min(axis=0)), np.maximum(start.max(axis=0), end.max(axis=0))


def _command_rows(op: "Operation") -> np.ndarray:
    return op.waypoints["command"]


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
    # each move takes the level of the next work move (the last ones the last level)
    after = np.searchsorted(cut, np.arange(rows.size))
    key = level_of_cut[np.minimum(after, cut.size - 1)]
    return key, [f"Z {v:g}" for v in z[cut][new].tolist()]


def move_segments(w: dict, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Straight segments of the moves ending at waypoints ``rows``, arcs in chords of :data:`CHORD_ANGLE_DEG`.

    Returns the segments' start and end points (n, 3) and the index into
    ``rows`` of the move each belongs to.  For a drawing of waypoint columns
    that are not an Operation's (a transpiler stage's text, emulated on its own).
    """
    return _move_segments(w, rows)[:3]


def _move_segments(w: dict, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`move_segments`, and each move's first segment with the count after the last, (m + 1,)."""
    from ..emulate.arcs import waypoint_arc_points

    interior, counts = waypoint_arc_points(w, rows, np.radians(CHORD_ANGLE_DEG))
    before, after = _points(w, rows - 1), _points(w, rows)
    if interior.shape[0] == 0:  # no arcs: one segment per move
        every = np.arange(rows.size + 1)
        return before, after, every[:-1], every
    # a move's segments join its start, the arc's interior points and its end, in order
    offsets = np.r_[0, np.cumsum(counts + 1)]
    first, last = offsets[:-1], offsets[1:] - 1
    start, end = np.empty((int(offsets[-1]), 3)), np.empty((int(offsets[-1]), 3))
    start[first], end[last] = before, after
    inside = np.ones(start.shape[0], bool)
    inside[first] = False
    start[inside] = interior  # every segment but a move's first starts at an interior point
    inside[:] = True
    inside[last] = False
    end[inside] = interior  # and every one but its last ends at one
    return start, end, np.repeat(np.arange(rows.size), counts + 1), offsets


def _points(w: dict, rows: np.ndarray) -> np.ndarray:
    """Waypoints ``rows``' x, y, z as (k, 3), mm: taken into place, no per-column copies."""
    out = np.empty((rows.size, 3))
    for j, k in enumerate("xyz"):
        np.take(np.asarray(w[k], float), rows, out=out[:, j])
    return out


def source_lines(op: "Operation") -> list[str] | None:
    """The program's text lines, read as the pipeline read them (None when it came from text).

    Any container and encoding the reader knows (gzip, bzip2, xz, UTF-16,
    byte-order marks, CR-only line ends); line ``k`` is item ``k - 1``.
    """
    from ..read.source import program_lines

    path = Path(op.file)
    if not path.is_file():
        return None
    return program_lines(path)
