"""Preprocess stage: RS274NGC expressions, parsed to a small AST and evaluated.

This is gcodekit's own evaluator (never Python's ``eval``), following
LinuxCNC 2.9's ``interp_read.cc`` and ``interp_execute.cc``:

* Text is read as LinuxCNC reads it: ASCII letters are folded to lower case
  and whitespace is dropped before anything else, so ``[1 0]`` is ``10``,
  ``#<My Var>`` is ``#<myvar>`` and keywords are case-insensitive.
* A *value* is a number (``1``, ``-1.5``, ``.5``, ``1.``; no exponent), a
  bracketed expression ``[...]``, a parameter ``#n`` / ``#<name>`` (``n`` is
  itself a value: ``##1``, ``#[1+2]``), a function ``NAME[...]``,
  ``ATAN[y]/[x]`` or ``EXISTS[#...]``, or ``+``/``-`` and a value.  The sign
  belongs to the value, so ``[-2**2]`` is 4, as in LinuxCNC.
* Binary operators appear only inside brackets, left associative, from
  highest to lowest precedence: ``**``; ``*`` ``/`` ``MOD``; ``+`` ``-``;
  ``EQ NE GT GE LT LE``; ``AND OR XOR``.
* Angles are in degrees.  Comparisons and logic give 1.0 or 0.0; ``EQ``
  and ``NE`` treat numbers within 0.0001 as equal, the others compare
  exactly (as rs274 does: ``[0.03755 LE 0.0375]`` is 0).

The parser reads the folded characters directly rather than a token list:
LinuxCNC's reader is character driven (a sign followed by a digit is part of
a number, a run of letters splits into keywords) and the parameter stage
must stop reading right after the value of a word.

Errors are :class:`~gcodekit.errors.GcodeExpressionError` (or
:class:`~gcodekit.errors.GcodeLimitError` for :data:`MAX_DEPTH` and
:data:`MAX_LENGTH`) whose ``diagnostic.column`` is the 1-based column of the
problem in the text that was parsed.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Protocol, Union

from ..errors import (
    Diagnostic,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    did_you_mean,
)

#: Deepest nesting of values (brackets, functions, parameter references and
#: signs) one expression may have; keeps the parser far from Python's
#: recursion limit.
MAX_DEPTH = 64
#: Longest text, in characters, the parser accepts (LinuxCNC stops at 255).
MAX_LENGTH = 10_000

#: RS274NGC's tolerance for EQ and NE (LinuxCNC ``TOLERANCE_EQUAL``).
EQUAL_TOLERANCE = 0.0001

#: Binary operators and their precedence (LinuxCNC ``Interp::precedence``).
PRECEDENCE = {
    "**": 5,
    "*": 4, "/": 4, "mod": 4,
    "+": 3, "-": 3,
    "eq": 2, "ne": 2, "gt": 2, "ge": 2, "lt": 2, "le": 2,
    "and": 1, "or": 1, "xor": 1,
}
#: Functions taking one bracketed argument.
FUNCTIONS = ("abs", "acos", "asin", "cos", "exp", "fix", "fup", "ln", "round", "sin", "sqrt", "tan")
#: Every word the lexer knows.  None is a prefix of another, so a run of
#: letters such as ``andsin`` splits unambiguously, as LinuxCNC reads it.
_ALL_FUNCTIONS = FUNCTIONS + ("atan", "exists")
KEYWORDS = tuple(k for k in PRECEDENCE if k.isalpha()) + _ALL_FUNCTIONS
_WHITESPACE = frozenset(" \t\r\n\v\f")
_ASCII_LOWER = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")
_NUMBER = re.compile(r"[0-9.]+")
_VALID_NUMBER = re.compile(r"[0-9]+\.?[0-9]*|\.[0-9]+")
_LETTERS = re.compile(r"[a-z]+")


class Parameters(Protocol):
    """What the evaluator reads: see :class:`~gcodekit.preprocess.ParameterStore`."""

    def get(self, key: int | str) -> float: ...

    def exists(self, key: int | str) -> bool: ...


# --- AST ------------------------------------------------------------------
# ``column`` is the 0-based offset of the node's first character (of the
# operator for Binary) in the original text, so errors found while
# evaluating point at the right place.


@dataclass(frozen=True, slots=True)
class Number:
    value: float
    column: int


@dataclass(frozen=True, slots=True)
class Parameter:
    """``#index``: a numbered parameter."""

    index: "Node"
    column: int


@dataclass(frozen=True, slots=True)
class NamedParameter:
    """``#<name>``; ``name`` is lower case without spaces."""

    name: str
    column: int


@dataclass(frozen=True, slots=True)
class Negate:
    operand: "Node"
    column: int


@dataclass(frozen=True, slots=True)
class Binary:
    op: str
    left: "Node"
    right: "Node"
    column: int


@dataclass(frozen=True, slots=True)
class Call:
    """A function; ``atan`` has two arguments (y, x), the others one."""

    function: str
    args: tuple["Node", ...]
    column: int


@dataclass(frozen=True, slots=True)
class Exists:
    parameter: Union[Parameter, NamedParameter]
    column: int


Node = Union[Number, Parameter, NamedParameter, Negate, Binary, Call, Exists]


# --- text -----------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class CompactText:
    """Text as RS274NGC reads it: lower case, without whitespace.

    ``columns[i]`` is the offset in the original text of ``chars[i]``; ``end``
    is the offset just past the compacted range.
    """

    chars: str
    columns: tuple[int, ...]
    end: int

    def column(self, pos: int) -> int:
        """Original offset of compact position ``pos`` (``end`` past the end)."""
        return self.columns[pos] if pos < len(self.columns) else self.end


def compact(text: str, start: int = 0, end: int | None = None) -> CompactText:
    """Fold ``text[start:end]`` the way LinuxCNC does before reading it.

    Raises
    ------
    GcodeLimitError
        The range is longer than :data:`MAX_LENGTH`.
    """
    end = len(text) if end is None else end
    if end - start > MAX_LENGTH:
        raise expression_error(f"text is longer than {MAX_LENGTH} characters", start, GcodeLimitError)
    kept = [i for i in range(start, end) if text[i] not in _WHITESPACE]
    # Only ASCII letters fold, as C's tolower does; str.lower() could also
    # change the length of non-ASCII text.
    chars = "".join(text[i] for i in kept).translate(_ASCII_LOWER)
    return CompactText(chars, tuple(kept), end)


def expression_error(
    message: str, column: int, kind: type[GcodeError] = GcodeExpressionError
) -> GcodeError:
    """An error about 0-based ``column`` of the text (stored 1-based, as everywhere)."""
    return kind(message, Diagnostic("<expression>", 1, column + 1, "error", message))


# --- parser ---------------------------------------------------------------


class _Parser:
    """Recursive descent over values; an operator stack inside brackets."""

    def __init__(self, code: CompactText):
        self.code = code
        self.s = code.chars
        self.depth = 0

    def fail(self, message: str, pos: int):
        return expression_error(message, self.code.column(pos))

    def value(self, pos: int) -> tuple[Node, int]:
        """Parse one value at ``pos``; return it and the position after it."""
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                raise expression_error(
                    f"expression nested deeper than {MAX_DEPTH} levels",
                    self.code.column(pos),
                    GcodeLimitError,
                )
            return self._value(pos)
        finally:
            self.depth -= 1

    def _value(self, pos: int) -> tuple[Node, int]:
        s = self.s
        col = self.code.column(pos)
        if pos >= len(s):
            raise self.fail("a value is missing", pos)
        c = s[pos]
        if c == "[":
            return self.bracket(pos)
        if c == "#":
            return self.parameter(pos)
        if c in "+-":
            operand, end = self.value(pos + 1)
            return (Negate(operand, col) if c == "-" else operand), end
        if c in "0123456789.":
            text = _NUMBER.match(s, pos).group()
            if not _VALID_NUMBER.fullmatch(text):
                raise self.fail(f"bad number {text!r}", pos)
            value = float(text)
            if math.isinf(value):
                raise self.fail(f"number {text!r} is too large", pos)
            return Number(value, col), pos + len(text)
        if _LETTERS.match(s, pos):
            return self.function(pos)
        raise self.fail(f"a value is expected, not {c!r}", pos)

    def bracket(self, pos: int) -> tuple[Node, int]:
        """``[ value (op value)* ]``, reduced by precedence, left to right.

        Mirrors LinuxCNC's stack-based ``read_real_expression``: an operator
        whose precedence is not higher than the one before it first reduces
        the stack, which makes operators of equal precedence left associative.
        """
        operands: list[Node] = []
        operators: list[tuple[str, int]] = []

        def reduce() -> None:
            op, col = operators.pop()
            right = operands.pop()
            operands.append(Binary(op, operands.pop(), right, col))

        node, p = self.value(pos + 1)
        operands.append(node)
        while True:
            if p >= len(self.s):
                raise self.fail("unclosed '[': ']' is missing", pos)
            if self.s[p] == "]":
                break
            op, after = self.operator(p)
            while operators and PRECEDENCE[operators[-1][0]] >= PRECEDENCE[op]:
                reduce()
            operators.append((op, self.code.column(p)))
            node, p = self.value(after)
            operands.append(node)
        while operators:
            reduce()
        return operands[0], p + 1

    def operator(self, pos: int) -> tuple[str, int]:
        s = self.s
        if s.startswith("**", pos):
            return "**", pos + 2
        if s[pos] in "*/+-":
            return s[pos], pos + 1
        word = self.keyword(pos)
        if word in PRECEDENCE:
            return word, pos + len(word)
        if word:
            raise self.fail(f"{word.upper()} is a function, not an operator", pos)
        letters = _LETTERS.match(s, pos)
        if letters and letters.group().startswith("e") and s[pos - 1] in "0123456789.":
            raise self.fail("numbers have no exponent in G-code: write 100000, not 1e5", pos)
        if letters:
            name = letters.group()
            ops = [k.upper() for k in PRECEDENCE if k.isalpha()]
            raise self.fail(f"unknown operator {name.upper()!r}" + did_you_mean(name.upper(), ops), pos)
        raise self.fail(f"an operator or ']' is expected, not {s[pos]!r}", pos)

    def keyword(self, pos: int) -> str:
        """The keyword starting at ``pos``, or ''."""
        for word in KEYWORDS:
            if self.s.startswith(word, pos):
                return word
        return ""

    def function(self, pos: int) -> tuple[Node, int]:
        s = self.s
        col = self.code.column(pos)
        # A function name is always followed by '[', so the whole run of
        # letters is the name.
        word = _LETTERS.match(s, pos).group()
        if word not in _ALL_FUNCTIONS:
            names = [f.upper() for f in _ALL_FUNCTIONS]
            hint = did_you_mean(word.upper(), names)
            raise self.fail(f"unknown function {word.upper()!r}{hint}", pos)
        p = pos + len(word)
        if not s.startswith("[", p):
            raise self.fail(f"{word.upper()} must be followed by '['", p)
        if word == "exists":
            if not s.startswith("#", p + 1):
                raise self.fail("EXISTS takes a parameter: EXISTS[#<name>]", p + 1)
            target, p = self.parameter(p + 1)
            if not s.startswith("]", p):
                raise self.fail("']' expected after the EXISTS parameter", p)
            return Exists(target, col), p + 1
        arg, p = self.bracket(p)
        if word != "atan":
            return Call(word, (arg,), col), p
        if not s.startswith("/[", p):
            raise self.fail("ATAN takes two arguments: ATAN[y]/[x]", p)
        x, p = self.bracket(p + 1)
        return Call(word, (arg, x), col), p

    def parameter(self, pos: int) -> tuple[Parameter | NamedParameter, int]:
        """``#<name>`` or ``#value``, with ``pos`` at the ``#``."""
        col = self.code.column(pos)
        if self.s.startswith("<", pos + 1):
            close = self.s.find(">", pos + 2)
            if close < 0:
                raise self.fail("named parameter is not closed by '>'", pos)
            if close == pos + 2:
                raise self.fail("named parameter has an empty name", pos)
            return NamedParameter(self.s[pos + 2 : close], col), close + 1
        index, end = self.value(pos + 1)
        return Parameter(index, col), end


def parse_value(code: CompactText, pos: int = 0) -> tuple[Node, int]:
    """Parse the one value that starts at compact position ``pos``.

    Returns
    -------
    node : Node
    end : int
        Compact position just after the value; the text there is not read.

    Raises
    ------
    GcodeExpressionError
        Malformed text: an unclosed ``[``, a bad number (``1.2.3``, ``1e5``),
        an unknown function or operator (with a did-you-mean), a function
        without ``[``, ``ATAN`` without ``/[x]``, an unclosed ``#<name``.
    GcodeLimitError
        Values nested deeper than :data:`MAX_DEPTH`.
    """
    return _Parser(code).value(pos)


def parse(text: str) -> Node:
    """Parse ``text``, which must hold exactly one value.

    Examples
    --------
    Operators bind by precedence, so this is ``2 + [3 * [4 ** 2]]``:

    >>> node = parse("[2 + 3 * 4 ** 2]")
    >>> node.op, node.right.op
    ('+', '*')
    """
    code = compact(text)
    node, end = parse_value(code)
    if end < len(code.chars):
        rest = code.chars[end:]
        raise expression_error(f"unexpected text after the value: {rest!r}", code.column(end))
    return node


# --- evaluator ------------------------------------------------------------


def evaluate(node: Node, parameters: Parameters) -> float:
    """Value of a parsed expression, reading parameters from ``parameters``.

    Walks the tree with an explicit stack (no recursion), applying
    LinuxCNC's rules:

    * ``/`` by zero and ``MOD`` by zero are errors; ``MOD`` is never
      negative (``[-1 MOD 3]`` is 2).
    * ``**`` of a negative number to a non-integer power, or of zero to a
      negative power, is an error.
    * ``SQRT`` of a negative number, ``LN`` of a number <= 0, and ``ACOS`` /
      ``ASIN`` outside [-1, 1] are errors.
    * ``FIX`` rounds down, ``FUP`` up, ``ROUND`` half away from zero.
    * A numbered parameter's number must be within 0.0001 of an integer
      (:func:`parameter_index`); ``parameters.get`` refuses numbers outside
      1 .. 5601 and names never set, where ``EXISTS`` gives 0.
    * A result that is infinite or not a number is an error.

    Raises
    ------
    GcodeExpressionError
        ``diagnostic.column`` locates the operator, function or parameter.
    """
    values: list[float] = []
    stack: list[tuple[Node, bool]] = [(node, False)]
    while stack:
        item, ready = stack.pop()
        if isinstance(item, Number):
            values.append(item.value)
            continue
        children = _children(item)
        if not ready:
            stack.append((item, True))
            stack.extend((child, False) for child in reversed(children))
            continue
        args = values[len(values) - len(children) :]
        del values[len(values) - len(children) :]
        result = _apply(item, args, parameters)
        if not math.isfinite(result):
            what = "not a number" if math.isnan(result) else "infinity"
            raise expression_error(f"calculation resulted in {what}", item.column)
        values.append(result)
    return values[0]


def _children(node: Node) -> tuple[Node, ...]:
    if isinstance(node, Binary):
        return (node.left, node.right)
    if isinstance(node, Call):
        return node.args
    if isinstance(node, Negate):
        return (node.operand,)
    if isinstance(node, Parameter):
        return (node.index,)
    if isinstance(node, Exists) and isinstance(node.parameter, Parameter):
        return (node.parameter.index,)
    return ()


def _apply(node: Node, args: list[float], parameters: Parameters) -> float:
    col = node.column
    if isinstance(node, Binary):
        return _binary(node.op, args[0], args[1], col)
    if isinstance(node, Call):
        return _function(node.function, args, col)
    if isinstance(node, Negate):
        return -args[0]
    if isinstance(node, Exists):
        if isinstance(node.parameter, NamedParameter):
            return float(parameters.exists(node.parameter.name))
        return float(parameters.exists(parameter_index(args[0], col)))
    key = node.name if isinstance(node, NamedParameter) else parameter_index(args[0], col)
    try:
        return parameters.get(key)
    except GcodeExpressionError as exc:
        message = exc.diagnostic.message if exc.diagnostic else str(exc)
        raise expression_error(message, col) from None


def parameter_index(value: float, column: int = 0) -> int:
    """The integer a parameter number stands for (LinuxCNC ``read_integer_value``).

    Values within 0.0001 of an integer count as that integer; others raise
    :class:`~gcodekit.errors.GcodeExpressionError`.
    """
    index = math.floor(value)
    if value - index > 0.9999:
        return index + 1
    if value - index > 0.0001:
        raise expression_error(f"parameter number {value!r} is not an integer", column)
    return index


def _binary(op: str, a: float, b: float, col: int) -> float:
    if op == "+":
        return a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    if op == "/":
        if b == 0.0:
            raise expression_error("division by zero", col)
        return a / b
    if op == "mod":
        if b == 0.0:
            raise expression_error("MOD by zero", col)
        r = math.fmod(a, b)
        return r + abs(b) if r < 0.0 else r
    if op == "**":
        if a < 0.0 and math.floor(b) != b:
            raise expression_error("negative number raised to a non-integer power", col)
        if a == 0.0 and b < 0.0:
            raise expression_error("zero raised to a negative power", col)
        try:
            return math.pow(a, b)
        except OverflowError:
            return math.inf
    if op in ("and", "or", "xor"):
        x, y = a != 0.0, b != 0.0
        return float(x and y if op == "and" else x or y if op == "or" else x != y)
    near = abs(a - b) < EQUAL_TOLERANCE
    return float(
        {
            "eq": near,
            "ne": not near,
            "lt": a < b,
            "gt": a > b,
            "le": a <= b,
            "ge": a >= b,
        }[op]
    )


def _function(name: str, args: list[float], col: int) -> float:
    x = args[0]
    if name == "atan":
        return math.atan2(x, args[1]) * 180.0 / math.pi
    if name in ("acos", "asin"):
        if not -1.0 <= x <= 1.0:
            raise expression_error(f"{name.upper()} of {x!r} is outside [-1, 1]", col)
        return (math.acos(x) if name == "acos" else math.asin(x)) * 180.0 / math.pi
    if name == "sqrt":
        if x < 0.0:
            raise expression_error(f"SQRT of negative number {x!r}", col)
        return math.sqrt(x)
    if name == "ln":
        if x <= 0.0:
            raise expression_error(f"LN of {x!r}, which is not positive", col)
        return math.log(x)
    if name == "exp":
        try:
            return math.exp(x)
        except OverflowError:
            return math.inf
    if name == "round":
        # LinuxCNC: (int)(x + 0.5) for x >= 0, (int)(x - 0.5) below: half away from zero.
        return float(math.trunc(x + 0.5 if x >= 0.0 else x - 0.5))
    # C's floor, ceil and LinuxCNC's ABS keep the sign of a zero (FUP[-0.5]
    # is -0.0), which ATAN can tell apart; Python's versions do not.
    simple = {
        "abs": lambda v: -v if v < 0.0 else v,
        "fix": lambda v: math.copysign(math.floor(v), v),
        "fup": lambda v: math.copysign(math.ceil(v), v),
        "sin": lambda v: math.sin(v * math.pi / 180.0),
        "cos": lambda v: math.cos(v * math.pi / 180.0),
        "tan": lambda v: math.tan(v * math.pi / 180.0),
    }
    return float(simple[name](x))
