"""Shrink a program that shows a difference down to a small reproducer.

Delta debugging (Zeller's ddmin) over the program's lines: drop ever smaller
chunks of lines while the difference stays the same kind, then try dropping
each remaining line alone.  Lines are only removed, never edited, so every
line stays unique (see :func:`generate.unique_lines`) and rs274's error still
names one line.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from .compare import Verdict, judge


def ddmin(lines: list[str], still_fails: Callable[[list[str]], bool], budget: int = 600) -> list[str]:
    """The smallest subsequence of ``lines`` found for which ``still_fails`` holds (``budget`` tries at most).

    Examples
    --------
    >>> ddmin([str(k) for k in range(40)], lambda ls: "7" in ls and "30" in ls)
    ['7', '30']
    """
    tries = 0
    parts = 2
    while len(lines) >= 2 and tries < budget:
        size = math.ceil(len(lines) / parts)
        for start in range(0, len(lines), size):
            candidate = lines[:start] + lines[start + size:]
            tries += 1
            if still_fails(candidate):
                lines, parts = candidate, max(parts - 1, 2)
                break
        else:
            if parts >= len(lines):
                break
            parts = min(parts * 2, len(lines))
    k = 0
    while k < len(lines) and tries < budget:  # one line at a time, to a local minimum
        candidate = lines[:k] + lines[k + 1:]
        tries += 1
        if still_fails(candidate):
            lines = candidate
        else:
            k += 1
    return lines


def same_difference(found: Verdict) -> Callable[[Verdict], bool]:
    """A test that a verdict shows the difference ``found`` shows: the same cluster (kind, and the codes of
    the line it shows on or the error message), so that shrinking does not drift to another difference."""
    def test(verdict: Verdict) -> bool:
        return not verdict.agree and verdict.cluster == found.cluster
    return test


def shrink(text: str, verdict: Verdict | None = None, budget: int = 600) -> tuple[str, Verdict]:
    """A small program showing the same difference as ``text``, and its verdict."""
    verdict = verdict or judge(text)
    if verdict.agree:
        return text, verdict
    keeps = same_difference(verdict)

    def still_fails(lines: list[str]) -> bool:  # (a loop that lost its counter runs until rs274's timeout)
        return keeps(judge("\n".join(lines) + "\n", timeout=3.0))

    lines = ddmin(text.rstrip("\n").split("\n"), still_fails, budget)
    small = "\n".join(lines) + "\n"
    return small, judge(small)
