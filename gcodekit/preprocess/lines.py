"""What every preprocess step takes and gives: :class:`SourceLine` and the :class:`Stage` protocol."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Iterator, Protocol, runtime_checkable

from ..errors import Diagnostics
from ..lathe_profile import LatheProfile


@dataclass(frozen=True, slots=True)
class SourceLine:
    """One line of program text and where it came from.

    Attributes
    ----------
    text : str
        The line without its line ending.
    line : int
        1-based line number in ``file``.
    file : str
    profile : LatheProfile or None
        On a lathe cycle (G70-G72) that ran: the profile its ``Q``
        subroutine gave (see :mod:`gcodekit.lathe_profile`).
    """

    text: str
    line: int
    file: str
    profile: LatheProfile | None = field(default=None, repr=False)


@runtime_checkable
class Stage(Protocol):
    """A preprocess step: a named map from lines to lines.

    ``process`` reports problems to ``diagnostics`` (which raises in strict
    mode) and, in lenient mode, goes on with the next line.
    """

    name: str

    def process(self, lines: Iterable[SourceLine], diagnostics: Diagnostics) -> Iterator[SourceLine]: ...
