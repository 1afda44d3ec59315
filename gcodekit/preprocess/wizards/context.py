"""What a wizard function is given (:class:`WizardContext`), may raise and may emit."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Iterable, Mapping

from ...errors import GcodeError
from ...units import MM_PER_INCH

#: Most lines one wizard call may emit; more is taken as a runaway.
MAX_LINES = 1_000_000
#: Defaults of the stage's ``settings``; lengths in mm, feeds in mm/min.
DEFAULT_SETTINGS: Mapping[str, float] = {
    "tool_diameter": 6.35,  # a 1/4 in end mill, GER's inch-first habit
    "feed": 500.0,
    "plunge_feed": 200.0,
    "safe_z": 5.0,
    "stepover": 0.4,  # fraction of the tool diameter
}


class WizardArgumentError(GcodeError, ValueError):
    """Raised by a wizard function about one of its arguments.

    The stage reports it at that argument's column as a
    :class:`~gcodekit.errors.GcodeExpressionError`.

    Parameters
    ----------
    message : str
    index : int, default: None
        0-based position of the argument; None points at the wizard's name.
    """

    def __init__(self, message: str, index: int | None = None):
        super().__init__(message)
        self.index = index


@dataclass(frozen=True)
class WizardContext:
    """What a wizard knows about the program where it is called.

    Attributes
    ----------
    units : {"mm", "inch"}
        The program's units at the call; arguments and output use them.
    tool_diameter : float or None
        Diameter of the current tool in ``units``, when known (the
        settings' ``tools[T]`` for the tool of the last ``M6 Tn``, else
        ``tool_diameter``).
    settings : dict
        The stage's settings, shared by every call of one run (a wizard may
        keep values in it); lengths in mm, feeds in mm/min.
    distance : {"absolute", "incremental"}
        G90 or G91 at the call.
    file : str
    line : int
        Where the call is.
    """

    units: str = "mm"
    tool_diameter: float | None = None
    settings: dict = field(default_factory=dict)
    distance: str = "absolute"
    file: str = "<string>"
    line: int = 0

    def length(self, mm: float) -> float:
        """``mm`` millimetres in the program's units."""
        return mm if self.units == "mm" else mm / MM_PER_INCH

    def setting(self, key: str) -> float:
        """A length or feed setting in the program's units (default: :data:`DEFAULT_SETTINGS`)."""
        value = self.settings.get(key, DEFAULT_SETTINGS[key])
        return float(value) if key == "stepover" else self.length(float(value))


WizardFunction = Callable[..., Iterable[str]]
