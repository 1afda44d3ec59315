"""Report stage: the numbers of one program's report, as plain data.

Everything the page shows besides pictures comes from here, so the HTML page,
the PDF and the notebook agree: the summary is the Operation's own statistics
(planned time is ``op.get_statistics()["time_s"]``), the breakdown is
``op.time_by``, and mill programs add the transpiler's stage table and text.

Examples
--------
>>> import gcodekit
>>> from gcodekit.report.build import report_data
>>> op = gcodekit.gcode_to_operation("G21\\nG1 X30 Y40 F600\\n", machine="linuxcnc", plan=False)
>>> data = report_data(op)
>>> data["summary"]["time_s"], data["summary"]["distance_mm"]["feed"]
(5.0, 50.0)
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..model.operation import Operation

#: Diagnostics listed on a page; the rest are counted (a broken program can have thousands).
MAX_DIAGNOSTICS = 200
#: Lines of the final toolpath shown on a page; a mill program larger than this is cut with a note.
MAX_TOOLPATH_LINES = 5000


def report_data(op: "Operation", *, transpile: bool = True) -> dict[str, Any]:
    """Summary, breakdown and (mill programs) transpiler stages of an emulated operation.

    Parameters
    ----------
    op : Operation
        An emulated operation (from :func:`gcodekit.gcode_to_operation`).
    transpile : bool, default: True
        Add the transpiler's stage table and final toolpath for subtractive programs.

    Returns
    -------
    dict with ``name``, ``summary``, ``breakdown`` (``by``, ``rows``), ``layers``
    (per-layer rows, additive only), ``stages`` and ``toolpath`` (mill only).
    """
    stats = op.get_statistics()
    machine = op.machine
    additive = machine is not None and machine.process == "additive"
    summary: dict[str, Any] = {
        "file": op.file,
        "machine": machine.name if machine else None,
        "process": machine.process if machine else "generic",
        "planner": (machine.planner or None) if machine else None,
        "flavor": op.flavor.name if op.flavor else None,
        "lines": stats["lines"],
        "moves": stats["moves"],
        "distance_mm": stats["distance_mm"],
        "time_s": stats["time_s"],
        "layers": stats["layers"],
        "bounds": stats["bounds"],
        "tools": stats["tools"],
        "filament_mm": stats["filament_mm"],
        "volume_mm3": None,
        "mass_g": None,
        # a problem in a subroutine file says which file
        "diagnostics": [{**d.as_dict(), "elsewhere": Path(d.file).name if d.file != op.diagnostics.file else ""}
                        for d in list(op.diagnostics)[:MAX_DIAGNOSTICS]],
        "diagnostics_total": len(op.diagnostics) + op.diagnostics.dropped,
        "errors": sum(1 for d in op.diagnostics if d.severity == "error"),
    }
    if additive and stats["filament_mm"]:
        volume = stats["filament_mm"] * op.filament_area
        summary["volume_mm3"] = volume
        summary["mass_g"] = volume / 1000.0 * machine.filament_density  # density in g/cm^3
    data: dict[str, Any] = {"name": Path(op.file).name, "summary": summary,
                            "breakdown": breakdown(op), "layers": None, "stages": None, "toolpath": None}
    if additive:
        by_layer = op.time_by("layer")
        by_layer = by_layer[by_layer.index >= 0]
        data["layers"] = [{"layer": int(k), "time_s": float(r.time_s), "filament_mm": float(r.filament_mm)}
                          for k, r in by_layer.iterrows()]
    if transpile and summary["process"] == "subtractive":
        from ..transpile import Transpiler

        t = Transpiler(op)
        data["stages"] = t.summary()
        lines = t.stage(6).splitlines()
        data["toolpath"] = {"text": "\n".join(lines[:MAX_TOOLPATH_LINES]), "lines": len(lines),
                            "shown": min(len(lines), MAX_TOOLPATH_LINES)}
    return data


def breakdown(op: "Operation") -> dict[str, Any]:
    """Time and distance by slicer feature when the program names features, else by tool.

    Rows that took no time and moved nowhere (a tool loaded but never used) are left out.
    """
    from ..analysis import features

    by = "feature" if np.any(features(op) != "") else "tool"
    table = op.time_by(by)
    table = table[(table["time_s"] > 0) | (table["distance_mm"] > 0)]
    rows = []
    for key, r in table.iterrows():
        label = (str(key) or "(before the first feature)") if by == "feature" else f"T{int(key)}"
        rows.append({"label": label, "time_s": float(r.time_s), "distance_mm": float(r.distance_mm),
                     "extrude_mm": float(r.extrude_mm)})
    return {"by": by, "rows": rows}


def key_figures(data: dict[str, Any]) -> dict[str, Any]:
    """The few numbers the index shows for a program."""
    s = data["summary"]
    return {"machine": s["machine"], "flavor": s["flavor"], "time_s": s["time_s"],
            "distance_mm": s["distance_mm"]["feed"] + s["distance_mm"]["rapid"], "layers": s["layers"],
            "mass_g": s["mass_g"], "diagnostics": s["diagnostics_total"], "errors": s["errors"]}
