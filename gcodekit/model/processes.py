"""Model: the Operation of each process -- additive (FFF, LFAM, DED) and subtractive (mill, lathe).

The machine preset's ``process`` picks the class (:data:`OPERATION_CLASSES`);
each adds what its process predicts: deposited volume and bead area, or
spindle speed.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..parse.calls import call_bead_area
from ..parse.table import NAME_ID
from .operation import Operation
from .process_data import AdditiveProcessData, SubtractiveProcessData

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["AdditiveOperation", "SubtractiveOperation", "OPERATION_CLASSES"]


class AdditiveOperation(Operation):
    """An Operation of a deposition process (FFF, LFAM, DED)."""

    process_data_class = AdditiveProcessData
    process = "additive"

    @property
    def work(self) -> np.ndarray:
        """Per waypoint, whether it lays the part: depositing from the first layer on (start-code purge lines
        are not the part)."""
        return self._kept("work", lambda: self.depositing & (self.layers >= 0))

    def volumes(self) -> np.ndarray:
        """Material laid by each waypoint, mm^3 (see :meth:`deposited_volumes`)."""
        return self.deposited_volumes()

    def to_vtk(self, path: str | os.PathLike | None = None, **options):
        """The deposition paths as a PyVista mesh, written to ``path`` (``.vtp``/``.vtk``) when given.

        Builds an :class:`~gcodekit.additive.AdditivePart` (``options`` such as
        ``bead=`` and ``layer_normal=`` go to it) and exports it with
        :meth:`~gcodekit.export.vtk.VTKExporter.additive_part_to_polydata`.
        """
        from ..additive import AdditivePart
        from ..export.vtk import VTKExporter

        part = AdditivePart(self, **options)
        if path is not None:
            VTKExporter.additive_part_to_vtk(part, path)
        return VTKExporter.additive_part_to_polydata(part)

    def to_dataframe(self) -> "pd.DataFrame":
        """As :meth:`Operation.to_dataframe`, plus ``deposited_volume`` (mm^3,
        NaN where material is laid in an unknown amount) once emulated."""
        frame = super().to_dataframe()
        if self.waypoints is not None:
            frame["deposited_volume"] = self.deposited_volumes()
        return frame

    @property
    def filament_area(self) -> float:
        d = self.machine.filament_diameter if self.machine else 1.75
        return float(np.pi * d * d / 4.0)

    def deposited_volumes(self) -> np.ndarray:
        """Material laid by each waypoint (mm^3).

        Filament machines: E pushed times the filament's cross-section (a
        retraction counts negative).  Screw extruders (BAAM): rpm x minutes x
        the screw's displacement per revolution on each depositing move; NaN
        when the machine does not give its displacement.  Bead extruders
        (CEAD): the programmed bead's width x height x the move's length on
        each depositing move.  Wire and powder (DED): unknown, NaN.  Which
        moves deposit is :attr:`depositing`.
        """
        w = self.waypoints
        kind = self.machine.extruder_type if self.machine else "filament"
        if kind == "filament":
            return np.asarray(w["de"], float) * self.filament_area
        on = self.depositing
        if kind == "screw":
            per_rev = self.machine.screw_displacement * 1000.0 or np.nan  # cm^3 -> mm^3
            minutes = np.nan_to_num(np.asarray(w["time"], float)) / 60.0
            return np.where(on, np.asarray(w["spindle"], float) * minutes * per_rev, 0.0)
        if kind == "bead":
            return np.where(on, self.bead_areas() * np.asarray(w["distance"], float), 0.0)
        return np.where(on, np.nan, 0.0)

    def bead_areas(self) -> np.ndarray:
        """Programmed bead cross-section in force at each waypoint (mm^2).

        The last ``set_bead`` command (CEAD's ``EXTRUDERSPEED2(w, h, ..)``)
        at or before the waypoint gives width x height; NaN before the
        first one.

        Examples
        --------
        >>> import gcodekit
        >>> op = gcodekit.gcode_to_operation("EXTRUDERSPEED2(8,2,1400)\\nG1 F600 X10 EM=1\\nM30\\n", "cead")
        >>> op.bead_areas().tolist()[-2:]
        [16.0, 16.0]
        """
        w = self.waypoints
        rows = np.asarray(w["command"])
        n = len(self.table)
        calls = np.flatnonzero(np.asarray(self.table.name) == NAME_ID["set_bead"]) if n else np.zeros(0, int)
        area_of_row = np.full(n, np.nan)
        set_at = np.full(n, -1)
        for row in calls.tolist():
            area_of_row[row] = call_bead_area(self.table.named.get(row, ("", ""))[1])
            set_at[row] = row
        np.maximum.accumulate(set_at, out=set_at)  # the last call at or before each row
        area = np.where(set_at >= 0, area_of_row[np.maximum(set_at, 0)], np.nan)
        return area[rows] if n else np.full(len(rows), np.nan)

    def _process_columns(self) -> dict[str, np.ndarray]:
        return {**super()._process_columns(), "deposited_volume": self.deposited_volumes()}

    def _process_fields(self, k: int, columns: dict[str, np.ndarray]) -> dict[str, Any]:
        fields = super()._process_fields(k, columns)
        volume = float(columns["deposited_volume"][k])
        distance = fields["distance"]
        fields.update(deposited_volume=volume, bead_area=volume / distance if distance > 0 and volume > 0 else 0.0,
                      extruder_type=self.machine.extruder_type if self.machine else "filament")
        return fields


class SubtractiveOperation(Operation):
    """An Operation of a machining process (mill, router, lathe)."""

    process_data_class = SubtractiveProcessData
    process = "subtractive"

    @property
    def depositing(self) -> np.ndarray:
        """A machining process lays no material: False at every waypoint."""
        return self._kept("depositing", lambda: np.zeros(len(self.waypoints["x"]), bool))

    def volumes(self) -> np.ndarray:
        """Material each waypoint removes, mm^3, once a cutting simulation has added its
        ``removed_volume`` column; NaN before."""
        w = self.waypoints
        if "removed_volume" in w:
            return np.asarray(w["removed_volume"], float)
        return super().volumes()

    def _process_fields(self, k: int, columns: dict[str, np.ndarray]) -> dict[str, Any]:
        fields = super()._process_fields(k, columns)
        removed = self.waypoints.get("removed_volume")
        fields.update(spindle_speed=float(self.waypoints["spindle"][k]),
                      removed_volume=None if removed is None else float(removed[k]))
        return fields


OPERATION_CLASSES = {"additive": AdditiveOperation, "subtractive": SubtractiveOperation, "generic": Operation}
