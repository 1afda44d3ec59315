"""The wizard stage: wizard calls in a program replaced by the lines their functions return."""

from __future__ import annotations

import contextlib
import re
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Mapping

from ...errors import (
    Diagnostic,
    Diagnostics,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    GcodeMachineError,
    did_you_mean,
)
from ...limits import MAX_MOTIONS
from ..lines import SourceLine
from .arguments import Argument, BadCall, bind, read_arguments
from .context import MAX_LINES, WizardArgumentError, WizardContext, WizardFunction
from .registry import DEFAULT_REGISTRY, NAME, WizardRegistry
from ...units import MM_PER_INCH

if TYPE_CHECKING:
    from ...syntax.flavor import Flavor

_LOOKS_LIKE_CALL = re.compile(r"(?m)^[ \t]*[A-Za-z]{2}")
_UNITS = re.compile(r"(?<![A-Za-z])[gG][ \t]*0*(2[01]|9[01])(?![0-9.])")
_TOOL_CHANGE = re.compile(r"(?<![A-Za-z])[mM][ \t]*0*6(?![0-9.])")
_TOOL = re.compile(r"(?<![A-Za-z])[tT][ \t]*([0-9]+)")


class WizardError(GcodeError, RuntimeError):
    """A wizard function failed; ``__cause__`` is its exception."""


def needs_wizards(text: str) -> bool:
    """Whether some line of ``text`` starts with two letters, as a wizard call does."""
    return _LOOKS_LIKE_CALL.search(text) is not None


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
        """Yield ``lines`` with every wizard call replaced by what it emits."""
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
        if not NAME.match(text, i):
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
        name = NAME.match(text, start).group()
        try:
            function = self.stage.registry.get(name)
            if function is None:
                with contextlib.suppress(BadCall):  # read on, for a comment left open
                    self.in_comment = read_arguments(text, start + len(name), self.flavor)[1]
                raise BadCall(start + 1, f"unknown wizard {name!r}"
                              + did_you_mean(name, self.stage.registry.names()))
            args, self.in_comment = read_arguments(text, start + len(name), self.flavor)
            values = bind(self.stage.registry.name_of(name), function, args, start + 1)
            return self._call(function, values, args, sl, start)
        except BadCall as bad:
            self._report(sl, bad.column, bad.message, bad.kind)
            return []

    def _context(self, sl: SourceLine) -> WizardContext:
        """What the wizard called on ``sl`` knows: units, tool diameter, settings, distance mode."""
        diameter = None
        tools = self.settings.get("tools")
        if self.tool is not None and isinstance(tools, Mapping) and self.tool in tools:
            diameter = tools[self.tool]
        elif "tool_diameter" in self.settings:
            diameter = self.settings["tool_diameter"]
        if diameter is not None:
            diameter = float(diameter) if self.units == "mm" else float(diameter) / MM_PER_INCH
        return WizardContext(self.units, diameter, self.settings, self.distance, sl.file, sl.line)

    def _call(self, function: WizardFunction, values: list, args: list[Argument],
              sl: SourceLine, start: int) -> list[str]:
        """The lines ``function`` returns for the call on ``sl``; its failures become diagnostics."""
        name = NAME.match(sl.text, start).group()
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
                    raise BadCall(start + 1, f"wizard {name} emitted more than {limit} lines (the limit)", "limit")
        except BadCall:
            raise
        except WizardArgumentError as exc:
            column = args[exc.index].column if exc.index is not None and 0 <= exc.index < len(args) else start + 1
            raise BadCall(column, f"{name}: {exc}", "expression") from None
        except GcodeError as exc:
            raise BadCall(start + 1, f"{name}: {exc.diagnostic.message if exc.diagnostic else exc}",
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

