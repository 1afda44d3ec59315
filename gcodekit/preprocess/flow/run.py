"""One execution of :class:`~.stage.ControlFlowStage`: a program counter over the statements.

The program's O-words are read (:mod:`.statements`) and matched
(:mod:`.linking`) once; then :class:`Run` steps through them, keeping the
call frames, loop counters and limits, and yields the plain lines it
executes with their parameters substituted.  Calls look their targets up in
the :class:`~.library.Library`; M98/M99 are :mod:`.fanuc`'s, the profile a
lathe cycle reads is :mod:`.profile`'s.
"""

from __future__ import annotations

import contextlib
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

from ...errors import Diagnostics, GcodeError, GcodeLimitError
from ..expressions import Node, evaluate
from .fanuc import m98, m99
from .library import Library
from .mcodes import flow_m, remove
from .lathe_profile_capture import with_profile
from .statements import Code, OWord, read_statement, where
from ..parameters import format_number

if TYPE_CHECKING:
    from ..lines import SourceLine
    from .stage import ControlFlowStage


@dataclass(slots=True)
class Frame:
    """A suspended caller, and what the call needs to repeat (M98 L)."""

    code: Code
    pc: int
    counters: dict[int, int]
    fanuc: bool
    start: tuple[Code, int] | None = None
    left: int = 0


class Stop(Exception):
    """Ends the run: a program end, or a limit."""


class Run:
    """The state of one execution of :class:`~.stage.ControlFlowStage`."""

    def __init__(self, stage: ControlFlowStage, diagnostics: Diagnostics):
        self.stage = stage
        self.diagnostics = diagnostics
        self.store = stage.store
        self.code_ranges = stage.parameters.code_ranges
        self.separators = "".join(stage.flavor.statement_separators)
        self.library = Library(self.statement, self._ends_program, self.report)
        self.iterations = 0
        self.executed = 0
        self.emitted = 0  # blocks passed on, against max_motions
        self.frames: list[Frame] = []
        self.code = Code("", [])
        self.pc = 0
        self.counters: dict[int, int] = {}
        # rs274 2.9: after a ``break`` out of a ``while`` loop, the next ``while`` that closes a
        # ``do`` does not loop back (the do's body runs once), wherever that do is
        self.broke_while = False
        # per loop (its code and test), what the last test saw: see _check_endless
        self.loop_states: dict[tuple[int, int], tuple] = {}

    # -- running -------------------------------------------------------------

    def run(self, lines: list[SourceLine]) -> Iterator[SourceLine]:
        """Yield the lines the program executes, substituted, in execution order."""
        file = lines[0].file if lines else self.diagnostics.file
        if os.path.isfile(file):
            self.library.directories.append(Path(file).resolve().parent)
        self.library.directories += self.stage.search_path
        for name in ("_value", "_value_returned", "_call_level"):
            if not self.store.exists(name):
                self.set_global(name, 0.0)
        self.code = self.library.add(Code(file, [self.statement(s) for s in lines]), main=True)
        try:
            while True:
                items = self.code.items
                if self.pc >= len(items):
                    if not self.frames:
                        self._file_ended(lines)
                        return
                    self.leave()  # a sub without endsub: reported when matched
                    continue
                self.executed += 1
                if self.executed > self.stage.max_lines:
                    self.limit(items[self.pc], f"more than {self.stage.max_lines} lines executed (the limit)")
                st = items[self.pc]
                if isinstance(st, OWord):
                    self.oword(st)
                else:
                    self.pc += 1
                    for out in self._plain(st):
                        self.emitted += 1
                        if self.emitted > self.stage.max_motions:
                            self.limit(st, f"the program makes more than max_motions={self.stage.max_motions:,} "
                                       "blocks; the rest is not run")
                        yield out
        except Stop:
            return

    def statement(self, line: SourceLine) -> SourceLine | OWord:
        """``line`` itself, or its O-word parsed (see :func:`~.statements.read_statement`)."""
        return read_statement(line, self.code_ranges, self.separators, self.report)

    def _ends_program(self, text: str) -> bool:
        found = flow_m(text, self.code_ranges)
        return found is not None and found.code in (2, 30)

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
        self.report(last, 1, message + " (M2 or M30)" * (not opened), kind="machine")

    def oword(self, st: OWord) -> None:
        """Run the O-word at the program counter and move the counter on."""
        if not st.valid:
            self.pc += 1
            return
        k = st.keyword
        items = self.code.items
        if k == "sub":
            self.pc = _after(st, items)
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
                self.tick(st)
                self._check_endless(st)
                self.pc = st.start + 1
            else:
                self.pc += 1
        elif k == "while":
            if self._condition(st):
                self._check_endless(st)
                self.pc += 1
            else:
                self.pc = _after(st, items)
        elif k == "endwhile":
            self.tick(st)
            self.pc = st.start
        elif k == "repeat":
            self._repeat(st)
        elif k == "endrepeat":
            left = self.counters.get(st.start, 0)
            if left > 0:
                self.tick(st)
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

    def _repeat(self, st: OWord) -> None:
        count = self.value(st, st.args[0]) if not st.bad else 0.0
        count = 0 if count is None else math.floor(count + 0.5)  # LinuxCNC round_to_int
        self.check_repeats(st, count, f"{st.name} [{count}]")
        if count > 0:
            self.counters[self.pc] = count - 1
            self.pc += 1
        else:
            self.pc = _after(st, self.code.items)

    def _leave_loop(self, st: OWord) -> None:
        """``break`` or ``continue``."""
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
            self.tick(st)
            self.pc = st.start
        else:  # do and repeat: their closing O-word tests and jumps back
            self.pc = loop.end

    def _condition(self, st: OWord) -> bool:
        if st.bad:
            return False
        value = self.value(st, st.args[0])
        return value is not None and value != 0.0

    # -- limits --------------------------------------------------------------

    def _check_endless(self, st: OWord) -> None:
        """Stop a loop, about to run again, whose last iteration changed nothing and read the machine.

        Such an iteration costs a machine run, so an endless loop would take
        minutes to reach ``max_iterations``.  When two tests of the loop in a
        row find the parameters, the run's loops and calls and (after the
        lines held for it have run) the machine the same, the iteration
        between them leaves everything as it found it: every later one
        repeats it, and the loop never ends (a probe loop missing its
        counter's increment).  Iterations that do not read the machine are
        not compared: they are cheap, and ``max_iterations`` stops them.
        """
        machine = self.stage.machine
        if machine is None:
            return
        key = (id(self.code), self.pc)
        before = self.loop_states.get(key)
        if before is None or before[0] == machine.runs:  # the first test, or an iteration without the machine
            self.loop_states[key] = (machine.runs, None, None)
            return
        state = (self.store.snapshot(), self.pc, tuple((id(f.code), f.pc, f.left) for f in self.frames),
                 tuple(sorted(self.counters.items())), self.broke_while)
        seen = machine.fingerprint() if state == before[1] else None
        if seen is not None and seen == before[2]:
            self.limit(st, "this loop never ends: an iteration left every parameter and the machine as the one "
                       "before it did, so the next ones would repeat it (LinuxCNC runs it forever)")
        self.loop_states[key] = (machine.runs, state, seen)

    def check_repeats(self, st: OWord | SourceLine, count: int, what: str) -> None:
        """Refuse ``count`` repeats up front when they would pass ``max_iterations``."""
        left = self.stage.max_iterations - self.iterations
        if count - 1 > left:
            self.limit(st, f"{what}: {count - 1:,} repeats, more than the {max(left, 0):,} iterations left of "
                       f"max_iterations={self.stage.max_iterations:,}")

    def tick(self, st: OWord | SourceLine) -> None:
        """Count one loop iteration (or M98 repeat) against ``max_iterations``."""
        self.iterations += 1
        if self.iterations > self.stage.max_iterations:
            self.limit(st, f"more than max_iterations={self.stage.max_iterations:,} loop iterations")

    def limit(self, st: OWord | SourceLine, message: str) -> None:
        """Report a limit at ``st`` and end the run (raises :class:`Stop`)."""
        line, column = where(st)
        self.report(line, column, message, kind="limit")
        raise Stop

    # -- calls ---------------------------------------------------------------

    def _call(self, st: OWord) -> None:
        self.pc += 1
        if st.bad:
            return
        label = st.label
        if label is None:
            number = self.value(st, st.label_node)
            if number is None:
                return
            label = format_number(float(math.floor(number + 0.5)))
        args = [self.value(st, node) for node in st.args]
        if any(a is None for a in args):
            return
        target = self.library.find(label, self.library.subs, st, self.code)
        if target is None:
            return
        # LinuxCNC clears the return value just before each call.
        self.set_global("_value", 0.0)
        self.set_global("_value_returned", 0.0)
        self.enter(st, target, args, fanuc=False)

    def enter(self, st: OWord | SourceLine, target: tuple[Code, int], args: list | None, *,
              fanuc: bool, repeats: int = 1) -> None:
        """Call ``target`` (a sub or program) with ``args`` (None: share #1 .. #30, as M98 does)."""
        if len(self.frames) >= self.stage.max_call_depth:
            self.limit(st, f"subroutine calls nested deeper than {self.stage.max_call_depth} levels (the limit)")
        try:
            self.store.enter_call(args)
        except GcodeError as exc:
            line, column = where(st)
            self.report(line, column, str(exc), kind="expression")
            return
        code, index = target
        start = (code, index + 1)
        self.frames.append(Frame(self.code, self.pc, self.counters, fanuc, start, repeats - 1))
        self.code, self.pc, self.counters = code, index + 1, {}
        self.set_global("_call_level", float(len(self.frames)))

    def _end_call(self, st: OWord) -> None:
        """``endsub`` or ``return``, with its value."""
        if not self.frames:
            self.pc += 1
            return
        if self.frames[-1].fanuc:
            self.report(st.line, st.column, f"{st.name} ends a program called by M98; M99 expected")
        if st.args and not st.bad:
            value = self.value(st, st.args[0])
            if value is not None:
                self.set_global("_value", value)
                self.set_global("_value_returned", 1.0)
        self.leave()

    def leave(self) -> None:
        """Return to the caller."""
        frame = self.frames.pop()
        self.store.leave_call()
        self.code, self.pc, self.counters = frame.code, frame.pc, frame.counters
        self.set_global("_call_level", float(len(self.frames)))

    # -- plain lines ---------------------------------------------------------

    def _plain(self, st: SourceLine) -> Iterator[SourceLine]:
        line = with_profile(self, self.substitute(st))
        text = line.text
        if not text.strip(" \t" + self.separators):
            return
        flow = flow_m(text, self.code_ranges)
        if not flow:
            yield line
            return
        if flow.code in (2, 30):
            yield line
            if not text.lstrip().startswith("/"):  # a block-deleted end may be skipped
                raise Stop
            return
        if not self.stage.fanuc_subs:
            self.report(line, 1, f"DISABLE_FANUC_STYLE_SUB set in INI file, but found m{flow.code}")
            return
        rest = remove(text, flow.spans)
        if rest.strip(" \t" + self.separators):
            yield replace(line, text=rest)
        if flow.code == 98:
            m98(self, line, flow.p, flow.count)
        elif m99(self, line):
            raise Stop

    def substitute(self, st: SourceLine) -> SourceLine:
        """``st`` with its parameters substituted and its assignments applied."""
        with self._as_file(st.file):
            return self.stage.parameters.substitute(st, self.diagnostics)

    # -- helpers -------------------------------------------------------------

    def set_global(self, name: str, value: float) -> None:
        """Set a predefined global unless the machine supplies it."""
        if not self.store.read_only(name):
            self.store.set(name, value)

    def value(self, st: OWord, node: Node) -> float | None:
        """The value of an O-word's expression; None after reporting an error."""
        try:
            return evaluate(node, self.store)
        except GcodeError as exc:
            kind = "limit" if isinstance(exc, GcodeLimitError) else "expression"
            self.report(st.line, exc.diagnostic.column, exc.diagnostic.message, kind=kind)
            return None

    def report(self, line: SourceLine, column: int, message: str, *, kind: str = "syntax",
               severity: str = "error") -> None:
        """Report at ``line`` of whichever file it was read from."""
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
