"""Emulate stage: the registry of modal command handlers, and what a handler is given.

A handler runs one state-changing block.  It is a function
``handler(ctx, block) -> Outcome | None`` registered with :func:`handles`
for the keys it serves: command names (``"units_inch"``) or the mode keys
below, for blocks that move in a mode of their own (axis words alone in a
canned-cycle mode, a spline's control points, G16 polar moves).  It is given
a :class:`Context` (the machine's state, configuration, diagnostics, tool
table and motion budget, and what handlers remember between blocks) and the
:class:`Block`; it changes the state and returns an :class:`Outcome` when
the tool moves.  The dispatcher (:mod:`gcodekit.emulate.modal`) chooses the
handler and writes the block's waypoint.

Examples
--------
>>> from gcodekit.emulate import handlers
>>> handlers.HANDLERS["units_inch"].__name__
'units'
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable

import numpy as np

from ...errors import Diagnostics
from ...limits import MotionBudget
from ...parse.commands import Command, Kind
from ...parse.table import MOTION_LINEAR, MOTION_NONE, NAME_ID, CommandTable
from ..splines import SplineBlocks
from ..state import MachineState
from ..tooltable import ToolTable

if TYPE_CHECKING:
    from ..presets import MachineConfig

# Mode keys: for blocks the dispatcher routes by more than their name (see modal.route): axis
# words alone in a mode, a T word, and the blocks the machine picks to run one at a time by their
# motion mode (canned cycles, G33/G33.1, G70-G72), whose names have no handler of their own.
#: a G70-G72 block (LinuxCNC's lathe cycles)
LATHE_CYCLE = "(lathe cycle)"
#: axis words alone after a lathe cycle: a move in the mode of the cycle's last move
AFTER_LATHE_CYCLE = "(after a lathe cycle)"
#: a block in a canned-cycle mode (G73, G81-G89, ...): the cycle runs at its point
CANNED_CYCLE = "(canned cycle)"
#: a block in G33/G33.1 mode: a move synchronized with the spindle
SYNCHRONIZED = "(spindle-synchronized move)"
#: axis words alone in a spline mode (a NURBS control point)
SPLINE_MODE = "(spline mode)"
#: a G0/G1 with ``@``/``^`` words: an end point in polar form
POLAR_WORDS = "(polar words)"
#: a move under G16: X a radius, Y an angle
POLAR_MODE = "(G16 polar move)"
#: a T word alone: a tool selection (or change, on printers)
T_WORD = "(T word)"
MODE_KEYS = frozenset({LATHE_CYCLE, AFTER_LATHE_CYCLE, CANNED_CYCLE, SYNCHRONIZED, SPLINE_MODE, POLAR_WORDS,
                       POLAR_MODE, T_WORD})

_MOVING_KINDS = frozenset(int(k) for k in (Kind.MOVE, Kind.MOVE_EXTRUDE, Kind.MOVE_MILL, Kind.EXTRUDE))


@dataclass
class Waypoint:
    """An intermediate point a command passes through (column -> value)."""

    values: dict[str, float] = field(default_factory=dict)


@dataclass
class CycleMode:
    """Which cycle or thread axis words alone repeat: carried from block to block."""

    name: str = ""  # the canned or lathe cycle whose mode is in force
    thread: str = "thread"  # G33 ("thread") or G33.1 ("rigid_tap")
    lathe_motion: int = MOTION_LINEAR  # the mode a lathe cycle's last move left in force
    open: bool = False  # the last chunk ended in a canned-cycle mode


@dataclass
class Context:
    """What handlers may read and change: the machine's parts, not the machine.

    ``warn_once(key, line, message)`` gives a warning the first time ``key``
    comes up in the program.  ``comp_profile_ends`` collects, for the cutter
    compensation pass, the source line and machine end point (X Y Z) of each
    lathe cycle run under compensation.
    """

    state: MachineState
    config: "MachineConfig"
    diagnostics: Diagnostics
    tools: ToolTable
    budget: MotionBudget
    warn_once: Callable[[str, int, str], None]
    rs274_blocks: bool = False  # RS274NGC block rules (see Machine)
    polar_incremental_only: bool = False  # GER's G16 rules
    rapid_is_feed: bool = False  # G0 moves at the modal feed
    zero_feed: str = "refused"  # what an F at or below 0 does (see Machine)
    comp_profile_ends: list[tuple[int, np.ndarray]] = field(default_factory=list)
    cycle_mode: CycleMode = field(default_factory=CycleMode)
    splines: SplineBlocks = field(init=False)  # the spline being read, block by block
    tool_change_line: int = -1  # source line of the last M6 (see tool length offsets)

    def __post_init__(self):
        self.splines = SplineBlocks(self.config.spline_tolerance)

    def error(self, line: int, message: str) -> None:
        """Report the machine refusing a block at ``line`` (rs274's error, or the firmware's)."""
        self.diagnostics.report(line, 1, message, kind="machine")


@dataclass(frozen=True)
class Block:
    """One state-changing command, as a handler reads it: its row of the command table."""

    table: CommandTable
    row: int
    command: Command

    @property
    def name(self) -> str:
        return self.command.name

    @property
    def params(self) -> dict[str, float]:
        """Word letter to value, as written (program units)."""
        return self.command.params

    @property
    def line(self) -> int:
        return self.command.line

    @property
    def letter(self) -> str:
        """The code letter (``"G"``, ``"M"``, ``"T"``, ``"@"`` for named commands), ``"\\x00"`` for none."""
        return chr(int(self.table.letter[self.row]))

    @property
    def motion(self) -> int:
        """The motion mode in force for the block (a table motion, see :mod:`gcodekit.parse.table`)."""
        return int(self.table.motion[self.row])

    @property
    def moves(self) -> bool:
        """The block is a straight move or an extrusion (an arc is not)."""
        return int(self.table.kind[self.row]) in _MOVING_KINDS


@dataclass
class Outcome:
    """What a block did, for the waypoint the dispatcher writes for it.

    A handler returns None when the tool stays where it is.
    """

    motion: int = MOTION_NONE  # of the block's own waypoint; MOTION_NONE: the tool stays
    passed: list[Waypoint] = field(default_factory=list)  # points passed on the way, in order
    de: float = 0.0  # filament moved (mm)
    feed: float | None = None  # the move's own feed (mm/min); None: the modal feed
    centre: tuple[float, float, float] = (np.nan, np.nan, np.nan)  # of an arc ending the block
    dwell: float = 0.0  # seconds spent at the end point
    believed: np.ndarray | None = None  # the program point rs274 takes the block to end at, if not the tool's
    axes_move: bool = True  # False for an extruder-only move: the program frame is not reached yet


Handler = Callable[[Context, Block], "Outcome | None"]

#: The handler of each key (a command name or one of :data:`MODE_KEYS`).
HANDLERS: dict[str, Handler] = {}


def handles(*keys: str) -> Callable[[Handler], Handler]:
    """Register the decorated function as the handler of ``keys``.

    Each key is a command name of :data:`gcodekit.parse.table.NAMES` (the
    machine then runs that command's blocks one at a time) or a mode key;
    each has one handler.
    """
    def register(handler: Handler) -> Handler:
        for key in keys:  # all checked before any is registered
            if key not in NAME_ID and key not in MODE_KEYS:
                raise ValueError(f"{key!r} is neither a command name nor a mode key")
            if key in HANDLERS:
                raise ValueError(f"{key!r} already has a handler: {HANDLERS[key].__qualname__}")
        HANDLERS.update(dict.fromkeys(keys, handler))
        return handler
    return register
