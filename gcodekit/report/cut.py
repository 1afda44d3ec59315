"""Front end: the material-removal section of a mill program's report (the cut part and its volumes).

The report cuts a box of stock made from the program (see
:class:`gcodekit.cut.CutSimulation`) with the program's tools: a tool
library ``tools/<program name>.toml`` beside the program when there is one,
else the machine's tool table's diameters, else 6 mm flat end mills (said
on the page).  The grid is coarsened to at most :data:`REPORT_MAX_CELLS`
cells so that a report stays quick.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

#: Cells the report's cut grid may have at most (2,000 x 2,000).
REPORT_MAX_CELLS = 4_000_000
#: Moves of the highest removal rate listed on the page.
TOP_MOVES = 5


def tools_for(op):
    """The tool library a report cuts ``op`` with, and where it came from."""
    from ..cut import ToolLibrary
    from ..emulate.tooltable import ToolTable

    library = ToolLibrary()
    beside = Path(op.file).parent / "tools" / f"{Path(op.file).stem}.toml"
    if beside.is_file():
        library = ToolLibrary.read(beside)
    table = getattr(op.machine, "tool_table", "")
    if table:
        library = library.merged(ToolLibrary.from_tool_table(ToolTable.read(table, units=op.machine.tool_table_units)))
    return library


def cut_section(op) -> dict[str, Any] | None:
    """The numbers of the report's cut section and the result (under ``"result"``), or None without feed moves."""
    from ..cut import CutSimulation
    from ..cut.path import moving_rows

    w = op.waypoints
    if w is None or moving_rows(w).size == 0:
        return None
    sim = CutSimulation(op, tools=tools_for(op), max_cells=REPORT_MAX_CELLS)
    result = sim.run()
    if not math.isfinite(result.stock_mm3) or result.stock_mm3 <= 0:
        return None
    summary = result.summary()
    summary.update(removal_rates(result))
    summary["notes"] = [{"line": d.line, "severity": d.severity, "message": d.message} for d in result.notes[:20]]
    summary["result"] = result
    return summary


def removal_rates(result, top: int = TOP_MOVES) -> dict[str, Any]:
    """The removal rate figures of the page: ``cutting_s`` (time of the moves that cut), ``mean_rate``
    (removed volume over it, mm^3/min) and ``top_moves`` (the ``top`` moves of the highest rate, each
    ``{"line", "motion", "removed_mm3", "rate"}``)."""
    import numpy as np

    from ..parse.table import MOTION_NAMES

    cutting = np.flatnonzero(result.cutting)
    cutting_s = float(result.time[cutting].sum())
    rate = result.removal_rate
    best = cutting[np.argsort(-rate[cutting], kind="stable")[:top]]
    return {"cutting_s": cutting_s,
            "mean_rate": result.removed_mm3 / (cutting_s / 60) if cutting_s > 0 else 0.0,
            "top_moves": [{"line": int(result.lines[r]), "motion": MOTION_NAMES[int(result.motion[r])],
                           "removed_mm3": float(result.removed[r]), "rate": float(rate[r])} for r in best]}
