"""Model: a program's statistics and its one summary record.

:func:`operation_statistics` counts moves, distances, time, layers, tools
and filament; :func:`summary` adds what identifies the program (file,
flavor, machine, planner) and its diagnostics.  ``gcodekit info``, the
report and the notebooks all show this one record.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G1 X3 Y4 F600\\nG0 X0 Y0\\n", machine="linuxcnc")
>>> stats = op.get_statistics()
>>> stats["distance_mm"]["feed"], stats["moves"]["rapid"]
(5.0, 1)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .derived import screw_extruder
from .filament import filament_used, slicer_convention

if TYPE_CHECKING:
    from .operation import Operation

__all__ = ["operation_statistics", "summary"]


def operation_statistics(op: "Operation") -> dict[str, Any]:
    """Counts, distances and time of an emulated operation (see ``get_statistics``)."""
    w = op.waypoints
    motion, distance, de = w["motion"], w["distance"], w["de"]
    moving = motion > 0
    extruding = op.depositing
    stats: dict[str, Any] = {
        "lines": op.n_lines,
        "commands": len(op.table),
        "moves": {
            "rapid": int(np.count_nonzero(motion == 1)),
            "feed": int(np.count_nonzero(motion == 2)),
            "arc_cw": int(np.count_nonzero(motion == 3)),
            "arc_ccw": int(np.count_nonzero(motion == 4)),
            "extruding": int(np.count_nonzero(extruding)),
        },
        "distance_mm": {
            "feed": float(distance[motion >= 2].sum()),
            "rapid": float(distance[motion == 1].sum()),
            "extrude": float(distance[extruding].sum()),
        },
        "time_s": float(np.nansum(w["time"])),
        # moves whose time gcodekit cannot know (a feed move with no feed rate): left out of time_s
        "untimed_moves": int(np.count_nonzero(moving & np.isnan(np.asarray(w["time"], float)))),
        "tools": _distinct(w["tool"][moving]),
        "bounds": op.get_bounds(),
    }
    if op.process == "additive":
        if screw_extruder(op):  # pellets: no filament
            stats["filament_mm"] = stats["filament_convention"] = stats["filament_pushed_mm"] = None
        else:
            stats["filament_mm"] = filament_used(op)
            stats["filament_convention"] = slicer_convention(op)
            stats["filament_pushed_mm"] = float(de.sum())
        stats["layers"] = op.n_layers
    else:
        stats["filament_mm"] = stats["filament_convention"] = stats["filament_pushed_mm"] = None
        stats["layers"] = None
    return stats


def _distinct(values: np.ndarray) -> list[int]:
    """The distinct values, ascending: ``np.unique``'s, without its import of ``numpy.ma`` (20 ms of a
    ``gcodekit info``, which calls no other ``np.unique`` that needs it)."""
    ordered = np.sort(values)
    return [int(v) for v in ordered[np.r_[True, ordered[1:] != ordered[:-1]]]] if ordered.size else []


def summary(op: "Operation") -> dict[str, Any]:
    """The one summary record of an emulated program: what ``gcodekit info --json`` prints,
    the report's summary and the notebooks' first table.

    Keys: ``file, flavor, machine, process, planner, lines, commands, moves,
    bounds, distance_mm, time_s, untimed_moves`` (moves left out of
    ``time_s`` because no feed rate was in force), ``layers, filament_mm,
    filament_convention, filament_pushed_mm, volume_mm3, mass_g, tools,
    diagnostics`` (each with
    its ``file``, ``line``, ``column``, ``severity``, ``message``, ``text``),
    ``diagnostics_dropped``, ``diagnostics_total``, ``errors`` and ``slicer``
    (what the slicer wrote into the file, :meth:`SlicerFigures.as_dict`, or
    None).  Volume and mass are made from ``filament_mm`` for filament
    printers, else None.
    """
    stats = op.get_statistics()
    machine = op.machine
    record: dict[str, Any] = {
        "file": op.file,
        "flavor": op.flavor.name if op.flavor else None,
        "machine": machine.name if machine else None,
        "process": machine.process if machine else "generic",
        "planner": (machine.planner or None) if machine else None,
        **{key: stats[key] for key in ("lines", "commands", "moves", "bounds", "distance_mm", "time_s", "untimed_moves",
                                       "layers",
                                       "filament_mm", "filament_convention", "filament_pushed_mm")},
        "volume_mm3": None,
        "mass_g": None,
        "tools": stats["tools"],
        "diagnostics": [{"file": d.file, **d.as_dict()} for d in op.diagnostics],
        "diagnostics_dropped": op.diagnostics.dropped,
        "diagnostics_total": len(op.diagnostics) + op.diagnostics.dropped,
        "errors": sum(1 for d in op.diagnostics if d.severity == "error"),
        "slicer": None,
    }
    figures = op.slicer_figures()
    if figures.slicer is not None or figures.time_s is not None or figures.filament_mm is not None:
        record["slicer"] = figures.as_dict()
    if stats["filament_mm"]:
        volume = stats["filament_mm"] * op.filament_area
        record["volume_mm3"] = volume
        record["mass_g"] = volume / 1000.0 * machine.filament_density  # density in g/cm^3
    return record
