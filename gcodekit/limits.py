"""Limits on the work one program may cause, shared by the preprocess, emulate and plan stages.

Real programs stay far below them.  A program that runs away -- a canned
cycle repeated a billion times, a peck depth of a micron, an endless loop,
an arc cut into a billion chords -- stops at a limit with an error naming
its line, and before the memory is spent: every expansion is counted before
it is made.

* ``max_motions`` (:data:`MAX_MOTIONS`): the motions a program may make.
  The emulator counts its waypoints (one per block, plus every move a
  cycle, thread, lathe cycle or spline expands into), the planner the moves
  arcs are cut into, and the preprocess stage the blocks its loops,
  subprogram repeats and wizards generate -- each against the same limit.
* ``max_iterations`` (:data:`MAX_ITERATIONS`): loop iterations and
  subprogram repeats (``M98 L``), all loops together; a repeat count larger
  than what is left is refused before the first repeat runs.  A loop that
  reads the machine each time round (a probe's result), each iteration a
  machine run, stops earlier: as soon as one iteration changes nothing
  (see :class:`~gcodekit.preprocess.ControlFlowStage`).

Both are settable: ``gcode_to_operation(..., max_motions=..., max_iterations=...)``
and the command line's ``--max-motions`` and ``--max-iterations``.

Examples
--------
>>> budget = MotionBudget(1000)
>>> budget.spend(600)
>>> budget.room
400
>>> budget.spend(500)
Traceback (most recent call last):
...
gcodekit.limits.TooManyMotions: 500 motions, more than the 400 left of max_motions=1,000
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import ConfigError

__all__ = ["MAX_MOTIONS", "MAX_ITERATIONS", "PLAUSIBLE_TIME_S", "Limits", "MotionBudget", "TooManyMotions", "check_limit"]

#: Default ``max_motions``: above any real program (a 150 mm FFF plate makes about
#: 3 million; the largest LFAM and DED programs tens of millions).
MAX_MOTIONS = 50_000_000
#: Default ``max_iterations``: an endless loop that moves nothing stops within seconds.
MAX_ITERATIONS = 100_000
#: A program planned to run longer than this (a year, in seconds) gets a warning: no machine runs it.
PLAUSIBLE_TIME_S = 365.25 * 86400.0


@dataclass(frozen=True)
class Limits:
    """The limits one run of the pipeline works under (see the module docstring)."""

    max_motions: int = MAX_MOTIONS
    max_iterations: int = MAX_ITERATIONS

    def __post_init__(self) -> None:
        check_limit("max_motions", self.max_motions)
        check_limit("max_iterations", self.max_iterations)


class TooManyMotions(Exception):
    """An expansion would pass ``max_motions``; the stage that made it reports its line."""

    def __init__(self, count: float, room: int, limit: int):
        many = f"{count:,.0f}" if count < 1e18 else "countless"
        super().__init__(f"{many} motions, more than the {max(room, 0):,} left of max_motions={limit:,}")


class MotionBudget:
    """The motions a program may still make, spent as stages make them.

    Parameters
    ----------
    limit : int, default: :data:`MAX_MOTIONS`
    """

    def __init__(self, limit: int = MAX_MOTIONS):
        self.limit = check_limit("max_motions", limit)
        self.used = 0

    @property
    def room(self) -> int:
        """Motions left."""
        return self.limit - self.used

    def spend(self, count: int) -> None:
        """Count ``count`` motions made, or raise :class:`TooManyMotions` (nothing spent)."""
        self.check(count)
        self.used += count

    def check(self, count: float) -> None:
        """Raise :class:`TooManyMotions` if ``count`` motions would not fit (nothing spent)."""
        if count > self.room:
            raise TooManyMotions(count, self.room, self.limit)


def check_limit(name: str, value: int) -> int:
    """A limit option must be a positive whole number."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ConfigError(f"{name} must be a whole number of 1 or more, not {value!r}")
    return value
