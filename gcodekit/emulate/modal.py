"""Emulate stage: the commands that change the machine's modal state.

These are rare (a few per layer or per tool), so each is handled alone, in
plain Python, in the interpreter's words: units, distance modes, planes,
work offsets (G54-G59.3), axis offsets (G92 family), homing (G28/G30),
machine-coordinate moves (G53), extrusion modes, tools, spindle, coolant
and program end.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..parse.table import (MOTION_CCW, MOTION_CW, MOTION_CYCLE, MOTION_LINEAR, MOTION_NONE, MOTION_NURBS, MOTION_RAPID,
                           MOTION_THREAD, NAME_ID, NAMES, SPLINE_MOTIONS, CommandTable)
from ..parse.calls import call_bead_area
from ..parse.commands import Kind
from .arcs import PLANES, centres, reach_tolerance, single_turn_lengths
from .cycles import CYCLES, TAPPING, polar_target, run_cycle
from .lathe import LATHE_CYCLES, CycleBlock, LatheCycleError, Move, run_lathe_cycle
from .threading import ThreadingError, check_words, threading_moves
from .splines import SPLINE_NAMES, SplineBlocks
from .state import AXES, MachineState, rotate_xy
from .tooltable import Tool
from . import work_systems

if TYPE_CHECKING:
    from ..lathe_profile import LatheProfile
    from .machine import Machine

SPECIAL_NAMES = frozenset(
    """units_inch units_mm distance_absolute distance_incremental arc_distance_absolute
    arc_distance_incremental plane_xy plane_zx plane_yz feed_inverse_time feed_per_minute
    feed_per_rev set_position clear_position_offset suspend_position_offset
    restore_position_offset home home_secondary store_home store_home_secondary
    extrude_absolute extrude_relative set_flow tool_change spindle_cw spindle_ccw spindle_off
    coolant_mist coolant_flood coolant_off program_end machine_coordinates
    firmware_retract firmware_unretract set_kinematic_position
    tool_length_offset tool_length_offset_dynamic tool_length_offset_add cancel_tool_length
    coordinate_data local_offset retract_initial retract_r laser_on laser_off deposition_switch set_bead polar_on polar_off diameter_mode radius_mode
    cutter_comp_off cutter_comp_left cutter_comp_right cutter_comp_left_dynamic cutter_comp_right_dynamic
    cycle_thread""".split()
) | {f"work_offset_{k}" for k in range(1, 10)} | SPLINE_NAMES

_MOVING_KINDS = frozenset(int(k) for k in (Kind.MOVE, Kind.MOVE_EXTRUDE, Kind.MOVE_MILL, Kind.EXTRUDE))
_PROGRAM_ZERO = frozenset({"local_offset", "set_position", "clear_position_offset"})  # G52, G92, G92.1
_SIMPLE = {
    "units_inch": ("units", 25.4), "units_mm": ("units", 1.0),
    "distance_absolute": ("incremental", False), "distance_incremental": ("incremental", True),
    "arc_distance_absolute": ("arc_incremental", False), "arc_distance_incremental": ("arc_incremental", True),
    "plane_xy": ("plane", 17), "plane_zx": ("plane", 18), "plane_yz": ("plane", 19),
    "feed_inverse_time": ("feed_mode", "inverse_time"), "feed_per_minute": ("feed_mode", "per_minute"),
    "feed_per_rev": ("feed_mode", "per_rev"),
    "extrude_absolute": ("e_relative", False), "extrude_relative": ("e_relative", True),
    "polar_on": ("polar", True), "polar_off": ("polar", False),
    "diameter_mode": ("diameter", True), "radius_mode": ("diameter", False),
}


@dataclass
class Waypoint:
    """An intermediate point a command passes through (column -> value)."""

    values: dict[str, float] = field(default_factory=dict)


#: Largest tool number: the tool column is 32-bit, as LinuxCNC's tool numbers are C ints.
MAX_TOOL = 2**31 - 1

#: Canned cycles rs274 refuses with the spindle stopped (with its spelling of each code)
_SPINDLE_CYCLES = {"cycle_tap_left": "G74", "cycle_tap": "G84", "cycle_bore_stop": "g86", "cycle_back_bore": "g87",
                   "cycle_bore_manual": "g88"}


class ModalHandler:
    """Applies one state-changing command to a :class:`Machine`'s state."""

    def __init__(self, machine: "Machine"):
        self.machine = machine
        self.special_ids = np.array(sorted(NAME_ID[n] for n in SPECIAL_NAMES), np.uint8)
        self._last_dwell = 0.0  # dwell at the end of a canned cycle's last move
        self._last_centre = (np.nan, np.nan, np.nan)  # arc centre of a lathe cycle's last move
        self._tool_change_line = -1  # source line of the last M6 (see tool length offsets)
        self.splines = SplineBlocks(machine.config.spline_tolerance)
        self.cycle_mode_open = False  # the last chunk ended in a canned-cycle mode
        self._cycle_name = ""  # the canned cycle whose mode is in force (axis words alone repeat it)
        self._thread_name = "thread"  # G33 or G33.1: which one axis words alone repeat
        self._lathe_motion = MOTION_LINEAR  # the mode a lathe cycle's last move left in force
        self._believed: np.ndarray | None = None  # program point rs274 takes a cycle to end at

    @property
    def state(self) -> MachineState:
        return self.machine.state

    def apply(self, t: CommandTable, row: int, out: dict) -> list[Waypoint]:
        """Run command ``row`` and write its waypoint; return points passed on the way."""
        s = self.state
        name = NAMES[int(t.name[row])]
        params = t.command(row).params
        line = int(t.line[row])
        before = s.position.copy()
        motion, extra = MOTION_NONE, []
        if self.machine.config.block_delete and row in set(t.deleted.tolist()):
            self._write(out, row, before, MOTION_NONE)
            return []
        keep_feed = self.machine.config.units_keep_feed
        if "F" in params and (chr(int(t.letter[row])) != "M" or self.machine.rs274_blocks):
            # an F beside G20/G21 is in the block's new units ("G20 F60" is 60 in/min);
            # where the units change keeps the F number, that follows below
            units = _SIMPLE[name][1] if name in ("units_inch", "units_mm") and not keep_feed else s.units
            s.feed = params["F"] * units
        moves = int(t.kind[row]) in _MOVING_KINDS
        if s.polar and self.machine.polar_incremental_only and (name in _PROGRAM_ZERO or
                                                                name.startswith("work_offset_")):
            self.machine.diagnostics.report(line, 1, "the program zero may not change while polar coordinates (G16) "
                                            "are on", kind="machine")
        repeat = moves and int(t.motion[row]) == MOTION_CYCLE and not name
        if name in LATHE_CYCLES:
            self._cycle_name = name
            motion, extra = self._lathe_cycle(name, params, t.profiles.get(row), line)
            self._lathe_motion = motion
        elif repeat and self._cycle_name in LATHE_CYCLES:
            motion = self._after_lathe_cycle(params, line)
        elif name == "cycle_thread" or (repeat and self._cycle_name == "cycle_thread"):
            self._cycle_name = "cycle_thread"
            motion, extra = self._threading_cycle(params, line)
        elif moves and int(t.motion[row]) == MOTION_CYCLE and name not in ("retract_initial", "retract_r"):
            in_mode = int(t.motion[row - 1]) == MOTION_CYCLE if row else self.cycle_mode_open
            if not in_mode:
                s.cycle.initial = None  # the cycle mode begins here
            same_mode = in_mode and name in ("", self._cycle_name)  # rs274: motion_mode == motion
            self._cycle_name = name or self._cycle_name
            motion, extra = self._cycle(name, params, line, same_mode)
        elif moves and int(t.motion[row]) == MOTION_THREAD:
            rigid = name == "rigid_tap" or (not name and self._thread_name == "rigid_tap")
            self._thread_name = "rigid_tap" if rigid else "thread"
            if rigid:
                tap = self._rigid_tap(params, line)
                if tap is not None:  # in to the bottom, then out again at the same pitch
                    s.program_shift[:] = 0.0
                    s.note_move()
                    self._fill_passing(tap, before)
                    bottom = np.array([tap.values[k] for k in AXES.lower()])
                    self._write(out, row, bottom, MOTION_LINEAR, feed=tap.values["feed"])
                    return [tap]
            else:
                rate = self._thread(params, line)
                if rate is not None:
                    s.program_shift[:] = 0.0
                    s.note_move()
                    self._write(out, row, before, MOTION_LINEAR, feed=rate)
                    return extra
        elif name in SPLINE_NAMES or (moves and int(t.motion[row]) in SPLINE_MOTIONS):
            motion, extra = self._spline(t, row, name, params)
        elif moves and ("@" in params or "^" in params):
            motion = self._polar_move(params, int(t.motion[row]), line)
        elif s.polar and (moves or int(t.motion[row]) in (MOTION_CW, MOTION_CCW)):
            motion = self._radius_angle_move(params, int(t.motion[row]), line)
        elif name in ("retract_initial", "retract_r"):
            s.cycle.retract_to_r = name == "retract_r"
        elif name in _SIMPLE:
            attr, value = _SIMPLE[name]
            if attr == "units" and keep_feed:
                s.feed *= value / s.units  # the same F number in the new units
            if attr == "units" and self.machine.rs274_blocks:
                s.cycle.keep_numbers(value / s.units)
            setattr(s, attr, value)
            if attr == "feed_mode" and self.machine.rs274_blocks and "F" not in params:
                s.feed = 0.0  # rs274 2.9: G93, G94 and G95 zero the feed rate (an F in the block is set after)
            if attr == "incremental" and self.machine.config.distance_mode_sets_extrusion:
                s.e_relative = value
        elif name.startswith("work_offset_"):
            work_systems.select(s, int(name.rsplit("_", 1)[1]))
        elif name == "set_position":
            self._set_position(params, line)
        elif name == "clear_position_offset":
            work_systems.clear_axis_offset(s)
        elif name == "suspend_position_offset":
            work_systems.suspend_axis_offset(s)
        elif name == "restore_position_offset":
            work_systems.restore_axis_offset(s)
        elif name in ("home", "home_secondary"):
            motion, extra = MOTION_RAPID, self._home(params, name == "home_secondary")
        elif name in ("store_home", "store_home_secondary"):
            # the machine point as the interpreter works it out, with the tool offset it holds
            stored = s.position + self._tool_offset_held() - s.tool_offset
            if name == "store_home":
                s.home = stored
            else:
                s.home_secondary = stored
        elif name == "machine_coordinates":
            motion = self._machine_move(params, int(t.motion[row]), line)
        elif name == "set_flow":
            s.flow = params.get("S", 100.0) / 100.0
        elif name == "tool_change" or chr(int(t.letter[row])) == "T":
            self._tool(t, row, params)
            if name == "tool_change":
                self._tool_change_line = line
        elif name in ("spindle_cw", "spindle_ccw", "spindle_off"):
            s.spindle = {"spindle_cw": 1, "spindle_ccw": -1, "spindle_off": 0}[name]
            s.speed = params.get("S", s.speed)
        elif name in ("laser_on", "laser_off"):
            s.laser = int(name == "laser_on")
        elif name == "deposition_switch":  # CEAD's "EM=1" / "EM=0": material on or off from here
            s.laser = int(params.get("value", 1.0) != 0.0)
        elif name == "set_bead":  # CEAD's EXTRUDERSPEED2(w, h, ..): a zero bead is the screw at 0 rpm
            area = call_bead_area(t.named.get(row, ("", ""))[1])
            if area == 0.0:
                s.laser = 0
        elif name in ("coolant_mist", "coolant_flood", "coolant_off"):
            s.coolant = {"coolant_mist": s.coolant | 1, "coolant_flood": s.coolant | 2, "coolant_off": 0}[name]
        elif name.startswith("cutter_comp_"):
            s.compensating = name != "cutter_comp_off"
            s.compensating_left = name.startswith("cutter_comp_left")
        elif name == "program_end":
            self._end_program()
        elif name in ("tool_length_offset", "tool_length_offset_add"):
            number = params.get("H", s.tool)
            if 0 <= number <= MAX_TOOL:
                if not self.machine.config.tool_table:
                    self._check_tool(int(number), line)
                offset = self.machine.tools.offset(int(number))
                # rs274 re-reads its position after a tool change, so a G43 in the
                # M6 block keeps the program position; elsewhere the machine stays.
                self._change_tool_offset(offset if name == "tool_length_offset" else self._tool_offset_held() + offset,
                                         keep_program_position=line == self._tool_change_line)
            else:
                self.machine.diagnostics.report(line, 1, f"H word {number:.0f} out of range (0 to {MAX_TOOL})",
                                                kind="machine")  # rs274: a negative H is refused too
        elif name == "tool_length_offset_dynamic":  # G43.1: the axes it names; the others keep their offsets
            scale, held = s.scale(), self._tool_offset_held()
            self._change_tool_offset([params[letter] * scale[ax] if letter in params else held[ax]
                                      for ax, letter in enumerate(AXES)])
        elif name == "cancel_tool_length":
            self._change_tool_offset(np.zeros(6))
        elif name == "coordinate_data":
            self._coordinate_data(params, line)
        elif name == "local_offset":
            work_systems.set_local_offset(s, self._axis_values(params))
        elif name == "set_kinematic_position":
            self._set_kinematic_position(t.command(row).text)
        elif name in ("firmware_retract", "firmware_unretract"):
            filament = self._firmware_retraction(name == "firmware_retract")
            if filament is not None:
                self._write(out, row, before, MOTION_LINEAR, *filament)
                return extra
        if motion != MOTION_NONE:
            s.program_shift[:] = 0.0  # the machine has reached the offsets in force
            s.note_move()
        if self._believed is not None:
            s.keep_program_position(self._believed)
            self._believed = None
        for w in extra:
            self._fill_passing(w, before)
            before = np.array([w.values[k] for k in AXES.lower()])
        self._write(out, row, before, motion)
        return extra

    # -- commands -----------------------------------------------------------------

    def _axis_values(self, params: dict) -> dict[int, float]:
        """The block's axis words, mm (degrees for A B C), by axis index."""
        scale = self.state.scale()
        return {ax: params[letter] * scale[ax] for ax, letter in enumerate(AXES) if letter in params}

    def _set_position(self, params: dict, line: int) -> None:
        """G92: offset the axes so the current point has the given coordinates (and E, on printers)."""
        s = self.state
        values = self._axis_values(params)
        if not values and "E" not in params and self.machine.config.home_mode == "stored":
            self.machine.diagnostics.report(line, 1, "G92 needs at least one axis word", kind="machine")
        work_systems.set_axis_offset(s, values)
        if "E" in params:
            s.e_program = params["E"] * s.units

    def _cycle(self, name: str, params: dict, line: int, same_mode: bool = True) -> tuple[int, list[Waypoint]]:
        """A canned-cycle block: its moves become waypoints (see :mod:`.cycles`)."""
        s = self.state
        unit = 0.001 if self.machine.config.dwell_p_unit == "ms" else 1.0
        try:
            if self.machine.rs274_blocks:
                self._check_cycle_conditions(name or self._cycle_name)
            steps, end = run_cycle(name if name in CYCLES else "", params, s.cycle, program=s.program_position(),
                                   to_machine=s.to_machine, scale=s.scale(), plane=s.plane,
                                   incremental=s.incremental, dwell_unit=unit,
                                   same_mode=same_mode or not self.machine.rs274_blocks, budget=self.machine.budget)
        except ValueError as exc:
            self.machine.diagnostics.report(line, 1, str(exc), kind="machine")
            return MOTION_NONE, []
        if not steps:
            return MOTION_NONE, []
        if s.cycle.name in TAPPING and s.plane != 17:
            self.machine.warn_once("tapping outside G17", line, f"G74/G84 in G{s.plane}: the feeds move as LinuxCNC "
                                   "2.9 sends them, with the axes mixed up (see gcodekit.emulate.cycles)")
        extra = [Waypoint({**dict(zip(AXES.lower(), st.point)), "motion": st.motion, "dwell": st.dwell})
                 for st in steps[:-1]]
        s.position = steps[-1].point.copy()
        self._believed = end  # where rs274 takes the tool to be (see cycles.TAPPING): kept after the block
        self._last_dwell = steps[-1].dwell
        return steps[-1].motion, extra

    def _check_cycle_conditions(self, name: str) -> None:
        """rs274 2.9's conditions on the machine for a canned cycle (raises ValueError with its message)."""
        s = self.state
        if s.feed <= 0:
            raise ValueError("Cannot feed with zero feed rate")
        if s.feed_mode == "inverse_time":
            raise ValueError("Cannot use inverse time feed with canned cycles")
        if s.compensating:
            raise ValueError("Cannot use canned cycles with cutter compensation on")
        code = _SPINDLE_CYCLES.get(name)
        if code and s.spindle == 0:
            raise ValueError(f"Spindle not turning in {code}")
        if name == "cycle_tap" and s.spindle < 0:
            raise ValueError("Spindle turning counterclockwise in G84")
        if name == "cycle_tap_left" and s.spindle > 0:
            raise ValueError("Spindle turning clockwise in G74")

    def _threading_cycle(self, params: dict, line: int) -> tuple[int, list[Waypoint]]:
        """G76: the passes of a threading cycle become waypoints (see :mod:`.threading`)."""
        s = self.state
        try:
            check_words(params, s.compensating)
        except ThreadingError as exc:
            self.machine.diagnostics.report(line, 1, str(exc), kind="machine")
            return MOTION_NONE, []
        k = s.units
        halve = 2.0 if s.diameter else 1.0  # I, J and K are diameters in G7 (X words are already radii)
        program = s.program_position()
        end = self._program_target(params, "XZ")
        moves = threading_moves((program[0], program[2]), end[2], p=params["P"] * k, i=params["I"] * k / halve,
                                j=params["J"] * k / halve, k=params["K"] * k / halve, q=params.get("Q", 0.0),
                                h=int(params.get("H", 0)), r=params.get("R", 1.0), e=params.get("E", 0.0) * k,
                                taper=int(params.get("L", 0)), budget=self.machine.budget)
        steps = []
        for kind, x, z, pitch in moves + [("rapid", end[0], end[2], None)]:
            point = program.copy()
            point[0], point[2] = x, z
            values = {**dict(zip(AXES.lower(), s.to_machine(point))), "motion": MOTION_RAPID}
            if pitch is not None:  # synchronized with the spindle: pitch per revolution
                values.update(motion=MOTION_LINEAR, feed=pitch * s.speed)
            steps.append(Waypoint(values))
        s.position = s.to_machine(end)
        return MOTION_RAPID, steps[:-1]

    def _after_lathe_cycle(self, params: dict, line: int) -> int:
        """Axis words alone after G70-G72: a move in the mode of the cycle's last move (rs274's
        ``motion_mode`` after the cycle ran its moves through ``convert_straight``/``convert_arc``)."""
        motion = self._lathe_motion
        arc = motion in (MOTION_CW, MOTION_CCW)
        if arc and not any(k in params for k in "IJKR"):
            self.machine.diagnostics.report(line, 1, "R i j k words all missing for arc", kind="machine")
            return MOTION_NONE
        before = self.state.program_position()
        self._move_to(self._program_target(params), params)
        if arc:
            self._last_centre = self._arc_centre(before, params, motion == MOTION_CW, line)
        return motion or MOTION_LINEAR

    def _arc_centre(self, before: np.ndarray, params: dict, clockwise: bool, line: int) -> tuple:
        """Centre (machine X Y Z, the plane's normal NaN) of an arc from program point ``before`` to the
        position, by I/J/K or R."""
        s = self.state
        (f, g, h), (l1, l2) = PLANES[s.plane]
        after = s.program_position()
        p0, p1 = before[[f, g]], after[[f, g]]
        words = np.array([[params.get(l1, np.nan), params.get(l2, np.nan)]]) * s.units
        radius = np.array([params.get("R", np.nan) * s.units])
        in_plane, short = centres(p0[None], p1[None], words, radius, np.array([clockwise]), s.arc_incremental)
        if short[0] > reach_tolerance(s.units):
            self.machine.diagnostics.report(line, 1, "arc radius too small to reach the end point", kind="machine")
        centre = after.copy()
        centre[[f, g]] = in_plane[0]
        centre = s.to_machine(centre)[:3]
        centre[h] = np.nan
        return tuple(centre)

    def _lathe_cycle(self, name: str, params: dict, profile: LatheProfile | None,
                     line: int) -> tuple[int, list[Waypoint]]:
        """G70-G72: the moves of a lathe cycle become waypoints (see :mod:`.lathe`)."""
        s = self.state
        program = s.program_position()
        block = CycleBlock(name, params, profile, complex(program[2], program[0]), s.units,
                           s.incremental, s.arc_incremental, s.diameter, s.plane, s.compensating)
        try:
            point, moves, profile_end = run_lathe_cycle(block, self.machine.budget)
        except LatheCycleError as exc:
            self.machine.diagnostics.report(line, 1, str(exc), kind="machine")
            return MOTION_NONE, []
        if s.compensating:
            end = program.copy()
            end[[0, 2]] = profile_end.imag, profile_end.real
            self.machine.comp_profile_ends.append((line, s.to_machine(end)[:3]))
        here = program.copy()
        steps = []
        kinds = {"rapid": MOTION_RAPID, "feed": MOTION_LINEAR}
        for move in [Move("rapid", point)] + moves:
            end = program.copy()
            end[[0, 2]] = move.end.imag, move.end.real
            values = dict(zip(AXES.lower(), s.to_machine(end)))
            if move.kind == "arc":
                if abs(end[0] - here[0]) < 1e-4 and abs(end[2] - here[2]) < 1e-4:
                    continue  # rs274 skips an arc that ends where it starts
                centre = end.copy()
                centre[[0, 2]] = move.centre.imag, move.centre.real
                centre = s.to_machine(centre)
                values.update(motion=MOTION_CCW if move.ccw else MOTION_CW, cx=centre[0], cy=np.nan, cz=centre[2])
            else:
                values["motion"] = kinds[move.kind]
            steps.append(Waypoint(values))
            here = end
        last = steps[-1].values
        s.position = np.array([last[k] for k in AXES.lower()])
        self._last_centre = tuple(last.get(k, np.nan) for k in ("cx", "cy", "cz"))
        return int(last["motion"]), steps[:-1]

    def _program_target(self, params: dict, letters: str = "XY") -> np.ndarray:
        """The program position moved by the words ``letters`` (absolute or incremental), mm."""
        s = self.state
        scale = s.scale()
        target = s.program_position()
        for letter in letters:
            if letter in params:
                ax = AXES.index(letter)
                target[ax] = (target[ax] if s.incremental else 0.0) + params[letter] * scale[ax]
        return target

    def _synchronized_rate(self, params: dict, line: int, code: str) -> float | None:
        """Feed (mm/min) of a G33/G33.1 move, K units per spindle revolution; None (reported) if rs274 refuses it."""
        s = self.state
        problem = ("K word missing with g33/g33.1" if "K" not in params else
                   "F word used with a g33/g33.1" if "F" in params else
                   f"Spindle not turning in {code}" if s.spindle == 0 or s.speed <= 0 else "")
        if problem:
            self.machine.diagnostics.report(line, 1, problem, kind="machine")
            return None
        return params["K"] * s.scale()[2] * s.speed

    def _thread(self, params: dict, line: int) -> float | None:
        """G33: a straight move at K units per spindle revolution; returns its feed (mm/min), None if refused."""
        rate = self._synchronized_rate(params, line, "G33")
        if rate is not None:
            self._move_to(self._program_target(params), params)
        return rate

    def _rigid_tap(self, params: dict, line: int) -> Waypoint | None:
        """G33.1: the bottom of a rigid tap (K units per spindle revolution); the tool returns to where it was.

        Returns the waypoint at the bottom, its feed the synchronized rate
        (mm/min), or None when rs274 refuses the block.
        """
        rate = self._synchronized_rate(params, line, "G33.1")
        if rate is None:
            return None
        bottom = self.state.to_machine(self._program_target(params, "XYZ"))
        return Waypoint({**dict(zip(AXES.lower(), bottom)), "motion": MOTION_LINEAR, "feed": rate})

    def _spline(self, t: CommandTable, row: int, name: str, params: dict) -> tuple[int, list[Waypoint]]:
        """G5, G5.1, G5.2/G5.3 and the control points between: the curve's chords become
        waypoints (see :mod:`.splines`)."""
        s = self.state
        line = int(t.line[row])
        mode_before = int(t.motion[row - 1]) if row else MOTION_NURBS  # (a chunk's first row: trust it)
        problem = ""
        if not name and int(t.motion[row]) != MOTION_NURBS:
            problem = "Cannot use axis values without a g code that uses them"  # rs274: G5/G5.1 are not modal
        elif name == "nurbs_end" and mode_before != MOTION_NURBS:
            problem = "Cannot use G5.3 without G5.2 first"
            self.splines.discard()
        elif name in ("spline_cubic", "spline_quadratic") and s.plane != 17:  # rs274 draws a NURBS in XY anyway
            problem = "Splines must be in the XY plane"
        elif name in ("spline_cubic", "spline_quadratic") and any(letter in params for letter in "ZABC"):
            problem = "Splines may not have motion in Z, A, B, or C"
        name = name or "nurbs_point"
        try:
            if problem:
                raise ValueError(problem)
            chords = self.splines.block(name, params, s.program_position()[:2], float(s.scale()[0]), s.incremental)
        except ValueError as exc:
            self.machine.diagnostics.report(line, 1, str(exc), kind="machine")
            return MOTION_NONE, []
        if chords is None:
            return MOTION_NONE, []
        points = np.repeat(s.program_position()[None, :], len(chords) - 1, axis=0)
        points[:, :2] = chords[1:]
        points = s.to_machine(points)
        extra = [Waypoint({**dict(zip(AXES.lower(), p)), "motion": MOTION_LINEAR}) for p in points[:-1]]
        s.position = points[-1].copy()
        return MOTION_LINEAR, extra

    def _radius_angle_move(self, params: dict, motion: int, line: int) -> int:
        """G0/G1 under G16 (Fanuc, GER): X the radius, Y the angle in degrees.

        In G90 the pole is the program origin and a missing word keeps the
        last polar value; in G91 the pole is the current point (the move is
        X long at angle Y), as GER requires.  Arcs are refused, as GER does.
        """
        s = self.state
        if motion not in (MOTION_RAPID, MOTION_LINEAR) or s.plane != 17:
            self.machine.diagnostics.report(line, 1, "G16 polar coordinates allow only G0 and G1 in the XY plane",
                                            kind="machine")
            return MOTION_NONE
        if self.machine.polar_incremental_only and not s.incremental:
            self.machine.diagnostics.report(line, 1, "polar coordinates (G16) may only be used in incremental "
                                            "mode (G91)", kind="machine")
            return MOTION_NONE
        program = s.program_position()
        scale = s.scale()
        if s.incremental:
            radius, angle = params.get("X", 0.0) * scale[0], np.radians(params.get("Y", 0.0))
            program[[0, 1]] += radius * np.array([np.cos(angle), np.sin(angle)])
        else:
            radius = params["X"] * scale[0] if "X" in params else float(np.hypot(*program[[0, 1]]))
            angle = np.radians(params["Y"]) if "Y" in params else float(np.arctan2(program[1], program[0]))
            program[[0, 1]] = radius * np.array([np.cos(angle), np.sin(angle)])
        self._move_to(program, params)
        return motion

    def _polar_move(self, params: dict, motion: int, line: int) -> int:
        """G0/G1 with ``@``/``^``: the X/Y end point in polar form (LinuxCNC, XY plane only)."""
        s = self.state
        if motion not in (MOTION_RAPID, MOTION_LINEAR) or s.plane != 17:
            self.machine.diagnostics.report(line, 1, "polar words need G0 or G1 in the XY plane", kind="machine")
            return MOTION_NONE
        program = s.program_position()
        scale = s.scale()
        program[[0, 1]] = polar_target(params, program[[0, 1]], scale[0], s.incremental)
        self._move_to(program, params)
        return motion

    def _move_to(self, program: np.ndarray, params: dict) -> None:
        """Finish a move whose X/Y the caller worked out: other axes from their words."""
        s = self.state
        scale = s.scale()
        for ax, letter in enumerate(AXES):
            if letter in params and letter not in "XY":
                program[ax] = program[ax] + params[letter] * scale[ax] if s.incremental else params[letter] * scale[ax]
        s.position = s.to_machine(program)
        s.program_shift[:] = 0.0

    def _tool_offset_held(self) -> np.ndarray:
        """The tool length offset (mm) the interpreter holds: with ``standalone_canon``, after G20/G21
        the numbers it was set with, read in the units now in force."""
        s = self.state
        if self.machine.config.standalone_canon:
            return s.tool_offset * (s.units / s.tool_offset_units)
        return s.tool_offset

    def _change_tool_offset(self, offset, keep_program_position: bool = False) -> None:
        """A new tool length offset; the program position moves by the held offset's change (rs274's
        ``current += old - new``, turned into the program frame), which the next move reaches when the
        held one was stale."""
        s = self.state
        held = self._tool_offset_held()
        if keep_program_position or not np.any(held != s.tool_offset):
            s.change_tool_offset(offset, keep_program_position)
            return
        believed = s.program_position() + rotate_xy(held - np.asarray(offset, float), -s.rotation)
        s.change_tool_offset(offset)
        s.keep_program_position(believed)

    def _coordinate_data(self, params: dict, line: int) -> None:
        """G10: L2/L20 set a work offset, L1/L10/L11 a tool's offsets (LinuxCNC 2.9)."""
        s = self.state
        scale = s.scale()
        mode = int(params.get("L", -1))
        given = [ax for ax, letter in enumerate(AXES) if letter in params]
        if mode in (2, 20):
            index = int(params.get("P", 0)) or s.work_offset
            if not 1 <= index <= 9:
                self.machine.diagnostics.report(line, 1, f"G10 L{mode} P must be 0 to 9", kind="machine")
                return
            if mode == 20 and "R" in params:
                self.machine.diagnostics.report(line, 1, "R not allowed in G10 L20", kind="machine")
                return
            if mode == 2:
                work_systems.set_offsets(s, index, self._axis_values(params), params.get("R"))
            else:
                work_systems.touch_off(s, index, self._axis_values(params))
        elif mode in (1, 10, 11):
            number = int(params.get("P", 0))
            tool = self.machine.tools.setdefault(number, Tool(number))
            for ax in given:
                value = params[AXES[ax]] * scale[ax]
                if mode == 1:
                    tool.offset[ax] = value
                else:  # the current point would have coordinate `value` with this tool's offset
                    system = s.work_offsets[9] if mode == 11 else s.frame
                    g92 = 0.0 if mode == 11 else s.g92[ax]
                    tool.offset[ax] = s.position[ax] - system[ax] - g92 - value
            if "R" in params:
                tool.diameter = 2 * params["R"] * s.units
            if "Q" in params:
                tool.orientation = int(params["Q"])
        else:
            self.machine.diagnostics.report(line, 1, "G10 needs L1, L2, L10, L11 or L20", kind="machine")

    def _home(self, params: dict, secondary: bool) -> list[Waypoint]:
        s = self.state
        # (a stale tool offset the interpreter holds shifts the machine point it aims at, see standalone_canon)
        stored = (s.home_secondary if secondary else s.home) + s.tool_offset - self._tool_offset_held()
        given = [ax for ax, letter in enumerate(AXES) if letter in params]
        if self.machine.config.home_mode == "select":
            for ax in given or [0, 1, 2]:
                s.position[ax] = stored[ax]
            return []
        # rs274 goes through the given point; with no axis words through the current
        # one (a rapid of no length), then every axis goes to the stored position
        program = self._program_target(params, AXES)
        via = s.to_machine(program)
        # the given axes reach the stored position as program coordinates (a rotation mixes X and Y)
        s.position = s.to_machine(np.where(np.isin(np.arange(6), given), s.to_program(stored), program)) \
            if given else stored.copy()
        return [Waypoint({k: v for k, v in zip(AXES.lower(), via)} | {"motion": MOTION_RAPID})]

    def _machine_move(self, params: dict, motion: int, line: int) -> int:
        """G53: move to machine coordinates in this block only."""
        s = self.state
        if motion not in (MOTION_RAPID, MOTION_LINEAR):
            self.machine.diagnostics.report(line, 1, "G53 needs G0 or G1 in force", kind="machine")
            return MOTION_NONE
        if s.incremental:
            self.machine.diagnostics.report(line, 1, "G53 is not allowed in incremental mode (G91)", kind="machine")
        # rs274 (find_ends) works the target out in program coordinates from its own idea of the
        # current point: an axis without a word keeps that point's coordinate in the turned frame
        scale, held, program = s.scale(), self._tool_offset_held(), s.program_position()
        target = program.copy()
        turned = rotate_xy(program + s.g92, s.rotation)
        for ax, letter in enumerate(AXES):
            if ax < 2:
                turned[ax] = params[letter] * scale[ax] - s.frame[ax] - held[ax] if letter in params else turned[ax]
            elif letter in params:
                target[ax] = params[letter] * scale[ax] - s.frame[ax] - s.g92[ax] - (held[ax] if ax == 2 else 0.0)
        target[:2] = rotate_xy(turned, -s.rotation)[:2] - s.g92[:2]
        s.position = s.to_machine(target)
        return motion

    def _tool(self, t: CommandTable, row: int, params: dict) -> None:
        s = self.state
        number = int(round(t.number[row] / 10)) if chr(int(t.letter[row])) == "T" else int(params.get("T", 0))
        if not 0 <= number <= MAX_TOOL:  # rs274's message for a negative one (interp_read.cc read_t)
            message = "Negative tool id used" if number < 0 else f"Tool number {number} out of range (at most {MAX_TOOL})"
            self.machine.diagnostics.report(int(t.line[row]), 1, message, kind="machine")
            return
        if chr(int(t.letter[row])) == "T":
            self._check_tool(number, int(t.line[row]))
            if self.machine.config.tool_change_on == "T":
                s.tool = number
            s.selected_tool = number
        else:
            if "T" in params:  # ``T1 M6``: the T selects too
                self._check_tool(int(params["T"]), int(t.line[row]))
            s.selected_tool = int(params.get("T", s.selected_tool))
            s.tool = s.selected_tool
            if self.machine.rs274_blocks and NAMES[int(t.name[row])] == "tool_change":
                s.spindle = 0  # rs274 stops the spindle for the change (a G86 after M6 is refused)
                if self.machine.config.standalone_canon:  # it re-reads its position (see standalone_canon)
                    s.keep_program_position(s.canon_point - s.frame - s.g92)

    def _check_tool(self, number: int, line: int) -> None:
        """With a tool table, selecting a tool it lacks is LinuxCNC's error (T0, no tool, is fine);
        without one, a mill's tools have no length or diameter, which is said once."""
        config = self.machine.config
        if number and config.tool_table and number not in self.machine.tools:
            self.machine.diagnostics.report(line, 1, f"Requested tool {number} not found in the tool table",
                                            kind="machine")
        elif number and not config.tool_table and config.process != "additive":
            self.machine.warn_once("no tool table", line, f"no tool table: tool {number} (and every other) is taken "
                                   "to have no length or diameter; LinuxCNC refuses a tool its table lacks (give "
                                   "the machine a tool_table)")

    def _set_kinematic_position(self, text: str) -> None:
        """Klipper's SET_KINEMATIC_POSITION X=.. Y=.. Z=..: the toolhead is declared there."""
        s = self.state
        for key, value in re.findall(r"\b([XYZ])\s*=\s*([-+]?[0-9.]+)", text.upper()):
            s.position["XYZ".index(key)] = float(value)

    def _firmware_retraction(self, retract: bool) -> tuple[float, float] | None:
        """G10/G11 on a printer: an extruder-only move of the configured length.

        Returns the filament moved and its feed (mm/min), or None when the
        machine has no retraction configured or is already in that state.
        The modal feed is kept (Klipper restores its G-code state after).
        """
        s, c = self.state, self.machine.config
        if c.retract_length <= 0 or s.retracted == retract:
            return None
        s.retracted = retract
        length = c.retract_length if retract else -(c.retract_length + c.unretract_extra_length)
        speed = c.retract_speed if retract else c.unretract_speed
        de = -length * s.flow
        s.e_total += de
        return de, speed * 60.0

    def _end_program(self) -> None:
        """M2/M30: LinuxCNC resets these modes and stops reading the program."""
        s = self.state
        s.select_work_system(1)
        s.plane, s.incremental, s.feed_mode = 17, False, "per_minute"
        s.spindle, s.coolant, s.compensating = 0, 0, False
        s.ended = True

    # -- output -------------------------------------------------------------------

    def _fill_passing(self, w: Waypoint, before: np.ndarray) -> None:
        point = np.array([w.values[k] for k in AXES.lower()])
        motion = int(w.values.get("motion", MOTION_RAPID))
        distance = self._length(before, point, motion, [w.values.get(k, np.nan) for k in ("cx", "cy", "cz")])
        rate = w.values["feed"] if "feed" in w.values and motion != MOTION_RAPID else self._rate(motion)
        dwell = w.values.pop("dwell", 0.0)
        w.values.update(distance=distance, time=(distance / (rate / 60.0) if distance and rate > 0 else 0.0) + dwell,
                        de=0.0)
        for k in ("cx", "cy", "cz"):
            w.values.setdefault(k, np.nan)

    def _rate(self, motion: int) -> float:
        """Feed of a move made by a special command, mm/min."""
        s = self.state
        feeding = motion in (MOTION_LINEAR, MOTION_CW, MOTION_CCW) or self.machine.rapid_is_feed
        return s.feed if feeding else self.machine.config.rapid_feed

    def _length(self, before: np.ndarray, point: np.ndarray, motion: int, centre) -> float:
        """Path length of a move made by a special command: the chord, or the arc round ``centre``."""
        (f, g, h), _ = PLANES[self.state.plane]
        centre = np.asarray(centre, float)
        if motion not in (MOTION_CW, MOTION_CCW) or np.isnan(centre[[f, g]]).any():
            return float(np.linalg.norm((point - before)[:3]))
        return float(single_turn_lengths(before[[f, g]][None], point[[f, g]][None], centre[[f, g]][None],
                                         np.array([motion == MOTION_CW]), np.array([point[h] - before[h]]))[0])

    def _write(self, out: dict, row: int, before: np.ndarray, motion: int, de: float = 0.0,
               feed: float | None = None) -> None:
        s = self.state
        for k, v in zip(AXES.lower(), s.position):
            out[k][row] = v
        distance = self._length(before, s.position, motion, self._last_centre)
        rate = self._rate(motion) if feed is None else feed
        path = distance or abs(de)
        out["distance"][row] = distance
        out["time"][row] = (path / (rate / 60.0) if path and rate > 0 else 0.0) + self._last_dwell
        self._last_dwell = 0.0
        out["de"][row] = de
        out["feed"][row] = rate if feed is not None else s.feed
        out["motion"][row] = motion
        out["cx"][row], out["cy"][row], out["cz"][row] = self._last_centre
        self._last_centre = (np.nan, np.nan, np.nan)
        out["spindle"][row] = s.speed * s.spindle
        self.machine.fill_state(row, out)
