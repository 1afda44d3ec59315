"""Emulate stage: run command tables on a modal machine, producing waypoints.

Most commands only move within a fixed modal state (units, distance mode,
offsets, plane).  Runs of such commands are emulated with array code: in
absolute mode a target coordinate is the last one given (a forward fill),
in incremental mode it is a running sum.  Commands that change that state
(G20/G21, G90/G91, G92, G54..., G28, G53, M82/M83, tool changes, ...) are
few and are handled one at a time between the runs, each by the handler
registered for it (:mod:`.modal` dispatches, :mod:`.handlers` holds them).

Every command gives one waypoint: its end state.  A command that moves
through several points (G28 via its intermediate point) adds waypoints
before its own, each pointing back to the command.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import Diagnostics
from ..limits import MAX_MOTIONS, MotionBudget, TooManyMotions
from ..parse.commands import Kind
from ..parse.split import MOTIONS
from ..parse.table import (MOTION_CCW, MOTION_CW, MOTION_CYCLE, MOTION_LINEAR, MOTION_RAPID, MOTION_THREAD, NAME_ID,
                           SPLINE_MOTIONS, CommandTable, in_ids)
from ..schema import allocate
from ..units import MM_PER_INCH, mm_per
from . import arcs
from .handlers import Context
from .handlers.modes import FEED_AT_OR_BELOW_ZERO
from .fill import forward_fill
from .ini import LinuxCncIni
from .modal import ModalHandler, Waypoint
from .presets import MachineConfig
from .state import AXES, MachineState
from .tooltable import ToolTable

_MOVING = np.array(sorted({Kind.MOVE, Kind.ARC, Kind.MOVE_EXTRUDE, Kind.ARC_EXTRUDE, Kind.MOVE_MILL,
                           Kind.ARC_MILL, Kind.EXTRUDE}), np.uint8)
_MILL = np.array([Kind.MILL, Kind.MOVE_MILL, Kind.ARC_MILL], np.uint8)
_G0_TO_G3 = np.array(sorted(NAME_ID[n] for n in ("rapid", "linear", "arc_cw", "arc_ccw")), np.uint8)
#: Said at each G0-G3 with an F at or below 0 on firmware whose zero_feed is "stops" (Klipper).
INVALID_SPEED = ("Invalid speed: Klipper refuses a move with F at or below 0, which is not made (its axis words are "
                 "dropped, the feed stays); a print from its virtual SD card stops here")


def _held(values: np.ndarray, before: float) -> np.ndarray:
    """Each row's last given value (NaN means none given), ``before`` until the first."""
    known = ~np.isnan(values)
    last = np.maximum.accumulate(np.where(known, np.arange(values.size), -1))
    return np.where(last >= 0, values[np.maximum(last, 0)], before)


def mode_rows(table: CommandTable, on: str, off: str, initially: bool = False) -> np.ndarray:
    """Which rows run while the modal switch ``on`` (not yet ``off``) is in force, in table order."""
    switches = np.full(len(table), -1, np.int8)
    switches[table.name == NAME_ID[on]] = 1
    switches[table.name == NAME_ID[off]] = 0
    if not (switches >= 0).any():
        return np.full(len(table), initially)
    last = np.maximum.accumulate(np.where(switches >= 0, np.arange(len(table)), -1))
    return np.where(last >= 0, switches[np.maximum(last, 0)], int(initially)) == 1


class Machine:
    """A modal machine that emulates command tables chunk by chunk.

    Parameters
    ----------
    config : MachineConfig
    diagnostics : Diagnostics, default: a new lenient collector
    rapid_is_feed : bool
        G0 moves at the modal feed (from the flavor unless the preset says).
    rs274_blocks : bool
        RS274NGC block rules (F in any block; unknown axis letters refused).
    polar_incremental_only : bool
        GER's G16 rules: polar moves only in G91, program zero fixed meanwhile.
    max_motions : int, default: :data:`gcodekit.limits.MAX_MOTIONS`
        The waypoints the program may make (one per block, plus the moves
        cycles and threads expand into); at the limit the machine stops with
        an error naming the line (see :mod:`gcodekit.limits`).
    zero_feed : {"refused", "kept", "minimum_speed", "stops"}
        What the firmware does with an F at or below 0 (see
        :attr:`gcodekit.syntax.Flavor.zero_feed`).
    minimum_feed : float, default: 0
        mm/min; where ``zero_feed`` is ``"minimum_speed"``, the slowest the
        firmware moves, however low the feed (RepRapFirmware's M203 I, which
        the program may change); 0 when not known: moves at F0 are untimed.
    """

    def __init__(self, config: MachineConfig, diagnostics: Diagnostics | None = None, *,
                 rapid_is_feed: bool = False, initial_units: str = "mm", initial_extrusion: str = "",
                 rs274_blocks: bool = False, polar_incremental_only: bool = False, max_motions: int = MAX_MOTIONS,
                 zero_feed: str = "refused", minimum_feed: float = 0.0):
        self.config = config
        self.budget = MotionBudget(max_motions)
        self.out_of_budget = False  # stopped at max_motions: the rest of the program is not run
        self.diagnostics = Diagnostics() if diagnostics is None else diagnostics
        self.rapid_is_feed = config.rapids_at_feed(rapid_is_feed)
        # RS274NGC block rules: an F word sets the feed whatever else the block
        # does, and a word for an axis the machine lacks is an error.  Printer
        # firmware reads F only on moves and U/V/W as flags (Prusa's G28 W).
        self.rs274_blocks = rs274_blocks
        self.zero_feed = zero_feed  # an F at or below 0: "refused", "kept" (Marlin), "minimum_speed" (RRF), "stops"
        self.polar_incremental_only = polar_incremental_only  # GER's G16 rules
        self.state = MachineState()
        self.state.units = mm_per(initial_units)
        self.state.e_relative = initial_extrusion == "relative"
        if zero_feed == "minimum_speed":
            self.state.minimum_feed = minimum_feed
        self.state.cycle.retract_to_r = config.cycle_retract == "r"
        if config.initial_feed > 0:
            self.state.feed = config.initial_feed
        for code, vector in config.work_offsets.items():
            self.state.work_offsets[_WORK_INDEX[code], : len(vector)] = vector
        self.state.select_work_system(1)
        self.tools = ToolTable.read(config.tool_table, units=config.tool_table_units) if config.tool_table else ToolTable()
        self.ini = LinuxCncIni.read(config.ini_file) if config.ini_file else None
        for number, text, reason in self.tools.skipped[:20]:
            self.diagnostics.report(number, 1, f"tool table line skipped, as LinuxCNC does: {reason}", text,
                                    severity="warning", file=self.tools.source)
        self._straight_ids = np.array([NAME_ID["rapid"], NAME_ID["linear"]], np.uint8)
        self._motion_mode_ids = np.array(sorted(NAME_ID[n] for n in MOTIONS | {"rigid_tap"}), np.uint8)
        self._table_z, self._table_w = np.nan, 0.0  # last Z and table-axis words (see _part_frame)
        self._warned: set[str] = set()
        #: Where the last probe move (G38.2-G38.5) "tripped": its target in program
        #: coordinates and units, X Y Z A B C (see :meth:`_after_probe`); None before one.
        self.probe_result: np.ndarray | None = None
        self.probes = 0  # probe moves run so far
        #: (source line, profile end X Y Z in machine coordinates) of each G70 run under cutter
        #: compensation, in order: the compensation pass needs it (see ``compensation``)
        self.comp_profile_ends: list[tuple[int, np.ndarray]] = []
        # the state-changing commands see the machine's parts, not the machine
        self.modal = ModalHandler(Context(self.state, config, self.diagnostics, self.tools, self.budget,
                                          self.warn_once, rs274_blocks=rs274_blocks,
                                          polar_incremental_only=polar_incremental_only,
                                          zero_feed=zero_feed,
                                          rapid_is_feed=self.rapid_is_feed, comp_profile_ends=self.comp_profile_ends))

    # -- running ----------------------------------------------------------------

    def _part_frame(self, table: CommandTable) -> CommandTable:
        """The table as the part sees it when a table axis carries it (BAAM's W): Z words become Z - W.

        Both are absolute positions held between blocks, so a block with
        only W (the table dropping a layer) moves the tool up in the part
        frame, and one with only Z moves by Z less the table's height.  Table
        moves before the program's first Z leave the tool's height alone.
        """
        axis = self.config.table_axis
        if not axis:
            return table
        z, w = table.param("Z"), table.param(axis)
        given = ~np.isnan(z) | ~np.isnan(w)
        if not given.any():
            return table
        z_held = _held(z, self._table_z)  # NaN until the program first gives Z: the table moves alone
        w_held = _held(w, self._table_w)
        self._table_z, self._table_w = float(z_held[-1]), float(w_held[-1])
        params = {k: v for k, v in table.params.items() if k != axis}
        params["Z"] = np.where(given, z_held - w_held, np.nan)
        return dataclasses.replace(table, params=params)

    def _radius_words(self, table: CommandTable) -> CommandTable:
        """The table as the machine reads it under G7: X words halved (diameters to radii).

        rs274 halves X on moves, canned cycles, G92 and G52, but not G10's
        offsets, and never I (an arc centre's X offset stays a radius).  The
        parsed table keeps the program's own words.
        """
        if "X" not in table.params:
            return table
        diameter = mode_rows(table, "diameter_mode", "radius_mode", self.state.diameter)
        diameter &= table.name != NAME_ID["coordinate_data"]
        x = table.param("X")
        if not (diameter & ~np.isnan(x)).any():
            return table
        return dataclasses.replace(table, params={**table.params, "X": np.where(diameter, x / 2.0, x)})

    def run(self, table: CommandTable) -> dict[str, np.ndarray]:
        """Waypoint columns for ``table``: one per command plus any extra ones.

        The returned dict holds the arrays of
        :data:`gcodekit.schema.WAYPOINT_COLUMNS` and ``command`` (row of the command each
        waypoint belongs to).
        """
        table = self._part_frame(self._radius_words(table))
        n = len(table)
        stop = 0 if self.out_of_budget else min(n, self.budget.room)  # each block makes a waypoint
        self.budget.spend(stop)
        out = allocate(n)
        special = in_ids(table.name, self.modal.special_ids) | (table.letter == ord("T"))
        special |= table.kind == Kind.MACHINE_COORDINATES
        moving_kind = in_ids(table.kind, _MOVING)
        special |= in_ids(table.motion, (MOTION_CYCLE, MOTION_THREAD) + SPLINE_MOTIONS) & moving_kind
        if self.rs274_blocks:
            self._check_axis_words(table)
        special |= mode_rows(table, "polar_on", "polar_off", self.state.polar) & moving_kind
        for letter in "@^":  # polar words depend on where the tool is: one block at a time
            if letter in table.params:
                special |= ~np.isnan(table.param(letter)) & moving_kind
        if self.config.block_delete and table.deleted.size:
            special[table.deleted] = True
        probing = (table.name == NAME_ID["probe"]) & ~special
        extra: list[tuple[int, Waypoint]] = []
        cursor = 0
        for row in np.flatnonzero(special | probing).tolist():
            if self.state.ended or row >= stop:
                break
            if row > cursor:
                self._run_segment(table, cursor, row, out)
            if probing[row]:
                start = self.state.position.copy()
                self._run_segment(table, row, row + 1, out)
                self._after_probe(start)
            else:
                try:
                    passed = self.modal.apply(table, row, out)
                    self.budget.spend(len(passed))
                except TooManyMotions as exc:
                    self._hold(row, row + 1, out)
                    self._out_of_budget(int(table.line[row]), f"this block would make up to {exc}")
                    passed = []
                extra += [(row, w) for w in passed]
            cursor = row + 1
        if cursor < stop and not self.state.ended:
            self._run_segment(table, cursor, stop, out)
            cursor = stop
        if stop < n and not self.out_of_budget:
            self._out_of_budget(int(table.line[stop]), f"the program makes more than max_motions="
                                f"{self.budget.limit:,} motions")
        self.modal.context.cycle_mode.open = bool(n) and int(table.motion[-1]) == MOTION_CYCLE
        setting = np.flatnonzero((table.letter == ord("G")) & in_ids(table.name, self._motion_mode_ids))
        if setting.size:  # the motion mode in force (#<_motion_mode>)
            self.state.motion_code = int(table.number[setting[-1]])
        if cursor < n:
            self._hold(cursor, n, out)
            # comments (and '%', which makes no row) after the end are no blocks left unrun
            unrun = np.flatnonzero(np.asarray(table.kind[cursor:]) != Kind.COMMENT)
            if unrun.size and not self.out_of_budget:
                self.warn_once("ended", int(table.line[cursor + int(unrun[0])]),
                               "blocks after the program end (M2/M30) are not run")
        return _constants_as_views(_with_extra_waypoints(out, extra, n))

    def _out_of_budget(self, line: int, problem: str) -> None:
        """Stop the machine at the motion limit: the rest of the program is not run."""
        self.diagnostics.report(line, 1, f"{problem}; the rest of the program is not run (raise max_motions "
                                "if it is meant to be this long)", kind="limit")
        self.out_of_budget = True
        self.state.ended = True
    def _after_probe(self, start: np.ndarray) -> None:
        """Where a probe move leaves the machine, as rs274 run standalone has it.

        With no probe input the move always "trips" at its target, which
        becomes :attr:`probe_result` (LinuxCNC's #5061-#5069; #5070, tripped,
        stays 0), and the tool then stands ``probe_backoff`` back towards
        the start without a move (saicanon.cc ``STRAIGHT_PROBE``: 0.01 inch
        or 0.254 mm).  A real machine's results depend on the part.  saicanon
        takes that direction from the last point it was sent, in the frame
        of then: after a G5x, G92 or tool offset change with no move in
        between it can point elsewhere; gcodekit backs off towards the
        probe's real start.
        """
        s = self.state
        target = s.position.copy()
        self.probe_result = s.program_position() / s.scale()
        self.probes += 1
        back = start[:3] - target[:3]
        length = float(np.linalg.norm(back))
        if length > 0 and self.config.probe_backoff > 0:
            s.position[:3] = target[:3] + back / length * self.config.probe_backoff

    def _check_probes(self, t: CommandTable, start: int, moving: np.ndarray, start_pos: np.ndarray,
                      position: np.ndarray) -> None:
        """A probe towards or away from the part (G38.2, G38.4) must go somewhere: rs274 refuses
        one that starts at its target; G38.3 and G38.5, which need no contact, may."""
        probing = moving & (t.name[start:start + moving.size] == NAME_ID["probe"])
        if not probing.any():
            return
        probes = np.flatnonzero(probing & np.isin(t.number[start:start + moving.size], (382, 384)))
        for i in probes[np.all(np.abs(position[probes] - start_pos[probes]) < 1e-9, axis=1)].tolist():
            self.diagnostics.report(int(t.line[start + i]), 1, "Start point too close to probe point", kind="machine")

    def _check_axis_words(self, table: CommandTable) -> None:
        """U/V/W words name axes this machine lacks: LinuxCNC refuses the block
        (``read_one_item`` in interp_read.cc has no reader for an axis letter
        outside the axis mask; rs274 standalone has X Y Z A B C)."""
        for letter in "UVW":
            col = table.params.get(letter)
            if col is None or letter in self._warned:
                continue
            given = ~np.isnan(col if isinstance(col, np.ndarray) else col.dense())
            rows = np.flatnonzero(given & (table.kind != Kind.COMMENT))
            if rows.size:
                self._warned.add(letter)
                self.diagnostics.report(int(table.line[rows[0]]), 1, f"Bad character '{letter.lower()}' used: "
                                        f"this machine has no {letter} axis (it has {' '.join(AXES)})",
                                        kind="machine")

    def _hold(self, start: int, stop: int, out: dict) -> None:
        """Rows after the program end: nothing moves."""
        self.state.fill_columns(slice(start, stop), out)
        for k, v in zip(AXES.lower(), self.state.position):
            out[k][start:stop] = v
        for k in ("de", "distance", "time"):
            out[k][start:stop] = 0.0
        for k in ("cx", "cy", "cz"):
            out[k][start:stop] = np.nan
        out["motion"][start:stop] = 0
        out["spindle"][start:stop] = self.state.speed * self.state.spindle
        out["feed"][start:stop] = self.state.feed

    # -- runs of plain commands ---------------------------------------------------

    def _run_segment(self, t: CommandTable, start: int, stop: int, out: dict) -> None:
        """Emulate rows ``start:stop``, none of which changes the modal state."""
        s = self.state
        rows = slice(start, stop)
        n = stop - start
        kind = t.kind[rows]
        moving = in_ids(kind, _MOVING)
        if self.config.empty_moves:
            moving |= in_ids(t.name[rows], self._straight_ids)
        if not self.config.radius_arcs and "R" in t.params:
            self._reject_radius_arcs(t, rows, moving)
        refused = self._refuse_invalid_speed(t, rows, moving) if self.zero_feed == "stops" else None
        motion = np.where(moving, t.motion[rows], 0).astype(np.uint8)
        scale = s.scale()
        program = s.program_position()
        # program coordinates, mm, stored axis by axis: each axis is filled and offset as one contiguous
        # column (NumPy's passes over rows of six are several times slower), same values either way
        targets = np.empty((6, n)).T
        for ax, letter in enumerate(AXES):
            col = t.params.get(letter)
            if col is None:
                targets[:, ax] = program[ax]
                continue
            values = _dense(col, rows) * scale[ax]
            values[~moving] = np.nan
            if s.incremental:
                targets[:, ax] = program[ax] + np.cumsum(np.nan_to_num(values))
            else:
                targets[:, ax] = forward_fill(values, program[ax])
        position = s.to_machine(targets)
        if s.program_shift.any():  # until the first move the machine stays where it is
            waiting = np.cumsum(moving) == 0
            position[waiting] = s.position
            if moving.any():
                s.program_shift[:] = 0.0
        start_pos = np.vstack([s.position[None, :], position[:-1]])
        self._check_probes(t, start, moving, start_pos, position)

        feed_words = _dense(t.params["F"], rows) if "F" in t.params else np.full(n, np.nan)
        if s.feed_mode != "inverse_time":  # G93's F is 1/minutes, not a length
            feed_words *= s.units
        feed_words[kind == Kind.COMMENT] = np.nan
        if not self.rs274_blocks:
            feed_words[kind == Kind.M] = np.nan
        if refused is not None:
            feed_words[refused] = np.nan  # the refused block sets no feed either
        if self.zero_feed in ("kept", "stops"):
            self._ignore_feed_at_or_below_zero(t, rows, feed_words)
        if s.feed_mode == "inverse_time":
            feed = feed_words  # 1/min, for this block only
        else:
            feed = forward_fill(feed_words, s.feed)
        if not s.feed_given:
            self._note_boot_feed(t, rows, feed_words, motion, position - start_pos)

        de = self._extrusion(t, rows, moving)
        delta = np.subtract(position, start_pos, order="C")  # row by row, as einsum has always summed it
        distance = np.sqrt(np.einsum("ij,ij->i", delta[:, :3], delta[:, :3]))
        centers = np.full((n, 3), np.nan)
        is_arc = (motion == MOTION_CW) | (motion == MOTION_CCW)
        if is_arc.any():
            program_start = np.vstack([program[None, :], targets[:-1]])
            self._arcs(t, start, np.flatnonzero(is_arc), program_start, targets, centers, distance)
        rotary = np.sqrt(np.einsum("ij,ij->i", delta[:, 3:], delta[:, 3:]))
        speed = self._spindle_speeds(t, rows, kind)
        no_spindle = np.zeros(n, bool)
        if s.feed_mode == "per_rev":  # G95: F is mm per spindle revolution
            no_spindle = (feed > 0) & ((speed == 0) | (s.spindle == 0))
            feed = feed * np.abs(speed) * (s.spindle != 0)
        minimum = self._minimum_feeds(t, rows) if self.zero_feed == "minimum_speed" else None
        time = self._durations(t, rows, kind, motion, distance, rotary, de, feed, no_spindle, minimum)

        for ax, letter in enumerate(AXES.lower()):
            out[letter][rows] = position[:, ax]
        out["de"][rows] = de
        # G93 gives each move a time (1/F minutes); like rs274, report the speed that makes it, over the
        # length from where rs274 takes the tool to be (after an offset change it may not be there yet)
        if s.feed_mode == "inverse_time":
            steps = np.linalg.norm(np.subtract(targets, np.vstack([program[None, :], targets[:-1]]), order="C")[:, :3],
                                   axis=1)
            length = np.where(is_arc, distance, steps)
            out["feed"][rows] = feed * np.where(length > 0, length, rotary)
        else:
            out["feed"][rows] = feed
        out["distance"][rows] = distance
        out["time"][rows] = time
        out["motion"][rows] = motion
        out["cx"][rows], out["cy"][rows], out["cz"][rows] = centers.T
        out["spindle"][rows] = speed * s.spindle
        self.state.fill_columns(rows, out)

        s.position = position[-1].copy()
        if moving.any():
            s.note_move()
        if s.feed_mode == "per_minute":
            s.feed = float(feed[-1])
        elif s.feed_mode == "per_rev":
            s.feed = float(forward_fill(feed_words, s.feed)[-1])
        s.speed = float(speed[-1])

    def _reject_radius_arcs(self, t: CommandTable, rows: slice, moving: np.ndarray) -> None:
        """Firmware without R-form arcs (Klipper) refuses the command: nothing moves."""
        arc = (t.motion[rows] == MOTION_CW) | (t.motion[rows] == MOTION_CCW)
        refused = moving & arc & ~np.isnan(_dense(t.params["R"], rows))
        for i in np.flatnonzero(refused)[:20]:
            self.diagnostics.report(int(t.line[rows][i]), 1, "this firmware rejects R-form arcs (give I/J); the arc is skipped",
                                    kind="machine")
        moving &= ~refused

    def _refuse_invalid_speed(self, t: CommandTable, rows: slice, moving: np.ndarray) -> np.ndarray | None:
        """Klipper refuses a G0-G3 with an F at or below 0: an error, and the block makes no move.

        gcode_move.py ``cmd_G1`` reads the axis words into ``last_position``,
        then raises "Invalid speed"; gcode.py's ``gcode:command_error`` event
        makes ``reset_last_position`` take the toolhead's position back
        (``toolhead.move`` never ran), so the words are dropped and the next
        move starts where the tool is.  An arc (gcode_arcs.py) passes its F
        to its first segment's ``cmd_G1``.  virtual_sdcard.py ``work_handler``
        runs ``on_error_gcode`` and stops the print on the error; gcodekit
        goes on in lenient mode, as for other firmware errors.  Returns the
        refused rows (None if none).
        """
        if "F" not in t.params:
            return None
        refused = (_dense(t.params["F"], rows) <= 0) & in_ids(t.name[rows], _G0_TO_G3)
        if not self.config.radius_arcs and "R" in t.params:  # an R-form arc is refused already
            arc = in_ids(t.motion[rows], (MOTION_CW, MOTION_CCW))
            refused &= ~(arc & ~np.isnan(_dense(t.params["R"], rows)))
        if not refused.any():
            return None
        for i in np.flatnonzero(refused)[:20]:
            self.diagnostics.report(int(t.line[rows][i]), 1, INVALID_SPEED, kind="machine")
        moving &= ~refused
        return refused

    def _extrusion(self, t: CommandTable, rows: slice, moving: np.ndarray) -> np.ndarray:
        s = self.state
        n = rows.stop - rows.start
        if "E" not in t.params:
            return np.zeros(n)
        e = _dense(t.params["E"], rows) * s.units
        e[~moving] = np.nan
        if s.e_relative or s.incremental:
            de = np.nan_to_num(e)
            s.e_program += float(de.sum())
        else:
            target = forward_fill(e, s.e_program)
            de = np.diff(target, prepend=s.e_program)
            s.e_program = float(target[-1])
        de *= s.flow
        s.e_total += float(de.sum())
        return de

    def _spindle_speeds(self, t: CommandTable, rows: slice, kind: np.ndarray) -> np.ndarray:
        if "S" not in t.params:
            return np.full(rows.stop - rows.start, self.state.speed)
        words = _dense(t.params["S"], rows).copy()
        words[~in_ids(kind, _MILL)] = np.nan
        return forward_fill(words, self.state.speed)

    def _arcs(self, t, start, idx, start_pos, end_pos, centers, distance) -> None:
        """Centres (machine coordinates) and lengths of the arc rows ``idx`` (relative to ``start``).

        ``start_pos`` and ``end_pos`` are program coordinates, the frame I/J/K
        and R are given in; the centre then turns with the work system.
        """
        s = self.state
        (f, g, h), (l1, l2) = arcs.PLANES[s.plane]
        rows = idx + start
        p0 = start_pos[idx][:, [f, g]]
        p1 = end_pos[idx][:, [f, g]]
        r_word = _take(t, "R", rows) * s.units
        o1 = _take(t, l1, rows) * s.units
        o2 = _take(t, l2, rows) * s.units
        clockwise = t.motion[rows] == MOTION_CW
        if self.rs274_blocks and "IJK"[h] in t.params:  # rs274 refuses the centre word of the plane's normal axis
            normal = ~np.isnan(_take(t, "IJK"[h], rows))
            for i in np.flatnonzero(normal)[:20]:
                self.diagnostics.report(int(t.line[rows[i]]), 1, f"{'IJK'[h]} word given for arc in "
                                        f"{arcs.PLANE_NAMES[s.plane]} plane", kind="machine")
        if self.rs274_blocks and not np.isnan(r_word).all():
            self._check_radius_ends(t, rows, ~np.isnan(r_word), p0, p1, "XYZ"[f] + "XYZ"[g])
        if self.rs274_blocks and not s.arc_incremental:  # G90.1: rs274 wants both centre words
            for letter, offsets in ((l1, o1), (l2, o2)):
                for i in np.flatnonzero(np.isnan(r_word) & np.isnan(offsets))[:20]:
                    self.diagnostics.report(int(t.line[rows[i]]), 1, f"{letter} word missing in absolute center arc",
                                            kind="machine")
        no_center = np.isnan(r_word) & np.isnan(o1) & np.isnan(o2)
        for i in np.flatnonzero(no_center)[:20]:
            self.diagnostics.report(int(t.line[rows[i]]), 1, f"arc needs {l1}/{l2} offsets or R in this plane (G{s.plane})",
                                    kind="machine")
        center, short = arcs.centres(p0, p1, np.column_stack([o1, o2]), r_word, clockwise, s.arc_incremental)
        for i in np.flatnonzero(short > arcs.reach_tolerance(s.units))[:20]:
            self.diagnostics.report(int(t.line[rows[i]]), 1, "arc radius too small to reach the end point",
                                    kind="machine")
        turns = np.nan_to_num(_take(t, "P", rows), nan=1.0)
        angle = arcs.sweep(p0, p1, center, clockwise, turns)
        radius = np.hypot(*(p0 - center).T)
        radius_end = np.hypot(*(p1 - center).T)
        self._check_radii(t, rows, radius, radius_end, s.units)
        rise = end_pos[idx, h] - start_pos[idx, h]
        distance[idx] = arcs.arc_length(radius, angle, rise)
        centre = end_pos[idx, :].copy()  # the helix axis keeps the end point's coordinate, then is blanked
        centre[:, f], centre[:, g] = center[:, 0], center[:, 1]
        if s.rotation and s.plane != 17:
            self.warn_once("tilted arc", int(t.line[rows[0]]), f"arc in G{s.plane} under an XY rotation of the "
                           "work system: its plane turns out of the machine's planes, which the centre columns "
                           "cannot show")
        centre = s.to_machine(centre)
        centers[idx, f] = centre[:, f]
        centers[idx, g] = centre[:, g]

    def _check_radius_ends(self, t, rows, radius_form, p0, p1, letters: str) -> None:
        """rs274 refuses an R-form arc without an end word in its plane, or ending where it starts."""
        words = ~np.isnan(_take(t, letters[0], rows)) | ~np.isnan(_take(t, letters[1], rows))
        first, second = sorted(letters)
        for i in np.flatnonzero(radius_form & ~words)[:20]:
            self.diagnostics.report(int(t.line[rows[i]]), 1, f"{first} and {second.lower()} words missing for arc "
                                    f"in {arcs.PLANE_NAMES[self.state.plane]} plane", kind="machine")
        for i in np.flatnonzero(radius_form & words & (np.hypot(*(p1 - p0).T) < 1e-9))[:20]:
            self.diagnostics.report(int(t.line[rows[i]]), 1, "Current point same as end point of arc", kind="machine")

    def _check_radii(self, t, rows, r0, r1, units) -> None:
        # LinuxCNC 2.9 rejects centre-format arcs whose end radius differs from the start
        # radius by more than its spiral tolerance (2*sqrt(2)*0.01 mm, or 0.001 in in G20)
        # and 0.1 % of the larger radius, or by 100 times that tolerance (interp_arc.cc)
        tolerance = 2 * np.sqrt(2) * (0.001 * MM_PER_INCH if units != 1.0 else 0.01)
        error = np.abs(r1 - r0)
        bad = (error > 100 * tolerance) | ((error > tolerance) & (error > 0.001 * np.maximum(r0, r1)))
        for i in np.flatnonzero(bad)[:20]:
            self.diagnostics.report(int(t.line[rows[i]]), 1,
                                    f"radius to end of arc differs from radius to start by {abs(r1[i] - r0[i]):.4g} mm",
                                    kind="machine")

    def _durations(self, t, rows, kind, motion, distance, rotary, de, feed, no_spindle, minimum=None) -> np.ndarray:
        """Time of each row: length over feed (the planner refines this later).

        ``no_spindle``: rows with a feed per revolution (G95) in force and the spindle stopped;
        ``minimum``: each row's minimum movement speed, mm/min (see :meth:`_minimum_feeds`), or None.
        """
        s = self.state
        n = kind.size
        time = np.zeros(n)
        feeding = (motion == MOTION_LINEAR) | (motion == MOTION_CW) | (motion == MOTION_CCW)
        rapid = motion == MOTION_RAPID
        path = np.where(distance > 0, distance, np.where(rotary > 0, rotary, np.abs(de)))
        if s.feed_mode == "inverse_time":
            with np.errstate(divide="ignore"):
                time[feeding] = 60.0 / feed[feeding]
            missing = feeding & np.isnan(feed)  # G93 wants an F word on every feed move
            if missing.any():
                first = int(np.flatnonzero(missing)[0])
                arc = motion[first] in (MOTION_CW, MOTION_CCW)
                if self.rs274_blocks:
                    self.diagnostics.report(int(t.line[rows][first]), 1, "F word missing with inverse time "
                                            f"{'arc' if arc else 'g1'} move", kind="machine")
                else:
                    self.warn_once("inverse time F", int(t.line[rows][first]), "inverse time move (G93) without an "
                                   "F word; its time is unknown")
            never = feeding & (feed == 0) & ((path > 0) | (rotary > 0))
            if never.any():  # rs274 accepts F0 in G93; the move would take forever
                time[never] = np.nan
                for i in np.flatnonzero(never)[:20]:
                    self.diagnostics.warn(int(t.line[rows][i]), 1, "inverse time move (G93) with F0: it never ends "
                                          "(a controller stalls); its time is unknown")
        else:
            rate = np.where(rapid, feed if self.rapid_is_feed else self.config.rapid_feed, feed)
            moving = feeding | rapid
            if minimum is not None:
                self._note_minimum_speed(t, rows, moving & (rate <= 0) & (path > 0), minimum)
                # DDA::InitStandardMove: requestedSpeed = max(feedRate, MinMovementSpeed), then the axis caps
                rate = np.maximum(rate, minimum)
            with np.errstate(divide="ignore", invalid="ignore"):
                time[moving] = path[moving] / (rate[moving] / 60.0)
            bad = moving & ~(rate > 0) & (path > 0)
            if self.rs274_blocks and (feeding & ~(rate > 0)).any():
                # RS274NGC refuses the block (interp_convert.cc), moving or not
                first = int(np.flatnonzero(feeding & ~(rate > 0))[0])
                arc = motion[first] in (MOTION_CW, MOTION_CCW)
                message = ("Cannot feed with zero spindle speed in feed per rev mode" if no_spindle[first] else
                           "Cannot make arc with zero feed rate" if arc else "Cannot do g1 with zero feed rate")
                self.diagnostics.report(int(t.line[rows][first]), 1, message, kind="machine")
            elif bad.any():
                first = int(np.flatnonzero(bad)[0])
                if no_spindle[first]:
                    self.warn_once("feed per rev", int(t.line[rows][first]), "feed per revolution (G95) with the "
                                   "spindle stopped: the move never ends (a controller stalls); its time is unknown")
                elif "feed" not in self._warned:
                    # no boot feed (GRBL's error 22, "undefined feed rate"; a Fanuc's feed-zero alarm)
                    self._warned.add("feed")
                    self.diagnostics.report(int(t.line[rows][first]), 1, "feed move with no feed rate (F) in force: "
                                            "the controller refuses it; its time is not counted", kind="machine")
            time[bad] = np.nan  # never an invented time: the summary counts these moves as untimed
        dwell = kind == Kind.DWELL
        if dwell.any():
            time[dwell] = self._dwell_times(t, rows, dwell)
        return time

    def _minimum_feeds(self, t: CommandTable, rows: slice) -> np.ndarray:
        """Each row's minimum movement speed, mm/min: RepRapFirmware's M203 I (GCodes2.cpp, case 203) held
        from the machine's until the program gives one; 0 while not known."""
        s = self.state
        n = rows.stop - rows.start
        if "I" not in t.params or not n:
            return np.full(n, s.minimum_feed)
        words = np.where(t.name[rows] == NAME_ID["set_max_feed"], _dense(t.params["I"], rows), np.nan)
        held = forward_fill(words, s.minimum_feed)
        s.minimum_feed = float(held[-1])
        return held

    def _note_minimum_speed(self, t, rows, crawling: np.ndarray, minimum: np.ndarray) -> None:
        """Once: a feed move at F0 (or below), which RepRapFirmware takes as written (``GCodeBuffer::GetSpeed``
        checks nothing) and moves at its minimum movement speed."""
        if not crawling.any():
            return
        first = int(np.flatnonzero(crawling)[0])
        speed = float(minimum[first])
        known = f", {speed:g} mm/min here" if speed > 0 else (", which this machine does not give: its time is "
                                                             "unknown")
        self.warn_once("feed", int(t.line[rows][first]), "feed move at F0 (or below): this firmware takes it as "
                       f"written and moves at its minimum movement speed (RepRapFirmware's M203 I){known}")

    def _ignore_feed_at_or_below_zero(self, t, rows, feed_words) -> None:
        """Firmware that sets its feed only from an F above 0: such F words go (said once)."""
        ignored = np.flatnonzero(feed_words <= 0)
        if ignored.size:
            self.warn_once("feed at or below 0", int(t.line[rows][int(ignored[0])]), FEED_AT_OR_BELOW_ZERO)
            feed_words[ignored] = np.nan

    def _note_boot_feed(self, t, rows, feed_words, motion, delta) -> None:
        """Once: an info where a move runs at the firmware's boot feed, before any F word."""
        given = np.flatnonzero(~np.isnan(feed_words))
        end = int(given[0]) if given.size else feed_words.size
        feeding = (motion >= MOTION_LINEAR) | ((motion == MOTION_RAPID) & self.rapid_is_feed)
        before = np.flatnonzero(feeding[:end] & (np.abs(delta[:end]).max(axis=1) > 0))
        if before.size and self.config.initial_feed > 0:
            self.diagnostics.report(int(t.line[rows][int(before[0])]), 1, "move before any F word: it runs at the "
                                    f"firmware's boot feed rate, {self.config.initial_feed:g} mm/min (the machine's "
                                    "initial_feed)", severity="info")
        if given.size or before.size:
            self.state.feed_given = True

    def _dwell_times(self, t, rows, dwell) -> np.ndarray:
        p = _dense(t.params["P"], rows)[dwell] if "P" in t.params else np.full(int(dwell.sum()), np.nan)
        s_word = _dense(t.params["S"], rows)[dwell] if "S" in t.params else np.full(p.size, np.nan)
        unit = 0.001 if self.config.dwell_p_unit == "ms" else 1.0
        seconds = np.nan_to_num(s_word) if self.config.dwell_s_seconds else np.zeros(p.size)
        return np.where(~np.isnan(p), p * unit, seconds)

    def warn_once(self, key: str, line: int, message: str) -> None:
        """A warning given the first time ``key`` comes up in the program (not on every block)."""
        if key not in self._warned:
            self._warned.add(key)
            self.diagnostics.warn(line, 1, message)


_WORK_INDEX = {c: i + 1 for i, c in enumerate(("G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3"))}


def _dense(col, rows: slice) -> np.ndarray:
    if isinstance(col, np.ndarray):
        return col[rows].copy()
    return col.window(rows.start, rows.stop)


def _take(t: CommandTable, letter: str, rows: np.ndarray) -> np.ndarray:
    col = t.params.get(letter)
    if col is None:
        return np.full(rows.size, np.nan)
    return col[rows] if isinstance(col, np.ndarray) else t.param_at(letter, rows)


def _constants_as_views(out: dict) -> dict:
    """Columns holding one value everywhere become zero-stride views (no memory)."""
    for key, col in out.items():
        if key != "command" and col.size and col.strides != (0,):
            first = col[0]
            same = np.isnan(col).all() if col.dtype.kind == "f" and first != first else (col == first).all()
            if same:
                out[key] = np.broadcast_to(first, col.shape)
    return out


def _with_extra_waypoints(out: dict, extra: list, n: int) -> dict:
    if not extra:
        return out
    rows = np.array([r for r, _ in extra])
    for key, arr in out.items():
        if key == "command":
            out[key] = np.insert(arr, rows, rows).astype(np.int32)
            continue
        values = [w.values.get(key, arr[r]) if r < n else 0 for r, w in extra]
        out[key] = np.insert(arr, rows, np.array(values, dtype=arr.dtype))
    return out
