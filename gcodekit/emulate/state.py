"""Emulate stage: the modal state of a machine between two commands.

Positions are machine coordinates in millimetres (degrees for A, B, C).  As
in LinuxCNC, a program point reaches the machine as
``rotate(program + g92, rotation) + work_offset + tool_offset``: the G92/G52
offset turns with the work system's XY rotation (G10 L2 R), the work and
tool offsets do not.  Offsets and stored positions are millimetres too,
whatever units the program uses.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .cycles import CycleState

N_AXES = 6  # X Y Z A B C
AXES = "XYZABC"
LINEAR = np.array([True, True, True, False, False, False])


def _zeros() -> np.ndarray:
    return np.zeros(N_AXES)


def rotate_xy(points: np.ndarray, degrees: float) -> np.ndarray:
    """``points`` (one X Y Z A B C point, or rows of them) turned about Z by ``degrees``, counter-clockwise.

    A new array when it turns; with no turn, ``points`` themselves.
    """
    points = np.asarray(points, float)
    if not degrees:
        return points
    angle = np.radians(degrees)
    cos, sin = np.cos(angle), np.sin(angle)
    turned = points.copy()
    turned[..., 0] = points[..., 0] * cos - points[..., 1] * sin
    turned[..., 1] = points[..., 0] * sin + points[..., 1] * cos
    return turned


@dataclass
class MachineState:
    """Everything that carries from one command to the next."""

    position: np.ndarray = field(default_factory=_zeros)
    units: float = 1.0  # mm per program unit: 1 (G21) or 25.4 (G20)
    incremental: bool = False  # G91
    polar: bool = False  # G16 (Fanuc, GER): X is a radius, Y an angle in degrees
    diameter: bool = False  # G7 (LinuxCNC lathes): X words are diameters
    arc_incremental: bool = True  # G91.1 (the default) or G90.1
    plane: int = 17
    feed: float = np.nan  # mm/min, or 1/min in inverse-time mode
    feed_mode: str = "per_minute"  # "inverse_time" (G93), "per_rev" (G95)
    feed_given: bool = False  # an F word (or the first move, at the boot feed) came; see Machine._note_boot_feed
    minimum_feed: float = 0.0  # mm/min, the slowest the firmware moves (RRF's M203 I); 0 if not known or none
    e_relative: bool = False  # M83
    e_program: float = 0.0  # E coordinate as the program sees it (mm)
    e_total: float = 0.0  # filament pushed so far (mm)
    flow: float = 1.0  # M221, as a ratio
    work_offset: int = 1  # 1..9 for G54..G59.3
    # Each work system's offsets and XY rotation (degrees) as stored (LinuxCNC's
    # #5221-#5390); the system in force applies its stored values when selected.
    work_offsets: np.ndarray = field(default_factory=lambda: np.zeros((10, N_AXES)))
    rotations: np.ndarray = field(default_factory=lambda: np.zeros(10))
    frame: np.ndarray = field(default_factory=_zeros)  # the work offset in force
    rotation: float = 0.0  # the XY rotation in force, degrees counter-clockwise
    g92: np.ndarray = field(default_factory=_zeros)  # the G92/G52 offset in force
    g92_stored: np.ndarray = field(default_factory=_zeros)  # as stored (#5211-#5219): G92.3 brings it back
    g92_on: bool = False  # #5210: set by G92, G52 and G92.3, cleared by G92.1 and G92.2
    tool_offset: np.ndarray = field(default_factory=_zeros)  # G43 tool length offset
    tool_offset_units: float = 1.0  # mm per program unit when the offset was set (see standalone_canon)
    # program point of the last move plus the work and G92 offsets then in force: what rs274 run
    # standalone re-reads as its position after M6, less the offsets in force (see standalone_canon)
    canon_point: np.ndarray = field(default_factory=_zeros)
    # rs274 keeps the program position when the tool offset changes in an M6
    # block, and turns it with a work system's new rotation: the machine reaches
    # the new frame on the next move.  Until then the program position differs
    # from to_program(position) by this much (see keep_program_position).
    program_shift: np.ndarray = field(default_factory=_zeros)
    home: np.ndarray = field(default_factory=_zeros)  # G28 stored position
    home_secondary: np.ndarray = field(default_factory=_zeros)  # G30 stored position
    tool: int = 0
    selected_tool: int = 0
    speed: float = 0.0  # S for the spindle, rpm
    spindle: int = 0  # 1 CW, -1 CCW, 0 stopped
    coolant: int = 0  # bit 1 mist, bit 2 flood
    laser: int = 0  # heat source (DED laser or weld arc) on
    retracted: bool = False  # firmware retraction (G10) in effect
    compensating: bool = False  # G41/G42 in force (the path is offset by a later pass)
    compensating_left: bool = False  # ... and on the left (G41, G41.1)
    motion_code: int = 800  # the motion mode's G code in tenths (G1 10, G38.2 382): rs274 starts in G80
    cycle: CycleState = field(default_factory=CycleState)  # canned-cycle words in force
    ended: bool = False  # M2/M30 reached: later blocks are not run

    def select_work_system(self, index: int) -> None:
        """G54..G59.3 (1..9): the system's stored offsets and rotation come into force."""
        self.work_offset = index
        self.frame = self.work_offsets[index].copy()
        self.rotation = float(self.rotations[index])

    def to_machine(self, program: np.ndarray) -> np.ndarray:
        """Program coordinates (one point or rows of points, mm) in machine coordinates."""
        turned = rotate_xy(np.asarray(program, float) + self.g92, self.rotation)  # a new array either way
        turned += self.frame
        turned += self.tool_offset
        return turned

    def to_program(self, machine: np.ndarray) -> np.ndarray:
        """Machine coordinates (one point or rows of points) in program coordinates, mm."""
        untool = np.asarray(machine, float) - self.frame - self.tool_offset
        return rotate_xy(untool, -self.rotation) - self.g92

    def program_position(self) -> np.ndarray:
        return self.to_program(self.position) + self.program_shift

    def note_move(self) -> None:
        """The machine has moved: remember the end for rs274 standalone's position after M6."""
        self.canon_point = self.program_position() + self.frame + self.g92

    def keep_program_position(self, program: np.ndarray) -> None:
        """After an offset change: the program position is ``program`` until the next move.

        The machine stays where it is; a move then goes to its program
        target in the new frame (rs274 keeps its own idea of the position).
        """
        shift = np.asarray(program, float) - self.to_program(self.position)
        self.program_shift = np.where(np.abs(shift) < 1e-9, 0.0, shift)

    def change_tool_offset(self, offset: np.ndarray, keep_program_position: bool = False) -> None:
        """New tool length offset, taking effect without motion.

        Normally the machine stays and the program position shifts by the
        change; with ``keep_program_position`` the program position stays and
        the machine catches up on the next move.
        """
        before = self.program_position()
        self.tool_offset = np.asarray(offset, float).copy()
        self.tool_offset_units = self.units
        if keep_program_position:
            self.keep_program_position(before)

    def scale(self) -> np.ndarray:
        """Program units to mm per axis (rotary axes stay in degrees)."""
        return np.where(LINEAR, self.units, 1.0)

    def fill_columns(self, rows: slice | int, out: dict) -> None:
        """Write the modal state into the waypoint columns ``out`` at ``rows`` (plane, units, tool, ...)."""
        out["plane"][rows] = self.plane
        out["units"][rows] = 1 if self.units != 1.0 else 0
        out["tool"][rows] = self.tool
        out["coolant"][rows] = self.coolant
        out["laser"][rows] = self.laser
        out["work_offset"][rows] = self.work_offset
        out["flow"][rows] = self.flow
        out["rotation"][rows] = self.rotation
