"""Emulate stage: tool tables (LinuxCNC ``.tbl`` files) for tool length offsets.

A line of a LinuxCNC tool table is ``T<tool> P<pocket> [X..] [Y..] [Z..]
[A..] [B..] [C..] [U..] [V..] [W..] [D<diameter>] [I<front angle>]
[J<back angle>] [Q<orientation>] ;comment``.  Values are in the machine's
units, which the caller states (rs274 run standalone reads them in inches).

Examples
--------
>>> table = ToolTable.parse("T1 P1 Z0.5 D0.125 ;end mill\\n", units="inch")
>>> float(table[1].offset[2]), table[1].diameter
(12.7, 3.175)
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError
from ..units import mm_per

_WORD = re.compile(r"([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
#: A line rs274 2.9 reads: only these letters, each with a number (it skips one with ``WX0.05`` or ``K5``)
_LINE = re.compile(r"\s*(?:[TPXYZABCUVWDIJQ]\s*[-+]?(?:\d+\.?\d*|\.\d+)\s*)*", re.IGNORECASE)
_AXES = "XYZABC"


@dataclass
class Tool:
    """One tool: offsets along X..C (mm, degrees), diameter (mm), lathe orientation and angles.

    ``orientation`` is the Q word, LinuxCNC's lathe tool orientation 1-9
    (where the tool tip's control point sits on the nose radius); 0 is a
    mill tool.
    """

    number: int
    pocket: int = 0
    offset: np.ndarray = field(default_factory=lambda: np.zeros(6))
    diameter: float = 0.0
    comment: str = ""
    orientation: int = 0
    front_angle: float = 0.0  # I, degrees (lathe tools)
    back_angle: float = 0.0  # J, degrees


class ToolTable(dict):
    """Tools by number, with lengths in mm.

    ``skipped`` lists the lines LinuxCNC skips, ``(line number, text,
    reason)``: lines without a T word (an old-format table's, for one) and
    lines with a word it does not know.
    """

    source = "<tool table>"
    skipped: list[tuple[int, str, str]]

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.skipped = []

    @classmethod
    def parse(cls, text: str, *, units: str = "mm", source: str = "<tool table>") -> "ToolTable":
        """Read a LinuxCNC tool table; ``units`` is ``"mm"`` or ``"inch"``."""
        if units not in ("mm", "inch"):
            raise ConfigError(f"tool table units must be 'mm' or 'inch', not {units!r}")
        scale = mm_per(units)
        table = cls()
        table.source = source
        for number, raw in enumerate(text.splitlines(), 1):
            body, _, comment = raw.partition(";")
            if not body.strip():
                continue
            words = {k.upper(): float(v) for k, v in _WORD.findall(body)}
            if not _LINE.fullmatch(body):
                table.skipped.append((number, raw.strip(), "a word LinuxCNC's tool table does not have"))
                continue
            if "T" not in words:
                table.skipped.append((number, raw.strip(), "no T word"))
                continue
            offset = np.array([words.get(a, 0.0) * (scale if a in "XYZ" else 1.0) for a in _AXES])
            tool = Tool(int(words["T"]), int(words.get("P", 0)), offset, words.get("D", 0.0) * scale,
                        comment.strip(), int(words.get("Q", 0)), words.get("I", 0.0), words.get("J", 0.0))
            table[tool.number] = tool
        return table

    @classmethod
    def read(cls, path: str | os.PathLike, *, units: str = "mm") -> "ToolTable":
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError as exc:
            raise ConfigError(f"cannot read tool table {os.fspath(path)!r}: {exc}") from exc
        return cls.parse(text, units=units, source=os.fspath(path))

    def offset(self, number: int) -> np.ndarray:
        """Offsets of tool ``number`` (zeros for an unknown tool)."""
        tool = self.get(int(number))
        return tool.offset.copy() if tool is not None else np.zeros(6)
