"""Emulate stage: cutter radius compensation (G41/G42, in the active plane), LinuxCNC's way.

The machine first computes the programmed path; this pass then moves the
tool off it by the tool radius, after the rules of LinuxCNC's interpreter
(interp_convert.cc, ``convert_straight_comp1/2`` and ``convert_arc_comp1/2``):

* the first move after G41/G42 (the entry) runs to its programmed end
  shifted by the radius to the left (G41) or right (G42) of that move: a
  line straight there, an arc on a centre moved along its end radius;
* a negative diameter compensates on the other side;
* every later move is shifted the same way (an arc's radius grows or shrinks
  by the tool radius); at an outside corner the tool rolls round the
  programmed corner on an arc of the tool radius, at an inside corner the
  previous move is cut short where the two shifted paths meet, worked out
  from the corner's angle as rs274 does; corners are measured from -90 to
  270 degrees, so a path turning back on itself within the tolerance rolls
  round the corner, unless the tool would end up between the two moves
  (atop an "h" or an "m" shape, rs274's special cases);
* a corner turning less than 0.05 rad (rs274's ``TOLERANCE_CONCAVE_CORNER``)
  either way gets neither: the move starts where the tool is; a rapid
  round an outside corner goes straight to where the roll would end (there
  is no rapid arc); moves with no motion in the plane in between are cut
  short with the move before them;
* the first move after G40 (the exit) runs straight to its programmed end;
* a lathe tool (orientation 1-8, the tool table's Q or G41.1/G42.1's L) in
  the XZ plane (G18) is compensated about its nose centre and then moved by
  the nose radius to the tool's control point, as rs274 does when it flushes
  its queue (interp_queue.cc ``latheorigin_x/z``); an entry arc first feeds
  that shift on its own (when the next move turns a corner, rs274 moves the
  end of that feed to the corner as well, so its arc ends where it starts:
  gcodekit keeps the arc, matching rs274 only when the next move is tangent);
* gouges are errors, as in rs274: an offset line that would run backwards
  between its corners, an inside corner whose offset paths never meet, or
  a queued arc whose end, moved to the next corner or to where G40 finds
  the tool, lies further round than the programmed arc turns (beyond
  rs274's tolerance, radians compared with 0.001 in G20 and 0.0254 in G21:
  an arc met nearly tangentially starts where the tool is, which can be
  enough);
* a G70 under compensation inherits a quirk of rs274's: reading the profile
  leaves rs274's current point on the profile's last point, so the cycle's
  first rapid (to where the programmed point already is) takes the tool
  there, uncompensated, and the next corner is judged from there.

Runs once over the emulated waypoints of programs that use G41/G42; it is a
per-move Python loop because each corner depends on the move before.  The
pass is a state machine (off, entry, on, exit: :mod:`.states`) over the
machine's waypoints; the offset and corner geometry is in :mod:`.geometry`,
the move held back for the next corner in :mod:`.queue` and the written
waypoints in :mod:`.path`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .geometry import CONCAVE_CORNER
from ...parse.table import in_ids
from .states import SIDES, Compensator

if TYPE_CHECKING:
    from ..program import EmulatedProgram

__all__ = ["CONCAVE_CORNER", "compensate", "uses_compensation"]


def uses_compensation(op: "EmulatedProgram") -> bool:
    """Whether the program switches compensation on (G41, G42, G41.1 or G42.1) anywhere."""
    return bool(in_ids(op.table.name, [k for k, side in SIDES.items() if side]).any())


def compensate(op: "EmulatedProgram", tools, profile_ends: list[tuple[int, np.ndarray]] = ()) -> None:
    """Rewrite ``op.waypoints`` with the compensated tool path (in place).

    Parameters
    ----------
    op : EmulatedProgram
        The emulated operation; compensation errors (gouges, entry moves
        shorter than the radius, arcs smaller than the tool) are reported to
        its diagnostics, as rs274 reports them.
    tools : dict
        The machine's tool table (number -> tool with ``diameter`` and
        ``orientation``), read for G41/G42's D word or the current tool.
    profile_ends : list of (int, ndarray), default: ()
        (source line, machine X Y Z) of each G70 run under compensation, in
        order (``Machine.comp_profile_ends``).
    """
    Compensator(op, tools, profile_ends).run()
