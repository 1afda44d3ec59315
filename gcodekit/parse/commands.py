"""Parse stage: the typed Command classes a program's blocks become.

Commands describe what the machine was *told*; what it then did is the
process data of :mod:`gcodekit.emulate`.  Inside the library commands are
rows of a :class:`~gcodekit.parse.table.CommandTable`; these objects are
made when a row is indexed (``operation.commands[i]``).

Examples
--------
>>> from gcodekit.parse.commands import MoveExtrude
>>> cmd = MoveExtrude("G1", {"X": 10.0, "E": 0.5}, line=3)
>>> cmd.x, cmd.e, str(cmd)
(10.0, 0.5, 'G1 X10 E0.5')
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import ClassVar

from ..lathe_profile import LatheProfile, written_comment


class Kind(IntEnum):
    """Command class of a row, stored as one byte per command."""

    COMMENT = 0
    MOVE = 1
    ARC = 2
    EXTRUDE = 3
    MOVE_EXTRUDE = 4
    ARC_EXTRUDE = 5
    MILL = 6
    MOVE_MILL = 7
    ARC_MILL = 8
    DWELL = 9
    PURGE = 10
    FEED_RATE = 11
    CONFIG = 12
    G = 13
    M = 14
    ABSOLUTE_POSITION = 15
    INCREMENTAL_POSITION = 16
    WORK_COORDINATES = 17
    MACHINE_COORDINATES = 18


def _format(value: float) -> str:
    text = repr(float(value))
    if "e" in text or "E" in text:
        text = f"{value:.12f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return text if text not in ("-0", "") else "0"


@dataclass(eq=True)
class Command:
    """A machine instruction: its code, parameters and source line.

    Attributes
    ----------
    code : str
        ``"G1"``, ``"M104"``, ``"T0"``, ``"SET_VELOCITY_LIMIT"`` or ``""``
        for a block of words without a code (a modal move).
    params : dict of str to float
        Word letter to value, as written (program units, not offset).
    line : int
        1-based source line.
    comment : str or None
    name : str
        Normalized meaning from the flavor (``"linear"``), ``""`` if unknown.
    text : str
        Raw argument text of named commands (``ACCEL=500``).
    profile : LatheProfile or None
        A lathe cycle's (G70-G72) profile, from its ``Q`` subroutine (see
        :mod:`gcodekit.lathe_profile`); written out after the comment.
    """

    code: str
    params: dict[str, float] = field(default_factory=dict)
    line: int = 0
    comment: str | None = None
    name: str = ""
    text: str = ""
    profile: LatheProfile | None = field(default=None, repr=False)

    kind: ClassVar[Kind] = Kind.CONFIG

    def get(self, letter: str, default: float | None = None) -> float | None:
        return self.params.get(letter, default)

    def __str__(self) -> str:
        words = [self.code] if self.code else []
        words += [f"{k}{_format(v)}" for k, v in self.params.items()]
        if self.text:
            words.append(self.text)
        comment = written_comment(self.comment, self.profile)
        if comment is not None:
            words.append(f"; {comment}" if words else f";{comment}")
        return " ".join(words)


class _Axes:
    """Target coordinates given by the command (None where not given)."""

    params: dict[str, float]

    x = property(lambda self: self.params.get("X"))
    y = property(lambda self: self.params.get("Y"))
    z = property(lambda self: self.params.get("Z"))
    a = property(lambda self: self.params.get("A"))
    b = property(lambda self: self.params.get("B"))
    c = property(lambda self: self.params.get("C"))
    feed = property(lambda self: self.params.get("F"))


class _ArcWords:
    params: dict[str, float]
    code: str
    name: str

    i = property(lambda self: self.params.get("I"))
    j = property(lambda self: self.params.get("J"))
    k = property(lambda self: self.params.get("K"))
    r = property(lambda self: self.params.get("R"))

    @property
    def clockwise(self) -> bool:
        return self.name == "arc_cw"


class _Extrusion:
    params: dict[str, float]
    e = property(lambda self: self.params.get("E"))


class _Spindle:
    params: dict[str, float]
    speed = property(lambda self: self.params.get("S"))


@dataclass(eq=True)
class Move(_Axes, Command):
    """Linear movement to a location at a feed rate (G0, G1)."""

    kind: ClassVar[Kind] = Kind.MOVE

    @property
    def rapid(self) -> bool:
        return self.name == "rapid"


@dataclass(eq=True)
class Arc(_ArcWords, _Axes, Command):
    """Arc movement to a location about a center point (G2, G3)."""

    kind: ClassVar[Kind] = Kind.ARC


@dataclass(eq=True)
class Extrude(_Extrusion, Command):
    """Extruder-only motion: a deposit amount or retraction with no travel."""

    kind: ClassVar[Kind] = Kind.EXTRUDE


@dataclass(eq=True)
class MoveExtrude(_Extrusion, Move):
    """Linear movement while extruding (FFF and LFAM deposition)."""

    kind: ClassVar[Kind] = Kind.MOVE_EXTRUDE


@dataclass(eq=True)
class ArcExtrude(_Extrusion, Arc):
    """Arc movement while extruding."""

    kind: ClassVar[Kind] = Kind.ARC_EXTRUDE


@dataclass(eq=True)
class Mill(_Spindle, Command):
    """A spindle rate for a milling tool (an ``S`` word on its own)."""

    kind: ClassVar[Kind] = Kind.MILL


@dataclass(eq=True)
class MoveMill(_Spindle, Move):
    """Linear movement that also sets the spindle rate."""

    kind: ClassVar[Kind] = Kind.MOVE_MILL


@dataclass(eq=True)
class ArcMill(_Spindle, Arc):
    """Arc movement that also sets the spindle rate."""

    kind: ClassVar[Kind] = Kind.ARC_MILL


@dataclass(eq=True)
class Dwell(Command):
    """Pause at the current location (G4); duration units depend on the machine."""

    kind: ClassVar[Kind] = Kind.DWELL


@dataclass(eq=True)
class Purge(_Extrusion, Dwell):
    """Dwell while extruding: stationary deposition."""

    kind: ClassVar[Kind] = Kind.PURGE


@dataclass(eq=True)
class FeedRate(Command):
    """Feed-rate-only update (``F1200`` or ``G1 F1200``)."""

    kind: ClassVar[Kind] = Kind.FEED_RATE
    feed = property(lambda self: self.params.get("F"))


@dataclass(eq=True)
class Config(Command):
    """Machine configuration with no dedicated class (``T1``, named commands)."""

    kind: ClassVar[Kind] = Kind.CONFIG


@dataclass(eq=True)
class G(Config):
    """A G-code configuration command (plane, units, offsets, ...)."""

    kind: ClassVar[Kind] = Kind.G


@dataclass(eq=True)
class M(Config):
    """An M-code configuration command (spindle, coolant, temperatures, ...)."""

    kind: ClassVar[Kind] = Kind.M


@dataclass(eq=True)
class AbsolutePosition(G):
    """Switch to absolute positioning (G90)."""

    kind: ClassVar[Kind] = Kind.ABSOLUTE_POSITION


@dataclass(eq=True)
class IncrementalPosition(G):
    """Switch to incremental positioning (G91)."""

    kind: ClassVar[Kind] = Kind.INCREMENTAL_POSITION


@dataclass(eq=True)
class WorkCoordinates(G):
    """Select a work coordinate system (G54-G59.3)."""

    kind: ClassVar[Kind] = Kind.WORK_COORDINATES


@dataclass(eq=True)
class MachineCoordinates(_Axes, G):
    """Move in machine coordinates for this block only (G53)."""

    kind: ClassVar[Kind] = Kind.MACHINE_COORDINATES


@dataclass(eq=True)
class Comment(Command):
    """A comment-only line with no machine instruction."""

    kind: ClassVar[Kind] = Kind.COMMENT

    def __str__(self) -> str:
        return f";{self.comment}" if self.comment else ";"


COMMAND_CLASSES: dict[Kind, type[Command]] = {
    cls.kind: cls
    for cls in (Comment, Move, Arc, Extrude, MoveExtrude, ArcExtrude, Mill, MoveMill, ArcMill,
                Dwell, Purge, FeedRate, Config, G, M, AbsolutePosition, IncrementalPosition,
                WorkCoordinates, MachineCoordinates)
}
MOTION_KINDS = frozenset({Kind.MOVE, Kind.ARC, Kind.MOVE_EXTRUDE, Kind.ARC_EXTRUDE, Kind.MOVE_MILL,
                          Kind.ARC_MILL, Kind.EXTRUDE, Kind.MACHINE_COORDINATES})
