"""Front end (FreeCAD Path API): ``Path``, an ordered list of commands with its length and extents.

FreeCAD's ``Path.Path``: built from commands or from G-code text, edited
with ``addCommands``, ``insertCommand`` and ``deleteCommand``, measured by
``Length`` and ``BoundBox`` and written by ``toGCode()``.

>>> p = Path([Command("g1", {"x": 1, "y": 0}), Command("g1", {"x": 0, "y": 2})])
>>> p
Path [ size:2 length:3.2361 ]
>>> p.addCommands(Command("G1 X0 Y0"))
Path [ size:3 length:5.2361 ]
>>> print(Path("G0 X2 Y2 G1 X0 Y2").toGCode(), end="")
G0 X2.000000 Y2.000000
G1 X0.000000 Y2.000000

``Length`` and ``BoundBox`` are exact where FreeCAD 0.20's are not (arcs,
G91; see :mod:`gcodekit.path.measure`); :meth:`Path.freecad_length` and
:meth:`Path.freecad_bound_box` give FreeCAD's own answers.
"""

from __future__ import annotations

from typing import Iterable

from ..errors import Diagnostics
from .command import Command
from .geometry import BoundBox, Vector
from .measure import bound_box, freecad_bound_box, freecad_length, length, walk
from .rules import read_commands, read_strict

__all__ = ["Path"]


def _command(name: str, params: dict[str, float]) -> Command:
    c = Command()
    c._name, c._params = name, params
    return c


class Path:
    """A toolpath: FreeCAD's ``Path.Path`` with gcodekit's measuring and pictures behind it.

    Parameters
    ----------
    commands : list of Command or str, default: empty
        The commands, or G-code text in FreeCAD's format (one line or
        many); see :mod:`gcodekit.path.rules` for how it is read.

    Raises
    ------
    FreeCADFormatError
        Text FreeCAD cannot read, with its line and column (FreeCAD 0.20
        aborts the process); use :func:`gcodekit.path.read` for programs
        in a controller's dialect.
    TypeError
        Anything else than a list of commands or a string, as FreeCAD's.
    """

    def __init__(self, commands: "Iterable[Command] | str | None" = None):
        self._commands: list[Command] = []
        self.diagnostics = Diagnostics("<path>")  # what reading found (from_gcode, read); empty here
        self.Center = Vector()
        if isinstance(commands, str):
            self.setFromGCode(commands)
        elif commands is not None:
            if not isinstance(commands, (list, tuple)):
                raise TypeError("Argument must be a list of commands or a gcode string")
            self.Commands = commands

    @classmethod
    def from_gcode(cls, text: str, *, mode: str = "lenient", file: str = "<string>",
                   freecad_compatible: bool = False) -> "Path":
        """A path read from FreeCAD-format text, problems in ``path.diagnostics`` rather than raised.

        Lenient mode skips a command FreeCAD cannot read (one it would abort
        on) with an error diagnostic, and warns where FreeCAD's reading
        differs from what a controller would do (words dropped after a
        comment, an argument given twice).  ``freecad_compatible=True``
        reads exactly as FreeCAD 0.20 does, its mistakes included (see
        :func:`gcodekit.path.rules.read_commands`).

        Examples
        --------
        >>> p = Path.from_gcode("G1 X1 Y\\nG1 X2 ; done\\n", file="a.nc")
        >>> p.Commands
        [Command G1 [ X:2 ], Command (done) [ ]]
        >>> print(p.diagnostics.items[0])
        a.nc:1:7: error: Badly formatted GCode argument: 'Y' has no number (FreeCAD 0.20 aborts here): 'G1 X1 Y'
        """
        path = cls()
        path.diagnostics = Diagnostics(file, mode)
        if mode == "strict":  # FreeCAD's error type, with the first problem's place
            commands = read_strict(text, file, freecad=freecad_compatible)
        else:
            commands = read_commands(text, path.diagnostics, freecad=freecad_compatible)
        path._commands = [_command(n, p) for n, p, _ in commands]
        return path

    # -- FreeCAD's attributes ------------------------------------------------------------

    @property
    def Commands(self) -> list[Command]:  # noqa: N802
        """Copies of the commands (as FreeCAD: edit the path with its methods, or assign a list)."""
        return [c.copy() for c in self._commands]

    @Commands.setter
    def Commands(self, commands: Iterable[Command]) -> None:  # noqa: N802
        commands = list(commands)
        if not all(isinstance(c, Command) for c in commands):
            raise TypeError("The list must contain only Path Commands")
        self._commands = [c.copy() for c in commands]

    @property
    def Size(self) -> int:  # noqa: N802
        """The number of commands."""
        return len(self._commands)

    @property
    def Length(self) -> float:  # noqa: N802
        """The length of every motion, mm, measured exactly (arcs, helices, G91, drilling cycles)."""
        return length(self._pairs())

    @property
    def BoundBox(self) -> BoundBox:  # noqa: N802
        """The box around every point the tool passes, mm, exact for arcs."""
        return bound_box(self._pairs())

    def freecad_length(self) -> float:
        """``Length`` as FreeCAD 0.20 computes it (wrong for arcs; see :mod:`gcodekit.path.measure`)."""
        return freecad_length(self._pairs())

    def freecad_bound_box(self) -> BoundBox:
        """``BoundBox`` as FreeCAD 0.20 computes it (arcs sampled)."""
        return freecad_bound_box(self._pairs())

    # -- FreeCAD's methods ----------------------------------------------------------------

    def addCommands(self, commands: "Command | Iterable[Command]") -> "Path":  # noqa: N802
        """Append a command or a list of commands; returns the path."""
        items = [commands] if isinstance(commands, Command) else list(commands)
        if not all(isinstance(c, Command) for c in items):
            raise TypeError("Wrong parameters - command or list of commands expected")
        self._commands.extend(c.copy() for c in items)
        return self

    def insertCommand(self, command: Command, position: int = -1) -> "Path":  # noqa: N802
        """Insert a command before ``position`` (-1 or the size: at the end); returns the path.

        Raises
        ------
        IndexError
            ``Index not in range`` for a position beyond the end or below -1
            (FreeCAD 0.20 crashes on positions below -1).
        """
        if not isinstance(command, Command):
            raise TypeError("Wrong parameters - expected a command and an optional integer")
        position = int(position)
        if position == -1:
            position = len(self._commands)
        if not 0 <= position <= len(self._commands):
            raise IndexError("Index not in range")
        self._commands.insert(position, command.copy())
        return self

    def deleteCommand(self, position: int = -1) -> "Path":  # noqa: N802
        """Delete the command at ``position`` (default: the last); returns the path.

        Raises
        ------
        IndexError
            ``Index not in range`` for a position that holds no command
            (FreeCAD 0.20 frees memory twice for the size itself and for
            positions below -1, and crashes).
        """
        if isinstance(position, bool) or not isinstance(position, int):
            raise TypeError("Wrong parameters - expected an integer (optional)")
        if position == -1 and self._commands:
            position = len(self._commands) - 1
        if not 0 <= position < len(self._commands):
            raise IndexError("Index not in range")
        del self._commands[position]
        return self

    def setFromGCode(self, text: str) -> None:  # noqa: N802
        """Replace the commands by those read from ``text`` (FreeCAD's rules; errors raised)."""
        self._commands = [_command(n, p) for n, p, _ in read_strict(text)]

    def toGCode(self) -> str:  # noqa: N802
        """Every command's ``toGCode()``, each followed by a newline."""
        return "".join(c.toGCode() + "\n" for c in self._commands)

    def copy(self) -> "Path":
        out = Path()
        out._commands = [c.copy() for c in self._commands]
        out.Center = Vector(*self.Center)
        return out

    # -- beyond FreeCAD --------------------------------------------------------------------

    def segments(self):
        """The path's motions as :class:`~gcodekit.path.measure.Segment` objects."""
        return walk(self._pairs())

    def _pairs(self) -> list[tuple[str, dict[str, float]]]:
        return [(c._name, c._params) for c in self._commands]

    def __iter__(self):
        return iter(self.Commands)

    def __len__(self) -> int:
        return len(self._commands)

    def __repr__(self) -> str:
        return f"Path [ size:{len(self._commands)} length:{self.Length:.5g} ]"
