"""Fanuc-style subprograms: ``O1000`` starts program 1000, ``M98 P1000 [L3]`` runs it, ``M99`` returns.

The called program shares #1 .. #30 with its caller (no arguments, no
fresh locals).  ``L`` repeats the call (L0: not at all); each repeat
counts against ``max_iterations``, and a count larger than what is left is
refused before the first repeat.  M99 in the main program, which LinuxCNC
takes as an endless restart, ends it here (with a warning).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..parameters import format_number

if TYPE_CHECKING:
    from ..lines import SourceLine
    from .run import Run


def m98(run: Run, line: SourceLine, p: float | None, count: float) -> None:
    """``M98 P<p> L<count>``: enter program ``p`` (``count`` times)."""
    if p is None:
        run.report(line, 1, "M98 needs a P word: the program number to call")
        return
    repeats = math.floor(count + 0.5)
    if repeats <= 0:
        return
    run.check_repeats(line, repeats, f"M98 L{repeats}")
    target = run.library.find(format_number(float(math.floor(p + 0.5))), run.library.programs, line, run.code)
    if target is not None:
        run.enter(line, target, None, fanuc=True, repeats=repeats)


def m99(run: Run, line: SourceLine) -> bool:
    """``M99``: run the program again while repeats are left, else return to the caller.

    Returns True when it ends the run (M99 in the main program).
    """
    if not run.frames:
        run.report(line, 1, "M99 in the main program restarts it endlessly on LinuxCNC; "
                   "treated as the program end", severity="warning")
        return True
    frame = run.frames[-1]
    if not frame.fanuc:
        run.report(line, 1, "M99 ends a subroutine called by 'o- call'; endsub or return expected")
    if frame.left > 0 and frame.start is not None:
        run.tick(line)
        frame.left -= 1
        run.store.leave_call()
        run.store.enter_call(None)
        run.code, run.pc = frame.start
        run.counters = {}
        return False
    run.leave()
    return False
