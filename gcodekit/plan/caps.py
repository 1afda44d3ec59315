"""Plan stage: the notice that programmed feeds exceed what the machine allows.

Firmware quietly caps a move's speed at its axes' maximum rates (GRBL's
``$110``-``$112``, Marlin's ``M203``), so a program whose feeds are above them
runs longer than its feeds say.  :func:`report_feed_caps` says so once, with
how many moves, by how much, and the time the cap adds.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .moves import PlannerMoves

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

#: Capped speeds within this fraction of the programmed one are rounding, not a cap.
TOLERANCE = 1e-6


def report_feed_caps(op: "EmulatedProgram", moves: PlannerMoves, allowed_v: np.ndarray, limits: str) -> float:
    """One info diagnostic when feed moves are programmed faster than ``allowed_v``; returns the time added, s.

    Parameters
    ----------
    op : EmulatedProgram
        Its diagnostics receive the notice, at the first capped move's line.
    moves : PlannerMoves
        The firmware's moves; ``speed_v`` is what the program asks for, mm/s.
    allowed_v : ndarray
        The fastest each move may go along its direction, mm/s.
    limits : str
        The settings that set ``allowed_v``, named in the notice (``"$110-$112"``).

    The time added is counted at cruise (length over allowed speed less
    length over programmed speed), leaving acceleration aside.
    """
    axes_d = moves.axes_d[:, :3]
    length = np.sqrt(np.einsum("ij,ij->i", axes_d, axes_d))
    asked = np.asarray(moves.speed_v, float)
    feeding = np.asarray(op.waypoints["motion"])[moves.waypoint] >= 2
    capped = feeding & (length > 0) & (asked > allowed_v * (1 + TOLERANCE))
    if not capped.any():
        return 0.0
    added = float(np.sum(length[capped] / allowed_v[capped] - length[capped] / asked[capped]))
    first = int(np.flatnonzero(capped)[0])
    n_waypoints = np.unique(moves.waypoint[capped]).size
    op.diagnostics.report(
        int(op.table.line[moves.row[first]]), 1,
        f"{n_waypoints} feed moves are programmed faster than the machine allows along their direction "
        f"(up to {asked[capped].max() * 60:.0f} mm/min against {allowed_v[capped].min() * 60:.0f} mm/min, {limits}): "
        f"the controller caps them, which adds about {added:.1f} s", severity="info")
    return added
