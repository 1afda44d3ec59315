"""The M codes that steer the flow, found in a plain line: M2/M30 end, M98 calls, M99 returns."""

from __future__ import annotations

import re
from typing import Callable, NamedTuple

from ..expressions import compact

#: A letter and the number after it, in compacted (lower-case, blank-free) text
WORD = re.compile(r"([a-z])([-+]?[0-9.]*)")
# Cheap test for a line that may hold M2, M30, M98 or M99.
_MAYBE_FLOW_M = re.compile(r"[mM][ \t0]*(?:2|3[ \t]*0|9[ \t]*[89])")


class FlowM(NamedTuple):
    """The flow M code of a line and the words that go with it."""

    code: int  # 2, 30, 98 or 99
    spans: list[tuple[int, int]]  # of the M word and, for M98, its P and L words
    p: float | None  # M98's program number
    count: float  # M98's L: how many times (1 without L)


def flow_m(text: str, code_ranges: Callable[[str], list[tuple[int, int]]]) -> FlowM | None:
    """The first M2, M30, M98 or M99 of ``text`` outside comments, or None."""
    if not _MAYBE_FLOW_M.search(text):
        return None
    found, words = None, {}
    for start, end in code_ranges(text):
        code = compact(text, start, end)
        for match in WORD.finditer(code.chars):
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
    return FlowM(value, spans, p, count)


def remove(text: str, spans: list[tuple[int, int]]) -> str:
    """``text`` without the characters of ``spans``."""
    for start, end in sorted(spans, reverse=True):
        text = text[:start] + text[end:]
    return text
