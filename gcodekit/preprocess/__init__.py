"""Preprocess stage: text lines in, plain G-code lines out.

Preprocessing rewrites a program's lines before they are read into words:
parameters and expressions (:mod:`.parameters`, :mod:`.expressions`), O-word
control flow and subprograms (:mod:`.flow`) and GER wizards (:mod:`.wizards`).
Each step is a :class:`Stage` that maps a stream of :class:`SourceLine` to
another, keeping every line's source file and 1-based line number so later
diagnostics still point at what the user wrote.  :func:`run_stages` chains
stages lazily, so a large file streams through with bounded memory.
"""

from __future__ import annotations

import dataclasses
from typing import Iterable, Iterator

from ..errors import Diagnostics, GcodeError
from .expressions import evaluate as _evaluate
from .expressions import parse
from .flow import ControlFlowStage
from .lines import SourceLine, Stage
from .parameters import ParameterStage, ParameterStore, needs_parameters


def run_stages(
    lines: Iterable[SourceLine], stages: Iterable[Stage], diagnostics: Diagnostics
) -> Iterator[SourceLine]:
    """Chain ``stages`` over ``lines``, first stage first; lazy.

    Examples
    --------
    >>> from gcodekit.syntax.flavor import Flavor
    >>> stage = ParameterStage(Flavor("ngc", parameters=True))
    >>> lines = [SourceLine("#<r> = 5", 1, "p.ngc"), SourceLine("G0 X[#<r> * 2]", 2, "p.ngc")]
    >>> [s.text for s in run_stages(lines, [stage], Diagnostics("p.ngc"))]
    ['', 'G0 X10']
    """
    stream: Iterable[SourceLine] = lines
    for stage in stages:
        stream = stage.process(stream, diagnostics)
    return iter(stream)


def evaluate(text: str, store: ParameterStore | None = None) -> float:
    """Value of one RS274NGC value or bracketed expression.

    Parameters
    ----------
    text : str
        A number, ``[expression]``, ``#parameter`` or function call.
    store : ParameterStore, default: a new, empty store

    Raises
    ------
    GcodeExpressionError, GcodeLimitError
        ``diagnostic.column`` is the 1-based column in ``text``.

    Examples
    --------
    >>> evaluate("[2 + 3 * 4 ** 2]"), evaluate("ATAN[1]/[1]"), evaluate("[-7 MOD 3]")
    (50.0, 45.0, 2.0)
    """
    try:
        return _evaluate(parse(text), ParameterStore() if store is None else store)
    except GcodeError as exc:
        # Quote the text, as every diagnostic does.
        where = dataclasses.replace(exc.diagnostic, text=text)
        raise type(exc)(where.message, where) from None


__all__ = [
    "SourceLine",
    "Stage",
    "run_stages",
    "needs_parameters",
    "evaluate",
    "parse",
    "ParameterStore",
    "ParameterStage",
    "ControlFlowStage",
]
