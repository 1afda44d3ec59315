"""Widgets stage: checking a student's answer in a worksheet.

A worksheet leaves ``answer_1 = None`` for the student to fill in and a test
cell that calls :func:`check` with what gcodekit computes.  A right answer
shows as a green box; a wrong or missing one is written to standard error
(a red box in JupyterLab), saying *what* is wrong and giving a hint, never
the expected value.  Standard error is also what nbgrader's autograder
scores as zero in a test cell, so the same cell serves the student and the
teacher without raising: the worksheet runs to its end either way.

Examples
--------
>>> check(1.03, 1.0333, tolerance=0.01)
Right: 1.03
>>> check(2.5, 1.0333, hint="two ramps and a cruise")
Not quite: 2.5 is too large. Hint: two ramps and a cruise
>>> check((110, 50, 25), (110, 50, 24), names=("x", "y", "z"))
Not quite: z is too large (x and y are right).
>>> check(None, 5.0)
Not answered yet: put your answer in the cell above and run both cells again.
"""

from __future__ import annotations

import html
import sys
from dataclasses import dataclass
from typing import Sequence

import numpy as np

_COLORS = {True: ("#e5f5e8", "#2e7d32"), False: ("#fdecea", "#c62828"), None: ("#f4f4f4", "#777")}


@dataclass
class Check:
    """The outcome of one answer: ``ok`` is True when right, False when wrong, None when not answered."""

    ok: bool | None
    message: str

    def __bool__(self) -> bool:
        return bool(self.ok)

    def __repr__(self) -> str:
        return self.message

    def _repr_html_(self) -> str:
        back, edge = _COLORS[self.ok]
        return (f'<div class="gcodekit-check" style="background:{back};border-left:4px solid {edge};'
                f'padding:4px 10px">{html.escape(self.message)}</div>')

    def _ipython_display_(self) -> None:
        """A right answer as a green box; anything else on standard error (nbgrader scores that zero)."""
        if self.ok:
            from IPython.display import HTML, display

            display(HTML(self._repr_html_()))
        else:
            print(self.message, file=sys.stderr)


def check(answer, expected, *, tolerance: float = 1e-3, hint: str = "",
          names: Sequence[str] | None = None) -> Check:
    """Compare ``answer`` with ``expected``: numbers (or sequences of them) within ``tolerance``, else equality.

    A wrong answer's message says which part is wrong and whether it is too
    large or too small, never the expected value.

    Parameters
    ----------
    answer : number, sequence of numbers, str or None
    expected : the same kind
    tolerance : float, default: 1e-3
        Absolute difference allowed per number.
    hint : str, default: ""
        Said when the answer is wrong.
    names : sequence of str, optional
        Names of a sequence's parts (``("x", "y", "z")``), used to say which is wrong.
    """
    if answer is None or answer is ...:
        return Check(None, "Not answered yet: put your answer in the cell above and run both cells again.")
    hint = f" Hint: {hint}" if hint else ""
    try:
        a, e = np.asarray(answer, float), np.asarray(expected, float)
    except (TypeError, ValueError):
        if isinstance(expected, str) and str(answer).strip().lower() == expected.strip().lower():
            return Check(True, f"Right: {_short(answer)}")
        if isinstance(expected, str):
            return Check(False, f"Not quite: {_short(answer)} is not the answer.{hint}")
        return Check(False, f"Not quite: {_short(answer)} is not a number or a list of numbers.{hint}")
    if e.ndim == 0 and a.ndim == 0:
        if abs(a - e) <= tolerance:
            return Check(True, f"Right: {_short(answer)}")
        return Check(False, f"Not quite: {_short(answer)} is too {'large' if a > e else 'small'}.{hint}")
    if a.shape != e.shape:
        return Check(False, f"Not quite: give {e.size} numbers, {_short(answer)} has {a.size}.{hint}")
    labels = list(names) if names is not None and len(names) == e.size else [f"number {k + 1}" for k in range(e.size)]
    a, e = a.ravel(), e.ravel()
    wrong = [k for k in range(e.size) if not abs(a[k] - e[k]) <= tolerance]
    if not wrong:
        return Check(True, f"Right: {_short(answer)}")
    said = ", ".join(f"{labels[k]} is too {'large' if a[k] > e[k] else 'small'}" for k in wrong)
    right = [labels[k] for k in range(e.size) if k not in wrong]
    tail = f" ({_join(right)} {'is' if len(right) == 1 else 'are'} right)" if right else ""
    return Check(False, f"Not quite: {said}{tail}.{hint}")


def _join(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def _short(value) -> str:
    if isinstance(value, (tuple, list, np.ndarray)):
        return "(" + ", ".join(_short(v) for v in value) + ")"
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    return repr(value) if isinstance(value, str) else str(value)
