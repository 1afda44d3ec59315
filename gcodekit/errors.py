"""Diagnostics shared by every stage: typed errors that name file:line:col.

Every problem found in a program becomes a :class:`Diagnostic`.  In lenient
mode (the default for reading and reporting) the stage records it and goes
on; in strict mode the same diagnostic is raised as a :class:`GcodeError`
subclass, so callers can catch gcodekit's errors without catching bugs.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from typing import Iterable, Literal

Severity = Literal["error", "warning", "info"]
Mode = Literal["lenient", "strict"]
MODES: tuple[str, ...] = ("lenient", "strict")


@dataclass(frozen=True, slots=True)
class Diagnostic:
    """One problem in a program, located by 1-based line and column."""

    file: str
    line: int
    column: int
    severity: Severity
    message: str
    text: str = ""

    def __str__(self) -> str:
        quoted = f": {self.text.strip()!r}" if self.text.strip() else ""
        return f"{self.file}:{self.line}:{self.column}: {self.severity}: {self.message}{quoted}"

    def as_dict(self) -> dict:
        return {
            "line": self.line,
            "column": self.column,
            "severity": self.severity,
            "message": self.message,
            "text": self.text.strip(),
        }


class GcodeError(Exception):
    """Base of every error gcodekit raises about a program or a setting."""

    def __init__(self, message: str, diagnostic: Diagnostic | None = None):
        super().__init__(str(diagnostic) if diagnostic is not None else message)
        self.diagnostic = diagnostic


class GcodeSyntaxError(GcodeError, ValueError):
    """The text cannot be read as words of the flavor."""


class GcodeExpressionError(GcodeError, ValueError):
    """An expression or parameter reference cannot be evaluated."""


class GcodeLimitError(GcodeError, RuntimeError):
    """A loop, recursion or size limit was reached."""


class GcodeMachineError(GcodeError, ValueError):
    """The machine cannot carry out a command (bad arc, missing word, ...)."""


class ProgramFileError(GcodeError, OSError):
    """The program file cannot be read as text (a damaged archive, binary data)."""


class ConfigError(GcodeError, ValueError):
    """A flavor, machine preset or option is invalid."""


class NothingToShowError(GcodeError, ValueError):
    """The program has nothing an output needs (no moves to draw, no deposition to export)."""


class MissingDependencyError(GcodeError, ImportError):
    """An optional feature's library is not installed; the message says which extra to install."""


_ERROR_TYPES: dict[str, type[GcodeError]] = {
    "syntax": GcodeSyntaxError,
    "expression": GcodeExpressionError,
    "limit": GcodeLimitError,
    "machine": GcodeMachineError,
    "file": ProgramFileError,
}


#: How many of a program's first lines :attr:`Diagnostics.unreadable_lines` follows
HEAD_LINES = 10_000


class Diagnostics:
    """Collects diagnostics for one program; raises in strict mode.

    Parameters
    ----------
    file : str
        Name used in every message.
    mode : {"lenient", "strict"}, default: "lenient"
    limit : int, default: 10000
        Lenient mode keeps at most this many diagnostics (then counts the rest),
        so a binary file cannot make the list unbounded.
    repeats : int, default: 20
        One message (same severity and words) is listed this many times; the
        rest are counted into one summary diagnostic at the first unlisted
        line, so one kind of unreadable text (a dialect's comments read as
        words) says so once rather than thousands of times.
    """

    def __init__(self, file: str = "<string>", mode: str = "lenient", limit: int = 10_000, repeats: int = 20):
        self.file = file
        self.mode = check_choice("mode", mode, MODES)
        self.limit = limit
        self.repeats = repeats
        self.items: list[Diagnostic] = []
        # of each item: which GcodeError it raises as (_ERROR_TYPES), or for an info what it notes
        # ("unknown_code": a code the flavor gives no meaning)
        self._kinds: list[str] = []
        self.dropped = 0  # not listed: beyond the limit, or repeats counted in a summary
        self._seen: dict[tuple[str, str], int] = {}  # (severity, message) -> times reported
        self._summary_at: dict[tuple[str, str], int] = {}  # -> index of its summary in items
        #: Line numbers standing for lines of other files (subroutine files): number -> (file, line)
        self.elsewhere: dict[int, tuple[str, int]] = {}
        self._first_error: tuple[str, Diagnostic] | None = None  # (kind, diagnostic), for raise_first
        #: The lines among the program's first :data:`HEAD_LINES` with an error in reading them (syntax or an
        #: expression), listed or not
        self.unreadable_lines: set[int] = set()

    def report(
        self,
        line: int,
        column: int,
        message: str,
        text: str = "",
        *,
        severity: Severity = "error",
        kind: str = "syntax",
        file: str | None = None,
    ) -> Diagnostic:
        """Record a diagnostic; in strict mode an error is raised instead.

        ``file`` defaults to the program's; a line number of :attr:`elsewhere`
        names its own file and line.
        """
        line = int(line)
        if file is None:
            file, line = self.elsewhere.get(line, (self.file, line))
        diag = Diagnostic(file, line, int(column), severity, message, text)
        if self.mode == "strict" and severity == "error":
            raise _ERROR_TYPES[kind](message, diag)
        if severity == "error" and self._first_error is None:
            self._first_error = (kind, diag)
        if severity == "error" and kind in ("syntax", "expression") and file == self.file and line <= HEAD_LINES:
            self.unreadable_lines.add(line)
        key = (severity, message)
        seen = self._seen[key] = self._seen.get(key, 0) + 1
        if seen > self.repeats:
            self._summarise(key, diag, kind, seen - self.repeats)
            return diag
        if len(self.items) < self.limit:
            self.items.append(diag)
            self._kinds.append(kind)
        else:
            self.dropped += 1
        return diag

    def _summarise(self, key: tuple[str, str], diag: Diagnostic, kind: str, more: int) -> None:
        """Count a repeat of a listed message into its one summary diagnostic (made at the first repeat)."""
        self.dropped += 1
        at = self._summary_at.get(key)
        if at is None:
            if len(self.items) >= self.limit:
                return
            self._summary_at[key] = at = len(self.items)
            self.items.append(diag)
            self._kinds.append(kind)
        first = self.items[at]
        self.items[at] = Diagnostic(first.file, first.line, first.column, first.severity,
                                    f"{key[1]} -- and {more} more times from this line on, not listed", first.text)

    def report_first(self, line: int, column: int, message: str, text: str = "", *,
                     severity: Literal["warning", "info"] = "warning") -> Diagnostic:
        """Record a diagnostic ahead of those recorded so far, past :attr:`limit` too: a note that explains
        them (the dialect a program looks written in) is read before them."""
        diag = Diagnostic(self.file, int(line), int(column), severity, message, text)
        self.items.insert(0, diag)
        self._kinds.insert(0, "syntax")
        self._summary_at = {key: at + 1 for key, at in self._summary_at.items()}
        return diag

    def warn(self, line: int, column: int, message: str, text: str = "") -> Diagnostic:
        return self.report(line, column, message, text, severity="warning")

    def extend(self, diagnostics: Iterable[Diagnostic]) -> None:
        for d in diagnostics:
            self.report(d.line, d.column, d.message, d.text, severity=d.severity, file=d.file)

    @property
    def has_error(self) -> bool:
        """Whether an error has been recorded (cheap: for checks on every line)."""
        return self._first_error is not None

    def raise_first(self) -> None:
        """Raise the first error recorded (as strict mode would have), if any."""
        if self._first_error is not None:
            kind, diag = self._first_error
            raise _ERROR_TYPES[kind](diag.message, diag)

    def raise_item(self, k: int) -> None:
        """Raise diagnostic ``k`` of :attr:`items` as the error it was reported as."""
        raise _ERROR_TYPES[self._kinds[k]](self.items[k].message, self.items[k])

    @property
    def limit_errors(self) -> list[Diagnostic]:
        """The errors of a limit reached (``max_motions``, ``max_iterations``, ...): the run stopped short
        of the program's end, or planned part of it coarser (see :mod:`gcodekit.limits`)."""
        return [d for d, kind in zip(self.items, self._kinds) if kind == "limit" and d.severity == "error"]

    @property
    def unknown_codes(self) -> list[Diagnostic]:
        """The infos on codes the flavor gives no meaning, one per code (infos, since firmware add codes
        freely; a program in another dialect makes them too)."""
        return [d for d, kind in zip(self.items, self._kinds) if kind == "unknown_code"]

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.items if d.severity == "error"]

    def __len__(self) -> int:
        return len(self.items)

    def __iter__(self):
        return iter(self.items)


def did_you_mean(word: str, options: Iterable[str]) -> str:
    """A ' (did you mean X?)' suffix, or '' when nothing is close."""
    close = difflib.get_close_matches(word, list(options), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_choice(name: str, value: str, options: Iterable[str]) -> str:
    """Validate a string option, listing the choices when it is wrong."""
    options = tuple(options)
    if value not in options:
        raise ConfigError(
            f"{name}={value!r} is not one of {', '.join(map(repr, options))}"
            + did_you_mean(str(value), options)
        )
    return value
