"""Model: the process data of one step, made from the waypoint columns when asked for.

``Operation.process_data[i]`` is a :class:`ProcessData` (or its additive or
subtractive kind) built from row ``i`` of the columns; :class:`LazyList` is
the sequence that builds them on indexing, so a program of millions of
steps never holds millions of objects.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["ProcessData", "AdditiveProcessData", "SubtractiveProcessData", "LazyList"]


@dataclass(frozen=True)
class ProcessData:
    """What the machine model predicts at the end of one step.

    Attributes
    ----------
    location : tuple of float
        Machine X, Y, Z (mm) and A, B, C (degrees).
    feed_rate : float
        Feed rate in force, mm/min.
    elapsed_time : float
        Time since the program started, s.
    distance : float
        Path length of the step, mm.
    duration : float
        Time the step takes, s.
    motion : str
        ``""``, ``"rapid"``, ``"feed"``, ``"arc_cw"`` or ``"arc_ccw"``.
    """

    location: tuple[float, float, float, float, float, float]
    feed_rate: float
    elapsed_time: float
    distance: float
    duration: float
    motion: str


@dataclass(frozen=True)
class AdditiveProcessData(ProcessData):
    """Process data of a deposition step.

    Attributes
    ----------
    deposited_volume : float
        Material deposited by the step, mm^3 (filament length times its area).
    bead_area : float
        Cross-section of the deposited bead, mm^2 (volume over path length;
        0 for travel).
    extruder_type : str
        ``"filament"`` for FFF, ``"screw"`` for pellet LFAM, ``"wire"`` for DED.
    """

    deposited_volume: float = 0.0
    bead_area: float = 0.0
    extruder_type: str = "filament"


@dataclass(frozen=True)
class SubtractiveProcessData(ProcessData):
    """Process data of a milling step.

    Attributes
    ----------
    spindle_speed : float
        rpm, negative when counter-clockwise.
    removed_volume : float or None
        Material the step removed, mm^3, once a cutting simulation has run
        (:func:`gcodekit.cut.cut`); None before.
    """

    spindle_speed: float = 0.0
    removed_volume: float | None = None


class LazyList(Sequence):
    """A read-only list whose items are made from columns when indexed."""

    def __init__(self, size: int, make):
        self._size = size
        self._make = make

    def __len__(self) -> int:
        return self._size

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self._make(k) for k in range(*i.indices(self._size))]
        if not -self._size <= i < self._size:
            raise IndexError(f"index {i} out of range for {self._size} items")
        return self._make(i % self._size)

    def __repr__(self) -> str:
        return f"<{self._size} items>"
