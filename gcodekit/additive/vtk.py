"""Output stage: an additive part as a VTK line mesh (ParaView, PyVista).

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

    from .part import AdditivePart


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


class VTKExporter:
    """Additive parts to PyVista meshes and VTK files."""

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
        path = Path(path)
        if path.suffix.lower() not in (".vtk", ".vtp"):
            raise ConfigError(f"{path}: choose a .vtk or .vtp file name")
        mesh = VTKExporter.additive_part_to_polydata(part, custom_scalars)
        if path.suffix.lower() == ".vtp":
            mesh.save(path, compression=compression)
        else:
            mesh.save(path)
        return path
