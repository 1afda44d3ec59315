"""Emulate stage: the cutter compensation pass as a state machine (off, entry, on, exit).

The states are rs274's (interp_convert.cc): ``cutter_comp_side`` and
``cutter_comp_firstmove`` hold the same four.

========  ==================================================================
off       no compensation: waypoints pass unchanged.
entry     after G41/G42/G41.1/G42.1: the next move in the plane is the entry
          (``convert_straight_comp1``, ``convert_arc_comp1``), run to its
          programmed end shifted by the tool radius; then ``on``.
on        each move is offset by the radius and joined to the one before
          (``convert_straight_comp2``, ``convert_arc_comp2``): an outside
          corner gets an arc about the programmed corner, an inside corner
          cuts the queued move before it short (:mod:`.queue`).
exit      after G40: the next move runs straight from where the tool is to
          its programmed end; then ``off``.
========  ==================================================================

The compensation codes and tool changes are commands without waypoints of
their own: they are read from the command table between one waypoint and
the next.  Besides the states, an M6 read in ``exit`` holds the tool where
it is until axis words move it (rs274 re-reads its position after a tool
change), whatever the state.  Geometry is in :mod:`.geometry`; the written
path in :mod:`.path`.
"""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ...parse.table import MOTION_CCW, MOTION_CW, MOTION_LINEAR, MOTION_NONE, MOTION_RAPID, NAME_ID, in_ids
from ...units import MM_PER_INCH
from ..arcs import PLANES
from .geometry import (CONCAVE_CORNER, TINY, OffsetArc, OffsetLine, OffsetMove, OffsetPath, angle_between,
                       corner_turn, entry_arc, inside_corner, is_inside_corner, lathe_shift, left, offset_arc,
                       offset_line, turn, unit)
from .path import ToolPath
from .queue import Queue, QueuedArc

if TYPE_CHECKING:
    from ..program import EmulatedProgram

#: The compensation codes and the side each puts the tool on (+1 left, -1 right, 0 off).
SIDES = {NAME_ID["cutter_comp_left"]: 1, NAME_ID["cutter_comp_right"]: -1, NAME_ID["cutter_comp_off"]: 0,
         NAME_ID["cutter_comp_left_dynamic"]: 1, NAME_ID["cutter_comp_right_dynamic"]: -1}
_DYNAMIC = {NAME_ID["cutter_comp_left_dynamic"], NAME_ID["cutter_comp_right_dynamic"]}  # G41.1/G42.1: D is a diameter
_ARC_GOUGE = "Arc move in concave corner cannot be reached by the tool without gouging"


class State(enum.Enum):
    """Where the pass is between G41/G42 and G40 (see the module's table)."""

    OFF = "off"
    ENTRY = "entry"
    ON = "on"
    EXIT = "exit"


class Step(NamedTuple):
    """One of the machine's waypoints, as the pass reads it."""

    k: int  #: its index among the machine's waypoints
    row: int  #: its command
    nth: int  #: 0 for its command's first waypoint, 1 for the second, ...
    a: str  #: the plane's first axis
    b: str  #: the plane's second axis
    h: str  #: the plane's normal
    motion: int


class Compensator:
    """One compensation pass over an operation's waypoints; :meth:`run` rewrites them.

    Parameters
    ----------
    op : EmulatedProgram
        The emulated operation (its waypoints are replaced; errors go to its diagnostics).
    tools : dict
        The machine's tool table: number -> tool (``diameter``, ``orientation``).
    profile_ends : list of (int, ndarray)
        (source line, machine X Y Z) of each G70 run under compensation, in order.
    """

    def __init__(self, op: "EmulatedProgram", tools, profile_ends):
        self.op, self.table, self.tools = op, op.table, tools
        w = op.waypoints
        self.rows = w["command"]
        self.out = ToolPath(w, self.rows)
        self.columns = self.out.columns
        self.profile_ends = list(profile_ends)
        t = self.table
        self.side_rows = {int(r): SIDES[int(t.name[r])] for r in np.flatnonzero(in_ids(t.name, list(SIDES)))}
        self.tool_changes = set(np.flatnonzero(t.name == NAME_ID["tool_change"]).tolist())

        self.state = State.OFF
        self.side, self.radius = 0, 0.0
        self.lathe = (0.0, 0.0)  # shift of a lathe tool's control point from its nose centre, in the plane
        self.queue = Queue()
        # the move before: its programmed end, the tangent there and its offset path
        self.last_corner: np.ndarray | None = None
        self.last_dir: np.ndarray | None = None
        self.last_path: OffsetPath | None = None
        self.held: dict[str, float] = {}  # plane axes held after an M6 in exit (see _hold)
        self.entry_row = -1  # the command whose entry length was refused (once per command)
        self._moves = {State.ENTRY: self._entry_move, State.ON: self._on_move, State.EXIT: self._exit_move}

    def run(self) -> None:
        """Compensate every waypoint in order and replace the operation's waypoints."""
        current_row, nth = -1, 0
        for k in range(self.rows.size):
            row = int(self.rows[k])
            (f, g, h), _ = PLANES[int(self.columns["plane"][k])]
            nth = nth + 1 if row == current_row else 0
            step = Step(k, row, nth, "xyz"[f], "xyz"[g], "xyz"[h], int(self.columns["motion"][k]))
            for r in range(current_row + 1, row + 1):  # the codes read since the last waypoint
                self._read_command(r, step)
            current_row = row
            self._step(step)
        self.out.finish(self.op.waypoints)

    # -- commands without waypoints: the transitions off/exit -> entry and entry/on -> exit

    def _read_command(self, r: int, step: Step) -> None:
        """Command ``r``, read before ``step``: a compensation code, which changes the state (G41/G42 while
        on, or G40 while off, leaves it as it is), or a tool change."""
        if r in self.side_rows:
            side = self.side_rows[r]
            if side and self.state in (State.OFF, State.EXIT):
                self._switch_on(r, side, step)
            elif not side and self.state in (State.ENTRY, State.ON):
                self._switch_off(r, step)
        if r in self.tool_changes and self.state is State.EXIT and self.out:
            self._hold(step)

    def _switch_on(self, r: int, side: int, step: Step) -> None:
        """G41/G42 (G41.1/G42.1): the tool's radius and side; the next move is the entry."""
        self.state, self.side = State.ENTRY, side
        params = self.table.command(r).params
        if int(self.table.name[r]) in _DYNAMIC:
            inch = self.columns["units"][step.k] == 1
            self.radius = params.get("D", 0.0) * (MM_PER_INCH if inch else 1.0) / 2.0
            orientation = int(params.get("L", 0))
        else:
            number = int(params.get("D", self.columns["tool"][step.k]))
            self.radius = self.tools[number].diameter / 2.0 if number in self.tools else 0.0
            orientation = self.tools[number].orientation if number in self.tools else 0
        if self.radius < 0:  # rs274: a negative diameter compensates on the other side
            self.radius, self.side = -self.radius, -self.side
        lathe = int(self.columns["plane"][step.k]) == 18
        self.lathe = lathe_shift(orientation, self.radius) if lathe else (0.0, 0.0)

    def _switch_off(self, r: int, step: Step) -> None:
        """G40: the next move is the exit.  Where the tool stops may overrun a queued arc."""
        self.state, self.side = State.EXIT, 0
        if self.out and self.queue.overruns(self.out.point(-1, step.a, step.b), self._inch(step)):
            self._error(r, _ARC_GOUGE)

    def _hold(self, step: Step) -> None:
        """M6 after G40: rs274 re-reads its position, so the program position becomes the compensated
        one and the exit starts from there (useful-subroutines.ngc)."""
        self.held = {step.a: self.out.last(step.a) + self.out.shift[0],
                     step.b: self.out.last(step.b) + self.out.shift[1]}
        self.out.shift = (0.0, 0.0)  # `held` is where the tool is already

    # -- waypoints

    def _step(self, step: Step) -> None:
        """One waypoint: written as it is, where the tool is, or by the state's handler of a move."""
        if self.held:
            self._held_step(step)
        elif self.state is State.OFF or self.radius <= 0:  # nothing to offset (the states still follow)
            self.out.emit(step.k)
        elif step.motion == MOTION_NONE:  # a command without motion stays where the tool is
            self.out.emit(step.k, **({step.a: self.out.last(step.a), step.b: self.out.last(step.b)}
                                     if self.out else {}))
        else:
            self._moves[self.state](step)

    def _held_step(self, step: Step) -> None:
        """A waypoint while an M6 holds the tool: the axes not named since stay where they were held."""
        given = self.table.command(step.row).params if step.motion else {}
        for axis in [axis for axis in self.held if axis.upper() in given]:
            del self.held[axis]  # a word for the axis ends the hold
        changes = dict(self.held)
        if self.state is State.EXIT and step.motion:
            self._off()
        self.out.emit(step.k, **changes)

    def _exit_move(self, step: Step) -> None:
        """exit -> off: straight from the compensated point to the programmed end."""
        self.out.shift = (0.0, 0.0)
        self.out.emit(step.k)
        self._off()

    def _off(self) -> None:
        """-> off: no move before, nothing queued."""
        self.state = State.OFF
        self.last_dir, self.last_corner, self.last_path = None, None, None
        self.queue.clear()

    def _entry_move(self, step: Step) -> None:
        """entry -> on: to the programmed end shifted by the radius, straight or on an arc."""
        tool_at, end = self._tool_at(step), self._end(step)
        self._check_entry_length(step, tool_at, end)
        move = self._offset(step, tool_at, end)
        if move is None:
            return
        self.out.shift = self.lathe
        at = {step.a: move.new_end[0], step.b: move.new_end[1]}
        if move.arc is None:  # comp1: straight to the end shifted off the entry move's own direction
            path = move.path
            self.queue.hold(self.out.emit(step.k, **at), tool_at, direction=move.in_dir)
        else:  # comp1 arc: on a centre moved along the end radius, so it leaves on the programmed tangent
            path = entry_arc(tool_at, move)
            if self.lathe != (0.0, 0.0):
                self._feed_onto_nose(step, tool_at)
            at.update({"c" + step.a: path.centre[0], "c" + step.b: path.centre[1]})
            self.queue.hold(self.out.emit(step.k, **at), tool_at)
        self.state = State.ON
        self.last_dir, self.last_corner, self.last_path = move.out_dir, move.end, path

    def _check_entry_length(self, step: Step, tool_at: np.ndarray, end: np.ndarray) -> None:
        """rs274 refuses a straight entry in the plane not longer than the radius (once per command)."""
        if self.entry_row != step.row and step.motion < MOTION_CW and np.hypot(*(end - tool_at)) < self.radius - TINY \
                and not self._leaves_plane(step):
            self.entry_row = step.row
            self._error(step.row, "Length of cutter compensation entry move is not greater than the tool radius")

    def _feed_onto_nose(self, step: Step, tool_at: np.ndarray) -> None:
        """Before a lathe tool's entry arc, rs274 feeds its control point onto the shifted start, or the
        entry would not be an arc (``convert_arc_comp1``)."""
        length = float(np.hypot(*self.lathe))
        feed = float(self.columns["feed"][step.k])
        height = self.out.last(step.h) if self.out else 0.0
        self.out.emit(step.k, **{step.a: tool_at[0], step.b: tool_at[1], step.h: height}, motion=MOTION_LINEAR,
                      cx=np.nan, cy=np.nan, cz=np.nan, distance=length, de=0.0,
                      time=length / (feed / 60.0) if feed > 0 else 0.0)

    def _on_move(self, step: Step) -> None:
        """on: the move offset, joined to the one before by an outside or inside corner."""
        if self._profile_end(step):
            return
        tool_at = self._tool_at(step)
        move = self._offset(step, tool_at, self._end(step))
        if move is None:
            return
        beta = corner_turn(self.last_dir, move.in_dir, self.side)
        inside = is_inside_corner(beta, move, self.last_path)
        gap = np.hypot(*(move.new_start - tool_at))
        # within CONCAVE_CORNER of straight on, rs274 neither rolls round nor trims: the move starts where
        # the tool is
        turns = gap > TINY and (inside or beta > CONCAVE_CORNER)
        start = move.new_start
        if turns and not inside:
            self._roll_round(step, move, tool_at, gap)
        elif turns:
            start = self._cut_inside_corner(step, move, beta, tool_at)
        self._check_queued_line(step)
        centre = move.arc.centre if move.arc is not None else (np.nan, np.nan)
        row = self.out.emit(step.k, **{step.a: move.new_end[0], step.b: move.new_end[1],
                                       "c" + step.a: centre[0], "c" + step.b: centre[1]})
        if move.arc is None:
            self.queue.hold(row, start, direction=move.in_dir)
        else:  # rs274's queue holds it from where the tool starts it (the corner's end, or where the tool is)
            sweep = turn(move.start, move.arc.centre, move.arc.ccw, move.end)
            self.queue.hold(row, start if turns else tool_at, arc=QueuedArc(move.arc.centre, move.arc.ccw, sweep))
        self.last_dir, self.last_corner, self.last_path = move.out_dir, move.end, move.path

    def _roll_round(self, step: Step, move: OffsetMove, tool_at: np.ndarray, gap: float) -> None:
        """An outside corner: the tool rolls round the programmed corner on an arc of its radius."""
        # rs274 ends the queued moves where the tool is: they end there already, except a G70's first rapid
        # and the approach queued before it
        self.out.move_ends(self.queue.rows(), step.a, step.b, tool_at)
        # the corner move stays at the height the tool is at: the move itself then rises or falls
        at = {step.a: move.new_start[0], step.b: move.new_start[1], step.h: self.out.last(step.h)}
        if step.motion == MOTION_RAPID:  # no rapid arc: rs274 traverses straight to where the roll would end
            whole = float(self.columns["distance"][step.k])  # at the rapid's own speed
            self.out.emit(step.k, **at, distance=float(gap), de=0.0,
                          time=float(self.columns["time"][step.k]) * gap / whole if whole > 0 else 0.0)
        else:
            length = self.radius * angle_between(tool_at, move.new_start, move.start)
            feed = float(self.columns["feed"][step.k])
            self.out.emit(step.k, **at, **{"c" + step.a: move.start[0], "c" + step.b: move.start[1]},
                          motion=MOTION_CCW if self.side < 0 else MOTION_CW, distance=length, de=0.0,
                          time=length / (feed / 60.0) if feed > 0 else 0.0)

    def _cut_inside_corner(self, step: Step, move: OffsetMove, beta: float, tool_at: np.ndarray) -> np.ndarray:
        """An inside corner: the queued move ends, and this one starts, where the two offset paths meet
        (worked out as rs274 does, which also picks the side when the path turns back on itself)."""
        meet = inside_corner(self.last_path, self.last_dir, move, beta, tool_at, self.side, self.radius)
        if meet is None:
            self._error(step.row, _corner_problem(self.last_path, move))
            return move.new_start
        if self.queue.overruns(meet, self._inch(step)):
            self._error(step.row, _ARC_GOUGE)
        self.out.move_ends(self.queue.rows(), step.a, step.b, meet)
        return meet

    def _check_queued_line(self, step: Step) -> None:
        """A queued straight move whose end a corner moved behind its start would gouge."""
        queue = self.queue
        if queue.direction is None:  # an arc: checked against its sweep instead (Queue.overruns)
            return
        if queue.runs_backwards(self.out.point(queue.row, step.a, step.b)):
            kind = "traverse" if self.out.motion(queue.row) == MOTION_RAPID else "feed"
            self._error(step.row, f"Straight {kind} in concave corner cannot be reached by the tool without gouging")

    def _profile_end(self, step: Step) -> bool:
        """A G70's first own rapid under compensation (its approach to the cycle point came before).

        rs274 reads the profile into its current point, so the tool goes to the
        profile's end, queued behind the approach, and the next corner is judged
        from the programmed point to there.
        """
        if not (step.nth == 1 and self.profile_ends and self.profile_ends[0][0] == int(self.table.line[step.row])
                and int(self.table.name[step.row]) == NAME_ID["lathe_finish"]):
            return False
        f, g = "xyz".index(step.a), "xyz".index(step.b)
        tool_at = self.profile_ends.pop(0)[1][[f, g]]
        self.queue.staying.append(self.out.emit(step.k, **{step.a: tool_at[0], step.b: tool_at[1]}))
        self.last_dir = -self.side * left(unit(tool_at - self.last_corner))
        self.last_path = OffsetLine(tool_at, self.last_dir)
        return True

    def _offset(self, step: Step, tool_at: np.ndarray, end: np.ndarray) -> OffsetMove | None:
        """The move offset by the radius from the last programmed corner (from the tool without one); None
        when it needs no corner: a move along the plane's normal, or an arc the tool cannot fit in."""
        corner = self.last_corner if self.last_corner is not None else tool_at
        if np.hypot(*(end - corner)) < TINY and step.motion < MOTION_CW:  # along the normal: keeps the offset
            row = self.out.emit(step.k, **{step.a: tool_at[0], step.b: tool_at[1]})
            if self.queue.row is not None:
                self.queue.staying.append(row)  # an inside corner moves it with the queued move
            return None
        if step.motion not in (MOTION_CW, MOTION_CCW):
            return offset_line(corner, end, self.side, self.radius)
        centre = np.array([self.columns["c" + step.a][step.k], self.columns["c" + step.b][step.k]])
        move = offset_arc(corner, end, centre, step.motion == MOTION_CCW, self.side, self.radius)
        if move is None:
            self._error(step.row, "Tool radius not less than arc radius with comp")
            self.out.emit(step.k)
        return move

    # -- small helpers

    def _tool_at(self, step: Step) -> np.ndarray:
        """Where the tool is in the plane: the last written point."""
        return self.out.point(-1, step.a, step.b) if self.out else np.zeros(2)

    def _end(self, step: Step) -> np.ndarray:
        """The programmed end of the waypoint's move, in the plane."""
        return np.array([self.columns[step.a][step.k], self.columns[step.b][step.k]])

    def _leaves_plane(self, step: Step) -> bool:
        """Whether the waypoint moves along the plane's normal (a plunge, not an entry)."""
        column = self.columns[step.h]
        return step.k > 0 and abs(column[step.k] - column[step.k - 1]) > TINY

    def _inch(self, step: Step) -> bool:
        return self.columns["units"][step.k] == 1

    def _error(self, row: int, message: str) -> None:
        self.op.diagnostics.report(int(self.table.line[row]), 1, message, kind="machine")


def _corner_problem(before: OffsetPath, move: OffsetMove) -> str:
    """rs274's message for an inside corner whose offset paths never meet."""
    if isinstance(before, OffsetLine) and move.arc is not None:
        return _ARC_GOUGE
    first = "Arc" if isinstance(before, OffsetArc) else "Straight"
    second = "arc" if move.arc is not None else "straight"
    return f"{first} to {second} motion makes a corner the compensated tool can't fit in without gouging"
