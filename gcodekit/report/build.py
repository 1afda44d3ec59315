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

import itertools
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.slicer import compare

if TYPE_CHECKING:
    import pandas as pd

    from ..model.operation import Operation

#: Diagnostics listed on a page; the rest are counted (a broken program can have thousands).
MAX_DIAGNOSTICS = 200
#: Lines of the final toolpath shown on a page; a mill program larger than this is cut with a note.
MAX_TOOLPATH_LINES = 5000


def report_data(op: "Operation", *, transpile: bool = True, cut: bool = True) -> dict[str, Any]:
    """Summary, breakdown and (mill programs) transpiler stages of an emulated operation.

    Parameters
    ----------
    op : Operation
        An emulated operation (from :func:`gcodekit.gcode_to_operation`).
    transpile : bool, default: True
        Add the transpiler's stage table and final toolpath for subtractive programs.
    cut : bool, default: True
        Add the material removal of mill programs (:mod:`gcodekit.report.cut`).

    Returns
    -------
    dict with ``name``, ``summary``, ``breakdown`` (``by``, ``rows``), ``layers``
    (per-layer rows, additive only), ``slicer_rows`` (gcodekit's figures
    beside the slicer's, :func:`gcodekit.model.slicer.compare`),
    ``slicer_layers`` (the layers the slicer's progress marks close,
    :func:`gcodekit.analysis.slicer_layer_times`), ``stages``, ``toolpath`` and
    ``cut`` (mill only).
    """
    summary = op.summary()
    additive = summary["process"] == "additive"
    # the page lists the first diagnostics, each saying which file when it is a subroutine file's
    summary["diagnostics"] = [{**d, "elsewhere": Path(d["file"]).name if d["file"] != op.diagnostics.file else ""}
                              for d in summary["diagnostics"][:MAX_DIAGNOSTICS]]
    data: dict[str, Any] = {"name": Path(op.file).name, "summary": summary,
                            "breakdown": breakdown(op), "layers": None, "stages": None, "toolpath": None,
                            "slicer_rows": compare(summary), "slicer_layers": [],
                            "cut": None}
    if additive:
        by_layer = op.time_by("layer")
        by_layer = by_layer[by_layer.index >= 0]
        data["layers"] = _rows(by_layer, "layer", time_s=float, filament_mm=float)
        data["slicer_layers"] = _rows(op.slicer_layer_times(), "layer", layers=int, time_s=float, slicer_time_s=float,
                                      elapsed_s=float, slicer_elapsed_s=float)
    if transpile and summary["process"] == "subtractive":
        from ..transpile import Transpiler

        t = Transpiler(op)
        data["stages"] = t.summary()
        shown = list(itertools.islice(t.lines(6), MAX_TOOLPATH_LINES))  # the title line, then the summary's lines
        data["toolpath"] = {"text": "\n".join(shown), "lines": data["stages"][6]["lines"] + 1, "shown": len(shown)}
    if cut and summary["process"] == "subtractive" and "lathe" not in op.machine.name:
        from .cut import cut_section

        data["cut"] = cut_section(op)
    return data


def breakdown(op: "Operation") -> dict[str, Any]:
    """Time and distance by slicer feature when the program names features, else by tool.

    Rows that took no time and moved nowhere (a tool loaded but never used) are left out.
    """
    by = "feature" if np.any(op.features != "") else "tool"
    table = op.time_by(by)
    table = table[(table["time_s"] > 0) | (table["distance_mm"] > 0)]
    rows = _rows(table, "label", time_s=float, distance_mm=float, extrude_mm=float)
    for r in rows:
        r["label"] = (str(r["label"]) or "(before the first feature)") if by == "feature" else f"T{int(r['label'])}"
    return {"by": by, "rows": rows}


def _rows(table: "pd.DataFrame", index: str, **columns: type) -> list[dict[str, Any]]:
    """Each row of ``table`` as a dict of plain numbers: its index under the name ``index`` (an int for the
    layers), then ``columns`` converted by their types.  Read column by column: ``iterrows`` builds a
    Series per row, most of the report's numbers' time."""
    keys = table.index.tolist()
    if index == "layer":
        keys = [int(k) for k in keys]
    values = [[kind(v) for v in table[name].tolist()] for name, kind in columns.items()]
    return [{index: k, **dict(zip(columns, row))} for k, *row in zip(keys, *values)]


def key_figures(data: dict[str, Any]) -> dict[str, Any]:
    """The few numbers the index shows for a program."""
    s = data["summary"]
    return {"machine": s["machine"], "flavor": s["flavor"], "time_s": s["time_s"],
            "distance_mm": s["distance_mm"]["feed"] + s["distance_mm"]["rapid"], "layers": s["layers"],
            "mass_g": s["mass_g"], "diagnostics": s["diagnostics_total"], "errors": s["errors"]}
