"""Preprocess stage: GER wizards, named commands expanded to plain G-code.

GER (seeds/ger_manual.md, sections 2 and 4) lets a program call *wizards*:
a line that starts with a name of two or more letters, followed by
space-separated arguments (numbers, or strings in double quotes) that run
to the end of the line::

    G21
    Pocket 75.0 30.0 10.0      (a 75 x 30 mm pocket, 10 mm deep)

:class:`WizardStage` replaces each call by the lines its function returns;
every emitted line keeps the call's file and line number, so later
diagnostics and the ``line`` column point at the call.  Wizards are kept in
a :class:`WizardRegistry` keyed by name (case-insensitive); the module-level
:func:`register_wizard`, :func:`unregister_wizard`, :func:`wizard` and
:func:`wizards` use the default registry, which holds the built-ins:

``Pocket width height depth [stepdown] [stepover]``
    Rectangular pocket centred on X0 Y0, from the surface Z0 down to
    Z-depth: a zigzag along X, then one pass round the walls, per depth.
``CirclePocket diameter depth [stepdown] [stepover]``
    Round pocket centred on X0 Y0: concentric full circles (G3 with I/J).
``DrillGrid nx ny dx dy depth [peck]``
    ``nx`` by ``ny`` holes, the first at X0 Y0, spaced ``dx`` and ``dy``.
``BoltCircle count diameter depth [start_angle]``
    ``count`` holes on a circle centred on X0 Y0; angle in degrees from +X.
``Face width height depth [stepdown] [stepover]``
    Face the rectangle X0..width, Y0..height (lower-left corner at the
    origin, as GER advises setting the PRZ) down to Z-depth.

Lengths are in the program's units at the call (G20/G21, starting with the
flavor's); ``stepover`` is a length, at most the tool diameter.  Defaults,
all from the stage's ``settings`` (lengths in mm, feeds in mm/min, converted
to the current units): ``tool_diameter`` 6.35 (a 1/4 in end mill; or
``tools[T]`` for the tool selected by ``M6 Tn``), ``stepdown`` half the tool
diameter, ``stepover`` 0.4 tool diameters, ``feed`` 500, ``plunge_feed``
200, ``safe_z`` 5 (rapid height above Z0).  The built-ins emit only
G0/G1/G3 with X Y Z I J F, valid for GER and RS274NGC; they switch to G90
for their moves (and back to G91 if the program was incremental), plunge
straight down and end at ``safe_z``, in G0 mode.

A wizard function is called as ``function(context, *arguments)`` with a
:class:`WizardContext` and the call's arguments in order (``float`` or
``str``; ``int`` when the parameter is annotated ``int``), and returns
lines of G-code (an iterable of str, read lazily up to the stage's
``max_lines``).  Emitted lines are not searched for further wizard calls.
Wrong argument counts or types, bad argument text and unknown wizards are
reported at the call's ``file:line:col``; a wizard that raises becomes a
diagnostic with its message (lenient) or a :class:`WizardError` (strict).
"""

from __future__ import annotations

import contextlib
import inspect
import math
import re
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Iterable, Iterator, Mapping

from gcodekit.errors import (
    ConfigError,
    Diagnostic,
    Diagnostics,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    GcodeMachineError,
    did_you_mean,
)
from gcodekit.limits import MAX_MOTIONS

if TYPE_CHECKING:
    from gcodekit.preprocess import SourceLine
    from gcodekit.syntax.flavor import Flavor

#: Most lines one wizard call may emit; more is taken as a runaway.
MAX_LINES = 1_000_000
#: Defaults of the stage's ``settings``; lengths in mm, feeds in mm/min.
DEFAULT_SETTINGS: Mapping[str, float] = {
    "tool_diameter": 6.35,  # a 1/4 in end mill, GER's inch-first habit
    "feed": 500.0,
    "plunge_feed": 200.0,
    "safe_z": 5.0,
    "stepover": 0.4,  # fraction of the tool diameter
}
MM_PER_INCH = 25.4
# Most passes, rows or rings one built-in plans; beyond that the arguments
# are nonsense (a 1e-9 stepdown), not a program.
_MAX_STEPS = MAX_LINES

# A wizard name: two ASCII letters, then letters, digits or '_' (GER: "wizard
# commands must start with two consecutive letters").
_NAME = re.compile(r"[A-Za-z]{2}[A-Za-z0-9_]*")
_NAME_FULL = re.compile(r"[A-Za-z]{2}[A-Za-z0-9_]*\Z")
_LOOKS_LIKE_CALL = re.compile(r"(?m)^[ \t]*[A-Za-z]{2}")
_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)")
_UNITS = re.compile(r"(?<![A-Za-z])[gG][ \t]*0*(2[01]|9[01])(?![0-9.])")
_TOOL_CHANGE = re.compile(r"(?<![A-Za-z])[mM][ \t]*0*6(?![0-9.])")
_TOOL = re.compile(r"(?<![A-Za-z])[tT][ \t]*([0-9]+)")


class WizardError(GcodeError, RuntimeError):
    """A wizard function failed; ``__cause__`` is its exception."""


class WizardWarning(UserWarning):
    """A wizard name is registered twice."""


class WizardArgumentError(ValueError):
    """Raised by a wizard function about one of its arguments.

    The stage reports it at that argument's column as a
    :class:`~gcodekit.errors.GcodeExpressionError`.

    Parameters
    ----------
    message : str
    index : int, default: None
        0-based position of the argument; None points at the wizard's name.
    """

    def __init__(self, message: str, index: int | None = None):
        super().__init__(message)
        self.index = index


@dataclass(frozen=True)
class WizardContext:
    """What a wizard knows about the program where it is called.

    Attributes
    ----------
    units : {"mm", "inch"}
        The program's units at the call; arguments and output use them.
    tool_diameter : float or None
        Diameter of the current tool in ``units``, when known (the
        settings' ``tools[T]`` for the tool of the last ``M6 Tn``, else
        ``tool_diameter``).
    settings : dict
        The stage's settings, shared by every call of one run (a wizard may
        keep values in it); lengths in mm, feeds in mm/min.
    distance : {"absolute", "incremental"}
        G90 or G91 at the call.
    file : str
    line : int
        Where the call is.
    """

    units: str = "mm"
    tool_diameter: float | None = None
    settings: dict = field(default_factory=dict)
    distance: str = "absolute"
    file: str = "<string>"
    line: int = 0

    def length(self, mm: float) -> float:
        """``mm`` millimetres in the program's units."""
        return mm if self.units == "mm" else mm / MM_PER_INCH

    def setting(self, key: str) -> float:
        """A length or feed setting in the program's units (default: :data:`DEFAULT_SETTINGS`)."""
        value = self.settings.get(key, DEFAULT_SETTINGS[key])
        return float(value) if key == "stepover" else self.length(float(value))


WizardFunction = Callable[..., Iterable[str]]


class WizardRegistry:
    """Wizard functions keyed by name, matched case-insensitively.

    Parameters
    ----------
    builtins : bool, default: True
        Start with the built-in wizards (``Pocket``, ``CirclePocket``,
        ``DrillGrid``, ``BoltCircle``, ``Face``).

    Examples
    --------
    >>> reg = WizardRegistry(builtins=False)
    >>> _ = reg.register("Hello", lambda ctx, who: [f"(hello {who})"])
    >>> reg.get("HELLO") is reg.get("hello"), reg.names()
    (True, ['Hello'])
    """

    def __init__(self, *, builtins: bool = True):
        self._items: dict[str, tuple[str, WizardFunction]] = {}
        if builtins:
            for name, function in _BUILTINS.items():
                self.register(name, function)

    def register(self, name: str, function: WizardFunction, *, replace: bool = False) -> WizardFunction:
        """Register ``function`` as wizard ``name``; returns ``function``.

        A name already taken (in any case) by another function warns
        (:class:`WizardWarning`) and keeps the old one, unless ``replace``.

        Raises
        ------
        ConfigError
            ``name`` does not start with two letters.
        TypeError
            ``function`` is not callable.
        """
        if not isinstance(name, str) or not _NAME_FULL.match(name):
            raise ConfigError(f"wizard name {name!r} must be two letters then letters, digits or '_'")
        if not callable(function):
            raise TypeError(f"wizard {name!r}: {function!r} is not callable")
        key = name.lower()
        old = self._items.get(key)
        if old is not None and old[1] is not function and not replace:
            warnings.warn(f"wizard {name!r} is already registered as {old[0]!r} ({_describe(old[1])}); "
                          "keeping it (pass replace=True to replace it)", WizardWarning, stacklevel=3)
            return function
        self._items[key] = (name, function)
        return function

    def unregister(self, name: str) -> WizardFunction:
        """Remove wizard ``name`` and return its function; KeyError if absent."""
        try:
            return self._items.pop(str(name).lower())[1]
        except KeyError:
            raise KeyError(f"no wizard {name!r}{did_you_mean(str(name), self.names())}") from None

    def get(self, name: str) -> WizardFunction | None:
        """The function of wizard ``name`` (any case), or None."""
        item = self._items.get(name.lower())
        return None if item is None else item[1]

    def name_of(self, name: str) -> str | None:
        """The name as registered."""
        item = self._items.get(name.lower())
        return None if item is None else item[0]

    def names(self) -> list[str]:
        """Registered names, as written, sorted case-insensitively."""
        return sorted((n for n, _ in self._items.values()), key=str.lower)

    def as_dict(self) -> dict[str, WizardFunction]:
        return {n: self._items[n.lower()][1] for n in self.names()}

    def copy(self) -> WizardRegistry:
        new = WizardRegistry(builtins=False)
        new._items = dict(self._items)
        return new

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name.lower() in self._items

    def __len__(self) -> int:
        return len(self._items)


def _describe(function: Callable) -> str:
    return getattr(function, "__qualname__", None) or repr(function)


def register_wizard(name: str, function: WizardFunction, *, replace: bool = False) -> WizardFunction:
    """Register a wizard in the default registry (see :meth:`WizardRegistry.register`).

    Examples
    --------
    >>> _ = register_wizard("Greet", lambda ctx, who: [f"(hello {who})"])
    >>> "Greet" in wizards()
    True
    >>> _ = unregister_wizard("Greet")
    """
    return DEFAULT_REGISTRY.register(name, function, replace=replace)


def unregister_wizard(name: str) -> WizardFunction:
    """Remove a wizard from the default registry; returns its function."""
    return DEFAULT_REGISTRY.unregister(name)


def wizards() -> dict[str, WizardFunction]:
    """The default registry's wizards, name to function, sorted by name."""
    return DEFAULT_REGISTRY.as_dict()


def wizard(name: str | None = None, *, replace: bool = False,
           registry: WizardRegistry | None = None) -> Callable[[WizardFunction], WizardFunction]:
    """Decorator form of :func:`register_wizard`; the name defaults to the function's.

    Examples
    --------
    >>> @wizard("Spot", registry=WizardRegistry(builtins=False))
    ... def spot(ctx, x: float, y: float):
    ...     return [f"G0 X{x} Y{y}", "G1 Z-0.1 F10", "G0 Z0.1"]
    """

    def decorate(function: WizardFunction) -> WizardFunction:
        reg = DEFAULT_REGISTRY if registry is None else registry
        reg.register(name or function.__name__, function, replace=replace)
        return function

    return decorate


def needs_wizards(text: str) -> bool:
    """Whether some line of ``text`` starts with two letters, as a wizard call does."""
    return _LOOKS_LIKE_CALL.search(text) is not None


# -- the stage ---------------------------------------------------------------


@dataclass(frozen=True)
class _Argument:
    value: float | str
    column: int  # 1-based


class _BadCall(Exception):
    """An argument problem, already worded: (column, message, kind)."""

    def __init__(self, column: int, message: str, kind: str = "syntax"):
        super().__init__(message)
        self.column, self.message, self.kind = column, message, kind


class WizardStage:
    """Replace wizard calls by the G-code their functions return (GER).

    Lines that start with a two-letter name are calls; other lines pass
    through unchanged, watched for ``(`` comments (which may span lines
    when the flavor allows), G20/G21, G90/G91 and ``M6 Tn`` so a wizard
    knows the units, distance mode and tool at its call.  A flavor without
    ``wizards`` passes every line through.

    Parameters
    ----------
    flavor : Flavor
    registry : WizardRegistry, default: the default registry
    settings : mapping, default: {}
        Copied into the dict every call's context shares; see
        :data:`DEFAULT_SETTINGS` and ``tools`` (tool number to diameter, mm).
    max_lines : int, default: :data:`MAX_LINES`
        Most lines one call may emit (a :class:`~gcodekit.errors.GcodeLimitError`).
    max_motions : int, default: :data:`gcodekit.limits.MAX_MOTIONS`
        Most lines all calls together may emit; the run stops there.

    Examples
    --------
    >>> from gcodekit.errors import Diagnostics
    >>> from gcodekit.preprocess import SourceLine
    >>> from gcodekit.syntax import load_flavor
    >>> stage = WizardStage(load_flavor("ger"), settings={"tool_diameter": 10})
    >>> lines = [SourceLine("G21", 1, "p.ger"), SourceLine("DrillGrid 2 1 20 0 5", 2, "p.ger")]
    >>> [(s.line, s.text) for s in stage.process(lines, Diagnostics("p.ger"))][:5]
    [(1, 'G21'), (2, 'G0 Z5'), (2, 'G0 X0 Y0'), (2, 'G1 Z-5 F200'), (2, 'G0 Z5')]
    """

    name = "wizards"

    def __init__(self, flavor: Flavor, registry: WizardRegistry | None = None, *,
                 settings: Mapping[str, Any] | None = None, max_lines: int = MAX_LINES,
                 max_motions: int = MAX_MOTIONS):
        self.flavor = flavor
        self.registry = DEFAULT_REGISTRY if registry is None else registry
        self.settings = dict(settings or {})
        self.max_lines = int(max_lines)
        self.max_motions = max_motions

    def process(self, lines: Iterable[SourceLine], diagnostics: Diagnostics) -> Iterator[SourceLine]:
        """Yield the lines with every wizard call expanded."""
        if not self.flavor.wizards:
            yield from lines
            return
        yield from _Run(self, diagnostics).run(lines)


class _Run:
    """State of one pass of :class:`WizardStage` over a program."""

    def __init__(self, stage: WizardStage, diagnostics: Diagnostics):
        self.stage = stage
        self.flavor = stage.flavor
        self.diagnostics = diagnostics
        self.settings = dict(stage.settings)
        self.units = "inch" if self.flavor.units == "inch" else "mm"
        self.distance = "absolute"
        self.tool: int | None = None
        self.in_comment = False
        self.emitted = 0  # lines all calls emitted, against max_motions

    def run(self, lines: Iterable[SourceLine]) -> Iterator[SourceLine]:
        from gcodekit.preprocess import SourceLine

        for sl in lines:
            start = self._call_start(sl.text)
            if start < 0:
                self._follow(sl.text)
                yield sl
                continue
            texts = self._expand(sl, start)
            self.emitted += len(texts)
            if self.emitted > self.stage.max_motions:
                self.diagnostics.report(sl.line, start + 1, f"wizard calls emit more than max_motions="
                                        f"{self.stage.max_motions:,} lines; the rest is not run", sl.text,
                                        kind="limit", file=sl.file)
                return
            # A '(' after the arguments opens a comment that goes on past the
            # call: re-open it after the emitted lines, for the reader.
            opened, self.in_comment = self.in_comment, False
            for text in texts:
                self._follow(text)
                yield SourceLine(text, sl.line, sl.file)
            if opened and not self.in_comment:
                self._follow("(")
                yield SourceLine("(", sl.line, sl.file)

    # -- following plain lines ------------------------------------------------

    def _call_start(self, text: str) -> int:
        """Index of a wizard name starting the line, or -1."""
        i = 0
        if self.in_comment:
            j = text.find(")")
            if j < 0:
                return -1
            i = j + 1
        while i < len(text) and text[i] in " \t":
            i += 1
        if not _NAME.match(text, i):
            return -1
        if i > 0 and self.in_comment:
            self.in_comment = False
        return i

    def _follow(self, text: str) -> None:
        """Track comments, units, distance mode and tool through a plain line."""
        fl = self.flavor
        code: list[str] = []
        i, n = 0, len(text)
        while i < n:
            if self.in_comment:
                j = text.find(")", i)
                if j < 0:
                    break
                self.in_comment = False
                i = j + 1
                code.append(" ")
                continue
            c = text[i]
            if c == "(" and fl.paren_comments:
                j = text.find(")", i + 1)
                if j < 0:
                    self.in_comment = fl.multiline_comments
                    break
                i = j + 1
                code.append(" ")
            elif c in fl.line_comments:
                break
            else:
                code.append(c)
                i += 1
        plain = "".join(code)
        if not any(ch in plain for ch in "gGmM"):
            return
        for m in _UNITS.finditer(plain):
            self.units, self.distance = {
                "20": ("inch", self.distance), "21": ("mm", self.distance),
                "90": (self.units, "absolute"), "91": (self.units, "incremental"),
            }[m.group(1)]
        if _TOOL_CHANGE.search(plain):
            m = _TOOL.search(plain)
            if m:
                self.tool = int(m.group(1))

    # -- calls ---------------------------------------------------------------

    def _expand(self, sl: SourceLine, start: int) -> list[str]:
        """The lines a call emits; [] after reporting a problem."""
        text = sl.text
        name = _NAME.match(text, start).group()
        try:
            function = self.stage.registry.get(name)
            if function is None:
                with contextlib.suppress(_BadCall):  # read on, for a comment left open
                    self._arguments(text, start + len(name))
                raise _BadCall(start + 1, f"unknown wizard {name!r}"
                               + did_you_mean(name, self.stage.registry.names()))
            args = self._arguments(text, start + len(name))
            values = _bind(self.stage.registry.name_of(name), function, args, start + 1)
            return self._call(function, values, args, sl, start)
        except _BadCall as bad:
            self._report(sl, bad.column, bad.message, bad.kind)
            return []

    def _arguments(self, text: str, i: int) -> list[_Argument]:
        """Numbers and "strings" after the name, to the end of the line."""
        fl = self.flavor
        args: list[_Argument] = []
        n = len(text)
        stops = " \t" + "".join(fl.statement_separators) + ("(" if fl.paren_comments else "")
        if i < n and text[i] not in stops:
            raise _BadCall(i + 1, f"expected a space after the wizard name, not {text[i]!r}")
        while i < n:
            c = text[i]
            if c in " \t":
                i += 1
                continue
            if c in fl.statement_separators:
                raise _BadCall(i + 1, f"wizard arguments run to the end of the line; {c!r} cannot end the call")
            if c == "(" and fl.paren_comments:
                j = text.find(")", i + 1)
                if j < 0:
                    self.in_comment = fl.multiline_comments
                    return args
                i = j + 1
                continue
            if c == '"':
                j = text.find('"', i + 1)
                if j < 0:
                    raise _BadCall(i + 1, "string argument without its closing '\"'")
                args.append(_Argument(text[i + 1 : j], i + 1))
                end = j + 1
            else:
                m = _NUMBER.match(text, i)
                end = m.end() if m else i
                if m is None or (end < n and text[end] not in stops + '"'):
                    k = end
                    while k < n and text[k] not in " \t":
                        k += 1
                    raise _BadCall(i + 1, f"wizard argument {text[i:k]!r} is neither a number nor a \"string\"")
                value = float(m.group())
                if not math.isfinite(value):
                    raise _BadCall(i + 1, f"number {m.group()[:20]!r}... is out of range", "expression")
                args.append(_Argument(value, i + 1))
            if end < n and text[end] not in stops:
                raise _BadCall(end + 1, f"expected a space between wizard arguments, not {text[end]!r}")
            i = end
        return args

    def _context(self, sl: SourceLine) -> WizardContext:
        diameter = None
        tools = self.settings.get("tools")
        if self.tool is not None and isinstance(tools, Mapping) and self.tool in tools:
            diameter = tools[self.tool]
        elif "tool_diameter" in self.settings:
            diameter = self.settings["tool_diameter"]
        if diameter is not None:
            diameter = float(diameter) if self.units == "mm" else float(diameter) / MM_PER_INCH
        return WizardContext(self.units, diameter, self.settings, self.distance, sl.file, sl.line)

    def _call(self, function: WizardFunction, values: list, args: list[_Argument],
              sl: SourceLine, start: int) -> list[str]:
        name = _NAME.match(sl.text, start).group()
        limit = self.stage.max_lines
        out: list[str] = []
        try:
            result = function(self._context(sl), *values)
            if result is None:
                return []
            if isinstance(result, str):
                result = [result]
            for item in result:
                if not isinstance(item, str):
                    raise TypeError(f"returned {type(item).__name__} {item!r}, not a line of text")
                for piece in item.split("\n"):
                    out.append(piece.rstrip("\r"))
                if len(out) > limit:
                    raise _BadCall(start + 1, f"wizard {name} emitted more than {limit} lines (the limit)", "limit")
        except _BadCall:
            raise
        except WizardArgumentError as exc:
            column = args[exc.index].column if exc.index is not None and 0 <= exc.index < len(args) else start + 1
            raise _BadCall(column, f"{name}: {exc}", "expression") from None
        except GcodeError as exc:
            raise _BadCall(start + 1, f"{name}: {exc.diagnostic.message if exc.diagnostic else exc}",
                           _kind(exc)) from None
        except Exception as exc:
            message = f"wizard {name} failed: {type(exc).__name__}: {exc}"
            if self.diagnostics.mode == "strict":
                diag = Diagnostic(self.diagnostics.file, sl.line, start + 1, "error", message, sl.text)
                raise WizardError(message, diag) from exc
            self._report(sl, start + 1, message, "syntax")
            return []
        return out

    def _report(self, sl: SourceLine, column: int, message: str, kind: str) -> None:
        self.diagnostics.report(sl.line, column, message, sl.text, kind=kind, file=sl.file)


def _kind(exc: GcodeError) -> str:
    for kind, cls in (("limit", GcodeLimitError), ("expression", GcodeExpressionError),
                      ("machine", GcodeMachineError)):
        if isinstance(exc, cls):
            return kind
    return "syntax"


def _annotation(parameter: inspect.Parameter) -> str | None:
    """'float', 'int', 'str' or None (anything) from a parameter's annotation."""
    ann = parameter.annotation
    if ann is inspect.Parameter.empty:
        return None
    text = ann if isinstance(ann, str) else getattr(ann, "__name__", str(ann))
    kinds = {t.strip() for t in text.split("|")} & {"float", "int", "str"}
    return kinds.pop() if len(kinds) == 1 else None


def _bind(name: str, function: WizardFunction, args: list[_Argument], column: int) -> list:
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
        raise _BadCall(column, f"{name} takes {_usage(params[1:])}; got {len(values)} argument"
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
            raise _BadCall(arg.column, f"{name}: {p.name} must be a number, not the string {arg.value!r}",
                           "expression")
        if want == "str" and not isinstance(arg.value, str):
            raise _BadCall(arg.column, f"{name}: {p.name} must be a \"string\", not a number", "expression")
        if want == "int":
            if arg.value != int(arg.value):
                raise _BadCall(arg.column, f"{name}: {p.name} must be a whole number, not {arg.value:g}",
                               "expression")
            values[k] = int(arg.value)
    return values


def _usage(params: list[inspect.Parameter]) -> str:
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


# -- built-in wizards ----------------------------------------------------------


def _n(value: float) -> str:
    """A coordinate to 4 decimals, trailing zeros dropped ('-0' is '0')."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _positive(value: float, what: str, index: int) -> float:
    if not value > 0:
        raise WizardArgumentError(f"{what} must be positive, not {value:g}", index)
    return value


def _steps(span: float, step: float, index: int | None) -> int:
    """How many steps of at most ``step`` cover ``span`` (at least 1)."""
    count = span / step
    if count > _MAX_STEPS:
        raise WizardArgumentError(f"needs {count:.3g} steps (more than {_MAX_STEPS})", index)
    return max(1, math.ceil(count - 1e-9))


class _Tool:
    """The tool and feeds a built-in uses, in the program's units."""

    def __init__(self, ctx: WizardContext, stepdown: float | None, stepover: float | None,
                 stepdown_index: int, stepover_index: int):
        self.diameter = ctx.tool_diameter if ctx.tool_diameter is not None else ctx.setting("tool_diameter")
        if not self.diameter > 0:
            raise WizardArgumentError(f"tool diameter must be positive, not {self.diameter:g}")
        self.radius = self.diameter / 2
        self.stepdown = self.radius if stepdown is None else _positive(stepdown, "stepdown", stepdown_index)
        if stepover is None:
            stepover = ctx.setting("stepover") * self.diameter
        elif not 0 < stepover <= self.diameter * (1 + 1e-9):
            raise WizardArgumentError(f"stepover must be above 0 and at most the tool diameter "
                                      f"{_n(self.diameter)}, not {stepover:g}", stepover_index)
        self.stepover = stepover
        self.feed = _n(ctx.setting("feed"))
        self.plunge = _n(ctx.setting("plunge_feed"))
        self.safe = _n(ctx.setting("safe_z"))
        self.incremental = ctx.distance == "incremental"

    def depths(self, depth: float, index: int) -> Iterator[float]:
        """Pass depths: stepdown, 2 stepdown, ..., the last one at ``depth``."""
        for k in range(1, _steps(depth, self.stepdown, index) + 1):
            yield -min(k * self.stepdown, depth)

    def start(self) -> Iterator[str]:
        if self.incremental:
            yield "G90"
        yield f"G0 Z{self.safe}"

    def end(self) -> Iterator[str]:
        yield f"G0 Z{self.safe}"
        if self.incremental:
            yield "G91"


def _evenly(low: float, high: float, step: float, index: int) -> Iterator[float]:
    """``low`` .. ``high`` inclusive, evenly spaced at most ``step`` apart."""
    count = _steps(high - low, step, index) if high > low else 0
    return (low + (high - low) * k / count if k < count else high for k in range(count + 1))


def pocket(ctx: WizardContext, width: float, height: float, depth: float,
           stepdown: float | None = None, stepover: float | None = None) -> Iterator[str]:
    """``Pocket width height depth [stepdown] [stepover]``: rectangular pocket on X0 Y0.

    The pocket spans X -width/2..width/2, Y -height/2..height/2 and Z0 down
    to Z-depth.  At each depth (``stepdown`` apart, default half the tool
    diameter) the tool zigzags along X, rows ``stepover`` apart (default 0.4
    tool diameters), then follows the walls once; it plunges at the
    lower-left corner.  The tool centre stays within the outline shrunk by
    the tool radius.
    """
    tool = _Tool(ctx, stepdown, stepover, 3, 4)
    _positive(width, "width", 0), _positive(height, "height", 1), _positive(depth, "depth", 2)
    for value, what, index in ((width, "width", 0), (height, "height", 1)):
        if value < tool.diameter * (1 - 1e-9):
            raise WizardArgumentError(f"pocket {what} {value:g} is less than the tool diameter "
                                      f"{_n(tool.diameter)}", index)
    x0, x1 = -width / 2 + tool.radius, width / 2 - tool.radius
    y0, y1 = -height / 2 + tool.radius, height / 2 - tool.radius
    x0, x1 = min(x0, x1), max(x0, x1)
    y0, y1 = min(y0, y1), max(y0, y1)
    yield from tool.start()
    yield f"G0 X{_n(x0)} Y{_n(y0)}"
    for z in tool.depths(depth, 2):
        yield f"G1 Z{_n(z)} F{tool.plunge}"
        for k, y in enumerate(_evenly(y0, y1, tool.stepover, 4)):
            if k:
                yield f"G1 Y{_n(y)}"
            yield f"G1 X{_n(x1 if k % 2 == 0 else x0)}" + ("" if k else f" F{tool.feed}")
        yield f"G1 X{_n(x0)} Y{_n(y0)}"
        yield f"G1 X{_n(x1)}"
        yield f"G1 Y{_n(y1)}"
        yield f"G1 X{_n(x0)}"
        yield f"G1 Y{_n(y0)}"
    yield from tool.end()


def circle_pocket(ctx: WizardContext, diameter: float, depth: float,
                  stepdown: float | None = None, stepover: float | None = None) -> Iterator[str]:
    """``CirclePocket diameter depth [stepdown] [stepover]``: round pocket on X0 Y0.

    At each depth the tool plunges at the centre and cuts concentric full
    circles (G3, I/J) at most ``stepover`` apart, out to the wall.
    """
    tool = _Tool(ctx, stepdown, stepover, 2, 3)
    _positive(diameter, "diameter", 0), _positive(depth, "depth", 1)
    outer = diameter / 2 - tool.radius
    if outer < -1e-9 * diameter:
        raise WizardArgumentError(f"pocket diameter {diameter:g} is less than the tool diameter "
                                  f"{_n(tool.diameter)}", 0)
    radii = list(_evenly(0.0, max(outer, 0.0), tool.stepover, 3))[1:]
    yield from tool.start()
    yield "G0 X0 Y0"
    for k, z in enumerate(tool.depths(depth, 1)):
        if k and radii:
            yield "G1 X0 Y0"
        yield f"G1 Z{_n(z)} F{tool.plunge}"
        for j, r in enumerate(radii):
            yield f"G1 X{_n(r)} Y0" + ("" if j else f" F{tool.feed}")
            yield f"G3 X{_n(r)} Y0 I{_n(-r)} J0"
    yield from tool.end()


def _drill(tool: _Tool, x: float, y: float, depth: float, peck: float | None, ctx: WizardContext) -> Iterator[str]:
    yield f"G0 X{_n(x)} Y{_n(y)}"
    if peck is None:
        yield f"G1 Z{_n(-depth)} F{tool.plunge}"
    else:
        clearance = ctx.length(0.5)  # stop short of the last peck's bottom: chips
        previous = 0.0
        for k in range(1, _steps(depth, peck, 5) + 1):
            z = -min(k * peck, depth)
            if k > 1:
                yield f"G0 Z{_n(min(previous + clearance, 0.0))}"
            yield f"G1 Z{_n(z)} F{tool.plunge}"
            if z > -depth:
                yield f"G0 Z{tool.safe}"
            previous = z
    yield f"G0 Z{tool.safe}"


def drill_grid(ctx: WizardContext, nx: int, ny: int, dx: float, dy: float, depth: float,
               peck: float | None = None) -> Iterator[str]:
    """``DrillGrid nx ny dx dy depth [peck]``: a grid of holes, the first at X0 Y0.

    Columns are ``dx`` apart along X, rows ``dy`` apart along Y (either may
    be negative); holes are drilled row by row, alternating direction.
    With ``peck`` the tool backs out to ``safe_z`` after each ``peck`` of
    depth.
    """
    tool = _Tool(ctx, None, None, -1, -1)
    for value, what, index in ((nx, "nx", 0), (ny, "ny", 1)):
        if value < 1:
            raise WizardArgumentError(f"{what} must be at least 1, not {value}", index)
    if nx * ny > _MAX_STEPS:
        raise WizardArgumentError(f"{nx} x {ny} holes is more than {_MAX_STEPS}", 0)
    _positive(depth, "depth", 4)
    if peck is not None:
        _positive(peck, "peck", 5)
    yield from tool.start()
    for j in range(ny):
        for i in range(nx) if j % 2 == 0 else range(nx - 1, -1, -1):
            yield from _drill(tool, i * dx, j * dy, depth, peck, ctx)
    if tool.incremental:
        yield "G91"


def bolt_circle(ctx: WizardContext, count: int, diameter: float, depth: float,
                start_angle: float = 0.0) -> Iterator[str]:
    """``BoltCircle count diameter depth [start_angle]``: holes on a circle on X0 Y0.

    The first hole is at ``start_angle`` degrees counter-clockwise from +X;
    the others follow counter-clockwise, evenly spaced.
    """
    tool = _Tool(ctx, None, None, -1, -1)
    if count < 1:
        raise WizardArgumentError(f"count must be at least 1, not {count}", 0)
    if count > _MAX_STEPS:
        raise WizardArgumentError(f"{count} holes is more than {_MAX_STEPS}", 0)
    _positive(diameter, "diameter", 1), _positive(depth, "depth", 2)
    yield from tool.start()
    for k in range(count):
        angle = math.radians(start_angle + 360.0 * k / count)
        yield from _drill(tool, diameter / 2 * math.cos(angle), diameter / 2 * math.sin(angle), depth, None, ctx)
    if tool.incremental:
        yield "G91"


def face(ctx: WizardContext, width: float, height: float, depth: float,
         stepdown: float | None = None, stepover: float | None = None) -> Iterator[str]:
    """``Face width height depth [stepdown] [stepover]``: face X0..width, Y0..height.

    The top is cut down to Z-depth in passes ``stepdown`` apart; each pass
    zigzags along X, from one tool radius outside the left edge to one
    outside the right, with rows from Y0 to Y``height`` at most
    ``stepover`` apart, so the cutter covers the whole rectangle.
    """
    tool = _Tool(ctx, stepdown, stepover, 3, 4)
    _positive(width, "width", 0), _positive(height, "height", 1), _positive(depth, "depth", 2)
    x0, x1 = -tool.radius, width + tool.radius
    yield from tool.start()
    for z in tool.depths(depth, 2):
        yield f"G0 X{_n(x0)} Y0"
        yield f"G1 Z{_n(z)} F{tool.plunge}"
        for k, y in enumerate(_evenly(0.0, height, tool.stepover, 4)):
            if k:
                yield f"G1 Y{_n(y)}"
            yield f"G1 X{_n(x1 if k % 2 == 0 else x0)}" + ("" if k else f" F{tool.feed}")
        yield f"G0 Z{tool.safe}"
    if tool.incremental:
        yield "G91"


_BUILTINS: dict[str, WizardFunction] = {
    "Pocket": pocket,
    "CirclePocket": circle_pocket,
    "DrillGrid": drill_grid,
    "BoltCircle": bolt_circle,
    "Face": face,
}

#: The registry :class:`WizardStage` uses by default, with the built-ins.
DEFAULT_REGISTRY = WizardRegistry()

__all__ = [
    "WizardStage",
    "WizardRegistry",
    "WizardContext",
    "WizardError",
    "WizardWarning",
    "WizardArgumentError",
    "register_wizard",
    "unregister_wizard",
    "wizards",
    "wizard",
    "needs_wizards",
    "DEFAULT_REGISTRY",
    "DEFAULT_SETTINGS",
    "MAX_LINES",
]
