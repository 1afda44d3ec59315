"""Judge one program: gcodekit's motions against rs274's, motion by motion in machine coordinates.

The two agree when rs274 runs the program and gcodekit, emulating LinuxCNC
(``machine="linuxcnc"``, the same tool table read in inches, the F number
kept across G20/G21 as standalone rs274 does), reports no error and gives
the same motions: type, end point and arc centre in machine coordinates,
units, plane and, in G94, feed; or when both refuse the program on the same
line (gcodekit in strict mode raises for the line that ran first).

A disagreement gets a *cluster*: what differs and the codes of the line it
shows on (the line of gcodekit's first differing motion, or the refused
line), with the canned cycle in force, so that ``run.py`` can count
differences by feature.
"""

from __future__ import annotations

import re
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
for folder in (HERE.parent, HERE.parents[2]):  # errors.py beside the golden cases; tests/ for test_linuxcnc_golden
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))

from .rs274 import TOOL_TABLE, Reference, run_rs274  # noqa: E402

#: End points agree within this many mm: rs274 prints %.4f in the units in force when a number is sent,
#: and a machine point sums up to five such numbers (program point, G92, G5x, tool offset, turned by
#: the rotation); an offset sent in inches and used in mm is off by up to 0.00127 mm.
ATOL_MM = 0.008
_CODE = re.compile(r"(?<![A-Z#<_])([GM])\s*0*(\d+(?:\.\d+)?)", re.I)
_NUMBERS = re.compile(r"[-+]?\d+(?:\.\d*)?")


@dataclass(frozen=True)
class Verdict:
    """The outcome for one program."""

    agree: bool
    kind: str  # agree | agree-error | motions | count | missed-error | extra-error | error-line | timeout
    cluster: str
    detail: str
    line: int | None = None  # the line the difference shows on


def codes_of(line: str) -> list[str]:
    """The G and M codes of one line, normalized (``g01`` -> ``G1``), comments left out.

    Examples
    --------
    >>> codes_of("g01 X1 (G2 in a comment) M03")
    ['G1', 'M3']
    """
    bare = re.sub(r"\([^)]*\)|;.*", "", line)
    return [f"{letter.upper()}{float(number):g}" for letter, number in _CODE.findall(bare)]


def line_features(lines: list[str], number: int | None) -> str:
    """The codes of line ``number`` (1-based) and the canned cycle in force there, as a cluster label."""
    if number is None or not 1 <= number <= len(lines):
        return "?"
    text = lines[number - 1]
    codes = codes_of(text)
    cycle = ""
    for earlier in reversed(lines[:number]):
        found = [c for c in codes_of(earlier) if c in _MOTION_CODES]
        if found:
            cycle = found[-1] if found[-1] in _CYCLE_CODES else ""
            break
    words = "".join(sorted({w for w in re.findall(r"[A-Z]", re.sub(r"\([^)]*\)|;.*|#<[^>]*>|\[.*\]", "",
                                                                         text.upper())) if w not in "GMNO"}))
    label = " ".join(codes) or ("O-word" if text.strip().lower().startswith("o") else f"words {words}")
    if cycle and cycle not in codes:
        label += f" (in {cycle})"
    return label


_CYCLE_CODES = {f"G{n}" for n in (73, 74, 81, 82, 83, 84, 85, 86, 87, 88, 89)}
_MOTION_CODES = _CYCLE_CODES | {"G0", "G1", "G2", "G3", "G80", "G33", "G38.2", "G5", "G5.1"}


def reference_table(ref: Reference) -> pd.DataFrame:
    """rs274's motions as :func:`test_linuxcnc_golden.reference_table` wants them."""
    from test_linuxcnc_golden import reference_table as table

    frame = pd.DataFrame(ref.motions).replace("", np.nan).infer_objects()
    if frame.empty:
        return pd.DataFrame(columns=["src_line", "line_match", "motion", "x", "y", "z", "a", "b", "c",
                                     "cx", "cy", "cz", "feed", "feed_mode", "plane", "units"])
    for key in ("arc_rotation", "arc_cx", "arc_cy", "arc_cz", "feed"):
        frame[key] = pd.to_numeric(frame[key])
    frame["src_line"], frame["line_match"] = -1, ""
    return table(frame)


def gcodekit_run(path: Path):
    """(our motions shaped like the canon, line of the error gcodekit raises or None, its message)."""
    import gcodekit
    from gcodekit.errors import GcodeError
    from test_linuxcnc_golden import RS274_STANDALONE, ours_like_canon

    try:
        op = gcodekit.gcode_to_operation(path, plan=False, mode="strict", tool_table=TOOL_TABLE, **RS274_STANDALONE)
    except GcodeError as exc:
        line = exc.diagnostic.line if exc.diagnostic is not None else None
        return None, line, str(exc)
    return ours_like_canon(op), None, ""


def judge(text: str, reference: Reference | None = None, timeout: float = 30.0) -> Verdict:
    """Compare gcodekit with rs274 on program ``text`` (rs274 is run, for ``timeout`` s at most, unless
    ``reference`` is given)."""
    from errors import expected_line
    from test_linuxcnc_golden import AXES, CENTRE, first_difference

    ref = reference if reference is not None else run_rs274(text, timeout=timeout)
    lines = text.split("\n")
    if ref.timed_out:
        return Verdict(False, "timeout", "rs274 timeout", "rs274 ran out of time")
    with tempfile.TemporaryDirectory(prefix="gk_diff_") as tmp:
        path = Path(tmp) / "program.ngc"
        path.write_text(text)
        ours, our_line, our_message = gcodekit_run(path)
        ref_line = None
        if ref.error is not None:
            ref_line, _ = expected_line(path, *ref.error)
    if ref.error is not None:
        message = _NUMBERS.sub("N", ref.error[0])
        if our_line is not None and our_line == ref_line:
            return Verdict(True, "agree-error", "", f"both refuse line {ref_line}: {ref.error[0]}", ref_line)
        if our_line is None:
            return Verdict(False, "missed-error", f"missed error: {message}",
                           f"rs274 refuses line {ref_line} ({ref.error[0]}: {ref.error[1]!r}); gcodekit runs it",
                           ref_line)
        return Verdict(False, "error-line", f"error on another line: {message}",
                       f"rs274 refuses line {ref_line} ({ref.error[0]}); gcodekit line {our_line}: {our_message}",
                       ref_line)
    if our_line is not None:
        ours_message = _NUMBERS.sub("N", our_message.split(": ", 1)[-1].split(":")[0])
        return Verdict(False, "extra-error", f"extra error: {ours_message} [{line_features(lines, our_line)}]",
                       f"gcodekit refuses line {our_line}: {our_message}", our_line)
    expected = reference_table(ref)
    atol = np.where(expected["units"] == "in", ATOL_MM / 25.4, ATOL_MM)[:min(len(ours), len(expected))]
    problem = first_difference(ours, expected, ["motion", "units", "plane"], AXES + CENTRE, atol=atol)
    kind = "motions"
    if problem is None:
        keep = (expected["feed_mode"] == 0).to_numpy() & ~ours["synced"].to_numpy()
        mine, theirs = ours[keep].copy(), expected[keep].copy()
        mine["feed"], theirs["feed"] = mine["feed"].fillna(-1.0), theirs["feed"].fillna(-1.0)
        problem = first_difference(mine, theirs, [], ["feed"], atol=atol[keep[:len(atol)]])
        kind = "feeds"
        if problem is None:
            return Verdict(True, "agree", "", f"{len(expected)} motions")
    line = None
    if problem.startswith("motion count differs"):
        kind = "count"
        extra = re.search(r"ours line (\d+)", problem)  # our first extra motion; else our last one
        line = int(extra.group(1)) if extra else (int(ours["line"].iloc[-1]) if len(ours) else None)
    elif match := re.search(r"first at motion (\d+)", problem):
        line = int(ours["line"].iloc[int(match.group(1))])
    return Verdict(False, kind, f"{kind}: {line_features(lines, line)}", problem, line)
