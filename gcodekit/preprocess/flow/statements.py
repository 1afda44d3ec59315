"""O-word lines read into :class:`OWord` statements (LinuxCNC ``read_o_word``).

A program file becomes a :class:`Code`: its lines in order, each either the
plain :class:`~gcodekit.preprocess.SourceLine` or, when the line starts with
an O-word, the parsed :class:`OWord`.  Matching the O-words with each other
is :mod:`.linking`'s job; running them is :mod:`.run`'s.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

from ...errors import GcodeError, GcodeLimitError, did_you_mean
from ..expressions import CompactText, Node, compact, expression_error, parse_value

if TYPE_CHECKING:
    from ..lines import SourceLine

# Longest first, so 'elseif' is not read as 'else'.
KEYWORDS = ("endrepeat", "continue", "endwhile", "elseif", "endsub", "repeat", "return",
            "endif", "break", "while", "call", "else", "sub", "do", "if")
_KEYWORD = re.compile("|".join(KEYWORDS))
# An O-word is the first word of its line, after block delete and N
# (LinuxCNC ``read_items``).
_O_WORD = re.compile(r"[ \t]*(?:/[ \t]*)?(?:[nN][0-9. \t]*)?[oO]")
_LABEL_NUMBER = re.compile(r"[0-9]+")
#: O-words that take a value: a condition or a repeat count
CONDITIONS = ("if", "elseif", "while", "repeat")

#: ``report(line, column, message, kind=...)``: where statement errors go
Report = Callable[..., None]


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
class Code:
    """The statements of one file: SourceLine or OWord."""

    file: str
    items: list


def where(st: OWord | SourceLine) -> tuple[SourceLine, int]:
    """The line and 1-based column a message about ``st`` points at."""
    return (st.line, st.column) if isinstance(st, OWord) else (st, 1)


def read_statement(line: SourceLine, code_ranges: Callable[[str], list[tuple[int, int]]], separators: str,
                   report: Report) -> SourceLine | OWord:
    """``line`` itself, or its O-word parsed (errors are reported, never raised).

    ``code_ranges`` gives the parts of a text outside comments; ``separators``
    are the flavor's statement separators, ignored at the end of the line.
    """
    text = line.text
    if "o" not in text and "O" not in text:
        return line
    match = _O_WORD.match(text)
    if not match:
        return line
    o_at = match.end() - 1
    ranges = code_ranges(text)
    if len(ranges) > 1:  # comments between the words (call arguments, say) are blanked, as rs274 skips them
        code = [" "] * len(text)
        for start, stop in ranges:
            code[start:stop] = text[start:stop]
        text = "".join(code)
    end = ranges[-1][1] if ranges else len(text)
    while end > o_at and text[end - 1] in " \t\r" + separators:
        end -= 1
    try:
        return _parse(line, compact(text, o_at, end), report)
    except GcodeError as exc:
        kind = "limit" if isinstance(exc, GcodeLimitError) else "syntax"
        report(line, exc.diagnostic.column, exc.diagnostic.message, kind=kind)
        return OWord(line, o_at + 1, "", "?", valid=False)


def _parse(line: SourceLine, code: CompactText, report: Report) -> OWord:
    """The O-word of ``code`` (the line from its ``o``, compacted)."""
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
        while pos < len(s) and (word == "call" or (word in CONDITIONS + ("return", "endsub") and not args)):
            node, pos = parse_value(code, pos)
            args.append(node)
        if word in CONDITIONS and not args:
            raise _error(f"{st.name} needs a value in brackets, as in [#1 LT 3]", code.column(pos))
        if pos < len(s):
            raise _error(f"unexpected text after {st.name}: {s[pos:]!r}", code.column(pos))
    except GcodeError as exc:
        # Keep the O-word for matching; it does nothing when run.
        kind = "limit" if isinstance(exc, GcodeLimitError) else "expression"
        report(line, exc.diagnostic.column, exc.diagnostic.message, kind=kind)
        st.bad = True
    st.args = tuple(args)
    return st


def _error(message: str, column: int) -> GcodeError:
    """An error at 0-based ``column`` of the line."""
    return expression_error(message, column)
