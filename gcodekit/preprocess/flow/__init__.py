"""Preprocess stage: O-word control flow, executed line by line (RS274NGC, Fanuc).

:class:`ControlFlowStage` runs a program's control flow the way LinuxCNC 2.9's
``interp_o_word.cc`` does and emits the lines it executes, in order, with
their parameters substituted by a :class:`~gcodekit.preprocess.ParameterStage`
sharing one :class:`~gcodekit.preprocess.ParameterStore`.  Every emitted line
keeps the file and line number it was written on, so a loop body run three
times yields three lines pointing at the same source line.

The program is read whole, its O-words are parsed (:mod:`.statements`) and
matched once (:mod:`.linking`: ``if`` to ``elseif``/``else``/``endif``,
``while`` to ``endwhile``, ``do`` to its closing ``while``, ``repeat`` to
``endrepeat``, ``sub`` to ``endsub``), then executed with a program counter
(:mod:`.run`):

* ``oN sub`` .. ``oN endsub [value]`` define a subroutine, skipped where it
  stands; ``oN call [a] [b] ...`` runs it with the arguments in #1 .. #30
  (the rest keep the caller's values; all 30 are restored on return) and
  fresh local named parameters (``#<name>``; ``#<_name>`` is global).
  ``oN return [value]`` or ``endsub [value]`` sets ``#<_value>`` and
  ``#<_value_returned>`` = 1; both are cleared just before each call.
  ``#<_call_level>`` is how deep the calls are nested (0 in the main program).
  Labels are numbers or ``<names>``; a call's label may be computed
  (``o[#101+2] call``).  A subroutine not in the program is read from
  ``name.ngc`` in the program's directory or the stage's ``search_path``
  (:mod:`.library`).
* ``if`` / ``elseif`` / ``else`` / ``endif``; ``while`` / ``endwhile``;
  ``do`` / ``while``; ``repeat [n]`` / ``endrepeat``; ``break`` and
  ``continue`` name the loop they leave or restart.  A condition is true
  when not 0.
* Fanuc-style numbered programs (:mod:`.fanuc`): ``O1000`` alone on a line
  starts program 1000, ``M98 P1000 [L3]`` runs it (L times; L0 not at all)
  with #1 .. #30 shared and ``M99`` returns.  M99 in the main program, which
  LinuxCNC takes as an endless restart, ends it here (with a warning).
* ``M2`` or ``M30`` ends the program: nothing after it is emitted.
* A lathe cycle (G70-G72) reads the profile of its ``Q`` subroutine when it
  runs (:mod:`.profile`).

Limits (:class:`~gcodekit.errors.GcodeLimitError`, which ends the run even
in lenient mode): loop iterations, call depth and executed lines.  Mistakes
in the structure (an ``endwhile`` without ``while``, an unknown
subroutine, ...) are reported with their file, line and column; in lenient
mode the faulty O-word is ignored and the run goes on.
"""

from .stage import MAX_CALL_DEPTH, MAX_LINES, ControlFlowStage
from .statements import KEYWORDS, OWord

__all__ = ["ControlFlowStage", "MAX_CALL_DEPTH", "MAX_LINES", "KEYWORDS", "OWord"]
