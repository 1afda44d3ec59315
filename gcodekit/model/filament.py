"""Model: the filament a program uses, counted the way its slicer counts it.

A print's filament can be counted several ways, and slicers disagree:

``net``
    The sum of the E steps as programmed: retractions subtract.
``consumed``
    Filament drawn from the spool by the part: the high-water mark of the
    programmed E from the first layer on.  A retraction that is primed back
    is not drawn twice, one left at the end still counts, and start code
    before the first layer (purge lines) is the printer's, not the part's.
    The ``; filament used [mm]`` of PrusaSlicer, SuperSlicer, Slic3r PE,
    OrcaSlicer, Bambu Studio and Creality Print (all Slic3r's descendants,
    whose G-code writer counts the E it emits this way).
``sliced``
    The net E from the first to the last extruding move of the layers: the
    sliced paths only, so the start code's purge line, the prime before the
    first path and the retraction after the last, and the end code are all
    left out.  CuraEngine's ``;Filament used:`` (4.x, 5.x and the 15.x
    legacy engine).
``positive``
    Every forward E step of the whole program, start code and re-primes
    included.

How each rule was established: against the figures the slicers wrote into
real files -- PrusaSlicer 2.5 (files made here), Slic3r PE 1.36, OrcaSlicer
2.3 and Creality Print 5.1 (files from public repositories), CuraEngine 4.13
(files made here with Debian's Cura printer definitions) and Cura 5.9 (a
public file); see ``tests/test_slicer_figures.py``.  Bambu Studio 1.7 writes
no filament figure into the file; Simplify3D's and ideaMaker's rules are not
established (no file of theirs to check against) and their files count ``net``.

All of them count E *as programmed*: an M221 flow override is the operator's
correction at the machine, which slicers do not see.  What the extruder
actually pushes (M221 applied) is the waypoint column ``de``; deposited
volume and mass come from that.

Examples
--------
>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("M83\\nM221 S50\\nG1 X10 E2 F600\\nG1 E-1\\nG1 E1\\n", machine="marlin")
>>> filament_used(op), filament_used(op, "consumed"), filament_used(op, "positive")
(2.0, 2.0, 3.0)
>>> float(op.waypoints["de"].sum())  # M221 S50 halves what is pushed
1.0
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .operation import Operation

CONVENTIONS = ("net", "consumed", "sliced", "positive")
#: How each slicer family (:attr:`SlicerFigures.family`) counts filament.
RULES = {"slic3r": "consumed", "cura": "sliced"}


def programmed_e(w: dict) -> np.ndarray:
    """E of each waypoint as the program wrote it, mm: ``de`` without the M221 multiplier."""
    de = np.asarray(w["de"], float)
    flow = np.asarray(w["flow"], float) if "flow" in w else np.ones(1)
    return np.divide(de, flow, out=np.zeros_like(de), where=flow > 0)


def slicer_convention(op: "Operation") -> str:
    """The convention of the slicer that wrote ``op`` (``net`` when unknown)."""
    return RULES.get(op.slicer_figures().family or "", "net")


def filament_used(op: "Operation", convention: str | None = None) -> float:
    """Filament the program uses, mm of filament (see the module docstring).

    Parameters
    ----------
    op : Operation
        An emulated additive operation.
    convention : {"net", "consumed", "sliced", "positive"}, default: the slicer's
        None takes the convention of the slicer named in the header, so the
        figure matches the one the slicer wrote into the file.
    """
    from ..errors import check_choice

    convention = check_choice("convention", convention or slicer_convention(op), CONVENTIONS)
    e = programmed_e(op.waypoints)
    if convention == "net":
        return float(e.sum())
    if convention == "positive":
        return float(e[e > 0].sum())
    if convention == "sliced":
        extruding = np.flatnonzero(op.depositing & (op.layers >= 0))
        return float(e[extruding[0]:extruding[-1] + 1].sum()) if extruding.size else 0.0
    first = np.flatnonzero(op.layers >= 0)
    start = int(first[0]) if first.size else 0
    drawn = np.cumsum(e)
    before = float(np.max(drawn[:start], initial=0.0))
    return float(max(np.max(drawn[start:], initial=0.0), before) - before)


#: How slicers state the filament diameter in their header or settings block (the first group is it, mm):
#: Slic3r/PrusaSlicer/OrcaSlicer/Bambu Studio, KISSlicer, Cura's Griffin header, Simplify3D.
_STATED_DIAMETER = re.compile(
    r"(?im)^;\s*(?:filament_diameter\s*=|fiber_dia_mm\s*=|EXTRUDER_TRAIN\.0\.MATERIAL\.DIAMETER:|"
    r"filamentDiameters?\s*,|Filament Diameter(?:\s*#\d+)?\s*:)\s*([0-9]*\.?[0-9]+)")


def stated_diameter(text: str) -> float | None:
    """The filament diameter a program's header or settings block states, mm; None when it states none.

    The first one found counts (the first extruder's); values outside 1-4 mm are no filament diameter.

    Examples
    --------
    >>> stated_diameter("; KISSlicer - FREE\\n; fiber_dia_mm = 3\\nG1 X1 E1\\n")
    3.0
    >>> stated_diameter("; filament_diameter = 2.85,1.75\\n"), stated_diameter("G1 X1\\n")
    (2.85, None)
    """
    for match in _STATED_DIAMETER.finditer(text):
        value = float(match[1])
        if 1.0 <= value <= 4.0:
            return value
    return None


#: A program whose E words fall on this share of its extruding moves writes them relative.
RELATIVE_SHARE = 0.3


def relative_e_suspect(op: "Operation") -> tuple[int, int, int] | None:
    """``(line, falling, extruding)`` when the E words read as absolute fall on many moves with XY motion.

    A slicer that writes E relative (KISSlicer does, per move) without an
    M83 leaves a firmware in absolute E, where each E is a position: the
    filament then runs back and forth and sums to about nothing.  Absolute E
    falls on a printing move only where a slicer wipes while retracting, a
    small share; at :data:`RELATIVE_SHARE` or more of at least 20 extruding
    moves this returns the first such move's source line and the counts.
    None when the program sets the E mode itself (M82/M83) or looks absolute.
    """
    from ..parse.table import NAME_ID, in_ids

    t, w = op.table, op.waypoints
    if in_ids(t.name, [NAME_ID["extrude_absolute"], NAME_ID["extrude_relative"]]).any():
        return None
    de = programmed_e(w)
    moving = (np.asarray(w["motion"]) >= 2) & (np.asarray(w["distance"]) > 0) & (de != 0)
    falling = moving & (de < 0)
    n, k = int(moving.sum()), int(falling.sum())
    if n < 20 or k < RELATIVE_SHARE * n:
        return None
    rows = w["command"] if "command" in w else np.arange(len(t))
    return int(t.line[rows[int(np.flatnonzero(falling)[0])]]), k, n
