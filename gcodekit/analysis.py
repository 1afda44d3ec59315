"""Output stage: statistics of an emulated operation.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G1 X3 Y4 F600\\nG0 X0 Y0\\n", machine="linuxcnc")
>>> stats = op.get_statistics()
>>> stats["distance_mm"]["feed"], stats["moves"]["rapid"]
(5.0, 1)
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .emulate.operation import Operation


def operation_statistics(op: "Operation") -> dict[str, Any]:
    """Counts, distances and time of an emulated operation (see ``get_statistics``)."""
    w = op.waypoints
    motion, distance, de = w["motion"], w["distance"], w["de"]
    moving = motion > 0
    extruding = moving & (de > 0) & (distance > 0)
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
        "tools": sorted(int(t) for t in np.unique(w["tool"][moving])) if moving.any() else [],
        "bounds": op.get_bounds(),
    }
    if op.machine is not None and op.machine.process == "additive":
        stats["filament_mm"] = float(de.sum())
        stats["layers"] = count_layers(op)
    else:
        stats["filament_mm"] = None
        stats["layers"] = None
    return stats


def count_layers(op: "Operation") -> int:
    """Layers: the flavor's layer-change comments, or distinct extruding Z heights."""
    patterns = [re.compile(p) for p in (op.flavor.layer_comments if op.flavor else ())]
    t = op.table
    if patterns and t.comment_rows.size:
        text = t.comment_data.decode("utf-8", "replace")
        ascii_only = text.isascii()  # then byte offsets are character offsets
        offsets = t.comment_offsets
        count = 0
        for k in range(t.comment_rows.size):
            comment = text[offsets[k]:offsets[k + 1]].strip() if ascii_only else t.comment(k)
            if any(p.search(comment) for p in patterns):
                count += 1
        if count:
            return count
    w = op.waypoints
    extruding = (w["motion"] > 0) & (w["de"] > 0) & (w["distance"] > 0)
    return int(np.unique(np.round(w["z"][extruding], 4)).size)
