"""Parse stage: the arguments of named calls (Sinumerik ``NAME(a, b, c)``, kept as text by the reader)."""

from __future__ import annotations

__all__ = ["call_bead_area"]


def call_bead_area(arguments: str) -> float:
    """Width x height (mm^2) from a bead call's argument text ``"8,2,1400"``; NaN if unreadable.

    Examples
    --------
    >>> call_bead_area("8.0000,2.0000,1400"), call_bead_area("0,0,1")
    (16.0, 0.0)
    """
    values = arguments.strip("() ").split(",")
    try:
        return float(values[0]) * float(values[1])
    except (IndexError, ValueError):
        return float("nan")
