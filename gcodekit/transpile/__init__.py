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

from typing import TYPE_CHECKING

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
        self._command_of = (-1, None)  # the last row's Command: the stages of one row share it

    # -- public -----------------------------------------------------------------

    def stage(self, k: int) -> str:
        """G-code text of stage ``k`` (0-6)."""
        if k not in STAGES:
            from ..errors import ConfigError

            raise ConfigError(f"stage must be one of 0-6, not {k!r}")
        lines = [self._title(k)] + self._head(k)
        for row in range(len(self.op.table)):
            lines.extend(self._row(row, k))
        return "\n".join(lines + self._tail()) + "\n"

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
        def is_move(line: str) -> bool:
            return any(f" G{g} " in f" {line} " for g in (0, 1, 2, 3))

        lines = {k: self._head(k) + self._tail() for k in STAGES}
        counts = {k: [len(lines[k]), sum(map(is_move, lines[k]))] for k in STAGES}
        for row in range(len(self.op.table)):
            for k in STAGES:
                out = self._row(row, k)
                counts[k][0] += len(out)
                counts[k][1] += sum(map(is_move, out))
        return [{"stage": k, "name": STAGE_NAMES[k], "lines": counts[k][0], "moves": counts[k][1]} for k in STAGES]

    # -- one command --------------------------------------------------------------

    def _row(self, row: int, k: int) -> list[str]:
        t = self.op.table
        name = NAMES[int(t.name[row])]
        kind = Kind(int(t.kind[row]))
        cmd = self._command(row)
        n = f"N{cmd.line}"
        comment = self._comment(row, cmd, k)
        if kind == Kind.COMMENT:
            return [f"({_paren(cmd.comment or '')})"] if cmd.comment else []
        moving = self._waypoints(row)
        motion_row = moving.size and np.any(self.op.waypoints["motion"][moving] > 0)
        polar = "@" in cmd.params or "^" in cmd.params or self._polar_rows[row]
        polar_stage = 2 if self._polar_rows[row] else 3
        if motion_row and (k >= 4 or (polar and k >= polar_stage) or (self._rotated_rows[row] and k >= 2)):
            return self._from_waypoints(row, k, moving, comment)
        if (k >= 1 and name in _UNITS) or (k >= 2 and name in _OFFSETS) or (k >= 4 and name in _DISTANCE) \
                or (k >= 2 and name in _POLAR) or (k >= 4 and name in _COMP) or (k >= 6 and name in _CYCLE_MODES):
            return [f"({n} {_paren(str(cmd))} resolved)"] if k < 6 else []
        if k >= 6 and not motion_row and name not in _KEPT and kind not in (Kind.FEED_RATE, Kind.MILL):
            return [f"(dropped: {n} {_paren(str(cmd))})"]
        words = self._words(row, cmd, k)
        return [f"{n} {words}{comment}".rstrip()]

    def _command(self, row: int):
        if self._command_of[0] != row:
            self._command_of = (row, self.op.table.command(row))
        return self._command_of[1]

    def _waypoints(self, row: int) -> np.ndarray:
        if self._first_waypoint is None:
            return np.array([row])
        return np.arange(self._first_waypoint[row], self._first_waypoint[row + 1])

    def _words(self, row: int, cmd, k: int) -> str:
        """The command's own words, with units (stage 1+) and offsets (2+) resolved."""
        name = NAMES[int(self.op.table.name[row])]
        scale = self._scale(row) if k >= 1 else 1.0
        offset = self._offset(row) / self.unit if k >= 2 else np.zeros(3)
        absolute = not self._incremental(row)
        lengths = length_words(name)
        halved = diameter_words(name)
        plane = int(self.op.waypoints["plane"][self._waypoints(row)[-1]])
        normal = "XYZ"[PLANES[plane][0][2]]
        levels = level_words(name, plane) if name in CYCLE_NAMES and name not in LATHE_CYCLE_NAMES else ""
        words = [cmd.code] if cmd.code and not cmd.code.startswith(("#", "@")) else []
        params = cmd.params
        if name in LATHE_CYCLE_NAMES and scale != 1.0:
            params = {**params, **lathe_defaults(name, params)}
        for letter, value in params.items():
            if letter in "@^" and k >= 3:
                continue
            angle = letter == "Y" and self._polar_rows[row]  # G16: Y is an angle in degrees
            v = value * scale if (letter in lengths or letter == "F") and not angle else value
            if letter in halved and k >= 1 and self._diameter_rows[row]:
                v /= 2.0
            if absolute and k >= 2 and (letter in "XYZ" or letter in levels):
                v += offset["XYZ".index(normal if letter in levels else letter)]
            words.append(f"{letter}{format_number(v, self.precision)}")
        return " ".join(words + ([cmd.text] if cmd.text else []))

    def _scale(self, row: int) -> float:
        """Output length units per program unit at ``row``."""
        return (MM_PER_INCH if self.op.waypoints["units"][self._waypoints(row)[-1]] == 1 else 1.0) / self.unit

    def _comment(self, row: int, cmd, k: int) -> str:
        """The command's comment as written out; a lathe cycle's profile takes the stage's units and offsets."""
        text = cmd.comment
        if cmd.profile is not None and k < 6:  # the cycle line is still there: so must its profile be
            body = None
            if k >= 1:
                offset = self._offset(row) / self.unit if k >= 2 else np.zeros(3)
                body = rewrite_profile(cmd.profile, scale=self._scale(row), halve=bool(self._diameter_rows[row]),
                                       offset_x=offset[0], offset_z=offset[2],
                                       arc_absolute=bool(self._arc_absolute_rows[row]), precision=self.precision)
            text = written_comment(text, cmd.profile, body)
        return f" ({_paren(text)})" if text else ""

    def _from_waypoints(self, row: int, k: int, points: np.ndarray, comment: str) -> list[str]:
        """Machine-frame moves of a command (stages 4-6; 2-3 for polar moves).

        Before stage 4 G91 may still be in force: the moves are then written
        as increments from the point before.
        """
        t, w = self.op.table, self.op.waypoints
        n = f"N{int(t.line[row])}"
        cycle = int(t.motion[row]) == MOTION_CYCLE or NAMES[int(t.name[row])] in CYCLE_NAMES
        if cycle and k < 6 and not self._rotated_rows[row]:
            return [f"{n} {self._words(row, self._command(row), k)}{comment}"]
        fmt = lambda v: format_number(v, self.precision)  # noqa: E731
        increments = k < 4 and self._incremental(row)
        absolute_centre = k < 4 and bool(self._arc_absolute_rows[row])  # G90.1 still in force

        def value(axis: str, p: int) -> float:
            column = w[axis.lower()]
            v = column[p] - (column[p - 1] if p > 0 else 0.0) if increments else column[p]
            return v / self.unit if axis in "XYZ" else v

        lines = []
        for p in points:
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
        dwell = self._command(row).params.get("P") if cycle and NAMES[int(t.name[row])] in (
            "cycle_drill_dwell", "cycle_bore_stop", "cycle_bore_dwell") else None
        if dwell is not None and k >= 6 and len(lines) >= 2:
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

    def _offset(self, row: int) -> np.ndarray:
        """Offset (mm, X Y Z) from program to machine coordinates in force at ``row``.

        Read off the row's waypoints: a move with an absolute word v ends at
        v*scale + offset (a cycle's words, see :func:`.cycle_words.cycle_offset`).
        """
        w = self.op.waypoints
        points = self._waypoints(row)
        cmd = self._command(row)
        if self._incremental(row):
            return np.zeros(3)
        scale = MM_PER_INCH if w["units"][points[-1]] == 1 else 1.0
        words = dict(cmd.params)
        if "X" in words and self._diameter_rows[row]:
            words["X"] /= 2.0  # G7: the X word is a diameter
        positions = np.column_stack([np.asarray(w[a])[points] for a in "xyz"])
        name = NAMES[int(self.op.table.name[row])]
        if name in CYCLE_NAMES or int(self.op.table.motion[row]) == MOTION_CYCLE:
            if name not in CYCLE_NAMES:  # axis words alone, repeating the cycle in force
                name = NAMES[int(self.op.table.name[self._last_cycle_row[row]])]
            feeds = np.asarray(w["motion"])[points] == MOTION_LINEAR
            return cycle_offset(name, words, scale, positions, feeds, int(w["plane"][points[-1]]))
        return np.array([positions[-1, i] - words[a] * scale if a in words else 0.0 for i, a in enumerate("XYZ")])

    def _incremental(self, row: int) -> bool:
        """G91 in force at ``row`` (from the distance-mode commands up to it)."""
        return bool(self._incremental_rows[row])


def _paren(text: str) -> str:
    return text.replace("(", "[").replace(")", "]")


__all__ = ["Transpiler", "STAGES", "STAGE_NAMES"]
