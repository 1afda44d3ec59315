"""Output stage: an additive part or a toolpath as a VTK line mesh (ParaView, PyVista).

PyVista and VTK are imported on first use, so ``import gcodekit`` stays light.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Mapping

import numpy as np

from ..errors import ConfigError, MissingDependencyError

if TYPE_CHECKING:
    import pyvista as pv

    from ..additive.part import AdditivePart
    from ..model.operation import Operation


def import_pyvista():
    """PyVista, set up for headless rendering (EGL) unless the user chose a window."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    try:
        import pyvista
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise MissingDependencyError("VTK export and 3D pictures need PyVista: pip install 'gcodekit[viz]'") from exc
    return pyvista


def _point_speed(w: dict, rows: np.ndarray) -> np.ndarray:
    """Mean speed of the move ending at each waypoint, mm/s (its length over its planned time)."""
    distance = np.asarray(w["distance"], float)[rows]
    time = np.nan_to_num(np.asarray(w["time"], float)[rows])
    return np.divide(distance, time, out=np.zeros_like(distance), where=time > 0)


def _check_vtk_path(path: str | os.PathLike) -> Path:
    path = Path(path)
    if path.suffix.lower() not in (".vtk", ".vtp"):
        raise ConfigError(f"{path}: choose a .vtk or .vtp file name")
    return path


def _save(mesh: "pv.PolyData", path: Path, compression: str | None) -> Path:
    if path.suffix.lower() == ".vtp":
        mesh.save(path, compression=compression)
    else:
        mesh.save(path)
    return path


def _runs(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and last index of each run of equal consecutive ``keys``."""
    if keys.size == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    change = np.flatnonzero(keys[1:] != keys[:-1]) + 1
    return np.r_[0, change], np.r_[change - 1, keys.size - 1]


class VTKExporter:
    """Additive parts and toolpaths to PyVista meshes and VTK files."""

    @staticmethod
    def additive_part_to_polydata(part: "AdditivePart",
                                  custom_scalars: Mapping[str, np.ndarray] | None = None) -> "pv.PolyData":
        """One poly-line cell per deposition segment, with its process data.

        Cell data (one value per segment): ``layer``, ``length``, ``start_time``,
        ``end_time``, ``time``, ``filament``, ``volume``, ``height``, ``feed``
        (length-weighted, mm/min), ``speed`` (length over time, mm/s),
        ``layer_time`` (s), ``bead_width``, ``bead_height``, ``bead_area``,
        ``tool_vector`` (5-axis programs) and each of ``custom_scalars``
        (arrays with one value per segment).  Point data: ``elapsed_time``,
        ``feed``, ``speed`` and, for 5-axis programs, ``tool_vector``.

        Examples
        --------
        >>> import gcodekit
        >>> op = gcodekit.gcode_to_operation("M83\\nG1 X10 E0.5 F600\\nG1 Y10 E0.5\\n", machine="marlin")
        >>> mesh = VTKExporter.additive_part_to_polydata(gcodekit.AdditivePart(op))
        >>> mesh.n_cells, mesh.n_points, float(mesh.cell_data["length"][0])
        (1, 3, 20.0)
        """
        pv = import_pyvista()
        points, offsets, rows = part.deposition_points()
        counts = np.diff(offsets)
        # VTK's cell array: for each cell its point count, then its point ids
        cells = np.insert(np.arange(points.shape[0], dtype=np.int64), offsets[:-1], counts)
        mesh = pv.PolyData(points, lines=cells if counts.size else None)
        w = part.operation.waypoints
        dep = part.depositions
        for key in ("layer", "length", "start_time", "end_time", "time", "filament", "volume", "height"):
            mesh.cell_data[key] = dep[key].to_numpy()
        is_move = np.ones(rows.size, bool)
        is_move[offsets[:-1]] = False
        move_rows = rows[is_move]
        length = np.asarray(w["distance"], float)[move_rows]
        feed_length = np.add.reduceat(np.asarray(w["feed"], float)[move_rows] * length,
                                      offsets[:-1] - np.arange(counts.size)) if counts.size else np.zeros(0)
        seg_length = dep["length"].to_numpy()
        mesh.cell_data["feed"] = np.divide(feed_length, seg_length, out=np.zeros_like(seg_length),
                                           where=seg_length > 0)
        seg_time = dep["time"].to_numpy()
        mesh.cell_data["speed"] = np.divide(seg_length, seg_time, out=np.zeros_like(seg_length), where=seg_time > 0)
        layer_time = part.layer_times()["time"].to_numpy()
        mesh.cell_data["layer_time"] = layer_time[dep["layer"].to_numpy()] if layer_time.size else np.zeros(0)
        for key, values in part.bead_geometry().items():
            mesh.cell_data[key] = values
        mesh.point_data["elapsed_time"] = part.operation.elapsed_time()[rows]
        mesh.point_data["feed"] = np.asarray(w["feed"], float)[rows]
        mesh.point_data["speed"] = _point_speed(w, rows)
        a, b = np.asarray(w["a"], float), np.asarray(w["b"], float)
        if np.any(a != 0) or np.any(b != 0):
            from ..analysis import tool_vectors

            mesh.point_data["tool_vector"] = tool_vectors(a[rows], b[rows])
            mesh.cell_data["tool_vector"] = tool_vectors(a[dep["start"].to_numpy()], b[dep["start"].to_numpy()])
        for key, values in (custom_scalars or {}).items():
            values = np.asarray(values)
            if values.shape[0] != mesh.n_cells:
                raise ValueError(f"custom scalar {key!r} has {values.shape[0]} values for {mesh.n_cells} segments")
            mesh.cell_data[key] = values
        return mesh

    @staticmethod
    def additive_part_to_vtk(part: "AdditivePart", path: str | os.PathLike,
                             custom_scalars: Mapping[str, np.ndarray] | None = None, *,
                             compression: str | None = "lz4") -> Path:
        """Write :meth:`additive_part_to_polydata` to ``path``: ``.vtk`` (legacy binary) or ``.vtp`` (XML).

        ``compression`` applies to ``.vtp``: ``"lz4"`` (default; six times
        faster to write than ``"zlib"`` for a 1.7 x larger file, read by VTK
        8.1 and ParaView 5.5 on), ``"zlib"``, ``"lzma"`` or None.  Returns the
        path written.
        """
        path = _check_vtk_path(path)
        return _save(VTKExporter.additive_part_to_polydata(part, custom_scalars), path, compression)

    @staticmethod
    def toolpath_to_polydata(op: "Operation") -> "pv.PolyData":
        """The moves of an emulated operation as poly-lines: one cell per run of rapids or feed moves of one tool.

        For programs that lay no material (mills, routers, lathes, lasers).
        Arcs and helices are drawn through points at most 5 degrees apart.
        Cell data: ``rapid`` (1 for a run of rapids), ``tool``, ``length``
        (mm), ``time`` (s), ``start_line`` (source line of its first move).
        Point data (each point carries the move that ends there): ``feed``
        (mm/min, 0 on rapids), ``speed`` (mm/s, length over planned time),
        ``elapsed_time`` (s), ``line`` (source line) and, when the program
        turns rotary axes A or B, ``tool_vector`` (the tool's direction).

        Raises
        ------
        NothingToShowError
            The program makes no move.

        Examples
        --------
        >>> import gcodekit
        >>> op = gcodekit.gcode_to_operation("G0 X10\\nG1 Y10 F600\\nG1 X0\\n", machine="linuxcnc", plan=False)
        >>> mesh = VTKExporter.toolpath_to_polydata(op)
        >>> mesh.n_cells, mesh.cell_data["rapid"].tolist(), mesh.cell_data["length"].tolist()
        (2, [1, 0], [10.0, 20.0])
        """
        from ..emulate.arcs import waypoint_arc_points
        from ..errors import NothingToShowError

        pv = import_pyvista()
        w = op.waypoints
        moves = np.flatnonzero(op.moving)
        if moves.size == 0:
            raise NothingToShowError(f"{op.file}: nothing to export (no move)")
        rapid = (np.asarray(w["motion"])[moves] == 1).astype(np.int8)
        tool = np.asarray(w["tool"])[moves]
        # a new cell where the kind of move or the tool changes, or where a move does not start where the last ended
        joined = np.r_[False, moves[1:] - 1 == moves[:-1]]
        key = np.cumsum((~joined) | np.r_[True, (rapid[1:] != rapid[:-1]) | (tool[1:] != tool[:-1])])
        first, last = _runs(key)
        arc_points, arc_counts = waypoint_arc_points(w, moves)
        # points of each cell: the start (the waypoint before its first move), then per move its arc points and end
        per_move = arc_counts + 1
        cell_points = np.add.reduceat(per_move, first) + 1
        offsets = np.r_[0, np.cumsum(cell_points)]
        xyz = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
        points = np.empty((offsets[-1], 3))
        owner = np.empty(offsets[-1], np.int64)  # the waypoint whose values each point carries
        move_start = np.r_[0, np.cumsum(per_move)[:-1]]  # of each move within the moves' points
        cell_of_move = np.repeat(np.arange(first.size), last - first + 1)
        base = offsets[cell_of_move] + 1 + move_start - move_start[first][cell_of_move]
        arc_at = np.r_[0, np.cumsum(arc_counts)]
        for m in np.flatnonzero(arc_counts):  # arcs are few next to straight moves
            points[base[m]:base[m] + arc_counts[m]] = arc_points[arc_at[m]:arc_at[m + 1]]
            owner[base[m]:base[m] + arc_counts[m]] = moves[m]
        points[base + arc_counts] = xyz[moves]
        owner[base + arc_counts] = moves
        before = moves[first] - 1  # a program's first move starts at the machine's origin
        points[offsets[:-1]] = np.where((before >= 0)[:, None], xyz[np.maximum(before, 0)], 0.0)
        owner[offsets[:-1]] = np.maximum(before, 0)
        cells = np.insert(np.arange(points.shape[0], dtype=np.int64), offsets[:-1], cell_points)
        mesh = pv.PolyData(points, lines=cells)
        distance = np.asarray(w["distance"], float)[moves]
        time = np.nan_to_num(np.asarray(w["time"], float))[moves]
        rows = w["command"]
        line = np.asarray(op.table.line)[rows]
        mesh.cell_data["rapid"] = rapid[first]
        mesh.cell_data["tool"] = tool[first]
        mesh.cell_data["length"] = np.add.reduceat(distance, first)
        mesh.cell_data["time"] = np.add.reduceat(time, first)
        mesh.cell_data["start_line"] = line[moves[first]]
        feed = np.where(np.asarray(w["motion"]) == 1, 0.0, np.asarray(w["feed"], float))
        mesh.point_data["feed"] = feed[owner]
        mesh.point_data["speed"] = _point_speed(w, owner)
        mesh.point_data["elapsed_time"] = op.elapsed_time()[owner]
        mesh.point_data["line"] = line[owner]
        a, b = np.asarray(w["a"], float), np.asarray(w["b"], float)
        if np.any(a != 0) or np.any(b != 0):
            from ..analysis import tool_vectors

            mesh.point_data["tool_vector"] = tool_vectors(a[owner], b[owner])
        return mesh

    @staticmethod
    def toolpath_to_vtk(op: "Operation", path: str | os.PathLike, *, compression: str | None = "lz4") -> Path:
        """Write :meth:`toolpath_to_polydata` to ``path`` (``.vtk`` or ``.vtp``, as :meth:`additive_part_to_vtk`)."""
        path = _check_vtk_path(path)
        return _save(VTKExporter.toolpath_to_polydata(op), path, compression)
