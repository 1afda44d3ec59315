"""Widgets stage: checking a student's answer in a worksheet.

A worksheet leaves ``answer = None`` for the student to fill in and a cell
that calls :func:`check` with what gcodekit computes; the result shows as a
green or red box, and says so in plain text too.

Examples
--------
>>> check(1.03, 1.0333, tolerance=0.01)
Right: 1.03 (expected 1.0333)
>>> check(None, 5.0)
Not answered yet: put your answer in the cell above and run both cells again.
"""

from __future__ import annotations

import html
from dataclasses import dataclass

import numpy as np


@dataclass
class Check:
    """The outcome of one answer: ``ok`` is True when right, None when not answered."""

    ok: bool | None
    message: str

    def __bool__(self) -> bool:
        return bool(self.ok)

    def __repr__(self) -> str:
        return self.message

    def _repr_html_(self) -> str:
        color = {True: ("#e5f5e8", "#2e7d32"), False: ("#fdecea", "#c62828"), None: ("#f4f4f4", "#777")}[self.ok]
        return (f'<div class="gcodekit-check" style="background:{color[0]};border-left:4px solid {color[1]};'
                f'padding:4px 10px">{html.escape(self.message)}</div>')


def check(answer, expected, *, tolerance: float = 1e-3, hint: str = "") -> Check:
    """Compare ``answer`` with ``expected``: numbers (or sequences of them) within ``tolerance``, else equality.

    Parameters
    ----------
    answer : number, sequence of numbers, str or None
    expected : the same kind
    tolerance : float, default: 1e-3
        Absolute difference allowed per number.
    hint : str, default: ""
        Said when the answer is wrong.
    """
    if answer is None or answer is ...:
        return Check(None, "Not answered yet: put your answer in the cell above and run both cells again.")
    try:
        a, e = np.asarray(answer, float), np.asarray(expected, float)
        right = a.shape == e.shape and bool(np.all(np.abs(a - e) <= tolerance))
    except (TypeError, ValueError):
        right = str(answer).strip().lower() == str(expected).strip().lower()
    shown = _short(expected)
    if right:
        return Check(True, f"Right: {_short(answer)} (expected {shown})")
    return Check(False, f"Not quite: {_short(answer)} is not {shown}." + (f" Hint: {hint}" if hint else ""))


def _short(value) -> str:
    if isinstance(value, (tuple, list, np.ndarray)):
        return "(" + ", ".join(_short(v) for v in value) + ")"
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    return str(value)
