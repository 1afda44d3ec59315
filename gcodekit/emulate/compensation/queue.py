"""Emulate stage: the compensated move held back until the next one shows its corner (rs274's queue).

rs274 does not send a compensated move on at once: it queues it
(interp_queue.cc) until the next move is known, because an inside corner
moves the queued move's end to where the two offset paths meet
(``move_endpoint_and_flush``), and an outside corner ends it where the tool
is.  Moves that do not move in the plane (a plunge) queue behind it and end
where it ends.  Moving the end can make the queued move a gouge, which is
checked here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .geometry import TINY, turn


class QueuedArc(NamedTuple):
    """A queued arc as programmed: its centre, direction and sweep (radians, signed)."""

    centre: np.ndarray
    ccw: bool
    sweep: float


@dataclass
class Queue:
    """The queued move: its waypoint in the output and what its gouge checks need."""

    row: int | None = None  #: its waypoint in the compensated path; None when nothing is queued
    staying: list[int] = field(default_factory=list)  #: later waypoints that end where it does
    start: np.ndarray | None = None  #: where the tool starts it
    direction: np.ndarray | None = None  #: a straight move's programmed direction
    arc: QueuedArc | None = None  #: an arc's programmed centre and sweep

    def hold(self, row: int, start: np.ndarray, direction: np.ndarray | None = None,
             arc: QueuedArc | None = None) -> None:
        """Queue the move written as waypoint ``row``, started at ``start``, in place of the one before."""
        self.row, self.staying, self.start, self.direction, self.arc = row, [], start, direction, arc

    def clear(self) -> None:
        """Nothing queued (compensation is off)."""
        self.hold(None, None)

    def rows(self) -> list[int]:
        """The waypoints whose end moves with the queued move's."""
        return [self.row, *self.staying]

    def runs_backwards(self, end: np.ndarray) -> bool:
        """Whether the queued straight move, ended at ``end``, would run against its programmed direction
        (rs274's "concave corner cannot be reached" for a straight move)."""
        return float((end - self.start) @ self.direction) < -TINY

    def overruns(self, end: np.ndarray, inch: bool) -> bool:
        """Whether the queued arc, ended at ``end``, would turn further round than programmed.

        rs274's ``move_endpoint_and_flush`` compares the turns (radians) with
        a tolerance in program units: 0.001 in G20, 0.0254 in G21.
        """
        if self.arc is None:
            return False
        return abs(turn(self.start, self.arc.centre, self.arc.ccw, end)) > abs(self.arc.sweep) + (
            0.001 if inch else 0.0254)
