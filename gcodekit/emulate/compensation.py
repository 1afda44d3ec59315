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
per-move Python loop because each corner depends on the move before.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..parse.table import MOTION_CCW, MOTION_CW, MOTION_LINEAR, MOTION_RAPID, NAME_ID
from .arcs import PLANES, single_turn_lengths

if TYPE_CHECKING:
    from ..model.operation import Operation

_SIDES = {NAME_ID["cutter_comp_left"]: 1, NAME_ID["cutter_comp_right"]: -1, NAME_ID["cutter_comp_off"]: 0,
          NAME_ID["cutter_comp_left_dynamic"]: 1, NAME_ID["cutter_comp_right_dynamic"]: -1}
_DYNAMIC = {NAME_ID["cutter_comp_left_dynamic"], NAME_ID["cutter_comp_right_dynamic"]}  # G41.1/G42.1: D is a diameter
_TINY = 1e-9
#: rs274's TOLERANCE_CONCAVE_CORNER (radians): a corner turning less than this is taken as straight on
CONCAVE_CORNER = 0.05


def uses_compensation(op: "Operation") -> bool:
    return bool(np.isin(op.table.name, [k for k, side in _SIDES.items() if side]).any())


def compensate(op: "Operation", tools, profile_ends: list[tuple[int, np.ndarray]] = ()) -> None:
    """Rewrite ``op.waypoints`` with the compensated tool path (in place).

    ``profile_ends``: (source line, machine X Y Z) of each G70 run under
    compensation, in order (``Machine.comp_profile_ends``).
    """
    w = op.waypoints
    t = op.table
    n = w["x"].size
    rows = w["command"] if "command" in w else np.arange(n)
    columns = {k: np.array(v, copy=True) for k, v in w.items()}
    columns["command"] = np.asarray(rows)  # corner arcs are added: every waypoint names its command
    out = {k: [] for k in columns}
    side, radius, mode = 0, 0.0, "off"  # mode: off, entry, on, exit
    lathe = (0.0, 0.0)  # shift of a lathe tool's control point from its nose centre, in the plane
    moved = (0.0, 0.0)  # the shift of the rows emitted now: ``lathe`` from the entry move to the exit move
    lathe_rows: list[tuple[int, float, float, int]] = []  # (index in `out`, shift along a, along b, plane)
    last_dir = None  # tangent at the end of the previous compensated move
    # its offset path: ("line", point, direction) or ("arc", centre, radius, ccw, tool inside the arc)
    last_path = None
    last_corner = None  # programmed end of the previous move
    pending = None  # index in `out` of the previous compensated waypoint
    staying: list[int] = []  # later rows that end where `pending` does (no move in the plane)
    pending_start, pending_dir = None, None  # where it starts and, for a line, its programmed direction
    pending_arc = None  # for an arc: (centre, ccw, programmed sweep) in the plane
    side_rows = {int(r): _SIDES[int(t.name[r])] for r in np.flatnonzero(np.isin(t.name, list(_SIDES)))}
    tool_changes = set(np.flatnonzero(t.name == NAME_ID["tool_change"]).tolist())
    held: dict[str, float] = {}  # plane axes rs274 re-read from the tool after an M6 (see below)
    current_row = -1
    nth = 0  # waypoint k is the nth of its command
    entry_row = -1  # the command whose entry length was refused
    profile_ends = list(profile_ends)

    def emit(k: int, **changes) -> int:
        for key in columns:
            out[key].append(changes.get(key, columns[key][k]))
        if moved != (0.0, 0.0):
            lathe_rows.append((len(out["x"]) - 1, *moved, int(columns["plane"][k])))
        return len(out["x"]) - 1

    for k in range(n):
        row = int(rows[k])
        (f, g, _), _ = PLANES[int(columns["plane"][k])]
        a, b = "xyz"[f], "xyz"[g]
        nth = nth + 1 if row == current_row else 0
        if row != current_row:
            for r in range(current_row + 1, row + 1):  # comp codes between the waypoints
                if r in side_rows:
                    new = side_rows[r]
                    if new and not side:
                        side, mode = new, "entry"
                        params = t.command(r).params
                        if int(t.name[r]) in _DYNAMIC:
                            radius = params.get("D", 0.0) * (25.4 if columns["units"][k] == 1 else 1.0) / 2.0
                            orientation = int(params.get("L", 0))
                        else:
                            number = int(params.get("D", columns["tool"][k]))
                            radius = tools[number].diameter / 2.0 if number in tools else 0.0
                            orientation = tools[number].orientation if number in tools else 0
                        if radius < 0:  # rs274: a negative diameter compensates on the other side
                            radius, side = -radius, -side
                        plane = int(columns["plane"][k])
                        lathe = _lathe_shift(orientation, radius) if plane == 18 else (0.0, 0.0)
                    elif not new and side:
                        side, mode = 0, "exit"
                        if pending_arc is not None and out["x"] and _arc_grows(
                                pending_arc, pending_start, np.array([out[a][-1], out[b][-1]]), columns["units"][k]):
                            op.diagnostics.report(int(t.line[r]), 1, _ARC_GOUGE, kind="machine")
                if r in tool_changes and mode == "exit" and out["x"]:
                    # rs274 re-reads its position after M6: the program position becomes
                    # the compensated one, so the exit starts from there (useful-subroutines.ngc)
                    held = {a: out[a][-1] + moved[0], b: out[b][-1] + moved[1]}
                    moved = (0.0, 0.0)  # `held` is where the tool is already
            current_row = row
        motion = int(columns["motion"][k])
        if held:
            given = t.command(row).params if motion else {}
            for axis in [axis for axis in held if axis.upper() in given]:
                del held[axis]  # a word for the axis ends the hold
            changes = dict(held)
            if mode == "exit" and motion:
                mode, last_dir, last_corner, pending, last_path = "off", None, None, None, None
                pending_start, pending_dir, pending_arc = None, None, None
            emit(k, **changes)
            continue
        if mode == "off" or radius <= 0:
            emit(k)
            continue
        if motion == 0:  # a command without motion stays where the tool is
            emit(k, **({a: out[a][-1], b: out[b][-1]} if out["x"] else {}))
            continue
        ca, cb = "c" + a, "c" + b
        start = np.array([out[a][-1], out[b][-1]]) if out["x"] else np.zeros(2)
        end = np.array([columns[a][k], columns[b][k]])
        programmed_start = last_corner if last_corner is not None else start
        if mode == "exit":
            moved = (0.0, 0.0)
            emit(k)  # straight from the compensated point to the programmed end
            mode, last_dir, last_corner, pending, last_path = "off", None, None, None, None
            pending_start, pending_dir, pending_arc = None, None, None
            continue
        if mode == "on" and nth == 1 and profile_ends and profile_ends[0][0] == int(t.line[row]) \
                and int(t.name[row]) == NAME_ID["lathe_finish"]:
            # the G70's first own rapid (its approach to the cycle point came before): the tool
            # goes to the profile's end, queued behind the approach; the next corner is judged
            # from the programmed point to there
            tool_at = profile_ends.pop(0)[1][[f, g]]
            staying.append(emit(k, **{a: tool_at[0], b: tool_at[1]}))
            last_dir = -side * _left(_unit(tool_at - programmed_start))
            last_path = ("line", tool_at, last_dir)
            continue
        chord = end - programmed_start
        if mode == "entry" and entry_row != row and motion < MOTION_CW and np.hypot(*(end - start)) < radius - _TINY \
                and not _leaves_plane(columns, k, f, g):
            entry_row = row  # once per command
            op.diagnostics.report(int(t.line[row]), 1, "Length of cutter compensation entry move is not "
                                  "greater than the tool radius", kind="machine")
        if np.hypot(*chord) < _TINY and motion < MOTION_CW:  # a move along the plane's normal keeps the offset
            row_out = emit(k, **{a: start[0], b: start[1]})
            if pending is not None:
                staying.append(row_out)  # an inside corner moves it with `pending` (move_endpoint_and_flush)
            continue
        if motion in (MOTION_CW, MOTION_CCW):
            center = np.array([columns[ca][k], columns[cb][k]])
            ccw = motion == MOTION_CCW
            r0 = np.hypot(*(programmed_start - center))
            r1 = np.hypot(*(end - center))
            grow = -side if ccw else side  # G41 on a CCW arc is inside it
            if grow < 0 and r1 < radius - _TINY:  # rs274 lets an arc shrink to a point
                op.diagnostics.report(int(t.line[row]), 1, "Tool radius not less than arc radius with comp",
                                      kind="machine")
                emit(k)
                continue
            new_r1 = r1 + grow * radius
            in_dir = _unit(np.array([-(programmed_start - center)[1], (programmed_start - center)[0]]) * (1 if ccw else -1))
            out_dir = _unit(np.array([-(end - center)[1], (end - center)[0]]) * (1 if ccw else -1))
            new_start = center + (programmed_start - center) / r0 * (r0 + grow * radius)
            new_end = center + (end - center) / r1 * new_r1
        else:
            in_dir = out_dir = _unit(chord)
            normal = _left(in_dir) * side * radius
            new_start, new_end = programmed_start + normal, end + normal
        if mode == "entry" and motion in (MOTION_CW, MOTION_CCW):
            # comp1 arc: from the current point to the radially shifted end, on a
            # centre moved along the end radius so the arc leaves on the same tangent
            entry_center = _meet(center, _unit(end - center), (start + new_end) / 2, _left(_unit(new_end - start)))
            if entry_center is None:
                entry_center = center
            moved = lathe
            if lathe != (0.0, 0.0):
                # rs274 feeds the tool's control point onto the shifted start first,
                # or the entry would not be an arc (convert_arc_comp1)
                length = float(np.hypot(*lathe))
                feed = float(columns["feed"][k])
                h = "xyz"[3 - f - g]
                emit(k, **{a: start[0], b: start[1], h: out[h][-1] if out["x"] else 0.0, "motion": MOTION_LINEAR,
                           "cx": np.nan, "cy": np.nan, "cz": np.nan, "distance": length, "de": 0.0,
                           "time": length / (feed / 60.0) if feed > 0 else 0.0})
            pending, staying = emit(k, **{a: new_end[0], b: new_end[1], ca: entry_center[0], cb: entry_center[1]}), []
            pending_start, pending_dir, pending_arc = start, None, None
            mode, last_dir, last_corner = "on", out_dir, end
            last_path = ("arc", entry_center, float(np.hypot(*(new_end - entry_center))), ccw, grow < 0)
            continue
        if mode == "entry":
            # comp1: straight to the end shifted off the entry move's own direction
            shifted = end + _left(_unit(chord)) * side * radius
            moved = lathe
            pending, staying = emit(k, **{a: shifted[0], b: shifted[1]}), []
            pending_start, pending_dir, pending_arc = start, _unit(chord), None
            mode, last_dir, last_corner = "on", _unit(chord), end
            last_path = ("line", shifted, _unit(chord))
            continue
        # beta: how far the path turns away from the tool's side (> 0: an outside corner),
        # from -90 to 270 degrees as rs274 measures it
        beta = -side * math.atan2(last_dir[0] * in_dir[1] - last_dir[1] * in_dir[0], float(last_dir @ in_dir))
        if beta < -math.pi / 2:
            beta += 2 * math.pi
        arc = motion in (MOTION_CW, MOTION_CCW)
        this_path = ("arc", center, new_r1, ccw, grow < 0) if arc else ("line", new_start, in_dir)
        # turning back on itself within the tolerance, rs274 keeps the tool on its side of
        # both moves (atop an "h" or an "m") when the arc, this one or the one before a
        # line, has the tool outside it
        reversal = (abs(beta - math.pi) < CONCAVE_CORNER and grow > 0) if arc else \
            (beta > math.pi - CONCAVE_CORNER and last_path[0] == "arc" and not last_path[4])
        inside = beta < -CONCAVE_CORNER or beta > math.pi + CONCAVE_CORNER or reversal
        gap = np.hypot(*(new_start - start))
        # within CONCAVE_CORNER of straight on, rs274 neither rolls round nor trims: the
        # move starts where the tool is
        if gap > _TINY and (inside or beta > CONCAVE_CORNER):
            if not inside:
                # rs274 ends the queued moves where the tool is: they end there already,
                # except a G70's first rapid and the approach queued before it
                for r in (pending, *staying):
                    if r is not None:
                        out[a][r], out[b][r] = start[0], start[1]
            # the corner move stays at the height the tool is at: the move itself then rises or falls
            level = {"xyz"[3 - f - g]: out["xyz"[3 - f - g]][-1]} if out["x"] else {}
            if not inside and motion == MOTION_RAPID:
                # no rapid arc: rs274 traverses straight to where the roll would end
                whole = float(columns["distance"][k])  # at the rapid's own speed
                emit(k, **{a: new_start[0], b: new_start[1]}, **level, distance=float(gap), de=0.0,
                     time=float(columns["time"][k]) * gap / whole if whole > 0 else 0.0)
            elif not inside:  # outside corner: roll round the programmed corner
                length = radius * _angle(start, new_start, programmed_start)
                feed = float(columns["feed"][k])
                emit(k, **{a: new_start[0], b: new_start[1], ca: programmed_start[0], cb: programmed_start[1]},
                     **level, motion=MOTION_CCW if side < 0 else MOTION_CW, distance=length, de=0.0,
                     time=length / (feed / 60.0) if feed > 0 else 0.0)
            elif pending is not None:
                # inside corner: cut the previous move where the two offset paths meet, worked
                # out as rs274 does (which also picks the side when the path turns back on itself)
                kinds = "Arc" if last_path[0] == "arc" else "Straight", "arc" if arc else "straight"
                problem = f"{kinds[0]} to {kinds[1]} motion makes a corner the compensated tool can't fit in " \
                    "without gouging"
                if last_path[0] == "line" and not arc:
                    meet = start - last_dir * radius / math.tan((beta + math.pi) / 2)
                elif last_path[0] == "line":
                    heading = math.atan2(*(start - programmed_start)[::-1]) - side * math.pi / 2
                    meet = _line_to_arc_corner(heading, beta, this_path, r1, radius)
                    problem = _ARC_GOUGE
                elif not arc:
                    meet = _arc_to_line_corner(last_path, programmed_start, math.atan2(in_dir[1], in_dir[0]), radius)
                else:
                    meet = _arc_to_arc_corner(last_path, this_path)
                if meet is not None:
                    if pending_arc is not None and _arc_grows(pending_arc, pending_start, meet, columns["units"][k]):
                        op.diagnostics.report(int(t.line[row]), 1, _ARC_GOUGE, kind="machine")
                    for r in (pending, *staying):
                        out[a][r], out[b][r] = meet[0], meet[1]
                    new_start = meet
                else:
                    op.diagnostics.report(int(t.line[row]), 1, problem, kind="machine")
        if pending_dir is not None and pending is not None:
            done = np.array([out[a][pending], out[b][pending]]) - pending_start
            if float(done @ pending_dir) < -_TINY:  # the offset move would run backwards
                kind = "traverse" if out["motion"][pending] == MOTION_RAPID else "feed"
                op.diagnostics.report(int(t.line[row]), 1, f"Straight {kind} in concave corner cannot be reached by "
                                      "the tool without gouging", kind="machine")
        centre = (columns[ca][k], columns[cb][k]) if motion in (MOTION_CW, MOTION_CCW) else (np.nan, np.nan)
        pending, staying = emit(k, **{a: new_end[0], b: new_end[1], ca: centre[0], cb: centre[1]}), []
        if arc:  # rs274's queue holds it from where the tool starts it (the corner's end, or where the tool is)
            arc_from = new_start if gap > _TINY and (inside or beta > CONCAVE_CORNER) else start
            pending_arc = (center, ccw, _turn(programmed_start, center, ccw, end))
            pending_start, pending_dir = arc_from, None
        else:
            pending_arc = None
            pending_start, pending_dir = new_start, in_dir
        last_dir, last_corner, last_path = out_dir, end, this_path
    for i, da, db, plane in lathe_rows:
        (f, g, _), _ = PLANES[plane]
        for axis, shift in (("xyz"[f], da), ("xyz"[g], db)):
            out[axis][i] += shift
            out["c" + axis][i] += shift  # NaN off arcs stays NaN
    for key in columns:
        w[key] = np.asarray(out[key], dtype=columns[key].dtype)
    _recompute_lengths(w)


_ARC_GOUGE = "Arc move in concave corner cannot be reached by the tool without gouging"


def _turn(start: np.ndarray, centre: np.ndarray, ccw: bool, end: np.ndarray) -> float:
    """The angle (radians, signed as the arc turns) from ``start`` to ``end`` about ``centre``, less than
    a full turn (rs274's ``find_turn`` for one turn).

    >>> round(_turn(np.array([1.0, 0]), np.zeros(2), True, np.array([0, 1.0])), 6)
    1.570796
    """
    alpha = math.atan2(*(start - centre)[::-1])
    beta = math.atan2(*(end - centre)[::-1])
    if ccw:
        return beta - alpha + (2 * math.pi if beta <= alpha else 0.0)
    return beta - alpha - (2 * math.pi if alpha <= beta else 0.0)


def _arc_grows(arc: tuple, start: np.ndarray, end: np.ndarray, inch: int) -> bool:
    """Whether a queued arc from ``start`` with its end moved to ``end`` turns further than programmed
    (rs274's ``move_endpoint_and_flush``, whose tolerance compares radians with 0.001 in or 0.0254 mm)."""
    centre, ccw, sweep = arc
    return abs(_turn(start, centre, ccw, end)) > abs(sweep) + (0.001 if inch == 1 else 0.0254)


def _lathe_shift(orientation: int, radius: float) -> tuple[float, float]:
    """(Z, X) from a lathe tool's nose centre to its control point (interp_queue.cc ``latheorigin_z/x``).

    Orientations 0 (a mill tool) and 9 (the control point is the nose centre)
    need no shift.

    >>> _lathe_shift(2, 0.5)
    (-0.5, -0.5)
    >>> _lathe_shift(7, 0.5)
    (-0.5, 0.0)
    """
    dz = -radius if orientation in (2, 7, 3) else radius if orientation in (1, 5, 4) else 0.0
    dx = -radius if orientation in (2, 6, 1) else radius if orientation in (3, 8, 4) else 0.0
    return dz, dx


def _leaves_plane(columns: dict, k: int, f: int, g: int) -> bool:
    """Whether waypoint ``k`` moves along the plane's normal (a plunge, not an entry)."""
    h = 3 - f - g
    axis = "xyz"[h]
    return k > 0 and abs(columns[axis][k] - columns[axis][k - 1]) > _TINY


def _unit(v: np.ndarray) -> np.ndarray:
    norm = float(np.hypot(*v))
    return v / norm if norm > _TINY else np.zeros(2)


def _left(d: np.ndarray) -> np.ndarray:
    return np.array([-d[1], d[0]])


def _line_to_arc_corner(heading: float, beta: float, arc: tuple, arc_radius: float,
                        radius: float) -> np.ndarray | None:
    """Where the tool leaves a line for an ``arc`` path at an inside corner (rs274's ``convert_arc_comp2``).

    ``heading``: the line's direction (radians); ``beta``: the corner's turn
    (see ``compensate``); ``arc_radius``: the programmed one.  None when the
    tool cannot reach the corner.
    """
    _, centre, _, ccw, inside = arc
    across = arc_radius * math.sin(beta - math.pi / 2)
    if inside:
        reach, towards = arc_radius - radius, across + radius
    else:
        reach, towards = arc_radius + radius, across - radius
    if abs(towards / reach) > 1.0:
        return None
    turn = math.asin(towards / reach) if ccw else -math.asin(towards / reach)
    angle = heading + turn if inside else heading + math.pi - turn
    return centre + reach * np.array([math.cos(angle), math.sin(angle)])


def _arc_to_line_corner(arc: tuple, corner: np.ndarray, heading: float, radius: float) -> np.ndarray | None:
    """Where the tool leaves an ``arc`` path for a line heading ``heading`` from the programmed
    ``corner`` (rs274's ``convert_straight_comp2``); None when it cannot fit."""
    _, centre, arc_radius, ccw, inside = arc
    normal = heading + (math.pi / 2 if ccw else -math.pi / 2)
    to_centre = math.atan2(*(centre - corner)[::-1])
    programmed = arc_radius + radius if inside else arc_radius - radius
    across = programmed * math.cos(normal - to_centre) + (-radius if inside else radius)
    if abs(across / arc_radius) > 1.0:
        return None
    turn = math.acos(across / arc_radius)
    angle = normal + math.pi + (turn if ccw != inside else -turn)
    return centre + arc_radius * np.array([math.cos(angle), math.sin(angle)])


def _arc_to_arc_corner(first: tuple, second: tuple) -> np.ndarray | None:
    """Where the tool leaves the ``first`` arc path for the ``second`` (rs274's ``convert_arc_comp2``)."""
    _, c0, r0, _, inside = first
    _, c1, r1, ccw, _ = second
    apart = float(np.hypot(*(c1 - c0)))
    if r0 == 0 or apart == 0:
        return None
    cosine = (r0 * r0 + apart * apart - r1 * r1) / (2 * r0 * apart)
    if abs(cosine) > 1.0:
        return None
    pullback = math.acos(cosine) if inside == ccw else -math.acos(cosine)
    angle = math.atan2(*(c1 - c0)[::-1]) + pullback
    return c0 + r0 * np.array([math.cos(angle), math.sin(angle)])


def _meet(p: np.ndarray, d: np.ndarray, q: np.ndarray, e: np.ndarray):
    """Where the lines p + s·d and q + u·e cross (None when parallel)."""
    det = d[0] * e[1] - d[1] * e[0]
    if abs(det) < _TINY:
        return None
    s = ((q - p)[0] * e[1] - (q - p)[1] * e[0]) / det
    return p + s * d


def _angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    return abs(math.atan2((a - c)[0] * (b - c)[1] - (a - c)[1] * (b - c)[0], float(np.dot(a - c, b - c))))


def _recompute_lengths(w: dict) -> None:
    """Move lengths after the path moved: straight moves and arcs in their plane."""
    points = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
    centers = np.column_stack([np.asarray(w["c" + k], float) for k in "xyz"])
    previous = np.vstack([np.zeros(3), points[:-1]])
    motion = np.asarray(w["motion"])
    distance = np.array(w["distance"], float)
    straight = motion <= MOTION_LINEAR
    distance[straight] = np.linalg.norm(points - previous, axis=1)[straight]
    plane = np.asarray(w["plane"])
    arcs = np.isin(motion, (MOTION_CW, MOTION_CCW))
    for code in np.unique(plane[arcs]):
        (f, g, h), _ = PLANES[int(code)]
        idx = np.flatnonzero(arcs & (plane == code))
        p0, p1, c = previous[idx][:, [f, g]], points[idx][:, [f, g]], centers[idx][:, [f, g]]
        distance[idx] = single_turn_lengths(p0, p1, c, motion[idx] == MOTION_CW, points[idx, h] - previous[idx, h])
    w["distance"] = distance
