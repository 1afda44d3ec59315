"""Transpile stage: GER's staged simplification of a mill program to plain G-code.

Each stage resolves one more feature, in GER's order, so a reader can watch
what a controller does with each (GER manual, "Simplify 00-05", extended
with canned cycles):

0. subprograms, loops and macros expanded (the program as it runs);
1. lengths in the machine's units (G20/G21 gone), lathe X diameters as
   radii (G7/G8 gone);
2. work offsets, G92, G52 and tool-length offsets applied (machine coordinates);
3. polar words (LinuxCNC ``@``/``^``) turned into X and Y; G16 moves go
   at stage 2 already, since their pole is the program origin the offsets move;
4. incremental moves written as absolute ones (G90/G91 gone);
5. cutter compensation applied (moves are written from the compensated
   waypoints from stage 4 on, so G40/G41/G42 already go at stage 4);
6. canned cycles expanded into the moves they make.

A work system turned by G10 L2 R cannot be written as offsets added to
words (an X word alone moves along both machine axes), so from stage 2 the
moves made under a rotation, canned cycles included, are written from the
emulated waypoints.

The last stage uses only G0/G1/G2/G3 (arcs outside XY carry their G18/G19),
G4 and tool, spindle and coolant codes.  Every line starts with the N-number
of the source line it came from.  Stages 4-6 are written from the emulated
waypoints; stages 1-3 rewrite the words of each command.

Examples
--------
>>> import gcodekit
>>> t = gcodekit.transpile_program("G20 G91 G0 X1\\nX1\\nM2\\n", machine="linuxcnc")
>>> print(t.stage(6))
(gcodekit transpile stage 6: machine units mm, absolute machine coordinates)
G21
N1 G0 X25.4 Y0 Z0
N2 G0 X50.8 Y0 Z0
N3 M2
<BLANKLINE>
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Iterator

import numpy as np

from ..emulate.arcs import PLANES
from ..export.gcode import format_number
from ..emulate.machine import mode_rows
from ..parse.commands import Kind
from ..lathe_profile import written_comment
from ..parse.table import CYCLE_NAMES, LATHE_CYCLE_NAMES, MOTION_CYCLE, MOTION_LINEAR, NAME_ID, NAMES, in_ids
from ..units import MM_PER_INCH
from .cycle_words import cycle_offset, diameter_words, lathe_defaults, length_words, level_words, rewrite_profile

if TYPE_CHECKING:
    from ..model.operation import Operation

STAGES = tuple(range(7))
STAGE_NAMES = ("expanded", "units", "offsets", "polar", "absolute", "cutter compensation", "canned cycles")

_UNITS = {"units_inch", "units_mm", "diameter_mode", "radius_mode"}
_OFFSETS = {"work_offset_%d" % k for k in range(1, 10)} | {
    "set_position", "clear_position_offset", "suspend_position_offset", "restore_position_offset",
    "local_offset", "coordinate_data", "tool_length_offset", "tool_length_offset_dynamic",
    "tool_length_offset_add", "cancel_tool_length"}
_DISTANCE = {"distance_absolute", "distance_incremental", "arc_distance_absolute", "arc_distance_incremental"}
_CYCLE_MODES = {"cancel_cycle", "retract_initial", "retract_r"}
_COMP = {"cutter_comp_off", "cutter_comp_left", "cutter_comp_right", "cutter_comp_left_dynamic",
         "cutter_comp_right_dynamic"}
_POLAR = {"polar_on", "polar_off"}
#: What the last stage keeps besides motion: dwell, tools, spindle, coolant, stops and the end.
_KEPT = {"dwell", "tool_change", "spindle_cw", "spindle_ccw", "spindle_off", "coolant_mist", "coolant_flood",
         "coolant_off", "program_stop", "optional_stop", "program_end"}
#: Commands read from the table at a time while the stages are written
_BLOCK_ROWS = 4096
#: A motion line: G0-G3 as a word of its own (between spaces or the line's ends)
_MOVE_WORD = re.compile(r"(?<![^ ])G[0-3](?![^ ])")


@dataclass
class _Row:
    """What one command row's stages share: read once, while the stages of the row are written.

    ``texts`` keeps the expensive parts already written for this row, keyed
    by everything they depend on, so two stages that resolve nothing new
    for the row (stage 1 of a program in mm, stages 4-6 of a plain move)
    share one text.
    """

    row: int
    cmd: Any
    name: str
    kind: Kind
    points: range  # the row's waypoints
    motion_row: bool
    polar: bool  # polar words, or G16 in force
    g16: bool  # G16 in force: X is a radius, Y an angle
    rotated: bool  # moves under a G10 L2 R rotation
    diameter: bool  # G7 in force
    incremental: bool  # G91 in force
    arc_absolute: bool  # G90.1 in force
    texts: dict = field(default_factory=dict)
    offset: np.ndarray | None = None  # mm, from program to machine coordinates (see Transpiler._offset)
    scale: float | None = None  # output length units per program unit (see Transpiler._scale)


class Transpiler:
    """Stages of one program, from the same emulation.

    Parameters
    ----------
    operation : Operation
        The emulated program (:func:`gcodekit.gcode_to_operation`; for a
        path or text in one call, :func:`gcodekit.transpile_program`).
    precision : int, default: 4
        Digits after the decimal point in the output.
    """

    def __init__(self, operation: "Operation", *, precision: int = 4):
        if getattr(operation, "waypoints", None) is None:
            raise TypeError("Transpiler needs an emulated Operation (gcodekit.gcode_to_operation); "
                            "gcodekit.transpile_program reads a path or text")
        self.op = operation
        self.precision = precision
        w = self.op.waypoints
        arcs = np.asarray(w["motion"]) >= 3
        # the plane is modal for whoever reads the output: name it on every arc
        # once the program has an arc outside XY
        self._plane_words = bool(np.any(np.asarray(w["plane"])[arcs] != 17))
        self._polar_rows = mode_rows(self.op.table, "polar_on", "polar_off")  # G16: X radius, Y angle
        # moves under a G10 L2 R rotation are written from their waypoints from stage 2
        self._rotated_rows = np.zeros(len(self.op.table), bool)
        turned = np.asarray(w["rotation"]) != 0
        np.logical_or.at(self._rotated_rows, w["command"], turned)
        self._incremental_rows = mode_rows(self.op.table, "distance_incremental", "distance_absolute")  # G91
        self._rotary_axes = [a for a in "ABC" if np.any(np.asarray(w[a.lower()]) != 0)]  # written when used
        self._arc_absolute_rows = mode_rows(self.op.table, "arc_distance_absolute", "arc_distance_incremental")
        # the last cycle command at or before each row (axis words alone repeat it)
        cycles = in_ids(self.op.table.name, [NAME_ID[n] for n in CYCLE_NAMES])
        self._last_cycle_row = np.maximum.accumulate(np.where(cycles, np.arange(len(cycles)), 0)) \
            if len(cycles) else np.zeros(0, int)
        # G7: X words are diameters, except G10's (as rs274 reads them)
        self._diameter_rows = mode_rows(self.op.table, "diameter_mode", "radius_mode") & (
            self.op.table.name != NAME_ID["coordinate_data"])
        flavor = self.op.flavor
        #: mm per output length unit from stage 1 on: the machine's own units
        self.unit = MM_PER_INCH if flavor is not None and flavor.units == "inch" else 1.0
        # each command row's waypoints, w["command"] being sorted: rows[r]..rows[r + 1] - 1, looked up once
        self._first_waypoint = np.searchsorted(w["command"], np.arange(len(self.op.table) + 1)) \
            if "command" in w else None
        # the rows with a waypoint that moves (w["command"] sorted, so a row's waypoints are its stretch)
        self._motion_rows = None
        if self._first_waypoint is not None:
            self._motion_rows = np.zeros(len(self.op.table), bool)
            moving = np.asarray(w["command"])[np.asarray(w["motion"]) > 0]
            self._motion_rows[moving[(moving >= 0) & (moving < len(self.op.table))]] = True
        self._current: _Row | None = None  # the row being written: its stages share it
        self._block_start, self._block = 0, []  # the commands of the rows being written, read a block at a time

    # -- public -----------------------------------------------------------------

    def stage(self, k: int) -> str:
        """G-code text of stage ``k`` (0-6)."""
        return "\n".join(self.lines(k)) + "\n"

    def lines(self, k: int) -> Iterator[str]:
        """The lines of stage ``k`` (0-6) one at a time, title first, without holding the whole text."""
        if k not in STAGES:
            from ..errors import ConfigError

            raise ConfigError(f"stage must be one of 0-6, not {k!r}")
        return self._lines(k)

    def _lines(self, k: int) -> Iterator[str]:
        yield self._title(k)
        yield from self._head(k)
        for row in range(len(self.op.table)):
            yield from self._row(row, k)
        yield from self._tail()

    def _title(self, k: int) -> str:
        frame = "absolute machine coordinates" if k >= 4 else "machine coordinates" if k >= 2 else "program coordinates"
        unit_name = "inch" if self.unit == MM_PER_INCH else "mm"
        return (f"(gcodekit transpile stage {k}: machine units {unit_name}, {frame})" if k >= 1 else
                "(gcodekit transpile stage 0: subprograms, loops and macros expanded)")

    def _head(self, k: int) -> list[str]:
        """The lines after the title: from stage 1 the output says its units, so any controller reads it alike."""
        return ["G20" if self.unit == MM_PER_INCH else "G21"] if k >= 1 else []

    def _tail(self) -> list[str]:
        if not (self.op.table.name == NAME_ID["program_end"]).any():
            return ["M2 (the source ends without M2 or M30)"]  # rs274 refuses a file with no end
        return []

    def commands(self, k: int):
        """Stage ``k`` read back as typed commands (its text is plain RS274NGC)."""
        from ..model.operation import Operation
        from ..parse import GcodeParser
        from ..read import read_text

        return Operation(GcodeParser("rs274ngc").parse(read_text(self.stage(k), "rs274ngc"))).commands

    def summary(self) -> list[dict]:
        """Per stage: its name and how many lines and motion lines it has (below the title line).

        Counted in one pass over the commands for every stage, without
        keeping any stage's text.
        """
        lines = {k: self._head(k) + self._tail() for k in STAGES}
        counts = {k: [len(lines[k]), sum(1 for line in lines[k] if _MOVE_WORD.search(line))] for k in STAGES}
        for row in range(len(self.op.table)):
            for k in STAGES:
                out = self._row(row, k)
                counts[k][0] += len(out)
                counts[k][1] += sum(1 for line in out if _MOVE_WORD.search(line))
        return [{"stage": k, "name": STAGE_NAMES[k], "lines": counts[k][0], "moves": counts[k][1]} for k in STAGES]

    # -- one command --------------------------------------------------------------

    def _row(self, row: int, k: int) -> list[str]:
        r = self._facts(row)
        name, kind, cmd = r.name, r.kind, r.cmd
        n = f"N{cmd.line}"
        comment = self._comment(r, k)
        if kind == Kind.COMMENT:
            return [f"({_paren(cmd.comment or '')})"] if cmd.comment else []
        polar_stage = 2 if r.g16 else 3
        if r.motion_row and (k >= 4 or (r.polar and k >= polar_stage) or (r.rotated and k >= 2)):
            return self._from_waypoints(r, k, comment)
        if (k >= 1 and name in _UNITS) or (k >= 2 and name in _OFFSETS) or (k >= 4 and name in _DISTANCE) \
                or (k >= 2 and name in _POLAR) or (k >= 4 and name in _COMP) or (k >= 6 and name in _CYCLE_MODES):
            return [f"({n} {_paren(str(cmd))} resolved)"] if k < 6 else []
        if k >= 6 and not r.motion_row and name not in _KEPT and kind not in (Kind.FEED_RATE, Kind.MILL):
            return [f"(dropped: {n} {_paren(str(cmd))})"]
        words = self._words(r, k)
        return [f"{n} {words}{comment}".rstrip()]

    def _facts(self, row: int) -> _Row:
        """The row's :class:`_Row`, read on its first stage."""
        if self._current is None or self._current.row != row:
            t = self.op.table
            if not self._block_start <= row < self._block_start + len(self._block):
                self._block_start, self._block = row, t.commands(row, row + _BLOCK_ROWS)
            cmd = self._block[row - self._block_start]
            if self._first_waypoint is None:
                points = range(row, row + 1)
            else:
                points = range(int(self._first_waypoint[row]), int(self._first_waypoint[row + 1]))
            if self._motion_rows is None:
                motion_row = bool(np.any(self.op.waypoints["motion"][points.start:points.stop] > 0))
            else:
                motion_row = bool(self._motion_rows[row])
            g16 = bool(self._polar_rows[row])
            self._current = _Row(row, cmd, NAMES[int(t.name[row])], Kind(int(t.kind[row])), points, motion_row,
                                 polar="@" in cmd.params or "^" in cmd.params or g16, g16=g16,
                                 rotated=bool(self._rotated_rows[row]), diameter=bool(self._diameter_rows[row]),
                                 incremental=bool(self._incremental_rows[row]),
                                 arc_absolute=bool(self._arc_absolute_rows[row]))
        return self._current

    def _words(self, r: _Row, k: int) -> str:
        """The command's own words, with units (stage 1+) and offsets (2+) resolved.

        Written once for each set of what they depend on (the scale, the
        halving of diameters, the offset added, the polar words dropped).
        """
        scale = self._scale(r) if k >= 1 else 1.0
        halve = k >= 1 and r.diameter
        offset = self._offset(r) if k >= 2 and not r.incremental else None
        # an offset of zero adds nothing (-0.0 + 0.0 is 0.0, and both are written "0"): such a stage shares the text
        key = ("words", scale, halve, None if offset is None or not offset.any() else tuple(offset),
               k >= 3 and ("@" in r.cmd.params or "^" in r.cmd.params))
        if key not in r.texts:
            r.texts[key] = self._written_words(r, scale, halve, None if offset is None else offset / self.unit,
                                               skip_polar=key[-1])
        return r.texts[key]

    def _written_words(self, r: _Row, scale: float, halve: bool, offset: np.ndarray | None,
                       skip_polar: bool) -> str:
        """:meth:`_words` for one scale, halving, offset (None: added nowhere) and polar choice."""
        name, cmd = r.name, r.cmd
        lengths = length_words(name)
        halved = diameter_words(name)
        plane = int(self.op.waypoints["plane"][r.points[-1]])
        normal = "XYZ"[PLANES[plane][0][2]]
        levels = level_words(name, plane) if name in CYCLE_NAMES and name not in LATHE_CYCLE_NAMES else ""
        words = [cmd.code] if cmd.code and not cmd.code.startswith(("#", "@")) else []
        params = cmd.params
        if name in LATHE_CYCLE_NAMES and scale != 1.0:
            params = {**params, **lathe_defaults(name, params)}
        for letter, value in params.items():
            if letter in "@^" and skip_polar:
                continue
            angle = letter == "Y" and r.g16  # G16: Y is an angle in degrees
            v = value * scale if (letter in lengths or letter == "F") and not angle else value
            if letter in halved and halve:
                v /= 2.0
            if offset is not None and (letter in "XYZ" or letter in levels):
                v += offset["XYZ".index(normal if letter in levels else letter)]
            words.append(f"{letter}{format_number(v, self.precision)}")
        return " ".join(words + ([cmd.text] if cmd.text else []))

    def _scale(self, r: _Row) -> float:
        """Output length units per program unit at the row."""
        if r.scale is None:
            r.scale = (MM_PER_INCH if self.op.waypoints["units"][r.points[-1]] == 1 else 1.0) / self.unit
        return r.scale

    def _comment(self, r: _Row, k: int) -> str:
        """The command's comment as written out; a lathe cycle's profile takes the stage's units and offsets."""
        cmd = r.cmd
        text = cmd.comment
        if cmd.profile is not None and k < 6:  # the cycle line is still there: so must its profile be
            body = None
            if k >= 1:
                offset = self._offset(r) / self.unit if k >= 2 else np.zeros(3)
                body = rewrite_profile(cmd.profile, scale=self._scale(r), halve=r.diameter,
                                       offset_x=offset[0], offset_z=offset[2],
                                       arc_absolute=r.arc_absolute, precision=self.precision)
            text = written_comment(text, cmd.profile, body)
        return f" ({_paren(text)})" if text else ""

    def _from_waypoints(self, r: _Row, k: int, comment: str) -> list[str]:
        """Machine-frame moves of a command (stages 4-6; 2-3 for polar moves).

        Before stage 4 G91 may still be in force: the moves are then written
        as increments from the point before.  Written once for each set of
        what they depend on (stages 4-6 of a plain move are one text).
        """
        row = r.row
        cycle = int(self.op.table.motion[row]) == MOTION_CYCLE or r.name in CYCLE_NAMES
        if cycle and k < 6 and not r.rotated:
            return [f"N{r.cmd.line} {self._words(r, k)}{comment}"]
        increments = k < 4 and r.incremental
        absolute_centre = k < 4 and r.arc_absolute  # G90.1 still in force
        key = ("moves", increments, absolute_centre, cycle and k >= 6, comment)
        if key not in r.texts:
            r.texts[key] = self._written_moves(r, increments, absolute_centre, cycle and k >= 6, comment)
        return list(r.texts[key])

    def _written_moves(self, r: _Row, increments: bool, absolute_centre: bool, dwells: bool,
                       comment: str) -> list[str]:
        """:meth:`_from_waypoints` for one choice of increments, arc centres and cycle dwells."""
        w = self.op.waypoints
        n = f"N{r.cmd.line}"
        fmt = lambda v: format_number(v, self.precision)  # noqa: E731

        def value(axis: str, p: int) -> float:
            column = w[axis.lower()]
            v = column[p] - (column[p - 1] if p > 0 else 0.0) if increments else column[p]
            return v / self.unit if axis in "XYZ" else v

        lines = []
        for p in r.points:
            motion = int(w["motion"][p])
            if motion == 0:
                continue
            xyz = " ".join(f"{a}{fmt(value(a, p))}" for a in "XYZ")
            abc = " ".join(f"{a}{fmt(value(a, p))}" for a in self._rotary_axes)
            coords = f"{xyz} {abc}".rstrip()
            if motion == 1:
                lines.append(f"{n} G0 {coords}")
                continue
            feed = f" F{fmt(w['feed'][p] / self.unit)}" if np.isfinite(w["feed"][p]) else ""
            if motion == 2 or self._is_point_arc(p):  # a helix of radius 0 is a straight line
                lines.append(f"{n} G1 {coords}{feed}")
            else:
                lines.append(f"{n} {self._arc(p, motion, absolute_centre)} {coords}{feed}")
        if lines:
            lines[-1] += comment
        dwell = r.cmd.params.get("P") if dwells and r.name in (
            "cycle_drill_dwell", "cycle_bore_stop", "cycle_bore_dwell") else None
        if dwell is not None and len(lines) >= 2:
            lines.insert(len(lines) - 1, f"{n} G4 P{fmt(dwell)}")
        return lines

    def _is_point_arc(self, p: int) -> bool:
        """An arc whose radius compensation shrank to nothing (rs274 refuses to read one back)."""
        w = self.op.waypoints
        start = np.array([w[a][p - 1] if p > 0 else 0.0 for a in "xyz"])
        center = np.array([w["cx"][p], w["cy"][p], w["cz"][p]])
        return bool(np.nansum((center - start) ** 2) < 1e-18)

    def _arc(self, p: int, motion: int, absolute_centre: bool) -> str:
        """G2/G3 and the centre words of the arc ending at waypoint ``p`` (I/J/K absolute under G90.1)."""
        w = self.op.waypoints
        plane = int(w["plane"][p])
        start = np.zeros(3) if absolute_centre else np.array([w[a][p - 1] if p > 0 else 0.0 for a in "xyz"])
        center = np.array([w["cx"][p], w["cy"][p], w["cz"][p]])
        offsets = np.nan_to_num(center - start) / self.unit
        words = " ".join(f"{letter}{format_number(offsets[i], self.precision)}"
                         for i, letter in enumerate("IJK") if not np.isnan(center[i]))
        code = "G2" if motion == 3 else "G3"
        return (f"G{plane} " if self._plane_words else "") + f"{code} {words}"

    def _offset(self, r: _Row) -> np.ndarray:
        """Offset (mm, X Y Z) from program to machine coordinates in force at the row.

        Read off the row's waypoints: a move with an absolute word v ends at
        v*scale + offset (a cycle's words, see :func:`.cycle_words.cycle_offset`).
        Worked out once per row.
        """
        if r.offset is None:
            r.offset = self._read_offset(r)
        return r.offset

    def _read_offset(self, r: _Row) -> np.ndarray:
        w, row, points = self.op.waypoints, r.row, r.points
        if r.incremental:
            return np.zeros(3)
        last = points[-1]
        scale = MM_PER_INCH if w["units"][last] == 1 else 1.0
        words = dict(r.cmd.params)
        if "X" in words and r.diameter:
            words["X"] /= 2.0  # G7: the X word is a diameter
        name = r.name
        if name in CYCLE_NAMES or int(self.op.table.motion[row]) == MOTION_CYCLE:
            if name not in CYCLE_NAMES:  # axis words alone, repeating the cycle in force
                name = NAMES[int(self.op.table.name[self._last_cycle_row[row]])]
            span = slice(points.start, points.stop)
            positions = np.column_stack([np.asarray(w[a])[span] for a in "xyz"])
            feeds = np.asarray(w["motion"])[span] == MOTION_LINEAR
            return cycle_offset(name, words, scale, positions, feeds, int(w["plane"][last]))
        return np.array([w[a][last] - words[a.upper()] * scale if a.upper() in words else 0.0 for a in "xyz"])


def _paren(text: str) -> str:
    return text.replace("(", "[").replace(")", "]")


__all__ = ["Transpiler", "STAGES", "STAGE_NAMES"]
