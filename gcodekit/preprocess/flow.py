"""Preprocess stage: O-word control flow, executed line by line (RS274NGC, Fanuc).

:class:`ControlFlowStage` runs a program's control flow the way LinuxCNC 2.9's
``interp_o_word.cc`` does and emits the lines it executes, in order, with
their parameters substituted by a :class:`~gcodekit.preprocess.ParameterStage`
sharing one :class:`~gcodekit.preprocess.ParameterStore`.  Every emitted line
keeps the file and line number it was written on, so a loop body run three
times yields three lines pointing at the same source line.

The program is read whole, its O-words are parsed and matched once
(``if`` to ``elseif``/``else``/``endif``, ``while`` to ``endwhile``, ``do``
to its closing ``while``, ``repeat`` to ``endrepeat``, ``sub`` to
``endsub``), then executed with a program counter:

* ``oN sub`` .. ``oN endsub [value]`` define a subroutine, skipped where it
  stands; ``oN call [a] [b] ...`` runs it with the arguments in #1 .. #30
  (the rest keep the caller's values; all 30 are restored on return) and
  fresh local named parameters (``#<name>``; ``#<_name>`` is global).
  ``oN return [value]`` or ``endsub [value]`` sets ``#<_value>`` and
  ``#<_value_returned>`` = 1; both are cleared just before each call.
  ``#<_call_level>`` is how deep the calls are nested (0 in the main program).
  Labels are numbers or ``<names>``; a call's label may be computed
  (``o[#101+2] call``).  A subroutine not in the program is read from
  ``name.ngc`` in the program's directory or the stage's ``search_path``.
* ``if`` / ``elseif`` / ``else`` / ``endif``; ``while`` / ``endwhile``;
  ``do`` / ``while``; ``repeat [n]`` / ``endrepeat``; ``break`` and
  ``continue`` name the loop they leave or restart.  A condition is true
  when not 0.
* Fanuc-style numbered programs: ``O1000`` alone on a line starts program
  1000, ``M98 P1000 [L3]`` runs it (L times; L0 not at all) with #1 .. #30
  shared and ``M99`` returns.  M99 in the main program, which LinuxCNC
  takes as an endless restart, ends it here (with a warning).
* ``M2`` or ``M30`` ends the program: nothing after it is emitted.

Limits (:class:`~gcodekit.errors.GcodeLimitError`, which ends the run even
in lenient mode): loop iterations, call depth and executed lines.  Mistakes
in the structure (an ``endwhile`` without ``while``, an unknown
subroutine, ...) are reported with their file, line and column; in lenient
mode the faulty O-word is ignored and the run goes on.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Iterable, Iterator, Sequence

from gcodekit.errors import Diagnostics, GcodeError, GcodeLimitError, did_you_mean
from gcodekit.limits import MAX_ITERATIONS, MAX_MOTIONS
from gcodekit.preprocess.expressions import Node, compact, evaluate, expression_error, parse_value
from gcodekit.parse.table import PROFILE_TAG
from gcodekit.preprocess.parameters import ParameterStage, ParameterStore, format_number

if TYPE_CHECKING:
    from gcodekit.preprocess import SourceLine
    from gcodekit.syntax.flavor import Flavor

#: Deepest nesting of subroutine calls.  LinuxCNC has
#: ``INTERP_SUB_ROUTINE_LEVELS`` = 10 call frames, frame 0 being the main
#: program, and refuses the call that would open frame 10.
MAX_CALL_DEPTH = 9
#: Most lines (O-words included) executed in one run; bounds the work of
#: calls that fan out without looping.
MAX_LINES = 5_000_000

# Longest first, so 'elseif' is not read as 'else'.
KEYWORDS = ("endrepeat", "continue", "endwhile", "elseif", "endsub", "repeat", "return",
            "endif", "break", "while", "call", "else", "sub", "do", "if")
_KEYWORD = re.compile("|".join(KEYWORDS))
# An O-word is the first word of its line, after block delete and N
# (LinuxCNC ``read_items``).
_O_WORD = re.compile(r"[ \t]*(?:/[ \t]*)?(?:[nN][0-9. \t]*)?[oO]")
_LABEL_NUMBER = re.compile(r"[0-9]+")
_WORD = re.compile(r"([a-z])([-+]?[0-9.]*)")
# Cheap test for a line that may hold M2, M30, M98 or M99.
_MAYBE_FLOW_M = re.compile(r"[mM][ \t0]*(?:2|3[ \t]*0|9[ \t]*[89])")
# Cheap test for a line that may hold a lathe cycle G70-G72
_MAYBE_LATHE_CYCLE = re.compile(r"[gG][ \t0]*7[ \t]*[012]")
_LATHE_CYCLES = frozenset((70.0, 71.0, 71.1, 71.2, 72.0, 72.1, 72.2))
# LinuxCNC subroutine file names: lower-case letters, digits, '-' and '_'.
_FILE_NAME = re.compile(r"[a-z0-9_-]+")
# A called name that reaches for a path: refused, so a program cannot read files elsewhere.
_PATH_PARTS = re.compile(r"[/\\]|\.\.")
_CONDITIONS = ("if", "elseif", "while", "repeat")
_CLOSERS = {"endsub": "sub", "endif": "if", "endwhile": "while", "endrepeat": "repeat"}


@dataclass(slots=True, eq=False)
class OWord:
    """One O-word line, parsed; the links are filled in by matching.

    Attributes
    ----------
    keyword : str
        ``"sub"``, ``"call"``, ``"if"``, ...; ``""`` for a Fanuc program
        number (``O1000``).
    label : str or None
        ``"100"`` or ``"<name>"``; None when computed (``label_node``).
    args : tuple of Node
        Call arguments, or the condition / count / return value.
    start, end, next : int
        Indices in the same file: the opening O-word of a closing or middle
        one; the closing O-word of an opening one; an ``if``'s or
        ``elseif``'s next branch.  -1 when none.
    """

    line: SourceLine
    column: int
    keyword: str
    label: str | None
    label_node: Node | None = None
    args: tuple[Node, ...] = ()
    bad: bool = False
    valid: bool = True
    start: int = -1
    end: int = -1
    next: int = -1

    @property
    def name(self) -> str:
        """``o100 while`` or ``o<name> call``, for messages."""
        label = "[...]" if self.label is None else self.label
        return f"o{label} {self.keyword}".rstrip()


@dataclass(slots=True)
class _Code:
    """The statements of one file: SourceLine or OWord."""

    file: str
    items: list


@dataclass(slots=True)
class _Frame:
    """A suspended caller, and what the call needs to repeat (M98 L)."""

    code: _Code
    pc: int
    counters: dict[int, int]
    fanuc: bool
    start: tuple[_Code, int] | None = None
    left: int = 0


class _Stop(Exception):
    """Ends the run: a program end, or a limit."""


class ControlFlowStage:
    """Execute O-word control flow and substitute parameters (LinuxCNC 2.9).

    Emits the lines the program executes, in execution order, with
    parameters and expressions substituted and assignments applied as
    :class:`~gcodekit.preprocess.ParameterStage` does (every read on a line
    sees the values from before its assignments).  O-word lines, ``M98``
    and ``M99`` words and lines left empty are not emitted; a line keeps
    the file and line number it was written on.  See the module docstring
    for the statements, :data:`MAX_CALL_DEPTH` and :data:`MAX_LINES`, and
    :mod:`gcodekit.limits` for ``max_iterations`` (every loop iteration and
    M98 repeat counts; a repeat count larger than what is left is refused
    before the first repeat) and ``max_motions`` (the blocks emitted).  A
    flavor without ``parameters`` passes lines through.

    Parameters
    ----------
    flavor : Flavor
    store : ParameterStore, default: a new, empty store
    search_path : sequence of path, default: ()
        Directories searched, after the program's own, for ``name.ngc``
        when ``o<name> call`` names a subroutine the program lacks.
    fanuc_subs : bool, default: True
        Fanuc-style subprograms run (M98/M99); False refuses them, as
        rs274 does under ``[RS274NGC] DISABLE_FANUC_STYLE_SUB``.
    max_iterations, max_call_depth, max_lines, max_motions : int
        Limits; default :data:`~gcodekit.limits.MAX_ITERATIONS`,
        :data:`MAX_CALL_DEPTH`, :data:`MAX_LINES`,
        :data:`~gcodekit.limits.MAX_MOTIONS`.

    Examples
    --------
    >>> from gcodekit.errors import Diagnostics
    >>> from gcodekit.preprocess import SourceLine
    >>> from gcodekit.syntax.flavor import Flavor
    >>> stage = ControlFlowStage(Flavor("ngc", paren_comments=True, parameters=True))
    >>> program = ["#1 = 0", "o1 while [#1 LT 3]", "G1 X[#1 * 2]", "#1 = [#1 + 1]", "o1 endwhile"]
    >>> lines = [SourceLine(t, n, "demo.ngc") for n, t in enumerate(program, 1)]
    >>> [(s.line, s.text) for s in stage.process(lines, Diagnostics("demo.ngc"))]
    [(3, 'G1 X0'), (3, 'G1 X2'), (3, 'G1 X4')]
    """

    name = "control_flow"

    def __init__(self, flavor: Flavor, store: ParameterStore | None = None, *,
                 search_path: Sequence[str | os.PathLike] = (), fanuc_subs: bool = True,
                 max_iterations: int = MAX_ITERATIONS, max_call_depth: int = MAX_CALL_DEPTH,
                 max_lines: int = MAX_LINES, max_motions: int = MAX_MOTIONS):
        self.flavor = flavor
        self.parameters = ParameterStage(flavor, store)
        self.store = self.parameters.store
        self.search_path = [Path(p) for p in search_path]
        self.fanuc_subs = fanuc_subs
        self.max_iterations = max_iterations
        self.max_call_depth = max_call_depth
        self.max_lines = max_lines
        self.max_motions = max_motions

    def process(self, lines: Iterable[SourceLine], diagnostics: Diagnostics) -> Iterator[SourceLine]:
        """Yield the executed lines, substituted, in execution order."""
        if not self.flavor.parameters:
            yield from lines
            return
        yield from _Run(self, diagnostics).run(list(lines))


class _Run:
    """The state of one execution of :class:`ControlFlowStage`."""

    def __init__(self, stage: ControlFlowStage, diagnostics: Diagnostics):
        self.stage = stage
        self.diagnostics = diagnostics
        self.store = stage.store
        self.separators = "".join(stage.flavor.statement_separators)
        self.subs: dict[str, tuple[_Code, int]] = {}
        self.programs: dict[str, tuple[_Code, int]] = {}
        self.loaded: set[str] = set()
        self.directories: list[Path] = []
        self.iterations = 0
        self.executed = 0
        self.emitted = 0  # blocks passed on, against max_motions
        self.frames: list[_Frame] = []
        self.code = _Code("", [])
        self.pc = 0
        self.counters: dict[int, int] = {}
        # rs274 2.9: after a ``break`` out of a ``while`` loop, the next ``while`` that closes a
        # ``do`` does not loop back (the do's body runs once), wherever that do is
        self.broke_while = False

    # -- running -------------------------------------------------------------

    def run(self, lines: list[SourceLine]) -> Iterator[SourceLine]:
        file = lines[0].file if lines else self.diagnostics.file
        if os.path.isfile(file):
            self.directories.append(Path(file).resolve().parent)
        self.directories += self.stage.search_path
        for name in ("_value", "_value_returned", "_call_level"):
            if not self.store.exists(name):
                self._set(name, 0.0)
        self.code = self._link(_Code(file, [self._statement(s) for s in lines]), main=True)
        try:
            while True:
                items = self.code.items
                if self.pc >= len(items):
                    if not self.frames:
                        self._file_ended(lines)
                        return
                    self._return()  # a sub without endsub: reported when matched
                    continue
                self.executed += 1
                if self.executed > self.stage.max_lines:
                    self._limit(items[self.pc], f"more than {self.stage.max_lines} lines executed (the limit)")
                st = items[self.pc]
                if isinstance(st, OWord):
                    self._oword(st)
                else:
                    self.pc += 1
                    for out in self._plain(st):
                        self.emitted += 1
                        if self.emitted > self.stage.max_motions:
                            self._limit(st, f"the program makes more than max_motions={self.stage.max_motions:,} "
                                        "blocks; the rest is not run")
                        yield out
        except _Stop:
            return

    def _file_ended(self, lines: list[SourceLine]) -> None:
        """The main program ran out of lines without M2/M30: LinuxCNC's ``read_text``
        (interp_read.cc) fails on the last line read unless a ``%`` line closed
        the program opened by a ``%`` first line.  Only program files: text given
        as a string is taken as MDI blocks, which need no end."""
        if not (self.stage.flavor.percent_delimiter and lines and os.path.isfile(lines[0].file)):
            return
        marks = [k for k, s in enumerate(lines) if s.text.strip() == "%"]
        opened = bool(marks) and not any(s.text.strip() for s in lines[:marks[0]])
        if opened and len(marks) > 1:
            return
        last = lines[-1]
        message = "File ended with no percent sign" if opened else "File ended with no percent sign or program end"
        self._report(last, 1, message + " (M2 or M30)" * (not opened), kind="machine")

    def _oword(self, st: OWord) -> None:
        if not st.valid:
            self.pc += 1
            return
        k = st.keyword
        items = self.code.items
        if k == "sub":
            self.pc = st.end + 1 if st.end >= 0 else len(items)
        elif k in ("endsub", "return"):
            self._end_call(st)
        elif k == "call":
            self._call(st)
        elif k == "if":
            self._branch(st)
        elif k in ("elseif", "else"):
            # Reached from the branch before it, which ran: leave the if.
            self.pc = st.end + 1 if st.end >= 0 else self.pc + 1
        elif k == "while" and st.start >= 0:  # closes a do
            if self.broke_while:
                self.broke_while = False
                self.pc += 1
            elif self._condition(st):
                self._tick(st)
                self.pc = st.start + 1
            else:
                self.pc += 1
        elif k == "while":
            self.pc = self.pc + 1 if self._condition(st) else _after(st, items)
        elif k == "endwhile":
            self._tick(st)
            self.pc = st.start
        elif k == "repeat":
            count = self._value(st, st.args[0]) if not st.bad else 0.0
            count = 0 if count is None else math.floor(count + 0.5)  # LinuxCNC round_to_int
            self._check_repeats(st, count, f"{st.name} [{count}]")
            if count > 0:
                self.counters[self.pc] = count - 1
                self.pc += 1
            else:
                self.pc = _after(st, items)
        elif k == "endrepeat":
            left = self.counters.get(st.start, 0)
            if left > 0:
                self._tick(st)
                self.counters[st.start] = left - 1
                self.pc = st.start + 1
            else:
                self.counters.pop(st.start, None)
                self.pc += 1
        elif k in ("break", "continue"):
            self._leave_loop(st)
        else:  # do, endif, a Fanuc program number
            self.pc += 1

    def _branch(self, st: OWord) -> None:
        """``if``: run the first branch whose condition holds, else the ``else``."""
        items, j = self.code.items, self.pc
        while True:
            branch = items[j]
            if branch.keyword == "endif" or branch.keyword == "else" or self._condition(branch):
                self.pc = j + 1
                return
            j = branch.next
            if j < 0:
                self.pc = _after(st, items)
                return

    def _leave_loop(self, st: OWord) -> None:
        items = self.code.items
        loop = items[st.start]
        if not loop.valid or loop.end < 0:
            self.pc += 1
            return
        if st.keyword == "break":
            self.counters.pop(st.start, None)
            self.pc = loop.end + 1
            self.broke_while |= loop.keyword == "while"
        elif loop.keyword == "while":
            self._tick(st)
            self.pc = st.start
        else:  # do and repeat: their closing O-word tests and jumps back
            self.pc = loop.end

    def _condition(self, st: OWord) -> bool:
        if st.bad:
            return False
        value = self._value(st, st.args[0])
        return value is not None and value != 0.0

    def _check_repeats(self, st: OWord | SourceLine, count: int, what: str) -> None:
        """Refuse ``count`` repeats up front when they would pass ``max_iterations``."""
        left = self.stage.max_iterations - self.iterations
        if count - 1 > left:
            self._limit(st, f"{what}: {count - 1:,} repeats, more than the {max(left, 0):,} iterations left of "
                        f"max_iterations={self.stage.max_iterations:,}")

    def _tick(self, st: OWord) -> None:
        self.iterations += 1
        if self.iterations > self.stage.max_iterations:
            self._limit(st, f"more than max_iterations={self.stage.max_iterations:,} loop iterations")

    def _limit(self, st: OWord | SourceLine, message: str) -> None:
        line, column = (st.line, st.column) if isinstance(st, OWord) else (st, 1)
        self._report(line, column, message, kind="limit")
        raise _Stop

    # -- calls ---------------------------------------------------------------

    def _call(self, st: OWord) -> None:
        self.pc += 1
        if st.bad:
            return
        label = st.label
        if label is None:
            number = self._value(st, st.label_node)
            if number is None:
                return
            label = format_number(float(math.floor(number + 0.5)))
        args = [self._value(st, node) for node in st.args]
        if any(a is None for a in args):
            return
        target = self._find(label, self.subs, st)
        if target is None:
            return
        # LinuxCNC clears the return value just before each call.
        self._set("_value", 0.0)
        self._set("_value_returned", 0.0)
        self._enter(st, target, args, fanuc=False)

    def _enter(self, st: OWord | SourceLine, target: tuple[_Code, int], args: list | None, *,
               fanuc: bool, repeats: int = 1) -> None:
        if len(self.frames) >= self.stage.max_call_depth:
            self._limit(st, f"subroutine calls nested deeper than {self.stage.max_call_depth} levels (the limit)")
        try:
            self.store.enter_call(args)
        except GcodeError as exc:
            line, column = (st.line, st.column) if isinstance(st, OWord) else (st, 1)
            self._report(line, column, str(exc), kind="expression")
            return
        code, index = target
        start = (code, index + 1)
        self.frames.append(_Frame(self.code, self.pc, self.counters, fanuc, start, repeats - 1))
        self.code, self.pc, self.counters = code, index + 1, {}
        self._set("_call_level", float(len(self.frames)))

    def _end_call(self, st: OWord) -> None:
        if not self.frames:
            self.pc += 1
            return
        if self.frames[-1].fanuc:
            self._report(st.line, st.column, f"{st.name} ends a program called by M98; M99 expected")
        if st.args and not st.bad:
            value = self._value(st, st.args[0])
            if value is not None:
                self._set("_value", value)
                self._set("_value_returned", 1.0)
        self._return()

    def _return(self) -> None:
        frame = self.frames.pop()
        self.store.leave_call()
        self.code, self.pc, self.counters = frame.code, frame.pc, frame.counters
        self._set("_call_level", float(len(self.frames)))

    def _find(self, label: str, table: dict[str, tuple[_Code, int]], st: OWord | SourceLine):
        """The sub (or Fanuc program) ``label``, read from a file if need be."""
        if label not in table:
            name = label.strip("<>")
            if _PATH_PARTS.search(name):
                line, column = (st.line, st.column) if isinstance(st, OWord) else (st, 1)
                self._report(line, column, f"o{label}: a subroutine is called by its name, not a path ('/', '\\' "
                             "and '..' are not allowed); its file is looked up in the program's folder and the "
                             "subroutine path")
                return None
            if _FILE_NAME.fullmatch(name):
                path = self._subroutine_file(name, st)
                if path is not None:
                    self._load(path)
        if label in table:
            return table[label]
        calling = st.line.line if isinstance(st, OWord) else st.line
        other = self.programs if table is self.subs else self.subs
        if label in other:  # defined in the other style: rs274 reports it at the definition
            code, i = other[label]
            item = code.items[i]
            message = (f"Fanuc-style program o{label} must be called with M98, not 'o{label} call'" if table is self.subs
                       else f"'o{label} sub' must be called with 'o{label} call', not M98")
            self._report(item.line if isinstance(item, OWord) else item, 1, f"{message} (called on line {calling})")
            return None
        what = "subroutine" if table is self.subs else "program"
        known = [f"o{k}" for k in table]
        hint = did_you_mean(f"o{label}", known)
        where = ", ".join(str(d) for d in self.directories) or "no search path"
        line, column = (st.line, st.column) if isinstance(st, OWord) else (st, 1)
        called = f"o{label}"
        if self.code.items:
            # rs274 looks for the sub or program down to the end of the file and reports the error there
            last = self.code.items[-1]
            line, column = (last.line if isinstance(last, OWord) else last), 1
            called += f" (called on line {calling})"
        message = f"call of unknown {what} {called}: not in the program nor as {label.strip('<>')}.ngc in {where}{hint}"
        self._report(line, column, message)
        return None

    def _subroutine_file(self, name: str, st: OWord | SourceLine) -> Path | None:
        """``name.ngc`` in the first search directory that has it, not loaded yet; a file that is
        a link out of its directory is not followed (a program may not read files elsewhere)."""
        for directory in self.directories:
            path = directory / f"{name}.ngc"
            if str(path) in self.loaded or not path.is_file():
                continue
            if not path.resolve().is_relative_to(directory.resolve()):
                line, column = (st.line, st.column) if isinstance(st, OWord) else (st, 1)
                self._report(line, column, f"{path} links to a file outside {directory}; not read",
                             severity="warning")
                continue
            return path
        return None

    def _load(self, path: Path) -> None:
        from gcodekit.preprocess import SourceLine

        self.loaded.add(str(path))
        text = path.read_text("utf-8", errors="replace")
        lines = text.split("\n")
        if lines and lines[-1] == "":
            lines.pop()
        items = [self._statement(SourceLine(t.rstrip("\r"), n, str(path))) for n, t in enumerate(lines, 1)]
        self._link(_Code(str(path), items))

    # -- plain lines ---------------------------------------------------------

    def _plain(self, st: SourceLine) -> Iterator[SourceLine]:
        with self._as_file(st.file):
            line = self.stage.parameters.substitute(st, self.diagnostics)
        text = line.text
        if not text.strip(" \t" + self.separators):
            return
        if _MAYBE_LATHE_CYCLE.search(text):
            line = self._with_profile(line)
            text = line.text
        flow = _MAYBE_FLOW_M.search(text) and self._flow_m(text)
        if not flow:
            yield line
            return
        code, spans, p, count = flow
        if code in (2, 30):
            yield line
            if not text.lstrip().startswith("/"):  # a block-deleted end may be skipped
                raise _Stop
            return
        if not self.stage.fanuc_subs:
            self._report(line, 1, f"DISABLE_FANUC_STYLE_SUB set in INI file, but found m{code}")
            return
        rest = _remove(text, spans)
        if rest.strip(" \t" + self.separators):
            yield line.__class__(rest, line.line, line.file)
        if code == 98:
            self._m98(line, p, count)
        else:
            self._m99(line)

    def _with_profile(self, line: SourceLine) -> SourceLine:
        """A lathe cycle (G70-G72) with the blocks of its Q subroutine attached as a comment.

        rs274 reads the subroutine when the cycle runs, without moving: its
        control flow and parameters run as in a call, ``#<_x>`` and ``#<_z>``
        give the profile's point so far (the cycle's X/Z at first).
        """
        words = self._code_words(line.text)
        if not any(letter == "g" and value in _LATHE_CYCLES for letter, value in words) or "q" not in dict(words):
            return line
        given = dict(words)
        label = format_number(float(math.floor(given["q"] + 0.5)))
        target = self._find(label, self.subs, line)
        if target is None:
            return line
        point = {"_x": given.get("x", math.nan), "_z": given.get("z", math.nan)}
        blocks = []
        depth = len(self.frames)
        self._enter(line, target, [], fanuc=False)
        with self.store.overlay(lambda key: point.get(key) if isinstance(key, str) else None):
            while len(self.frames) > depth:
                items = self.code.items
                if self.pc >= len(items):
                    self._return()
                    continue
                st = items[self.pc]
                if isinstance(st, OWord):
                    self._oword(st)
                    continue
                self.pc += 1
                with self._as_file(st.file):
                    text = self.stage.parameters.substitute(st, self.diagnostics).text
                code = dict(self._code_words(text))
                for axis, key, letter in (("x", "_x", "u"), ("z", "_z", "w")):
                    if axis in code:
                        point[key] = code[axis]
                    elif letter in code:
                        point[key] += code[letter]
                code_text = " ".join(text[a:b] for a, b in self.stage.parameters.code_ranges(text)).strip()
                if code_text:
                    blocks.append(code_text.replace(";", " ").replace("(", " ").replace(")", " "))
        return line.__class__(f"{line.text} ({PROFILE_TAG} {'; '.join(blocks)})", line.line, line.file)

    def _code_words(self, text: str) -> list[tuple[str, float]]:
        """(letter, value) of the plain-number words of a line, comments left out."""
        out = []
        for start, end in self.stage.parameters.code_ranges(text):
            for letter, number in _WORD.findall(compact(text, start, end).chars):
                with contextlib.suppress(ValueError):
                    out.append((letter, float(number)))
        return out

    def _flow_m(self, text: str):
        """``(M code, spans of M98/M99/P/L, P, L)`` of a line, or None."""
        found, words = None, {}
        for start, end in self.stage.parameters.code_ranges(text):
            code = compact(text, start, end)
            for match in _WORD.finditer(code.chars):
                letter, number = match.groups()
                try:
                    value = float(number)
                except ValueError:
                    continue
                span = (code.column(match.start()), code.column(match.end() - 1) + 1)
                if letter == "m" and value in (2, 30, 98, 99) and found is None:
                    found = (int(value), span)
                elif letter in "pl":
                    words[letter] = (value, span)
        if found is None:
            return None
        value, span = found
        spans = [span] + ([w[1] for w in words.values()] if value == 98 else [])
        p = words["p"][0] if "p" in words else None
        count = words["l"][0] if "l" in words else 1.0
        return value, spans, p, count

    def _m98(self, line: SourceLine, p: float | None, count: float) -> None:
        if p is None:
            self._report(line, 1, "M98 needs a P word: the program number to call")
            return
        repeats = math.floor(count + 0.5)
        if repeats <= 0:
            return
        self._check_repeats(line, repeats, f"M98 L{repeats}")
        target = self._find(format_number(float(math.floor(p + 0.5))), self.programs, line)
        if target is not None:
            self._enter(line, target, None, fanuc=True, repeats=repeats)

    def _m99(self, line: SourceLine) -> None:
        if not self.frames:
            self._report(line, 1, "M99 in the main program restarts it endlessly on LinuxCNC; "
                         "treated as the program end", severity="warning")
            raise _Stop
        frame = self.frames[-1]
        if not frame.fanuc:
            self._report(line, 1, "M99 ends a subroutine called by 'o- call'; endsub or return expected")
        if frame.left > 0 and frame.start is not None:
            self._tick_line(line)
            frame.left -= 1
            self.store.leave_call()
            self.store.enter_call(None)
            self.code, self.pc = frame.start
            self.counters = {}
            return
        self._return()

    def _tick_line(self, line: SourceLine) -> None:
        self.iterations += 1
        if self.iterations > self.stage.max_iterations:
            self._limit(line, f"more than max_iterations={self.stage.max_iterations:,} loop iterations")

    # -- reading O-words -----------------------------------------------------

    def _statement(self, line: SourceLine) -> SourceLine | OWord:
        """``line`` itself, or its O-word parsed (None-free: errors are reported)."""
        text = line.text
        if "o" not in text and "O" not in text:
            return line
        match = _O_WORD.match(text)
        if not match:
            return line
        o_at = match.end() - 1
        ranges = self.stage.parameters.code_ranges(text)
        if len(ranges) > 1:  # comments between the words (call arguments, say) are blanked, as rs274 skips them
            code = [" "] * len(text)
            for start, stop in ranges:
                code[start:stop] = text[start:stop]
            text = "".join(code)
        end = ranges[-1][1] if ranges else len(text)
        while end > o_at and text[end - 1] in " \t\r" + self.separators:
            end -= 1
        try:
            return self._parse(line, compact(text, o_at, end))
        except GcodeError as exc:
            kind = "limit" if isinstance(exc, GcodeLimitError) else "syntax"
            self._report(line, exc.diagnostic.column, exc.diagnostic.message, kind=kind)
            return OWord(line, o_at + 1, "", "?", valid=False)

    def _parse(self, line: SourceLine, code) -> OWord:
        s, column = code.chars, code.column(0) + 1
        pos, label, label_node = 1, None, None
        if s.startswith("<", pos):
            close = s.find(">", pos)
            if close < 0:
                raise _error("O-word name is not closed by '>'", code.column(pos))
            if close == pos + 1:
                raise _error("O-word has an empty name", code.column(pos))
            label, pos = s[pos : close + 1], close + 1
        elif pos < len(s) and s[pos].isdigit():
            digits = _LABEL_NUMBER.match(s, pos)
            label, pos = str(int(digits.group())), digits.end()
        elif pos < len(s) and s[pos] in "[#":
            label_node, pos = parse_value(code, pos)
        else:
            raise _error("an O-word needs a number or <name>, as in o100 or o<name>", code.column(pos))
        keyword = _KEYWORD.match(s, pos)
        if keyword is None:
            if pos == len(s) and label is not None:
                return OWord(line, column, "", label)  # a program's number or name (O1234, O<name>)
            rest = re.match(r"[a-z]*", s[pos:]).group() or s[pos:pos + 1]
            hint = did_you_mean(rest, KEYWORDS)
            raise _error(f"unknown O-word keyword {rest!r}{hint}", code.column(pos))
        word, pos = keyword.group(), keyword.end()
        if label is None and word != "call":
            raise _error(f"a computed O-word label is only allowed with call, not {word}", code.column(1))
        st = OWord(line, column, word, label, label_node)
        try:
            args = []
            while pos < len(s) and (word == "call" or (word in _CONDITIONS + ("return", "endsub") and not args)):
                node, pos = parse_value(code, pos)
                args.append(node)
            if word in _CONDITIONS and not args:
                raise _error(f"{st.name} needs a value in brackets, as in [#1 LT 3]", code.column(pos))
            if pos < len(s):
                raise _error(f"unexpected text after {st.name}: {s[pos:]!r}", code.column(pos))
        except GcodeError as exc:
            # Keep the O-word for matching; it does nothing when run.
            kind = "limit" if isinstance(exc, GcodeLimitError) else "expression"
            self._report(line, exc.diagnostic.column, exc.diagnostic.message, kind=kind)
            st.bad = True
        st.args = tuple(args)
        return st

    # -- matching ------------------------------------------------------------

    @staticmethod
    def _program_title(items: list) -> int | None:
        """Index of a program-number O-word (``O1``) that opens the file before any code, else None."""
        for i, st in enumerate(items):
            if isinstance(st, OWord):
                return i if st.keyword == "" and st.valid else None
            if st.text.strip() and not st.text.strip().startswith(("(", ";", "%")):
                return None
        return None

    def _link(self, code: _Code, main: bool = False) -> _Code:
        """Match the O-words of one file and register its subs and programs.

        A main program titled with a program number (``O1`` first) must end
        (M2/M30) before its first ``o- sub``, as rs274 requires.
        """
        items = code.items
        stack: list[int] = []
        branches: dict[int, list[int]] = {}
        title = self._program_title(items) if main else None
        for i, st in enumerate(items):
            if title is not None and not isinstance(st, OWord) and (flow := _MAYBE_FLOW_M.search(st.text) and
                                                                   self._flow_m(st.text)) and flow[0] in (2, 30):
                title = None  # the titled main program has ended
            if not isinstance(st, OWord) or not st.valid:
                continue
            k = st.keyword
            if k == "sub" and title is not None and i > title:
                self._report(st.line, st.column, f"{st.name} found in an illegal location: the main program "
                             f"{items[title].name} must end with M2 or M30 before its subroutines")
                title = None
            if k == "sub":
                if stack:
                    self._report(st.line, st.column, f"{st.name} inside {items[stack[-1]].name}: "
                                 "subroutines cannot be nested")
                    st.valid = False
                    continue
                if st.label in self.subs:
                    where = self.subs[st.label]
                    self._report(st.line, st.column, f"{st.name} is already defined at "
                                 f"{where[0].file}:{where[0].items[where[1]].line.line}")
                else:
                    self.subs[st.label] = (code, i)
                stack.append(i)
            elif k == "":
                self.programs.setdefault(st.label, (code, i))
            elif k == "while" and (j := self._open(items, stack, st, ("do",), quiet=True)) is not None:
                self._unwind(items, stack, j, st, branches)
                stack.pop()
                st.start, items[j].end = j, i
            elif k in ("if", "while", "do", "repeat"):
                if k == "if":
                    branches[i] = [i]
                stack.append(i)
            elif k in _CLOSERS:
                j = self._open(items, stack, st, (_CLOSERS[k],))
                if j is None:
                    continue
                self._unwind(items, stack, j, st, branches)
                stack.pop()
                st.start, items[j].end = j, i
                if k == "endif":
                    chain = branches.pop(j) + [i]
                    for a, b in zip(chain, chain[1:]):
                        items[a].next = b
                        items[b].start, items[b].end = j, i
            elif k in ("elseif", "else"):
                j = self._open(items, stack, st, ("if",))
                if j is None:
                    continue
                self._unwind(items, stack, j, st, branches)
                chain = branches[j]
                if items[chain[-1]].keyword == "else":
                    self._report(st.line, st.column, f"{st.name} after {items[chain[-1]].name}")
                    st.valid = False
                else:
                    chain.append(i)
            elif k in ("break", "continue"):  # rs274 2.9 refuses them in a repeat loop, run or not
                j = self._open(items, stack, st, ("while", "do"))
                if j is not None:
                    st.start = j
            elif k == "return":
                # rs274 returns from the enclosing sub whatever the return's own label
                # (LinuxCNC's retval.ngc writes "o1010 return" inside "o1000 sub")
                if not stack or items[stack[0]].keyword != "sub":
                    self._report(st.line, st.column, f"{st.name} is not inside a subroutine")
                    st.valid = False
        for j in reversed(stack):
            self._unclosed(items, j, None, branches)
        return code

    def _open(self, items: list, stack: list[int], st: OWord, kinds: tuple[str, ...], *,
              quiet: bool = False) -> int | None:
        """Index of the innermost open O-word of ``kinds`` with ``st``'s label."""
        for j in reversed(stack):
            opener = items[j]
            if opener.keyword == "sub":
                break
            if opener.keyword in kinds and opener.label == st.label:
                return j
        if not quiet and "sub" in kinds and stack and items[stack[0]].label == st.label:
            return stack[0]
        if not quiet:
            what = " or ".join(kinds)
            self._report(st.line, st.column, f"{st.name} without a matching o{st.label} {what}")
            st.valid = False
        return None

    def _unwind(self, items: list, stack: list[int], j: int, st: OWord, branches: dict) -> None:
        """Close, as errors, what is still open above index ``j`` of the stack."""
        while stack[-1] != j:
            self._unclosed(items, stack.pop(), st, branches)

    def _unclosed(self, items: list, j: int, at: OWord | None, branches: dict) -> None:
        opener = items[j]
        closer = {"sub": "endsub", "if": "endif", "while": "endwhile", "do": "while",
                  "repeat": "endrepeat"}[opener.keyword]
        where = f"before {at.name} on line {at.line.line}" if at else "at the end of the file"
        self._report(opener.line, opener.column, f"{opener.name} is not closed by o{opener.label} {closer} {where}")
        if opener.keyword != "sub":  # an open sub still runs to the end of its file
            opener.valid = False
            for b in branches.pop(j, []):
                items[b].valid = False

    # -- helpers -------------------------------------------------------------

    def _set(self, name: str, value: float) -> None:
        """Set a predefined global unless the machine supplies it."""
        if not self.store.read_only(name):
            self.store.set(name, value)

    def _value(self, st: OWord, node: Node) -> float | None:
        try:
            return evaluate(node, self.store)
        except GcodeError as exc:
            kind = "limit" if isinstance(exc, GcodeLimitError) else "expression"
            self._report(st.line, exc.diagnostic.column, exc.diagnostic.message, kind=kind)
            return None

    def _report(self, line: SourceLine, column: int, message: str, *, kind: str = "syntax",
                severity: str = "error") -> None:
        with self._as_file(line.file):
            self.diagnostics.report(line.line, column, message, line.text, kind=kind, severity=severity, file=line.file)

    @contextlib.contextmanager
    def _as_file(self, file: str):
        """Report under ``file`` (a subroutine file) rather than the program's name."""
        # Diagnostics names one file; lines read from subroutine files must
        # name theirs, so it is swapped for the duration of the report.
        if not file or file == self.diagnostics.file:
            yield
            return
        saved, self.diagnostics.file = self.diagnostics.file, file
        try:
            yield
        finally:
            self.diagnostics.file = saved


def _after(st: OWord, items: list) -> int:
    """Index after ``st``'s closing O-word (the file's end when it has none)."""
    return st.end + 1 if st.end >= 0 else len(items)


def _remove(text: str, spans: list[tuple[int, int]]) -> str:
    for start, end in sorted(spans, reverse=True):
        text = text[:start] + text[end:]
    return text


def _error(message: str, column: int) -> GcodeError:
    """An error at 0-based ``column`` of the line."""
    return expression_error(message, column)
