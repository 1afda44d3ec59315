"""Report stage: the numbers of one program's report, as plain data.

Everything the page shows besides pictures comes from here, so the HTML page,
the PDF and the notebook agree: the summary is the Operation's one summary
record (``op.summary()``, what ``gcodekit info --json`` prints), the breakdown is
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

from ..model.slicer import compare

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
    (per-layer rows, additive only), ``slicer_rows`` (gcodekit's figures
    beside the slicer's, :func:`gcodekit.model.slicer.compare`),
    ``slicer_layers`` (the layers the slicer's progress marks close,
    :func:`gcodekit.analysis.slicer_layer_times`), ``stages`` and ``toolpath``
    (mill only).
    """
    summary = op.summary()
    additive = summary["process"] == "additive"
    # the page lists the first diagnostics, each saying which file when it is a subroutine file's
    summary["diagnostics"] = [{**d, "elsewhere": Path(d["file"]).name if d["file"] != op.diagnostics.file else ""}
                              for d in summary["diagnostics"][:MAX_DIAGNOSTICS]]
    data: dict[str, Any] = {"name": Path(op.file).name, "summary": summary,
                            "breakdown": breakdown(op), "layers": None, "stages": None, "toolpath": None,
                            "slicer_rows": compare(summary), "slicer_layers": []}
    if additive:
        by_layer = op.time_by("layer")
        by_layer = by_layer[by_layer.index >= 0]
        data["layers"] = [{"layer": int(k), "time_s": float(r.time_s), "filament_mm": float(r.filament_mm)}
                          for k, r in by_layer.iterrows()]
        marks = op.slicer_layer_times()
        data["slicer_layers"] = [{"layer": int(k), "layers": int(r.layers), "time_s": float(r.time_s),
                                  "slicer_time_s": float(r.slicer_time_s), "elapsed_s": float(r.elapsed_s),
                                  "slicer_elapsed_s": float(r.slicer_elapsed_s)} for k, r in marks.iterrows()]
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
    by = "feature" if np.any(op.features != "") else "tool"
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
