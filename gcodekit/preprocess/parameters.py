"""Preprocess stage: RS274NGC parameters, substituted line by line.

:class:`ParameterStore` holds numbered (``#1`` .. ``#5601``) and named
(``#<name>``) parameters.  :class:`ParameterStage` replaces every parameter
reference and expression that is the value of a word by its number and
removes parameter assignments, so later stages see plain words:
``G1 X[#1+2]`` becomes ``G1 X3``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import operator
import re
from decimal import Decimal
from typing import TYPE_CHECKING, Callable, Iterable, Iterator, Protocol, Sequence

from ..errors import Diagnostics, GcodeError, GcodeExpressionError, GcodeLimitError
from .expressions import (
    CompactText,
    NamedParameter,
    Node,
    Parameter,
    compact,
    evaluate,
    expression_error,
    parameter_index,
    parse_value,
)

if TYPE_CHECKING:
    from .lines import SourceLine
    from ..syntax.flavor import Flavor

#: Highest parameter number.  LinuxCNC's ``RS274NGC_MAX_PARAMETERS`` is 5602
#: and it accepts numbers below it, 1 .. 5601.
MAX_PARAMETER = 5601
#: Numbered parameters local to an ``O- call``: #1 .. #30 (LinuxCNC
#: ``INTERP_SUB_PARAMS``).
CALL_PARAMETERS = 30

#: ``system(key)`` gives a read-only system parameter (``5420``, ``"_x"``)
#: or None when ``key`` is not one.
SystemParameters = Callable[[int | str], float | None]


class MachineView(Protocol):
    """The machine behind a store's system parameters, as a loop sees it (the pipeline's feedback)."""

    runs: int  # times the machine ran the lines held for it

    def fingerprint(self) -> bytes:
        """Run the held lines, then every machine state a later line can read or depend on, as bytes."""


class SystemWrites(Protocol):
    """System parameters a program may write (LinuxCNC's ``#5221``, a stored work offset)."""

    def writable(self, key: int | str) -> bool:
        """Whether ``key`` is one."""

    def write(self, key: int | str, value: float) -> None:
        """Store ``value`` where the machine keeps ``key``."""

O_WORD_MESSAGE = "O-word control flow is not supported yet (issue #4)"

# An O-word is the first word of its line, after block delete and N
# (LinuxCNC ``read_items``); a '(' or ';' ends the match, so commented
# O-words are not seen.
#: LinuxCNC's ``(abort, message)`` comment: the program stops with an error showing the message
_ABORT = re.compile(r"\(\s*abort\s*,([^)]*)\)", re.IGNORECASE)
#: Parameters a comment message shows (``#42``, ``#<name>``), as LinuxCNC fills them in
_SHOWN_PARAMETER = re.compile(r"#(\d+|<[^>]*>)")
_O_WORD = re.compile(r"[ \t]*(?:/[ \t]*)?(?:[nN][0-9. \t]*)?([oO])")
#: ``O1234`` alone (a comment may follow) names a Fanuc-style program: no flow.
_PROGRAM_NUMBER = re.compile(r"[ \t]*[oO](?:[0-9]+|<[^>]*>)[ \t]*(\(.*\))?[ \t]*$")
_SPACE = " \t\r\n\v\f"

# (start, end, replacement) in the line's text, in order; and (key, value).
_Edits = list[tuple[int, int, str]]
_Assignments = list[tuple[int | str, float]]
# A line's values, parsed once: (start, end, value node, assignment target
# or None, column of the assignment).
_Plan = list[tuple[int, int, Node, "Node | None", int]]
#: Lines whose parsed values a stage keeps, so loops do not parse again.
PLAN_CACHE_SIZE = 4096


def needs_parameters(text: str) -> bool:
    """Whether ``text`` may hold a parameter or expression (a fast pre-check)."""
    return "#" in text or "[" in text


def format_number(value: float) -> str:
    """Plain decimal text that reads back as exactly ``value``.

    Examples
    --------
    >>> format_number(2.0), format_number(0.1 + 0.2), format_number(1e-7)
    ('2', '0.30000000000000004', '0.0000001')
    """
    # repr() is the shortest text that round-trips; Decimal writes it out
    # without an exponent, which G-code cannot read.
    text = format(Decimal(repr(value)), "f")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


class ParameterStore:
    """Numbered and named parameters of one program run.

    Numbered parameters ``1`` .. :data:`MAX_PARAMETER` start at 0.0.  Named
    parameters are case-insensitive and ignore spaces; names starting with
    ``_`` are global, the others local to the running subroutine call (or
    the main program): see :meth:`enter_call`.

    Parameters
    ----------
    system : callable, default: None
        ``system(key)`` returns the value of a system parameter or None; see
        :data:`SystemParameters`.  A later machine stage supplies it (current
        position ``#5420``, ...).  System parameters are read-only unless
        ``system_writes`` takes them (:class:`SystemWrites`).

    Examples
    --------
    >>> store = ParameterStore()
    >>> store.set("My Depth", 2.5)
    >>> store.get("mydepth"), store.get(1), store.exists("_other")
    (2.5, 0.0, False)
    """

    def __init__(self, *, system: SystemParameters | None = None, system_writes: SystemWrites | None = None):
        self._numbered = [0.0] * (MAX_PARAMETER + 1)
        self._globals: dict[str, float] = {}
        self._locals: dict[str, float] = {}
        self._system = system
        self._system_writes = system_writes
        # One (caller's named locals, caller's #1..#30 or None) per open call.
        self._calls: list[tuple[dict[str, float], list[float] | None]] = []

    def get(self, key: int | str) -> float:
        """Value of ``#key`` (int) or ``#<key>`` (str).

        Raises
        ------
        GcodeExpressionError
            A number outside 1 .. 5601, or a name never set.
        """
        key = _normalize(key)
        value = self._system(key) if self._system is not None else None
        if value is not None:
            return float(value)
        if isinstance(key, int):
            _check_number(key)
            return self._numbered[key]
        scope = self._scope(key)
        if key not in scope:
            raise GcodeExpressionError(f"named parameter #<{key}> is not defined")
        return scope[key]

    def set(self, key: int | str, value: float) -> None:
        """Set ``#key`` or ``#<key>``.

        Raises
        ------
        GcodeExpressionError
            A number outside 1 .. 5601, or a system parameter.
        """
        key = _normalize(key)
        if isinstance(key, int):
            _check_number(key)
        if self._system_writes is not None and self._system_writes.writable(key):
            self._system_writes.write(key, float(value))
            return
        if self.read_only(key):
            raise GcodeExpressionError(f"parameter {_show(key)} is read-only")
        if isinstance(key, int):
            self._numbered[key] = float(value)
        else:
            self._scope(key)[key] = float(value)

    def exists(self, key: int | str) -> bool:
        """``EXISTS``: a number in range, or a name that has a value."""
        key = _normalize(key)
        if isinstance(key, int):
            return 1 <= key <= MAX_PARAMETER
        return self.read_only(key) or key in self._scope(key)

    def read_only(self, key: int | str) -> bool:
        """Whether ``key`` is a system parameter :meth:`set` refuses."""
        key = _normalize(key)
        if self._system_writes is not None and self._system_writes.writable(key):
            return False
        return self._system is not None and self._system(key) is not None

    @contextlib.contextmanager
    def overlay(self, system: SystemParameters):
        """Read-only parameters given by ``system`` first while the block lasts (a lathe
        cycle reading its profile sees the profile's point as ``#<_x>``)."""
        saved = self._system

        def combined(key: int | str) -> float | None:
            value = system(key)
            return value if value is not None or saved is None else saved(key)

        self._system = combined
        try:
            yield
        finally:
            self._system = saved

    def enter_call(self, args: Sequence[float] | None = None) -> None:
        """Open the scope of a subroutine call, as LinuxCNC ``execute_call``.

        Named locals start empty.  With ``args`` (an ``O- call``), #1 ..
        #:data:`CALL_PARAMETERS` are saved, #1 .. #len(args) take the
        arguments and the rest keep the caller's values; with None (a Fanuc
        ``M98`` call) the numbered parameters stay shared.
        """
        if args is not None and len(args) > CALL_PARAMETERS:
            raise GcodeExpressionError(f"a call takes at most {CALL_PARAMETERS} arguments, not {len(args)}")
        saved = None if args is None else self._numbered[1 : CALL_PARAMETERS + 1]
        self._calls.append((self._locals, saved))
        self._locals = {}
        for number, value in enumerate(args or (), 1):
            self._numbered[number] = float(value)

    def leave_call(self) -> None:
        """Close the innermost call scope: restore the caller's locals and #1 .. #30."""
        self._locals, saved = self._calls.pop()
        if saved is not None:
            self._numbered[1 : CALL_PARAMETERS + 1] = saved

    def snapshot(self) -> tuple:
        """Every value the store holds, comparable with ``==`` (a loop that changed nothing, see
        :class:`~.flow.run.Run`): numbered, global and local parameters and the callers' saved ones."""
        return (tuple(self._numbered), tuple(sorted(self._globals.items())), tuple(sorted(self._locals.items())),
                tuple((tuple(sorted(names.items())), None if saved is None else tuple(saved))
                      for names, saved in self._calls))

    @property
    def call_depth(self) -> int:
        """Number of open subroutine calls (0 in the main program)."""
        return len(self._calls)

    def _scope(self, name: str) -> dict[str, float]:
        return self._globals if name.startswith("_") else self._locals


def _normalize(key: int | str) -> int | str:
    if isinstance(key, str):
        name = compact(key).chars
        if not name:
            raise GcodeExpressionError("a named parameter needs a name")
        return name
    return operator.index(key)


def _check_number(key: int) -> None:
    if not 1 <= key <= MAX_PARAMETER:
        raise GcodeExpressionError(f"parameter number {key} is outside 1 .. {MAX_PARAMETER}")


def _show(key: int | str) -> str:
    return f"#{key}" if isinstance(key, int) else f"#<{key}>"


class ParameterStage:
    """Substitute parameters and expressions, line by line (RS274NGC).

    Every value of a word written as a parameter, an expression or a
    function (``X#1``, ``Y#<y>``, ``Z[#1*2]``, ``A-#2``, ``B SIN[30]``) is
    replaced by its number, formatted by :func:`format_number`.  Parameter
    assignments (``#1 = 5``, ``#<d> = [#1*2]``) are removed and take effect
    after the whole line was read, so every read on a line sees the values
    from before it, as in LinuxCNC.  A line holding only assignments
    becomes empty; lines are never added or dropped.  Comments are left as
    written.

    Errors go to ``diagnostics`` with kind ``"expression"`` or ``"limit"``;
    in lenient mode the line becomes empty and its assignments are
    skipped.  O-word lines (``o100 sub``) are reported as not supported yet
    and emptied.  A flavor without ``parameters`` passes lines through.

    Parameters
    ----------
    flavor : Flavor
        Gives the comment syntax (``line_comments``, ``paren_comments``).
    store : ParameterStore, default: a new, empty store

    Examples
    --------
    >>> from gcodekit.errors import Diagnostics
    >>> from gcodekit.preprocess import SourceLine
    >>> from gcodekit.syntax.flavor import Flavor
    >>> stage = ParameterStage(Flavor("ngc", paren_comments=True, parameters=True))
    >>> program = ["#1 = 2", "#1 = 3 G1 X[#1 + 0.5] (X#1)"]
    >>> lines = [SourceLine(t, n, "demo.ngc") for n, t in enumerate(program, 1)]
    >>> [s.text for s in stage.process(lines, Diagnostics("demo.ngc"))]
    ['', 'G1 X2.5 (X#1)']
    """

    name = "parameters"

    def __init__(self, flavor: Flavor, store: ParameterStore | None = None):
        self.flavor = flavor
        self.store = ParameterStore() if store is None else store
        starts = [re.escape(c) for c in flavor.line_comments if c]
        if flavor.paren_comments:
            starts.append(r"\(")
        self._comment = re.compile("|".join(starts)) if starts else None
        self._plans: dict[str, _Plan] = {}

    def process(self, lines: Iterable[SourceLine], diagnostics: Diagnostics) -> Iterator[SourceLine]:
        """Yield each line with its parameters substituted."""
        if not self.flavor.parameters:
            yield from lines
            return
        for line in lines:
            yield self._line(line, diagnostics)

    def _line(self, line: SourceLine, diagnostics: Diagnostics) -> SourceLine:
        text = line.text
        number = _PROGRAM_NUMBER.match(text)
        if number:
            return dataclasses.replace(line, text=number.group(1) or "")
        o_word = _O_WORD.match(text)
        if o_word:
            diagnostics.report(line.line, o_word.start(1) + 1, O_WORD_MESSAGE, text, kind="syntax", file=line.file)
            return dataclasses.replace(line, text="")
        return self.substitute(line, diagnostics)

    def substitute(self, line: SourceLine, diagnostics: Diagnostics) -> SourceLine:
        """``line`` with its values substituted and its assignments applied.

        For a line that is not an O-word line; the control-flow stage calls
        this for each line it executes.  Errors are reported as by
        :meth:`process` and empty the line.
        """
        text = line.text
        abort = _ABORT.search(text) if "(" in text else None
        if abort is not None:
            diagnostics.report(line.line, abort.start() + 1, f"program aborted: {self._message(abort.group(1))}",
                               text, kind="machine", file=line.file)
        if not needs_parameters(text):
            return line
        try:
            new = self._substitute(text)
        except GcodeError as exc:
            kind = "limit" if isinstance(exc, GcodeLimitError) else "expression"
            where = exc.diagnostic  # every error raised here is located
            diagnostics.report(line.line, where.column, where.message, text, kind=kind, file=line.file)
            return dataclasses.replace(line, text="")
        return line if new == text else dataclasses.replace(line, text=new)

    def _message(self, text: str) -> str:
        """A comment message with its parameters' values (6 decimals, as LinuxCNC prints them)."""
        def value(match: re.Match) -> str:
            key = match.group(1)
            key = int(key) if key.isdigit() else key[1:-1]
            try:
                return f"{self.store.get(key):f}"
            except GcodeError:
                return match.group(0)  # unknown here (an INI value, say): left as written

        return _SHOWN_PARAMETER.sub(value, text).strip()

    def _substitute(self, text: str) -> str:
        plan = self._plans.get(text)
        if plan is None:
            plan = []
            for start, end in self.code_ranges(text):
                self._scan(compact(text, start, end), text, plan)
            if len(self._plans) < PLAN_CACHE_SIZE:
                self._plans[text] = plan
        edits: _Edits = []
        assignments: _Assignments = []
        for start, end, node, target, column in plan:
            if target is None:
                edits.append((start, end, format_number(evaluate(node, self.store))))
                continue
            key = self._key(target)
            if self.store.read_only(key):
                raise expression_error(f"parameter {_show(key)} is read-only", column)
            assignments.append((key, evaluate(node, self.store)))
            edits.append((start, end, ""))
        # RS274NGC sets parameters in parallel: only now that every value on
        # the line has been read.
        for key, value in assignments:
            self.store.set(key, value)
        if not edits:
            return text
        pieces, done = [], 0
        for start, end, new in edits:
            pieces += [text[done:start], new]
            done = end
        result = "".join(pieces) + text[done:]
        if assignments and not text[-1:].isspace():
            # Only a removed assignment at the end can leave trailing space.
            result = result.rstrip(_SPACE)
        return "" if result.strip(_SPACE) == "" else result

    def code_ranges(self, text: str) -> list[tuple[int, int]]:
        """``(start, end)`` of the parts of ``text`` outside comments."""
        ranges, pos = [], 0
        while self._comment is not None:
            found = self._comment.search(text, pos)
            if found is None:
                break
            ranges.append((pos, found.start()))
            close = text.find(")", found.end()) if found.group() == "(" else -1
            if close < 0:
                return ranges
            pos = close + 1
        ranges.append((pos, len(text)))
        return ranges

    def _scan(self, code: CompactText, text: str, plan: _Plan) -> None:
        """Find the values to replace and the assignments in one code range."""
        s, i = code.chars, 0
        while i < len(s):
            c = s[i]
            if c == "#":
                i = self._assignment(code, i, text, plan)
            elif c == "[":
                message = "an expression must be the value of a word, as in X[...]"
                raise expression_error(message, code.column(i))
            elif "a" <= c <= "z" or (c in "@^" and self.flavor.polar_words):  # @ ^: polar words
                run = i + 1
                while run < len(s) and "a" <= s[run] <= "z":
                    run += 1
                if not _has_value(s, i, run):
                    i = run
                    continue
                start = i + 1
                node, i = parse_value(code, start)
                plan.append((code.column(start), code.column(i - 1) + 1, node, None, 0))
            else:
                i += 1

    def _assignment(self, code: CompactText, pos: int, text: str, plan: _Plan) -> int:
        """Read ``#target = value`` at ``pos``; return the position after it."""
        s = code.chars
        target, eq = parse_value(code, pos)
        if not s.startswith("=", eq):
            raise expression_error("'=' expected: a parameter here must be assigned", code.column(eq))
        node, end = parse_value(code, eq + 1)
        stop = code.column(end - 1) + 1
        while stop < len(text) and text[stop] in _SPACE:
            stop += 1
        plan.append((code.column(pos), stop, node, target, code.column(pos)))
        return end

    def _key(self, target: Node) -> int | str:
        if isinstance(target, NamedParameter):
            return target.name
        assert isinstance(target, Parameter)
        key = parameter_index(evaluate(target.index, self.store), target.column)
        if not 1 <= key <= MAX_PARAMETER:
            message = f"parameter number {key} is outside 1 .. {MAX_PARAMETER}"
            raise expression_error(message, target.column)
        return key


def _has_value(s: str, i: int, run: int) -> bool:
    """Whether the word whose letter is ``s[i]`` has a value to evaluate.

    ``run`` ends the letters starting at ``i``.  Mirrors LinuxCNC
    ``read_real_value``: ``#``, ``[``, a sign not followed by a digit, or a
    function name (letters then ``[``).
    """
    if run > i + 1:
        return s.startswith("[", run)
    after = s[i + 1 : i + 3]
    if after[:1] in ("#", "["):
        return True
    return after[:1] in ("+", "-") and len(after) == 2 and after[1] not in "0123456789."
