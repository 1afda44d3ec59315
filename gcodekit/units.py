"""Units: the one definition of the inch, and conversions between program units and mm.

Inside gcodekit every length is in mm and every speed in mm/min or mm/s;
program words, tool tables and firmware settings in inches are converted on
the way in, with these.

Examples
--------
>>> mm_per("inch"), mm_per("mm")
(25.4, 1.0)
>>> to_mm(2.0, "inch")
50.8
"""

from __future__ import annotations

__all__ = ["MM_PER_INCH", "UNITS", "mm_per", "to_mm"]

#: Millimetres in an inch (exact, by definition since 1959).
MM_PER_INCH = 25.4
#: Length units gcodekit reads: name -> millimetres per unit.
UNITS = {"mm": 1.0, "inch": MM_PER_INCH}


def mm_per(unit: str) -> float:
    """Millimetres in one ``unit`` (``"mm"`` or ``"inch"``)."""
    from .errors import check_choice

    return UNITS[check_choice("unit", unit, UNITS)]


def to_mm(value: float, unit: str) -> float:
    """``value`` in ``unit`` as millimetres."""
    return value * mm_per(unit)
