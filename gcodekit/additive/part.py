"""Output stage: an additive part, the deposition and travel segments of an operation.

:class:`AdditivePart` groups the moves of an emulated additive operation into
runs: a *deposition* segment is a run of consecutive moves that lay material
(filament pushed, or the DED heat source on during a feed move) within one
layer; a *travel* segment is a run of moves that do not; a *purge* segment
lays material before the first layer (start code), and is not counted in
the part's length, volume or mass.  Each segment keeps
the first and last waypoint of its moves, so any question about it goes back
to ``operation.waypoints`` (or ``operation.process_data``) by index.

Paths follow arcs with a point every 5 degrees (waypoints hold only their end points).

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("M83\\nG1 X10 E0.5 F600\\nG1 Y10 E0.5\\nG0 X0\\nG1 Z0.2\\nG1 Y0 E0.5\\n",
...                                  machine="marlin", plan=False)
>>> part = AdditivePart(op)
>>> part.summary[["kind", "start", "end", "layer", "length"]].values.tolist()
[['deposition', 1, 2, 0, 20.0], ['travel', 3, 4, 0, 10.2], ['deposition', 5, 5, 1, 10.0]]
>>> part.n_layers, part.deposition_length
(2, 30.0)
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from ..emulate.arcs import waypoint_arc_points
from ..errors import ConfigError
from ..model import derived
from .bead import Bead

if TYPE_CHECKING:
    import pandas as pd

    from ..model.operation import Operation


def concatenated_ranges(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """``concatenate([arange(s, s + n) for s, n in zip(starts, lengths)])`` without the loop."""
    lengths = np.asarray(lengths, np.int64)
    total = int(lengths.sum())
    if total == 0:
        return np.zeros(0, np.int64)
    offsets = np.cumsum(lengths) - lengths
    return np.repeat(np.asarray(starts, np.int64) - offsets, lengths) + np.arange(total)


class AdditivePart:
    """Deposition and travel segments of an additive operation, by layer.

    Parameters
    ----------
    operation : Operation
        Emulated, from an additive machine (``gcode_to_operation`` does both).
    bead : Bead, default: None
        The cross-section laid down.  None derives it from the program: bead
        area from the filament pushed per mm of path, height from the layer
        spacing (DED programs, which push no filament, then have no volume).
    layer_normal : sequence of 3 floats, default: (0, 0, 1)
        Direction in which layers stack.  Along +Z the slicer's layer
        comments are used when the program has them; otherwise a layer
        starts at each new height (position along the normal) reached by a
        depositing move.

    Attributes
    ----------
    summary : DataFrame
        One row per segment: ``kind`` (``deposition``, ``travel``, or
        ``purge`` for material laid before the first layer), ``start``
        and ``end`` (first and last waypoint of its moves, rows of
        ``operation.waypoints``), ``start_command`` and ``end_command``
        (the same as indices of ``operation.process_data``), ``moves``,
        ``layer``, ``length`` (mm), ``start_time``/``end_time``/``time`` (s),
        ``filament`` (mm pushed, M221 applied), ``volume`` (mm^3) and
        ``height`` (mm along the normal at its start).
    waypoint_layer : ndarray
        Layer of every waypoint (-1 before the first).
    """

    def __init__(self, operation: "Operation", bead: Bead | None = None, *,
                 layer_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)):
        if operation.waypoints is None:
            raise ValueError(f"{operation.file}: an AdditivePart needs an emulated operation (use gcode_to_operation)")
        normal = np.asarray(layer_normal, float)
        if normal.shape != (3,) or not np.linalg.norm(normal) > 0:
            raise ConfigError(f"layer_normal must be a non-zero 3-vector, not {layer_normal!r}")
        self.operation = operation
        self.bead = bead
        self.layer_normal = normal / np.linalg.norm(normal)
        w = operation.waypoints
        along_z = np.allclose(self.layer_normal, (0.0, 0.0, 1.0))
        height = np.asarray(w["z"], float) if along_z else sum(
            c * np.asarray(w[k], float) for c, k in zip(self.layer_normal, "xyz") if c)
        self.waypoint_layer = operation.layers if along_z else derived.layers(operation, height)
        moves = np.flatnonzero((np.asarray(w["motion"]) > 0) & (np.asarray(w["distance"]) > 0))
        deposit = derived.depositing(w, self.extruder_type == "screw")[moves]
        layer = self.waypoint_layer[moves]
        # a segment ends where the move kind or the layer changes
        first = np.r_[True, (deposit[1:] != deposit[:-1]) | (layer[1:] != layer[:-1])] if moves.size else np.zeros(0, bool)
        first_move = np.flatnonzero(first)
        last_move = np.r_[first_move[1:] - 1, moves.size - 1] if moves.size else first_move
        self._moves = moves
        self._segment_moves = (first_move, last_move)
        self._layer_times: "pd.DataFrame | None" = None
        self.summary = self._summarize(moves, first_move, last_move, deposit, height)

    # -- construction --------------------------------------------------------

    def _summarize(self, moves, first_move, last_move, deposit, height) -> "pd.DataFrame":
        import pandas as pd

        w = self.operation.waypoints
        start, end = moves[first_move], moves[last_move]
        elapsed = self.operation.elapsed_time()

        def per_segment(column):
            values = np.asarray(column, float)[moves]
            return np.add.reduceat(values, first_move) if first_move.size else np.zeros(0)

        length = per_segment(w["distance"])
        filament = per_segment(w["de"])
        start_time = elapsed[start] - np.nan_to_num(np.asarray(w["time"], float)[start])
        command = w["command"]
        # material laid before the first layer is start code's (purge lines), not the part's
        kind = np.where(deposit[first_move], np.where(self.waypoint_layer[start] >= 0, "deposition", "purge"),
                        "travel") if first_move.size else np.zeros(0, str)
        frame = pd.DataFrame({
            "kind": pd.Categorical(kind, categories=["deposition", "travel", "purge"]),
            "start": start, "end": end,
            "start_command": command[start], "end_command": command[end],
            "moves": last_move - first_move + 1,
            "layer": self.waypoint_layer[start], "length": length,
            "start_time": start_time, "end_time": elapsed[end], "time": elapsed[end] - start_time,
            "filament": filament, "height": height[np.maximum(start - 1, 0)],
        })
        depositing_rows = kind == "deposition"
        if self.bead is not None:
            volume = self.bead.volume(length)
        else:
            volume = per_segment(self.operation.deposited_volumes())
        frame["volume"] = np.where(depositing_rows, volume, 0.0)
        return frame

    # -- properties ----------------------------------------------------------

    @property
    def extruder_type(self) -> str:
        machine = self.operation.machine
        return machine.extruder_type if machine is not None else "filament"

    @property
    def depositions(self) -> "pd.DataFrame":
        """The deposition rows of :attr:`summary`."""
        return self.summary[self.summary["kind"] == "deposition"]

    @property
    def n_layers(self) -> int:
        """Layers in which material is deposited."""
        return int(np.unique(self.depositions["layer"]).size)

    @property
    def deposition_length(self) -> float:
        """Path length of all deposition segments, mm."""
        return float(self.depositions["length"].sum())

    @property
    def volume(self) -> float:
        """Deposited volume, mm^3: bead area times length, else filament pushed times its section."""
        return float(np.sum(self.depositions["volume"].to_numpy()))  # NaN when unknown, not 0

    @property
    def density(self) -> float:
        """Material density, g/cm^3: the bead's, else the machine's."""
        if self.bead is not None and self.bead.density is not None:
            return float(self.bead.density)
        machine = self.operation.machine
        return float(machine.filament_density) if machine is not None else float("nan")

    @property
    def mass(self) -> float:
        """Deposited mass, g (1 g/cm^3 is 1e-3 g/mm^3)."""
        return self.volume * self.density * 1e-3

    def layer_times(self) -> "pd.DataFrame":
        """Per layer: ``time`` (s, travel included), ``deposition_time``,
        ``deposition_length`` (mm), ``volume`` (mm^3) and ``height`` (mm,
        length-weighted mean height of its depositions)."""
        if self._layer_times is not None:
            return self._layer_times.copy()
        import pandas as pd

        w = self.operation.waypoints
        layer = self.waypoint_layer
        inside = layer >= 0
        size = int(layer.max()) + 1 if inside.any() else 0
        time = np.bincount(layer[inside], np.nan_to_num(np.asarray(w["time"], float))[inside], minlength=size)
        dep = self.depositions
        idx = dep["layer"].to_numpy()

        def by_layer(values):
            return np.bincount(idx, np.asarray(values, float), minlength=size)[:size]

        length = by_layer(dep["length"])
        with np.errstate(invalid="ignore", divide="ignore"):
            height = by_layer(dep["height"] * dep["length"]) / length
        self._layer_times = pd.DataFrame({"time": time, "deposition_time": by_layer(dep["time"]),
                                          "deposition_length": length, "volume": by_layer(dep["volume"]),
                                          "height": height}, index=pd.RangeIndex(size, name="layer"))
        return self._layer_times.copy()

    def bead_geometry(self) -> dict[str, np.ndarray]:
        """``bead_width``, ``bead_height``, ``bead_area`` of each deposition segment, mm and mm^2.

        From the :class:`Bead` when given; else the area is volume over length
        and the height the spacing of this layer over the previous one, with
        the width of the rectangle of that area and height.
        """
        dep = self.depositions
        n = len(dep)
        if self.bead is not None:
            return {"bead_width": np.full(n, self.bead.width), "bead_height": np.full(n, self.bead.height),
                    "bead_area": np.full(n, self.bead.area)}
        with np.errstate(invalid="ignore", divide="ignore"):
            area = dep["volume"].to_numpy() / dep["length"].to_numpy()
            heights = self.layer_times()["height"].to_numpy()
            spacing = np.diff(heights, prepend=0.0)
            height = spacing[dep["layer"].to_numpy()] if heights.size else np.zeros(n)
            height = np.where(height > 0, height, np.nan)
            return {"bead_width": area / height, "bead_height": height, "bead_area": area}

    # -- paths ---------------------------------------------------------------

    def deposition_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Ragged points of the deposition paths.

        Returns ``(points, offsets, waypoint)``: path ``k`` is
        ``points[offsets[k]:offsets[k + 1]]`` (its start, then each move's
        end, arcs with points every 5 degrees before their end), and
        ``waypoint`` gives each point's waypoint index (the start point's is
        the waypoint before the first move, an arc's points are its own).
        """
        first_move, last_move = self._segment_moves
        dep = np.flatnonzero(self.summary["kind"].to_numpy() == "deposition")
        n_moves = last_move[dep] - first_move[dep] + 1
        move_rows = self._moves[concatenated_ranges(first_move[dep], n_moves)]
        lengths = n_moves + 1
        offsets = np.r_[0, np.cumsum(lengths)]
        waypoint = np.empty(int(offsets[-1]), np.int64)
        is_start = np.zeros(waypoint.size, bool)
        is_start[offsets[:-1]] = True
        waypoint[~is_start] = move_rows
        waypoint[is_start] = self.summary["start"].to_numpy()[dep] - 1
        w = self.operation.waypoints
        rows = np.maximum(waypoint, 0)
        # an arc's end point comes after its interior points: one group of points per original point
        counts = np.zeros(rows.size, np.int64)
        interior, counts[~is_start] = waypoint_arc_points(w, move_rows)
        group = counts + 1
        ends = np.cumsum(group)
        expand = np.repeat(np.arange(rows.size), group)
        points = np.empty((expand.size, 3))
        for axis, key in enumerate("xyz"):
            points[:, axis] = np.asarray(w[key], float)[rows[expand]]
        points[np.repeat(waypoint < 0, group)] = 0.0  # a program's very first move starts at the machine's origin
        inside = np.arange(expand.size) < np.repeat(ends - 1, group)
        points[inside] = interior
        return points, np.r_[(ends - group)[offsets[:-1]], expand.size], rows[expand]

    def generate_deposition_paths(self) -> Iterator[np.ndarray]:
        """Each deposition segment as an ``(n, 3)`` array of x, y, z points, mm."""
        points, offsets, _ = self.deposition_points()
        for k in range(offsets.size - 1):
            yield points[offsets[k]:offsets[k + 1]]

    def __repr__(self) -> str:
        return (f"<AdditivePart {self.operation.file!r}: {len(self.depositions)} depositions, "
                f"{self.n_layers} layers, {self.deposition_length:.1f} mm>")
