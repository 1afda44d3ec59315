"""Emulate stage: the plane geometry of cutter compensation (offset moves, corners), after rs274.

Points and directions are 2-vectors in the active plane (its first and
second axis).  ``side`` is +1 with the tool left of the path (G41), -1 right
of it (G42); ``radius`` is the tool's, positive.  The corner formulas are
those of LinuxCNC 2.9's interp_convert.cc (``convert_straight_comp2``,
``convert_arc_comp2``), written from their angles as rs274 works them out so
that the numbers agree with it, including where the path turns back on
itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple, Union

import numpy as np

#: Lengths (mm) below this count as zero.
TINY = 1e-9
#: rs274's TOLERANCE_CONCAVE_CORNER (radians): a corner turning less than this is taken as straight on
CONCAVE_CORNER = 0.05


class OffsetLine(NamedTuple):
    """The tool's path beside a straight move: the line through ``point`` along ``direction``."""

    point: np.ndarray
    direction: np.ndarray


class OffsetArc(NamedTuple):
    """The tool's path beside an arc: the programmed centre, the radius grown or shrunk by the tool's."""

    centre: np.ndarray
    radius: float
    ccw: bool
    tool_inside: bool  #: the tool runs inside the arc (its radius shrank)


OffsetPath = Union[OffsetLine, OffsetArc]


class ProgrammedArc(NamedTuple):
    """What the corner rules need of a programmed arc."""

    centre: np.ndarray
    ccw: bool
    radius: float  #: programmed, at the arc's end
    grow: int  #: +1 when the tool runs outside the arc, -1 inside


@dataclass(frozen=True)
class OffsetMove:
    """One programmed move in the plane, from its programmed ``start`` to ``end``, moved off by the tool radius.

    ``in_dir`` and ``out_dir`` are the programmed tangents at its start and
    end; ``new_start`` and ``new_end`` where the tool would run them were
    there no corner before; ``arc`` is None for a straight move.
    """

    start: np.ndarray
    end: np.ndarray
    in_dir: np.ndarray
    out_dir: np.ndarray
    new_start: np.ndarray
    new_end: np.ndarray
    path: OffsetPath
    arc: ProgrammedArc | None = None


def offset_line(start: np.ndarray, end: np.ndarray, side: int, radius: float) -> OffsetMove:
    """A straight move shifted sideways by ``radius``.

    >>> offset_line(np.zeros(2), np.array([10.0, 0]), -1, 1.0).new_end
    array([10., -1.])
    """
    direction = unit(end - start)
    normal = left(direction) * side * radius
    return OffsetMove(start, end, direction, direction, start + normal, end + normal,
                      OffsetLine(start + normal, direction))


def offset_arc(start: np.ndarray, end: np.ndarray, centre: np.ndarray, ccw: bool, side: int,
               radius: float) -> OffsetMove | None:
    """An arc on the same centre, its radius grown or shrunk by ``radius``.

    None when the tool would run inside an arc not larger than itself (rs274
    refuses it; an arc may shrink to a point within :data:`TINY`).

    >>> offset_arc(np.array([1.0, 0]), np.array([0, 1.0]), np.zeros(2), True, 1, 0.25).new_end
    array([0.  , 0.75])
    """
    r1 = np.hypot(*(end - centre))
    grow = -side if ccw else side  # G41 on a CCW arc is inside it
    if grow < 0 and r1 < radius - TINY:
        return None
    r0 = np.hypot(*(start - centre))
    new_r1 = r1 + grow * radius
    turning = 1 if ccw else -1
    return OffsetMove(start, end, unit(left(start - centre) * turning), unit(left(end - centre) * turning),
                      centre + (start - centre) / r0 * (r0 + grow * radius), centre + (end - centre) / r1 * new_r1,
                      OffsetArc(centre, new_r1, ccw, grow < 0), ProgrammedArc(centre, ccw, r1, grow))


def entry_arc(tool_at: np.ndarray, move: OffsetMove) -> OffsetArc:
    """The entry arc from ``tool_at`` to the arc ``move``'s offset end (rs274's ``convert_arc_comp1``).

    Its centre lies on the programmed end radius, so it leaves on the
    programmed arc's tangent; the programmed centre when that radius and the
    chord's bisector are parallel.
    """
    centre = move.arc.centre
    moved = meet(centre, unit(move.end - centre), (tool_at + move.new_end) / 2, left(unit(move.new_end - tool_at)))
    if moved is None:
        moved = centre
    return OffsetArc(moved, float(np.hypot(*(move.new_end - moved))), move.arc.ccw, move.arc.grow < 0)


def corner_turn(before: np.ndarray, after: np.ndarray, side: int) -> float:
    """How far the path turns from tangent ``before`` to ``after`` away from the tool's side (radians).

    Positive is an outside corner; measured from -90 to 270 degrees as rs274
    measures it, so a path turning back on itself counts as outside.

    >>> round(corner_turn(np.array([1.0, 0]), np.array([0, 1.0]), -1), 6)  # G42, a left turn
    1.570796
    """
    beta = -side * math.atan2(before[0] * after[1] - before[1] * after[0], float(before @ after))
    if beta < -math.pi / 2:
        beta += 2 * math.pi
    return beta


def is_inside_corner(beta: float, move: OffsetMove, before: OffsetPath) -> bool:
    """Whether the corner of turn ``beta`` from path ``before`` into ``move`` is an inside one.

    Turning back on itself within :data:`CONCAVE_CORNER`, rs274 keeps the
    tool on its side of both moves (atop an "h" or an "m") when the arc, this
    one or the one before a line, has the tool outside it.
    """
    if move.arc is not None:
        reversal = abs(beta - math.pi) < CONCAVE_CORNER and move.arc.grow > 0
    else:
        reversal = beta > math.pi - CONCAVE_CORNER and isinstance(before, OffsetArc) and not before.tool_inside
    return beta < -CONCAVE_CORNER or beta > math.pi + CONCAVE_CORNER or reversal


def inside_corner(before: OffsetPath, before_dir: np.ndarray, move: OffsetMove, beta: float, tool_at: np.ndarray,
                  side: int, radius: float) -> np.ndarray | None:
    """Where the offset path ``before`` meets ``move``'s at an inside corner; None when they never meet.

    ``before_dir`` is the programmed tangent at the end of the move before,
    ``tool_at`` where the tool ends it, ``beta`` the corner's turn
    (:func:`corner_turn`).

    >>> inside_corner(OffsetLine(np.array([0, 1.0]), np.array([1.0, 0])), np.array([1.0, 0]),
    ...               offset_line(np.array([10.0, 0]), np.array([10.0, 10]), 1, 1.0), -math.pi / 2,
    ...               np.array([10.0, 1]), 1, 1.0).round(9)
    array([9., 1.])
    """
    if isinstance(before, OffsetLine) and move.arc is None:
        return tool_at - before_dir * radius / math.tan((beta + math.pi) / 2)
    if isinstance(before, OffsetLine):
        heading = math.atan2(*(tool_at - move.start)[::-1]) - side * math.pi / 2
        return _line_to_arc(heading, beta, move.path, move.arc.radius, radius)
    if move.arc is None:
        return _arc_to_line(before, move.start, math.atan2(move.in_dir[1], move.in_dir[0]), radius)
    return _arc_to_arc(before, move.path)


def _line_to_arc(heading: float, beta: float, arc: OffsetArc, arc_radius: float, radius: float) -> np.ndarray | None:
    """Where the tool leaves a line for an ``arc`` path at an inside corner (rs274's ``convert_arc_comp2``).

    ``heading``: the line's direction (radians); ``arc_radius``: the
    programmed one.  None when the tool cannot reach the corner.
    """
    across = arc_radius * math.sin(beta - math.pi / 2)
    if arc.tool_inside:
        reach, towards = arc_radius - radius, across + radius
    else:
        reach, towards = arc_radius + radius, across - radius
    if abs(towards / reach) > 1.0:
        return None
    turn = math.asin(towards / reach) if arc.ccw else -math.asin(towards / reach)
    angle = heading + turn if arc.tool_inside else heading + math.pi - turn
    return arc.centre + reach * np.array([math.cos(angle), math.sin(angle)])


def _arc_to_line(arc: OffsetArc, corner: np.ndarray, heading: float, radius: float) -> np.ndarray | None:
    """Where the tool leaves an ``arc`` path for a line heading ``heading`` from the programmed
    ``corner`` (rs274's ``convert_straight_comp2``); None when it cannot fit."""
    normal = heading + (math.pi / 2 if arc.ccw else -math.pi / 2)
    to_centre = math.atan2(*(arc.centre - corner)[::-1])
    programmed = arc.radius + radius if arc.tool_inside else arc.radius - radius
    across = programmed * math.cos(normal - to_centre) + (-radius if arc.tool_inside else radius)
    if abs(across / arc.radius) > 1.0:
        return None
    turn = math.acos(across / arc.radius)
    angle = normal + math.pi + (turn if arc.ccw != arc.tool_inside else -turn)
    return arc.centre + arc.radius * np.array([math.cos(angle), math.sin(angle)])


def _arc_to_arc(first: OffsetArc, second: OffsetArc) -> np.ndarray | None:
    """Where the tool leaves the ``first`` arc path for the ``second`` (rs274's ``convert_arc_comp2``)."""
    c0, r0, c1, r1 = first.centre, first.radius, second.centre, second.radius
    apart = float(np.hypot(*(c1 - c0)))
    if r0 == 0 or apart == 0:
        return None
    cosine = (r0 * r0 + apart * apart - r1 * r1) / (2 * r0 * apart)
    if abs(cosine) > 1.0:
        return None
    pullback = math.acos(cosine) if first.tool_inside == second.ccw else -math.acos(cosine)
    angle = math.atan2(*(c1 - c0)[::-1]) + pullback
    return c0 + r0 * np.array([math.cos(angle), math.sin(angle)])


def turn(start: np.ndarray, centre: np.ndarray, ccw: bool, end: np.ndarray) -> float:
    """The angle (radians, signed as the arc turns) from ``start`` to ``end`` about ``centre``, less than
    a full turn (rs274's ``find_turn`` for one turn).

    >>> round(turn(np.array([1.0, 0]), np.zeros(2), True, np.array([0, 1.0])), 6)
    1.570796
    """
    alpha = math.atan2(*(start - centre)[::-1])
    beta = math.atan2(*(end - centre)[::-1])
    if ccw:
        return beta - alpha + (2 * math.pi if beta <= alpha else 0.0)
    return beta - alpha - (2 * math.pi if alpha <= beta else 0.0)


def lathe_shift(orientation: int, radius: float) -> tuple[float, float]:
    """(Z, X) from a lathe tool's nose centre to its control point (interp_queue.cc ``latheorigin_z/x``).

    Orientations 0 (a mill tool) and 9 (the control point is the nose centre)
    need no shift.

    >>> lathe_shift(2, 0.5)
    (-0.5, -0.5)
    >>> lathe_shift(7, 0.5)
    (-0.5, 0.0)
    """
    dz = -radius if orientation in (2, 7, 3) else radius if orientation in (1, 5, 4) else 0.0
    dx = -radius if orientation in (2, 6, 1) else radius if orientation in (3, 8, 4) else 0.0
    return dz, dx


def unit(v: np.ndarray) -> np.ndarray:
    """``v`` scaled to length 1 (zero stays zero)."""
    norm = float(np.hypot(*v))
    return v / norm if norm > TINY else np.zeros(2)


def left(d: np.ndarray) -> np.ndarray:
    """``d`` turned a quarter turn counter-clockwise."""
    return np.array([-d[1], d[0]])


def meet(p: np.ndarray, d: np.ndarray, q: np.ndarray, e: np.ndarray) -> np.ndarray | None:
    """Where the lines p + s·d and q + u·e cross (None when parallel)."""
    det = d[0] * e[1] - d[1] * e[0]
    if abs(det) < TINY:
        return None
    s = ((q - p)[0] * e[1] - (q - p)[1] * e[0]) / det
    return p + s * d


def angle_between(a: np.ndarray, b: np.ndarray, about: np.ndarray) -> float:
    """The angle (radians, 0 to pi) between ``a`` and ``b`` seen from ``about``."""
    u, v = a - about, b - about
    return abs(math.atan2(u[0] * v[1] - u[1] * v[0], float(np.dot(u, v))))
