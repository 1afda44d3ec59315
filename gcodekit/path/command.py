"""Front end (FreeCAD Path API): ``Command``, one G-code command of a path.

A command is a name (``G1``, ``M3``, or a whole ``(comment)``) and a
dictionary of capital letters to numbers, FreeCAD's ``Path.Command``:

>>> c = Command("G1", {"x": 34, "y": 1.2})
>>> c
Command G1 [ X:34 Y:1.2 ]
>>> c.toGCode()
'G1 X34.000000 Y1.200000'
>>> c.setFromGCode("G1X1Y0"); c
Command G1 [ X:1 Y:0 ]
>>> c.x = 10; c.Placement
Placement [Pos=(10,0,0), Yaw-Pitch-Roll=(0,0,0)]
"""

from __future__ import annotations

import math
from numbers import Real

from .geometry import Placement, Rotation, Vector
from .rules import command_gcode, parse_command

__all__ = ["Command"]


def _key(key: object) -> str:
    if not isinstance(key, str):
        raise TypeError("The dictionary can only contain string keys")
    return key.upper()


def _number(key: str, value: object) -> float:
    if not isinstance(value, Real):
        raise TypeError("The dictionary can only contain number values")
    value = float(value)
    if not math.isfinite(value):  # FreeCAD stores it and writes -922337203685.477581
        raise ValueError(f"parameter {key.upper()} must be a finite number, not {value}")
    return value


class Command:
    """One command: ``Name`` and ``Parameters``, read and written as FreeCAD 0.20 does.

    Parameters
    ----------
    name : str, default: ""
        A command name (``"G1"``, any case) or a whole command's text
        (``"G1 X1 Y2"``, ``"g1x1"``), read by FreeCAD's rules.
    parameters : dict or Placement, default: none
        Letter -> number (keys in either case, stored in capitals), or a
        placement whose non-zero position and angles become X Y Z A B C.

    Raises
    ------
    FreeCADFormatError
        A text FreeCAD cannot read (``"G1 X1 Y"``): a ValueError, as FreeCAD's.
    TypeError
        Parameters that are not string -> number, as FreeCAD's.
    """

    __slots__ = ("_name", "_params")

    def __init__(self, name: str = "", parameters: "dict[str, float] | Placement | None" = None):
        if not isinstance(name, str):
            raise TypeError(f"argument 1 must be str, not {type(name).__name__}")
        self._name = ""
        self._params: dict[str, float] = {}
        if name:
            self.setFromGCode(name)
        if isinstance(parameters, Placement):
            given = self._name
            self.Placement = parameters
            self._name = given or self._name
        elif parameters is not None:
            if not isinstance(parameters, dict):
                raise TypeError(f"argument 2 must be a dictionary or a Placement, not {type(parameters).__name__}")
            self.Parameters = {**self._params, **parameters}

    # -- FreeCAD's attributes ------------------------------------------------------------

    @property
    def Name(self) -> str:  # noqa: N802
        """The command's name: ``G1``, ``M3``, ``(a comment)``; set in any case, kept in capitals."""
        return self._name

    @Name.setter
    def Name(self, value: str) -> None:  # noqa: N802
        self._name = value if value.startswith("(") else value.upper()

    @property
    def Parameters(self) -> dict[str, float]:  # noqa: N802
        """A copy of the parameters: letter -> number (as FreeCAD, changing the copy changes nothing)."""
        return dict(self._params)

    @Parameters.setter
    def Parameters(self, value: dict[str, float]) -> None:  # noqa: N802
        self._params = {_key(k): _number(k, v) for k, v in value.items()}

    @property
    def Placement(self) -> Placement:  # noqa: N802
        """The end point (X Y Z, 0 where absent) and the A B C angles as a placement."""
        p = self._params
        return Placement(Vector(p.get("X", 0.0), p.get("Y", 0.0), p.get("Z", 0.0)),
                         Rotation(p.get("A", 0.0), p.get("B", 0.0), p.get("C", 0.0)))

    @Placement.setter
    def Placement(self, placement: Placement) -> None:  # noqa: N802
        # FreeCAD: the command becomes a G1 move with only the non-zero coordinates
        values = dict(zip("XYZ", placement.Base))
        values.update(zip("ABC", placement.Rotation.getYawPitchRoll()))
        self._name = "G1"
        self._params = {k: float(v) for k, v in values.items() if v != 0.0}

    def __getattr__(self, key: str) -> float | None:
        """``c.x``, ``c.F``: a parameter's value, or None when the command has none."""
        if len(key) == 1 and key.isalpha():
            return self._params.get(key.upper())
        raise AttributeError(f"'Command' object has no attribute {key!r}")

    def __setattr__(self, key: str, value) -> None:
        if len(key) == 1 and key.isalpha():
            self._params[key.upper()] = _number(key, value)
        else:
            object.__setattr__(self, key, value)

    # -- FreeCAD's methods ----------------------------------------------------------------

    def toGCode(self) -> str:  # noqa: N802
        """The command as FreeCAD writes it: ``G1 X1.000000 Y2.000000`` (N words left out)."""
        return command_gcode(self._name, self._params)

    def setFromGCode(self, text: str) -> None:  # noqa: N802
        """Replace name and parameters by those read from ``text`` (FreeCAD's rules)."""
        self._name, self._params = parse_command(text)

    def transform(self, placement: Placement) -> "Command":
        """A copy moved by ``placement`` as FreeCAD does: ``own placement * placement``.

        Only coordinates the command has are replaced (I, J, K and F stay).
        """
        moved = self.Placement.multiply(placement)
        values = dict(zip("XYZ", moved.Base))
        values.update(zip("ABC", moved.Rotation.getYawPitchRoll()))
        out = Command(self._name)
        out._params = {k: (values[k] if k in values else v) for k, v in self._params.items()}
        return out

    # -- Python ---------------------------------------------------------------------------

    def __repr__(self) -> str:
        words = " ".join(f"{k}:{v:.5g}" for k, v in sorted(self._params.items()))
        return f"Command {self._name} [ {words} ]" if words else f"Command {self._name} [ ]"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Command) and (self._name, self._params) == (other._name, other._params)

    __hash__ = None  # mutable, like FreeCAD's

    def copy(self) -> "Command":
        out = Command()
        out._name, out._params = self._name, dict(self._params)
        return out
