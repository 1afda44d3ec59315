"""The subroutines and Fanuc programs one run knows, and the files they are read from.

``o<name> call`` and ``M98 P1000`` look their target up here.  A
subroutine the program lacks is read from ``name.ngc`` in the program's
directory or the stage's search path (then matched like the program itself);
a name that reaches for a path, or a file that links out of its directory,
is refused, so a program cannot read files elsewhere.  A target not found is
reported the way rs274 reports it.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Callable

from ...errors import did_you_mean
from .linking import Table, link
from .statements import Code, OWord, Report, where
from ..lines import SourceLine

# LinuxCNC subroutine file names: lower-case letters, digits, '-' and '_'.
_FILE_NAME = re.compile(r"[a-z0-9_-]+")
# A called name that reaches for a path: refused, so a program cannot read files elsewhere.
_PATH_PARTS = re.compile(r"[/\\]|\.\.")


class Library:
    """Subroutines (``subs``) and Fanuc programs (``programs``) by label, and where to look for more.

    Parameters
    ----------
    statement : callable
        Reads one line into a statement (:func:`~.statements.read_statement`).
    ends_program : callable
        Whether a plain line's text ends the program (M2/M30).
    report : callable
        ``report(line, column, message, severity=...)``.
    """

    def __init__(self, statement: Callable[[SourceLine], SourceLine | OWord], ends_program: Callable[[str], bool],
                 report: Report):
        self.statement = statement
        self.ends_program = ends_program
        self.report = report
        self.subs: Table = {}
        self.programs: Table = {}
        self.loaded: set[str] = set()
        self.directories: list[Path] = []

    def add(self, code: Code, *, main: bool = False) -> Code:
        """Match the O-words of one file and register its subs and programs; returns ``code``."""
        return link(code, self.subs, self.programs, self.report, self.ends_program, main=main)

    def find(self, label: str, table: Table, st: OWord | SourceLine, running: Code) -> tuple[Code, int] | None:
        """The sub (``table`` is ``subs``) or Fanuc program ``label``, read from a file if need be.

        ``st`` is the call, ``running`` the file it runs in (rs274 reports a
        target not found at that file's end).
        """
        if label not in table:
            name = label.strip("<>")
            if _PATH_PARTS.search(name):
                line, column = where(st)
                self.report(line, column, f"o{label}: a subroutine is called by its name, not a path ('/', '\\' "
                            "and '..' are not allowed); its file is looked up in the program's folder and the "
                            "subroutine path")
                return None
            if _FILE_NAME.fullmatch(name):
                path = self._subroutine_file(name, st)
                if path is not None:
                    self._load(path)
        if label in table:
            return table[label]
        self._not_found(label, table, st, running)
        return None

    def _not_found(self, label: str, table: Table, st: OWord | SourceLine, running: Code) -> None:
        calling = st.line.line if isinstance(st, OWord) else st.line
        other = self.programs if table is self.subs else self.subs
        if label in other:  # defined in the other style: rs274 reports it at the definition
            code, i = other[label]
            item = code.items[i]
            message = (f"Fanuc-style program o{label} must be called with M98, not 'o{label} call'" if table is self.subs
                       else f"'o{label} sub' must be called with 'o{label} call', not M98")
            self.report(item.line if isinstance(item, OWord) else item, 1, f"{message} (called on line {calling})")
            return
        what = "subroutine" if table is self.subs else "program"
        known = [f"o{k}" for k in table]
        hint = did_you_mean(f"o{label}", known)
        places = ", ".join(str(d) for d in self.directories) or "no search path"
        line, column = where(st)
        called = f"o{label}"
        if running.items:
            # rs274 looks for the sub or program down to the end of the file and reports the error there
            last = running.items[-1]
            line, column = (last.line if isinstance(last, OWord) else last), 1
            called += f" (called on line {calling})"
        message = f"call of unknown {what} {called}: not in the program nor as {label.strip('<>')}.ngc in {places}{hint}"
        self.report(line, column, message)

    def _subroutine_file(self, name: str, st: OWord | SourceLine) -> Path | None:
        """``name.ngc`` in the first search directory that has it, not loaded yet; a file that is
        a link out of its directory is not followed (a program may not read files elsewhere)."""
        for directory in self.directories:
            path = directory / f"{name}.ngc"
            if str(path) in self.loaded or not path.is_file():
                continue
            if not path.resolve().is_relative_to(directory.resolve()):
                line, column = where(st)
                self.report(line, column, f"{path} links to a file outside {directory}; not read",
                            severity="warning")
                continue
            return path
        return None

    def _load(self, path: Path) -> None:
        self.loaded.add(str(path))
        text = path.read_text("utf-8", errors="replace")
        lines = text.split("\n")
        if lines and lines[-1] == "":
            lines.pop()
        items = [self.statement(SourceLine(t.rstrip("\r"), n, str(path))) for n, t in enumerate(lines, 1)]
        self.add(Code(str(path), items))
