"""The control-flow stage: its settings and limits; each run is a :class:`~.run.Run`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Iterable, Iterator, Sequence

from ...errors import Diagnostics
from ...limits import MAX_ITERATIONS, MAX_MOTIONS
from .run import Run
from ..parameters import MachineView, ParameterStage, ParameterStore

if TYPE_CHECKING:
    from ..lines import SourceLine
    from ...syntax.flavor import Flavor

#: Deepest nesting of subroutine calls.  LinuxCNC has
#: ``INTERP_SUB_ROUTINE_LEVELS`` = 10 call frames, frame 0 being the main
#: program, and refuses the call that would open frame 10.
MAX_CALL_DEPTH = 9
#: Most lines (O-words included) executed in one run; bounds the work of
#: calls that fan out without looping.
MAX_LINES = 5_000_000


class ControlFlowStage:
    """Execute O-word control flow and substitute parameters (LinuxCNC 2.9).

    Emits the lines the program executes, in execution order, with
    parameters and expressions substituted and assignments applied as
    :class:`~gcodekit.preprocess.ParameterStage` does (every read on a line
    sees the values from before its assignments).  O-word lines, ``M98``
    and ``M99`` words and lines left empty are not emitted; a line keeps
    the file and line number it was written on.  See
    :mod:`gcodekit.preprocess.flow` for the statements,
    :data:`MAX_CALL_DEPTH` and :data:`MAX_LINES`, and
    :mod:`gcodekit.limits` for ``max_iterations`` (every loop iteration and
    M98 repeat counts; a repeat count larger than what is left is refused
    before the first repeat) and ``max_motions`` (the blocks emitted).  A
    flavor without ``parameters`` passes lines through.

    Parameters
    ----------
    flavor : Flavor
    store : ParameterStore, default: a new, empty store
    search_path : sequence of path, default: ()
        Directories searched, after the program's own, for ``name.ngc``
        when ``o<name> call`` names a subroutine the program lacks.
    fanuc_subs : bool, default: True
        Fanuc-style subprograms run (M98/M99); False refuses them, as
        rs274 does under ``[RS274NGC] DISABLE_FANUC_STYLE_SUB``.
    max_iterations, max_call_depth, max_lines, max_motions : int
        Limits; default :data:`~gcodekit.limits.MAX_ITERATIONS`,
        :data:`MAX_CALL_DEPTH`, :data:`MAX_LINES`,
        :data:`~gcodekit.limits.MAX_MOTIONS`.
    machine : MachineView, optional
        The machine behind the store's system parameters.  A loop whose
        iterations read it costs a machine run each, so an endless one
        would take minutes to reach ``max_iterations``: it is stopped as
        soon as an iteration leaves the parameters, the loops' state and
        the machine exactly as the one before (the next ones can only
        repeat it).

    Examples
    --------
    >>> from gcodekit.errors import Diagnostics
    >>> from gcodekit.preprocess import SourceLine
    >>> from gcodekit.syntax.flavor import Flavor
    >>> stage = ControlFlowStage(Flavor("ngc", paren_comments=True, parameters=True))
    >>> program = ["#1 = 0", "o1 while [#1 LT 3]", "G1 X[#1 * 2]", "#1 = [#1 + 1]", "o1 endwhile"]
    >>> lines = [SourceLine(t, n, "demo.ngc") for n, t in enumerate(program, 1)]
    >>> [(s.line, s.text) for s in stage.process(lines, Diagnostics("demo.ngc"))]
    [(3, 'G1 X0'), (3, 'G1 X2'), (3, 'G1 X4')]
    """

    name = "control_flow"

    def __init__(self, flavor: Flavor, store: ParameterStore | None = None, *,
                 search_path: Sequence[str | os.PathLike] = (), fanuc_subs: bool = True,
                 max_iterations: int = MAX_ITERATIONS, max_call_depth: int = MAX_CALL_DEPTH,
                 max_lines: int = MAX_LINES, max_motions: int = MAX_MOTIONS, machine: MachineView | None = None):
        self.flavor = flavor
        self.machine = machine
        self.parameters = ParameterStage(flavor, store)
        self.store = self.parameters.store
        self.search_path = [Path(p) for p in search_path]
        self.fanuc_subs = fanuc_subs
        self.max_iterations = max_iterations
        self.max_call_depth = max_call_depth
        self.max_lines = max_lines
        self.max_motions = max_motions

    def process(self, lines: Iterable[SourceLine], diagnostics: Diagnostics) -> Iterator[SourceLine]:
        """Yield the executed lines, substituted, in execution order."""
        if not self.flavor.parameters:
            yield from lines
            return
        yield from Run(self, diagnostics).run(list(lines))
