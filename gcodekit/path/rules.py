"""Front end (FreeCAD Path API): FreeCAD 0.20's rules for reading and writing its G-code.

FreeCAD keeps a path as *commands*: a name that starts with G or M (or a
whole ``(comment)``) and a dictionary of letter -> number.  These are the
rules of FreeCAD 0.20.2's ``Path.Command`` and ``Path.Path`` as measured by
running it (``tests/golden/freecad/regenerate.py``):

* A program is cut into commands before every ``G``/``M`` letter and around
  every ``(...)`` comment; words after a command's name are its arguments,
  even on the next lines, and a repeated argument keeps its last value.
  Words before the first command and between a comment and the next command
  are dropped; ``N`` words are kept as parameters but never written.
* Letters are read in either case and stored in capitals; a number is the
  run of digits, ``-`` and ``.`` after its letter, read like C's ``atof``
  (``X1.2.3`` is 1.2, ``X--1`` is 0); ``X1e5`` is X1 and E5.
* ``G20`` and ``G21`` are not kept: after ``G20`` the lengths are scaled by
  25.4.
* ``toGCode()`` writes the name, then the arguments in alphabetical order
  except ``N``, each with six decimals rounded half away from zero.

Where FreeCAD 0.20 is plainly wrong gcodekit answers right (each case is in
``docs/freecad.md``): a letter without a number, a ``;`` comment followed by
text and a LinuxCNC ``#<name>`` abort FreeCAD's whole process and are a
:class:`FreeCADFormatError` naming line and column here; characters FreeCAD
skips inside a number (``X#1``, ``X[1+2]``, ``X1*57``) are an error rather
than a wrong number; ``;`` starts a comment to the end of the line; after
``G20`` the arc's ``K`` is scaled like ``I`` and ``J`` (FreeCAD forgets it);
numbers beyond 9e8 mm are written as they are (FreeCAD's double arithmetic
writes 922337203685 as ``922337203684.999987`` and overflows a 64-bit
integer from 922337203686, writing ``-922337203685.477581``).

Examples
--------
>>> parse_command("g1x1 y-2.5")
('G1', {'X': 1.0, 'Y': -2.5})
>>> command_gcode("G1", {"Y": 2.0, "X": 1.0, "N": 10.0})
'G1 X1.000000 Y2.000000'
"""

from __future__ import annotations

import bisect
import math
import re
from dataclasses import dataclass
from decimal import Decimal

from ..errors import Diagnostics, GcodeSyntaxError

__all__ = ["FreeCADFormatError", "format_value", "freecad_format_value", "command_gcode", "parse_command",
           "read_commands", "read_strict", "INCH_LETTERS"]

#: Letters scaled by 25.4 after G20.  FreeCAD 0.20 scales F I J Q R X Y Z and forgets K.
INCH_LETTERS = frozenset("FIJKQRXYZ")
FREECAD_INCH_LETTERS = frozenset("FIJQRXYZ")

_NUMBER_CHARS = frozenset("0123456789-.")
_LETTERS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz")
_ATOF = re.compile(r"-?(?:\d+\.?\d*|\.\d+)")
_CUT = re.compile(r"[(gGmM]")
_ALLOWED_IN_COMMAND = re.compile(r"(?:[A-Za-z]\s*\+|[A-Za-z0-9.\-\s%])*")  # a '+' sign only after a letter
_INT64 = 1 << 63
#: Below this FreeCAD's ``value * 1e7`` is exact to the unit it rounds; above, gcodekit writes the decimal
#: value itself (FreeCAD writes 922337203685 as 922337203684.999987, and overflows from 922337203686)
_EXACT_BELOW = 2.0**53 / 1e7


class FreeCADFormatError(GcodeSyntaxError):
    """Text FreeCAD's Path cannot read as commands (FreeCAD's ``Badly formatted GCode ...``).

    A :class:`ValueError`, as FreeCAD's ``Path.Command`` raises; where FreeCAD
    0.20 aborts the whole process instead (inside ``Path.Path``), gcodekit
    raises this with the line and column.
    """


def _atof(text: str) -> float:
    """C's ``atof`` on a run of digits, ``-`` and ``.``: the longest number at the start, else 0."""
    m = _ATOF.match(text)
    return float(m.group()) if m else 0.0


def format_value(value: float) -> str:
    """A parameter as FreeCAD 0.20 writes it: six decimals, rounded half away from zero.

    Unlike FreeCAD, values beyond 9e8 (where its arithmetic loses the sixth
    decimal and then overflows) are written correctly.

    Examples
    --------
    >>> format_value(1.2), format_value(-0.0000005), format_value(1e12)
    ('1.200000', '-0.000001', '1000000000000.000000')
    """
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write {value} as a G-code number")
    if abs(value) < _EXACT_BELOW:
        return freecad_format_value(value)
    sign = "-" if value < 0 else ""
    units = (int(Decimal(abs(value)) * 10**7) + 5) // 10  # the double's exact value; no overflow
    return f"{sign}{units // 10**6}.{units % 10**6:06d}"


def freecad_format_value(value: float) -> str:
    """Exactly FreeCAD 0.20's writing of a parameter, overflow included.

    FreeCAD truncates ``value * 1e7`` to a 64-bit integer (out of range and
    NaN become its smallest value), prints a ``-`` for a negative one, adds 5
    to the magnitude as an unsigned number and drops the last digit.

    Examples
    --------
    >>> freecad_format_value(-0.0000001), freecad_format_value(1e300)
    ('-0.000000', '-922337203685.477581')
    """
    scaled = float(value) * 1e7
    n = int(scaled) if math.isfinite(scaled) and abs(scaled) < _INT64 else -_INT64
    sign = "-" if n < 0 else ""
    units = ((-n if n < 0 else n) + 5) // 10
    return f"{sign}{units // 10**6}.{units % 10**6:06d}"


def command_gcode(name: str, params: dict[str, float]) -> str:
    """A command's ``toGCode()`` text: its name, then ``KEYvalue`` in key order, ``N`` left out."""
    words = [name] + [f"{k}{format_value(v)}" for k, v in sorted(params.items()) if k != "N"]
    return " ".join(words)


@dataclass
class _Problem(Exception):
    offset: int  # in the text given to parse_command
    message: str


def _parse(text: str) -> tuple[str, dict[str, float]]:
    """FreeCAD 0.20's ``Command::setFromGCode`` on one command's text; a :class:`_Problem` where it throws."""
    mode, key, value = "none", "", ""
    key_at = 0
    name = ""
    params: dict[str, float] = {}
    for i, ch in enumerate(text):
        if ch in _NUMBER_CHARS:
            value += ch
        elif ch in _LETTERS:
            if mode == "command":
                if not (key and value):
                    raise _Problem(key_at, f"Badly formatted GCode command: {key!r} has no number")
                name, key, value, mode = (key + value).upper(), "", "", "argument"
            elif mode == "none":
                mode = "command"
            elif mode == "argument":
                if not (key and value):
                    raise _Problem(key_at, f"Badly formatted GCode argument: {key!r} has no number")
                params[key.upper()] = _atof(value)
                key, value = "", ""
            else:  # a comment keeps its letters
                value += ch
            key, key_at = ch, i
        elif ch == "(":
            mode = "comment"
        elif ch == ")":
            key, value = "(", value + ")"
        elif mode == "comment":
            value += ch
    if not (key and value):
        raise _Problem(key_at, f"Badly formatted GCode argument: {key!r} has no number" if key
                       else "Badly formatted GCode argument: no command")
    if mode == "command":
        name = (key + value).upper()
    elif mode == "comment":
        name = key + value
    else:
        params[key.upper()] = _atof(value)
    return name, params


def parse_command(text: str) -> tuple[str, dict[str, float]]:
    """One command's name and parameters, read as FreeCAD's ``Command.setFromGCode`` reads it.

    Raises
    ------
    FreeCADFormatError
        Where FreeCAD raises ``Badly formatted GCode ...`` (a letter without
        a number, a name without a number).
    """
    try:
        return _parse(text)
    except _Problem as p:
        raise FreeCADFormatError(f"{p.message} at column {p.offset + 1} of {text!r}") from None


class _Lines:
    """Offsets in a text to 1-based (line, column)."""

    def __init__(self, text: str):
        self.starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def __call__(self, offset: int) -> tuple[int, int]:
        k = bisect.bisect_right(self.starts, offset) - 1
        return k + 1, offset - self.starts[k] + 1


_PAREN_OR_SEMICOLON = re.compile(r"\([^)]*\)?|;[^\n]*")


def _blank_semicolons(text: str) -> tuple[str, list[tuple[int, str]]]:
    """The text with each ``;`` comment (outside parentheses) replaced by spaces, and those comments.

    Blanking keeps every offset, so line and column numbers stay right.
    """
    if ";" not in text:
        return text, []
    comments = []
    pieces = []
    last = 0
    for m in _PAREN_OR_SEMICOLON.finditer(text):
        if m.group().startswith(";"):
            pieces.append(text[last:m.start()])
            pieces.append(" " * len(m.group()))
            last = m.end()
            # parentheses would end or nest the '(comment)' it becomes: brackets instead, as FreeCAD's own posts do
            comments.append((m.start(), m.group()[1:].strip().replace("(", "[").replace(")", "]")))
    pieces.append(text[last:])
    return "".join(pieces), comments


def _segments(text: str):
    """FreeCAD's cut of a program into command and comment texts.

    Yields ``(kind, start, text)``: kind ``"command"``, ``"comment"`` or
    ``"dropped"`` (text FreeCAD throws away: before the first command,
    between a comment and the next command, an unclosed comment and all
    after it).
    """
    pos, n = 0, len(text)
    current = -1  # start of the command being collected
    while True:
        m = _CUT.search(text, pos)
        end = m.start() if m else n
        if current < 0 and end > pos:
            yield "dropped", pos, text[pos:end]
        if m is None:
            break
        if m.group() == "(":
            if current >= 0:
                yield "command", current, text[current:end]
                current = -1
            stop = text.find(")", end + 1)
            if stop < 0:
                yield "dropped", end, text[end:]
                return
            yield "comment", end, text[end:stop + 1]
            pos = stop + 1
        else:
            if current >= 0:
                yield "command", current, text[current:end]
            current, pos = end, end + 1
    if current >= 0:
        yield "command", current, text[current:]


def read_strict(text: str, file: str = "<string>", *, freecad: bool = False) -> list[tuple[str, dict[str, float], int]]:
    """:func:`read_commands`, raising the first problem as a :class:`FreeCADFormatError`."""
    diagnostics = Diagnostics(file, "lenient")
    commands = read_commands(text, diagnostics, freecad=freecad)
    if diagnostics.errors:
        first = diagnostics.errors[0]
        raise FreeCADFormatError(first.message, first)
    return commands


def read_commands(text: str, diagnostics: Diagnostics, *,
                  freecad: bool = False) -> list[tuple[str, dict[str, float], int]]:
    """A program's commands by FreeCAD 0.20's rules, with gcodekit's corrections (see the module).

    ``freecad=True`` leaves the corrections out and reads exactly as FreeCAD
    0.20 does where it reads at all (``;`` is skipped, K is not scaled after
    G20, characters FreeCAD skips are skipped); it exists to show, in the
    tests, that every difference from FreeCAD is one of the corrections.

    Returns ``(name, parameters, line)`` per command.  What FreeCAD cannot
    read is reported to ``diagnostics`` (raised in strict mode; skipped in
    lenient mode); what it reads differently from G-code's meaning is a
    warning: words it drops, arguments a later word of the same letter
    replaces.
    """
    where = _Lines(text)
    blanked, semicolons = (text, []) if freecad else _blank_semicolons(text)
    inch_letters = FREECAD_INCH_LETTERS if freecad else INCH_LETTERS
    parts = list(_segments(blanked))
    if semicolons:  # each after the command it ends
        parts = sorted(parts + [("semicolon", at, body) for at, body in semicolons], key=lambda p: p[1])
    out: list[tuple[str, dict[str, float], int]] = []
    inches = False
    for kind, start, part in parts:
        line, col = where(start)
        if kind == "semicolon":
            if part:
                out.append((f"({part})", {}, line))
            continue
        if kind == "dropped":
            words = re.sub(r"(?i)\bN\s*\d+|%|\s", "", part)
            if words:
                diagnostics.warn(line, col, "words before the first command or after a comment are dropped "
                                 "(FreeCAD's rule: a command starts with G or M)", part.strip()[:60])
            continue
        if kind == "command":
            bad = len(part) if freecad else _ALLOWED_IN_COMMAND.match(part).end()
            if bad < len(part):
                bl, bc = where(start + bad)
                diagnostics.report(bl, bc, f"{part[bad]!r} is not FreeCAD Path G-code: FreeCAD 0.20 skips it and "
                                   "misreads the number around it (or aborts on letters after it); parameters "
                                   "and expressions need the pre-processor, gcodekit.path.read()", part.strip()[:60])
                continue
            repeated = _repeated_letters(part)
            if repeated:
                diagnostics.warn(line, col, f"argument(s) {', '.join(repeated)} given twice: the last value "
                                 "replaces the first (FreeCAD's rule: one value per letter and command)",
                                 " ".join(part.split())[:60])
        try:
            name, params = _parse(part)
        except _Problem as p:
            bl, bc = where(start + p.offset)
            diagnostics.report(bl, bc, p.message + " (FreeCAD 0.20 aborts here)", part.strip()[:60])
            continue
        if name == "G20":
            inches = True
        elif name == "G21":
            inches = False
        else:
            if inches:
                params = {k: v * 25.4 if k in inch_letters else v for k, v in params.items()}
            out.append((name, params, line))
    return out


def _repeated_letters(part: str) -> list[str]:
    """Argument letters that occur more than once in a command's text (N excepted)."""
    letters = [m.group(1).upper() for m in re.finditer(r"([A-Za-z])[-.0-9]", part)][1:]
    seen: set[str] = set()
    twice = []
    for k in letters:
        if k in seen and k != "N" and k not in twice:
            twice.append(k)
        seen.add(k)
    return twice
