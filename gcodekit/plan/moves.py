"""Plan stage: the moves a firmware plans, and what it planned.

A firmware does not plan G-code lines; it plans *moves*: straight segments
of the toolhead (arcs cut into chords by the firmware's own rule) and
extruder-only moves.  :func:`firmware_moves` turns an emulated operation's
waypoints into those moves, each remembering the command row and waypoint
it came from, so a plan can be summed back onto the program.

Names follow Klipper's suffixes: ``_d`` mm, ``_v`` mm/s, ``_v2`` mm^2/s^2,
``_t`` s, ``_r`` ratio.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..columns import Column, GatheredColumn, stored
from ..emulate import arcs
from ..parse.table import MOTION_RAPID, NAME_ID, in_ids
from .kernels import engine, runs_of, units_of
from .points import MoveEnds, RunningSum, chained

if TYPE_CHECKING:
    from ..emulate.program import EmulatedProgram

#: Chords of each arc, from its length (mm), swept angle (rad), radius (mm)
#: and requested speed (mm/s): how many segments.
ArcRule = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class MoveSource:
    """The waypoint columns :func:`firmware_moves` reads each move's requested speed and command row from.

    A planner's kept moves (:class:`PlannedMoves`) hold these columns, which
    the operation keeps anyway, instead of two arrays per move (36 MB on a
    3 M-move print), and read the values again, bit for bit, when asked.
    """

    feed: Column  # read at the moves' waypoints only: a column stored as runs stays so
    command: np.ndarray
    motion: np.ndarray
    rapid_v: float | None
    factor: np.ndarray | None
    n_rows: int

    def speed_v(self, waypoint: np.ndarray) -> np.ndarray:
        """Requested speed (mm/s) of the moves of ``waypoint``: the feed over 60 (G0 at ``rapid_v`` when it is
        not the feed), times the speed factor."""
        speed = np.asarray(self.feed[waypoint], float) / 60.0
        if self.rapid_v is not None:  # G0 at the machine's rapid rate (Sailfish), as the emulator times it
            speed[self.motion[waypoint] == MOTION_RAPID] = self.rapid_v
        if self.factor is not None:
            speed *= self.factor[waypoint]
        return speed

    def row(self, waypoint: np.ndarray) -> np.ndarray:
        """Command row of the moves of ``waypoint``."""
        return _narrow(self.command[waypoint], self.n_rows)


class _SpeedsAndRows:
    """Each move's requested speed and command row: stored, or read again from the moves' :class:`MoveSource`
    (``source``) at their waypoints, bit for bit, on each access."""

    _speed_v: np.ndarray | None
    _row: np.ndarray | None
    source: MoveSource | None
    waypoint: np.ndarray

    @property
    def speed_v(self) -> np.ndarray:
        return self.speeds(slice(None))

    @property
    def row(self) -> np.ndarray:
        return self.rows(slice(None))

    @property
    def read_from_source(self) -> bool:
        """Whether the speeds and rows are read from :attr:`source` (not stored)."""
        return self._speed_v is None

    def speeds(self, sel: slice | np.ndarray) -> np.ndarray:
        """The requested speeds of the moves ``sel``, without reading every move's."""
        return self._speed_v[sel] if self._speed_v is not None else self.source.speed_v(self.waypoint[sel])

    def rows(self, sel: slice | np.ndarray) -> np.ndarray:
        """The command rows of the moves ``sel``."""
        return self._row[sel] if self._row is not None else self.source.row(self.waypoint[sel])


class PlannerMoves(_SpeedsAndRows):
    """Straight moves in the order the firmware receives them.

    Attributes
    ----------
    start, end : ndarray, shape (n, 4)
        X, Y, Z and extruder position (mm) at both ends (or, from
        ``firmware_moves(gathered=True)``, views that gather a slice of moves
        when indexed: see :class:`.points.MoveEnds`).
    speed_v : ndarray, shape (n,)
        Requested speed (mm/s): the feed rate over 60 times the speed factor.
    row : ndarray of int32 (int64 past 2**31 rows)
        Command row each move comes from.
    waypoint : ndarray of int32 (int64 past 2**31 waypoints)
        Waypoint each move belongs to (several for a segmented arc).
    source : MoveSource, optional
        Where ``speed_v`` and ``row`` were read (moves straight from
        :func:`firmware_moves`; moves changed since have none).  Given
        without ``speed_v`` and ``row``, those are read from it on each
        access, and :meth:`speeds` and :meth:`rows` read a block of moves'
        (Marlin's planner, which never holds every move's).
    """

    def __init__(self, start: np.ndarray, end: np.ndarray, speed_v: np.ndarray | None, row: np.ndarray | None,
                 waypoint: np.ndarray, source: MoveSource | None = None):
        if source is None and (speed_v is None or row is None):
            raise ValueError("moves need their speeds and rows, or the source to read them from")
        for values in (speed_v, row) if source is not None else ():
            if values is not None:  # what the source gives: changing them would part them from it
                values.flags.writeable = False
        self.start, self.end, self.waypoint, self.source = start, end, waypoint, source
        self._speed_v, self._row = speed_v, row

    def __len__(self) -> int:
        return int(self.waypoint.size)

    @property
    def axes_d(self) -> np.ndarray:
        return np.asarray(self.end) - np.asarray(self.start)

    def select(self, keep: np.ndarray | slice) -> "PlannerMoves":
        """The moves ``keep`` (a slice reads gathered points for those moves alone)."""
        if isinstance(keep, slice):
            start, end = self.start[keep], self.end[keep]
        else:
            start, end = np.asarray(self.start)[keep], np.asarray(self.end)[keep]
        return PlannerMoves(start, end, self.speeds(keep), self.rows(keep), self.waypoint[keep])

    def planned(self, length_d: np.ndarray | None = None) -> "PlannedMoves":
        """What an operation keeps after planning: no end points, just each move's length (``length_d``, the
        planner's, or computed from the end points), and the speeds and rows read from :attr:`source` when
        there is one."""
        if length_d is None:
            axes_d = self.axes_d
            length_d = np.sqrt(np.einsum("ij,ij->i", axes_d[:, :3], axes_d[:, :3]))
            length_d = np.where(length_d > 0, length_d, np.abs(axes_d[:, 3]))  # extruder-only moves
        if self.source is not None:
            return PlannedMoves(None, None, self.waypoint, length_d, source=self.source)
        return PlannedMoves(self.speed_v, self.row, self.waypoint, length_d)


class PlannedMoves(_SpeedsAndRows):
    """The planned moves an operation keeps (``op.plan``), a quarter of :class:`PlannerMoves`' size.

    Attributes
    ----------
    speed_v : ndarray
        Requested speed (mm/s).
    row, waypoint : ndarray of int32 (int64 past 2**31)
        Command row and waypoint each move comes from.
    length_d : ndarray
        Toolhead travel (mm); the extruder's for extruder-only moves (kept
        as a :class:`~gcodekit.columns.GatheredColumn` of the waypoints'
        distances where a planner gives it so).

    Given a ``source`` instead of ``speed_v`` and ``row``, those two are read
    from the waypoint columns at each move's waypoint, on every access.
    """

    def __init__(self, speed_v: np.ndarray | None, row: np.ndarray | None, waypoint: np.ndarray,
                 length_d: np.ndarray, *, source: MoveSource | None = None):
        if source is None and (speed_v is None or row is None):
            raise ValueError("planned moves need their speeds and rows, or the source to read them from")
        self._speed_v, self._row, self.source = speed_v, row, source
        self.waypoint, self._length_d = waypoint, length_d

    def __len__(self) -> int:
        return int(self.waypoint.size)

    def __repr__(self) -> str:
        return f"PlannedMoves({len(self)} moves)"

    @property
    def length_d(self) -> np.ndarray:
        return np.asarray(self._length_d)

    @length_d.setter
    def length_d(self, lengths: np.ndarray | GatheredColumn) -> None:
        self._length_d = lengths


@dataclass
class PlanResult:
    """Per move: the planned velocities, acceleration and phase durations."""

    start_v: np.ndarray
    cruise_v: np.ndarray
    end_v: np.ndarray
    accel: np.ndarray
    accel_t: np.ndarray
    cruise_t: np.ndarray
    decel_t: np.ndarray

    @property
    def duration_t(self) -> np.ndarray:
        return self.durations()

    def durations(self, sel: slice = slice(None)) -> np.ndarray:
        """Each move's time (of the moves ``sel``), s: ``accel_t + cruise_t + decel_t``."""
        duration_t = self.accel_t[sel] + self.cruise_t[sel]
        duration_t += self.decel_t[sel]  # in place: one array fewer
        return duration_t

    def phases(self, sel: slice | np.ndarray = slice(None)) -> "PlanResult":
        """The moves ``sel`` (a slice or indices); see :meth:`.trapezoids.TrapezoidPlan.phases`."""
        return PlanResult(*(getattr(self, f)[sel] for f in ("start_v", "cruise_v", "end_v", "accel", "accel_t",
                                                              "cruise_t", "decel_t")))


def command_rows(op: "EmulatedProgram", *, names: tuple[str, ...] = (), codes: tuple[str, ...] = ()) -> np.ndarray:
    """Rows of the commands with these normalized names or literal codes (``"M204"``, named commands)."""
    t = op.table
    mask = np.zeros(len(t), bool)
    ids = [NAME_ID[n] for n in names if n in NAME_ID]
    if ids:
        mask |= in_ids(t.name, ids)
    for code in codes:
        m = re.fullmatch(r"([GMT])(\d+)(?:\.(\d))?", code)
        if m:  # compare letter and number columns, no strings per row
            tenths = int(m.group(2)) * 10 + int(m.group(3) or 0)
            mask |= (t.letter == ord(m.group(1))) & (t.number == tenths)
        else:
            rows = [r for r, (name, _) in t.named.items() if name.upper() == code]
            mask[rows] = True
    return np.flatnonzero(mask)


def speed_factor(op: "EmulatedProgram") -> np.ndarray | None:
    """M220 S, as a ratio, in force at each waypoint (1 before any); None without M220."""
    t = op.table
    rows = command_rows(op, names=("set_speed_factor",))
    if rows.size == 0:
        return None
    w = op.waypoints
    cmd = w["command"]
    values = t.param_at("S", rows) / 100.0
    values = np.where(np.isnan(values), 1.0, values)
    k = np.searchsorted(rows, cmd, side="right") - 1
    return np.where(k >= 0, values[np.maximum(k, 0)], 1.0)


def searchsorted_many(a: np.ndarray, v: np.ndarray, side: str = "left") -> np.ndarray:
    """``np.searchsorted(a, v, side)``, merged in one pass when ``v`` is sorted and much longer than ``a``.

    A program has a few thousand setting commands and millions of moves in
    order: placing each move among the commands jumps about memory, while
    placing the commands among the moves and counting them up is linear.
    ``a[j] < v[i]`` (``side="left"``) holds exactly for ``i`` at or past
    ``v``'s right insertion point of ``a[j]``; likewise ``<=`` for the left one.
    """
    if 8 * a.size > v.size or not (v.size < 2 or bool(np.all(v[1:] >= v[:-1]))):
        return np.searchsorted(a, v, side=side)
    at = np.searchsorted(v, a, side="right" if side == "left" else "left")
    counts = np.bincount(at, minlength=v.size + 1)[:v.size]
    return np.cumsum(counts, out=counts)


def in_force(moves: PlannerMoves, rows: np.ndarray, values: np.ndarray, initial: float) -> np.ndarray:
    """Per move, the last value set by a command row before the move's row."""
    return StepSetting(rows, values, initial).at(moves.row)


@dataclass(frozen=True)
class StepSetting:
    """A setting that command ``rows`` change to ``values`` (``initial`` before the first).

    Kept as the changes, not one value per move, so that a planner reads it
    a block of moves at a time (:meth:`at`): one array fewer at the peak.
    """

    rows: np.ndarray
    values: np.ndarray
    initial: float

    def at(self, row: np.ndarray) -> np.ndarray:
        """The value in force at each of the command rows ``row``: the last set before it."""
        rows, n = self.rows, row.size
        if rows.size == 0 or n == 0 or rows[0] >= row[-1]:
            return np.full(n, self.initial, dtype=float)
        if rows[-1] < row[0]:  # set before the first move (the usual place): one value for all
            return np.full(n, float(self.values[-1]))
        k = searchsorted_many(rows, row, side="left") - 1
        return np.where(k >= 0, np.asarray(self.values, float)[np.maximum(k, 0)], self.initial)


def m204_in_force(op: "EmulatedProgram", moves: PlannerMoves, rows: np.ndarray,
                  targets: dict[str, tuple[str, float]], *, steps: bool = False) -> dict[str, np.ndarray]:
    """M204 per move: S sets every acceleration, a named word (P, T) overrides it.

    ``targets`` maps a word letter to (result name, value before any M204).
    Marlin 2 (M204.cpp) and RepRapFirmware 3 read it this way.  With
    ``steps`` each is a :class:`StepSetting` to read a block at a time.
    """
    t = op.table
    s_word = t.param_at("S", rows)
    out = {}
    for letter, (name, default) in targets.items():
        word = t.param_at(letter, rows)
        value = np.where(np.isnan(word), s_word, word)
        given = ~np.isnan(value)
        setting = StepSetting(rows[given], value[given], default)
        out[name] = setting if steps else setting.at(moves.row)
    return out


def settings_in_force(op: "EmulatedProgram", moves: PlannerMoves, rows: np.ndarray, letter: str,
                      initial: float, scale: float | np.ndarray = 1.0) -> np.ndarray | float:
    """Per move, the last value of word ``letter`` among ``rows`` before it (``initial`` before any).

    ``scale`` converts the word to the planner's unit (one factor, or one
    per row).  Returns a number when one value holds for every move (the
    common case: the limits are set once at the top), else an array.
    """
    values = op.table.param_at(letter, rows) * scale
    given = ~np.isnan(values)
    if not given.any():
        return float(initial)
    if len(moves) and rows[given][-1] < moves.rows(slice(0, 1))[0]:  # set once before the first move: one value
        return float(values[given][-1])
    per_move = in_force(moves, rows[given], values[given], initial)
    return float(per_move[0]) if per_move.min() == per_move.max() else per_move


def happens_before(moves: PlannerMoves, rows: np.ndarray) -> np.ndarray:
    """Per move: does one of ``rows`` (sorted) come between the previous move and this one?

    Moves come in program order, so each command row is placed among the
    moves' rows: the first move past it has it in between when that move's
    predecessor comes before it.  Arrays the size of ``rows`` (a program's
    few thousand setting commands) instead of four the size of the moves,
    which on a 3 M-line program left 47 MB of freed heap under the planner's
    peak.  Moves out of order (none that :func:`firmware_moves` makes) are
    counted move by move.
    """
    n = len(moves)
    out = np.zeros(n, bool)
    if rows.size == 0 or n == 0:
        return out
    row = moves.row
    if not bool(np.all(row[1:] >= row[:-1])):
        previous = np.r_[-1, row[:-1]]
        same_row = previous == row  # chords of one arc have nothing between them
        count_before = searchsorted_many(rows, row, side="left") - searchsorted_many(rows, previous, side="right")
        return (count_before > 0) & ~same_row
    first_after = np.searchsorted(row, rows, side="right")  # the first move whose row is past each command's
    inside = first_after < n
    first_after, command = first_after[inside], rows[inside]
    before = np.where(first_after > 0, row[np.maximum(first_after - 1, 0)], -1)  # that move's predecessor
    out[first_after[before < command]] = True  # not the command of the predecessor itself
    return out


def follows_kept_step(moves: PlannerMoves, kept: np.ndarray) -> np.ndarray:
    """Per move: does one of the waypoints ``kept`` (sorted) come between the previous move and this one?"""
    if kept.size == 0 or len(moves) == 0:
        return np.zeros(len(moves), bool)
    previous_wp = np.r_[-1, moves.waypoint[:-1]]
    return np.searchsorted(kept, moves.waypoint) > np.searchsorted(kept, previous_wp)


def firmware_moves(op: "EmulatedProgram", speed_factor: np.ndarray | None = None,
                   arc_segments: ArcRule | None = None, *, gathered: bool = False) -> PlannerMoves:
    """The straight moves of an emulated operation, arcs cut by ``arc_segments``.

    Parameters
    ----------
    op : EmulatedProgram
        Emulated (``op.waypoints`` present).
    speed_factor : ndarray, optional
        Per waypoint multiplier of the feed (M220), 1 when None.
    arc_segments : callable, optional
        Segment count from arc length, swept angle, radius and requested
        speed (see :data:`ArcRule`); None keeps each arc as one move along
        its chord (only for machines that do not segment).
    gathered : bool, default: False
        Give ``start`` and ``end`` as :class:`.points.MoveEnds` views that
        gather a slice of moves from the waypoints when indexed, instead of
        stored arrays, for a planner that reads them a block at a time (when
        no arc is cut into chords).
    """
    w = op.waypoints
    n = len(stored(w, "x"))
    rows = w["command"]
    # Homing moves go to an endstop from wherever the axis really is: their
    # length and time are unknown, and firmware time estimates leave them out.
    homing = in_ids(op.table.name[rows], [NAME_ID["home"], NAME_ID["home_secondary"]])
    compiled = engine(n)
    # columns kept compactly (decimal units, runs) are read as they are, or decoded here for a moment: the
    # operation keeps them compact, and the planner's own arrays come after these
    points = tuple(stored(w, k) for k in ("x", "y", "z"))
    e = np.cumsum(stored(w, "de")) if compiled is None else None
    if compiled is not None:  # the same moves and points in one loop, without the temporaries below
        (x, x_scale), (y, y_scale), (de, de_scale) = (units_of(stored(w, k)) for k in ("x", "y", "de"))
        idx, start, end, is_chained = compiled.move_points(x, y, *runs_of(points[2]), de,
                                                           np.array([x_scale, y_scale, de_scale]), w["motion"], homing,
                                                           w["distance"], not gathered)
        del x, y, de
        idx = _narrow(idx, n)
    else:
        points = tuple(np.asarray(c) for c in points)
        columns = (*points, e)
        changed = np.zeros(n, bool)
        for col in columns:  # compare with the previous waypoint column by column
            changed[:1] |= col[:1] != 0
            changed[1:] |= col[1:] != col[:-1]
        full_circle = (w["motion"] >= 3) & (w["distance"] > 0)  # ends where it started
        idx = _narrow(np.flatnonzero((w["motion"] > 0) & ~homing & (changed | full_circle)), n)
        del changed
        is_chained = chained(columns, idx)
    del homing
    rapids_at_feed = op.machine.rapids_at_feed(op.flavor is None or op.flavor.rapid_is_feed)
    source = MoveSource(stored(w, "feed"), rows, w["motion"], None if rapids_at_feed else op.machine.rapid_feed / 60.0,
                        speed_factor, len(op.table))
    is_arc = w["motion"][idx] >= 3
    segmenting = arc_segments is not None and bool(is_arc.any())
    # gathered, the planner reads the speeds and rows a block at a time too: two arrays fewer at its peak
    speed, rows = (None, None) if gathered and not segmenting else (source.speed_v(idx), source.row(idx))
    if gathered or compiled is None:  # the points from the waypoint columns: gathered when asked, else stored
        ends = MoveEnds((*points, RunningSum(stored(w, "de"), e)), idx, is_chained)
        start, end = (ends.start, ends.end) if gathered and not segmenting else ends.arrays()
        del ends, e
    if not segmenting:
        return PlannerMoves(start, end, speed, rows, idx, source)
    return _with_segmented_arcs(op, idx, is_arc, start, end, speed, rows, arc_segments, source)


def _narrow(index: np.ndarray, bound: int) -> np.ndarray:
    """Indices below ``bound`` as int32 when it fits: a move's row and waypoint take half the memory."""
    return index.astype(np.int32) if bound < 2**31 else index


def _chords_within_limit(op, chords: np.ndarray, angle: np.ndarray, rows: np.ndarray, room: int) -> np.ndarray:
    """Chord counts of the arcs, cut down when they would pass ``max_motions`` (an arc with a huge
    radius or a billion turns can ask for billions); the error names the arc asking for the most.

    An arc whose fewer chords would each sweep more than a quarter turn (a
    multi-turn arc: its chords would collapse to points) gets none: it keeps
    the emulator's time, its length over its feed.
    """
    total = float(chords.sum())
    if total <= room:
        return chords.astype(np.int64)
    worst = int(np.argmax(chords))
    scale = max(room, chords.size) / total
    counts = np.maximum(np.floor(chords * scale), 1.0).astype(np.int64)
    unplanned = angle / counts > np.pi / 2
    counts[unplanned] = 0
    coarser = "planned with fewer chords, so their times are approximate"
    if unplanned[worst]:
        what = f"this one (asking for {chords[worst]:,.0f}) is timed at its length over its feed"
        what += f"; other arcs are {coarser}" if (~unplanned).any() else ""
    else:
        what = f"{coarser} (this one asked for {chords[worst]:,.0f})"
        what += "; arcs of many turns are timed at their length over their feed" if unplanned.any() else ""
    op.diagnostics.report(int(op.table.line[rows[worst]]), 1, f"arcs would be cut into {total:,.0f} moves, more than "
                          f"max_motions={op.max_motions:,}; {what}", kind="limit")
    return counts


def _with_segmented_arcs(op, idx, is_arc, move_start, move_end, speed, rows, arc_segments,
                         source: MoveSource) -> PlannerMoves:
    """Replace each arc waypoint by its chords (Klipper's and Marlin's plan_arc)."""
    w = op.waypoints
    counts = np.ones(idx.size, np.int64)
    arc_idx = idx[is_arc]
    centers = np.column_stack([w["cx"], w["cy"], w["cz"]])[arc_idx]
    planes = np.asarray(w["plane"])[arc_idx]
    start = move_start[is_arc]
    end = move_end[is_arc]
    cw = np.asarray(w["motion"])[arc_idx] == 3
    radius = np.zeros(arc_idx.size)
    axes = np.zeros((arc_idx.size, 3), np.int64)
    for plane in (17, 18, 19):
        sel = planes == plane
        if not sel.any():
            continue
        (f, g, h), _ = arcs.PLANES[plane]
        axes[sel] = (f, g, h)
        radius[sel] = np.hypot(*(start[sel][:, [f, g]] - centers[sel][:, [f, g]]).T)
    rise = end[np.arange(arc_idx.size), axes[:, 2]] - start[np.arange(arc_idx.size), axes[:, 2]]
    # The emulator's path length holds the whole sweep, extra turns (P) included: the angle is
    # the unrolled arc (the length without the rise) over the radius.
    travel = np.asarray(w["distance"], float)[arc_idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        angle = np.sqrt(np.maximum(travel**2 - rise**2, 0.0)) / radius
    angle = np.where(np.isfinite(angle), angle, 0.0)
    chords = np.maximum(arc_segments(travel, angle, radius, speed[is_arc]), 1.0)
    counts[is_arc] = _chords_within_limit(op, chords, angle, rows[is_arc],
                                          room=op.max_motions - (idx.size - arc_idx.size))
    if not counts.all():  # arcs left unplanned: no moves
        kept, kept_arcs = counts > 0, counts[is_arc] > 0
        idx, is_arc, move_start, move_end, speed, rows, counts = (a[kept] for a in (idx, is_arc, move_start, move_end,
                                                                                  speed, rows, counts))
        centers, start, cw, angle, radius, axes = (a[kept_arcs] for a in (centers, start, cw, angle, radius, axes))

    total = int(counts.sum())
    owner = np.repeat(np.arange(idx.size), counts)
    step = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts) + 1  # 1..k within a move
    frac = step / counts[owner]
    end_all = move_start[owner] + (move_end - move_start)[owner] * frac[:, None]
    arc_pos = np.flatnonzero(is_arc)
    which = np.full(idx.size, -1)
    which[arc_pos] = np.arange(arc_pos.size)
    arc_owner = which[owner]
    sel = (arc_owner >= 0) & (step < counts[owner])  # inner chord ends; the last one is exact
    k = arc_owner[sel]
    sign = np.where(cw[k], -1.0, 1.0)
    theta = sign * angle[k] * frac[sel]
    a0 = np.arctan2(start[k, axes[k, 1]] - centers[k, axes[k, 1]], start[k, axes[k, 0]] - centers[k, axes[k, 0]])
    rows_sel = np.flatnonzero(sel)
    end_all[rows_sel, axes[k, 0]] = centers[k, axes[k, 0]] + radius[k] * np.cos(a0 + theta)
    end_all[rows_sel, axes[k, 1]] = centers[k, axes[k, 1]] + radius[k] * np.sin(a0 + theta)
    start_all = np.vstack([move_start[:1], end_all[:-1]])
    first = np.cumsum(counts) - counts
    start_all[first] = move_start
    return PlannerMoves(start_all, end_all, speed[owner], rows[owner], idx[owner], source)


def with_kept_steps(w, moves: PlannerMoves, result: PlanResult, kept: np.ndarray) -> tuple[PlannerMoves, PlanResult]:
    """Insert the steps ``kept`` (waypoints the planner has no move for) in program order, at the emulator's time.

    Such steps are rotary-only moves, moves through stored points and arcs
    too long to cut into chords within ``max_motions``; the machine is taken
    to be at rest around them (see :func:`follows_kept_step`).
    """
    k = kept.size
    position = np.column_stack([w["x"], w["y"], w["z"], np.cumsum(w["de"])])[kept]
    rows = w["command"][kept]
    extra = PlannerMoves(position, position.copy(), np.asarray(w["feed"], float)[kept] / 60.0, rows, kept)
    zero = np.zeros(k)
    extra_result = PlanResult(zero, zero, zero, np.full(k, np.inf), zero, np.asarray(w["time"], float)[kept], zero)
    order = np.argsort(np.r_[moves.waypoint, kept], kind="stable")

    def merged(a, b):
        return np.concatenate([a, b])[order]

    moves = PlannerMoves(*(merged(getattr(moves, f), getattr(extra, f))
                           for f in ("start", "end", "speed_v", "row", "waypoint")))
    result = PlanResult(*(merged(getattr(result, f), getattr(extra_result, f))
                          for f in ("start_v", "cruise_v", "end_v", "accel", "accel_t", "cruise_t", "decel_t")))
    return moves, result
