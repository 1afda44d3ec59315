"""A lathe cycle's profile, read from its Q subroutine when the cycle line runs.

rs274 reads the subroutine when G70-G72 runs, without moving: its control
flow and parameters run as in a call, ``#<_x>`` and ``#<_z>`` give the
profile's point so far (the cycle's X/Z at first).  The blocks it reads are
attached to the cycle line as a :class:`~gcodekit.lathe_profile.LatheProfile`,
so later stages run the cycle without the subroutine.
"""

from __future__ import annotations

import contextlib
import math
import re
from dataclasses import replace
from typing import TYPE_CHECKING

from ...lathe_profile import LatheProfile, ProfileBlock
from ..expressions import compact
from .mcodes import WORD
from .statements import OWord
from ..parameters import format_number

if TYPE_CHECKING:
    from ..lines import SourceLine
    from .run import Run

# Cheap test for a line that may hold a lathe cycle G70-G72
_MAYBE_LATHE_CYCLE = re.compile(r"[gG][ \t0]*7[ \t]*[012]")
_LATHE_CYCLES = frozenset((70.0, 71.0, 71.1, 71.2, 72.0, 72.1, 72.2))


def with_profile(run: Run, line: SourceLine) -> SourceLine:
    """A lathe cycle (G70-G72) with the profile its Q subroutine gives attached.

    Any other line, or a cycle whose subroutine is not found (reported), is
    returned as it is.
    """
    if not _MAYBE_LATHE_CYCLE.search(line.text):
        return line
    words = _code_words(run, line.text)
    if not any(letter == "g" and value in _LATHE_CYCLES for letter, value in words) or "q" not in dict(words):
        return line
    given = dict(words)
    label = format_number(float(math.floor(given["q"] + 0.5)))
    target = run.library.find(label, run.library.subs, line, run.code)
    if target is None:
        return line
    point = {"_x": given.get("x", math.nan), "_z": given.get("z", math.nan)}
    blocks = []
    depth = len(run.frames)
    run.enter(line, target, [], fanuc=False)
    with run.store.overlay(lambda key: point.get(key) if isinstance(key, str) else None):
        while len(run.frames) > depth:
            items = run.code.items
            if run.pc >= len(items):
                run.leave()
                continue
            st = items[run.pc]
            if isinstance(st, OWord):
                run.oword(st)
                continue
            run.pc += 1
            text = run.substitute(st).text
            code = dict(_code_words(run, text))
            for axis, key, letter in (("x", "_x", "u"), ("z", "_z", "w")):
                if axis in code:
                    point[key] = code[axis]
                elif letter in code:
                    point[key] += code[letter]
            code_text = " ".join(text[a:b] for a, b in run.code_ranges(text)).strip()
            if code_text:  # without the written form's separator and comment marks
                blocks.append(ProfileBlock.read(code_text.replace(";", " ").replace("(", " ").replace(")", " ")))
    return replace(line, profile=LatheProfile(tuple(blocks)))


def _code_words(run: Run, text: str) -> list[tuple[str, float]]:
    """(letter, value) of the plain-number words of a line, comments left out."""
    out = []
    for start, end in run.code_ranges(text):
        for letter, number in WORD.findall(compact(text, start, end).chars):
            with contextlib.suppress(ValueError):
                out.append((letter, float(number)))
    return out
