"""A wizard call's arguments: read from the line, then checked against the function's signature."""

from __future__ import annotations

import inspect
import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .context import WizardFunction

if TYPE_CHECKING:
    from ...syntax.flavor import Flavor

_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)")


@dataclass(frozen=True)
class Argument:
    """One argument of a call: a number or a string, and its 1-based column."""

    value: float | str
    column: int


class BadCall(Exception):
    """A problem with a call, already worded: (column, message, kind)."""

    def __init__(self, column: int, message: str, kind: str = "syntax"):
        super().__init__(message)
        self.column, self.message, self.kind = column, message, kind


def read_arguments(text: str, i: int, fl: Flavor) -> tuple[list[Argument], bool]:
    """Numbers and "strings" of ``text`` from index ``i`` (after the name) to the end of the line.

    Returns the arguments and whether a ``(`` comment after them goes on
    past the line (when the flavor has multi-line comments).

    Raises
    ------
    BadCall
        Text that is not an argument, or a statement separator.
    """
    args: list[Argument] = []
    n = len(text)
    stops = " \t" + "".join(fl.statement_separators) + ("(" if fl.paren_comments else "")
    if i < n and text[i] not in stops:
        raise BadCall(i + 1, f"expected a space after the wizard name, not {text[i]!r}")
    while i < n:
        c = text[i]
        if c in " \t":
            i += 1
            continue
        if c in fl.statement_separators:
            raise BadCall(i + 1, f"wizard arguments run to the end of the line; {c!r} cannot end the call")
        if c == "(" and fl.paren_comments:
            j = text.find(")", i + 1)
            if j < 0:
                return args, fl.multiline_comments
            i = j + 1
            continue
        if c == '"':
            j = text.find('"', i + 1)
            if j < 0:
                raise BadCall(i + 1, "string argument without its closing '\"'")
            args.append(Argument(text[i + 1 : j], i + 1))
            end = j + 1
        else:
            m = _NUMBER.match(text, i)
            end = m.end() if m else i
            if m is None or (end < n and text[end] not in stops + '"'):
                k = end
                while k < n and text[k] not in " \t":
                    k += 1
                raise BadCall(i + 1, f"wizard argument {text[i:k]!r} is neither a number nor a \"string\"")
            value = float(m.group())
            if not math.isfinite(value):
                raise BadCall(i + 1, f"number {m.group()[:20]!r}... is out of range", "expression")
            args.append(Argument(value, i + 1))
        if end < n and text[end] not in stops:
            raise BadCall(end + 1, f"expected a space between wizard arguments, not {text[end]!r}")
        i = end
    return args, False


def _annotation(parameter: inspect.Parameter) -> str | None:
    """'float', 'int', 'str' or None (anything) from a parameter's annotation."""
    ann = parameter.annotation
    if ann is inspect.Parameter.empty:
        return None
    text = ann if isinstance(ann, str) else getattr(ann, "__name__", str(ann))
    kinds = {t.strip() for t in text.split("|")} & {"float", "int", "str"}
    return kinds.pop() if len(kinds) == 1 else None


def bind(name: str, function: WizardFunction, args: list[Argument], column: int) -> list:
    """Check count and types of ``args`` against ``function``'s signature."""
    values: list = [a.value for a in args]
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):  # a builtin without a signature: take it on trust
        return values
    params = [p for p in signature.parameters.values()
              if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.VAR_POSITIONAL)]
    try:
        signature.bind(None, *values)
    except TypeError:
        raise BadCall(column, f"{name} takes {_usage(params[1:])}; got {len(values)} argument"
                      f"{'' if len(values) == 1 else 's'}") from None
    formal = [p for p in params[1:] if p.kind != p.VAR_POSITIONAL]
    rest = [p for p in params[1:] if p.kind == p.VAR_POSITIONAL]
    for k, arg in enumerate(args):
        if k < len(formal):
            p = formal[k]
        elif rest:
            p = rest[0]
        else:
            break
        want = _annotation(p)
        if want in ("float", "int") and isinstance(arg.value, str):
            raise BadCall(arg.column, f"{name}: {p.name} must be a number, not the string {arg.value!r}",
                          "expression")
        if want == "str" and not isinstance(arg.value, str):
            raise BadCall(arg.column, f"{name}: {p.name} must be a \"string\", not a number", "expression")
        if want == "int":
            if arg.value != int(arg.value):
                raise BadCall(arg.column, f"{name}: {p.name} must be a whole number, not {arg.value:g}",
                              "expression")
            values[k] = int(arg.value)
    return values


def _usage(params: list[inspect.Parameter]) -> str:
    """How a wizard is called, for messages: ``2 to 3 arguments (width height [depth])``."""
    words = []
    for p in params:
        if p.kind == p.VAR_POSITIONAL:
            words.append(f"[{p.name} ...]")
        elif p.default is not inspect.Parameter.empty:
            words.append(f"[{p.name}]")
        else:
            words.append(p.name)
    required = sum(1 for p in params if p.kind != p.VAR_POSITIONAL and p.default is inspect.Parameter.empty)
    most = None if any(p.kind == p.VAR_POSITIONAL for p in params) else len(params)
    if most == required:
        count = f"{required} argument{'' if required == 1 else 's'}"
    elif most is None:
        count = f"at least {required} arguments"
    else:
        count = f"{required} to {most} arguments"
    return f"{count} ({' '.join(words)})" if words else "no arguments"

