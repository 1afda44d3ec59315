"""Pipeline: the one feedback loop -- the machine's state flowing back into the parameter stage.

Everything else in gcodekit flows one way, text to blocks to commands to
waypoints.  RS274NGC programs can read what the machine did, though: a probe
move's results (#5061-#5070) and the machine's state (``#5420``,
``#<_x>``, ``#<_imperial>``, ...), and write stored offsets (``#5221``...).
rs274 runs a block before it reads the next, so when a line reads such a
parameter every line before it has run.  :class:`MachineFeedback` gives the
parameter stage that view: it holds the preprocessed lines and emulates
them whenever a line needs the machine (and every
:data:`~gcodekit.read.CHUNK_LINES` lines, so a long loop's output is never
held whole).
"""

from __future__ import annotations

import pickle
import re
from typing import Callable, Iterator

from ..emulate.machine import Machine
from ..emulate.state_parameters import is_state_parameter, is_stored_parameter, machine_parameter, set_machine_parameter
from ..errors import Diagnostics, GcodeError
from ..read import CHUNK_LINES, Blocks, iter_source_blocks, read_source_lines
from ..syntax import Flavor

__all__ = ["MachineFeedback", "MachineStop"]

_PROBE_LINE = re.compile(r"(?i)g\s*0*3\s*8\s*\.\s*[2-5]")  # G38.2 .. G38.5 in a preprocessed line
_PROBE_RESULTS = range(5061, 5071)


class MachineFeedback:
    """Parameters the machine gives the parameter stage: probe results and the machine's state.

    The lines the stages pass on are held back and emulated as soon as a
    line needs the machine: then every line before it has run, as in
    rs274, which runs a block before it reads the next.

    * State parameters (``#5420``, ``#<_x>``, ``#<_imperial>``, ... when the
      flavor has them, see :mod:`gcodekit.emulate.state_parameters`) are
      read from the machine.
    * Probe results (#5061-#5070): rs274 sets them when it reads the block
      after a probe move (``set_probe_data``): #5061-#5066 the X Y Z A B C
      where the probe tripped, in program coordinates, #5067-#5069 U V W
      (0 here) and #5070 1 when it tripped.  Run standalone it has no probe
      input: every probe "trips" at its target and #5070 is 0
      (saicanon.cc), and so does gcodekit (see ``Machine._after_probe``).
      When a line after a probe touches one of them, the results of the
      last probe emulated since the previous time are written to the store
      (axis words alone after a G38.x probe again, so any held line may
      have probed); they stay ordinary, writable parameters.
    """

    def __init__(self, flavor: Flavor, diagnostics: Diagnostics, machine: Machine,
                 emulate: Callable[[Blocks, int], None]):
        self.flavor, self.diagnostics, self.machine, self.emulate = flavor, diagnostics, machine, emulate
        self.held: list = []  # preprocessed lines not emulated yet
        self.probed = False  # a probe line went by: held lines may probe
        self.applied = 0  # probes whose results went to the store
        self.store = None
        self.state_parameters = flavor.state_parameters == "linuxcnc"
        self.runs = 0  # times the held lines were emulated

    def watch(self, lines: Iterator, store) -> Iterator:
        """Pass ``lines`` on, noting probe moves; yields only the lines left at the end.

        Held lines are emulated every :data:`~gcodekit.read.CHUNK_LINES`
        lines, so a long loop's output is never held whole.
        """
        self.store = store
        for line in lines:
            self.held.append(line)
            if _PROBE_LINE.search(line.text.split(";")[0].split("(")[0]):
                self.probed = True
            if len(self.held) >= CHUNK_LINES:
                self._catch_up()
        yield from self.held

    def system(self, key: int | str) -> float | None:
        """The store's system-parameter hook: the machine's value of ``key``, or None."""
        if key in _PROBE_RESULTS:
            if self.probed:  # held lines may hold a probe; earlier ones were emulated already
                self._catch_up()
                self._store_probe_results()
            return None
        if self.state_parameters and is_state_parameter(key):
            self._catch_up()
            return machine_parameter(self.machine, key)
        return None

    def writable(self, key: int | str) -> bool:
        """Whether ``key`` is a stored offset or position the program may write (see ``SystemWrites``)."""
        return self.state_parameters and is_stored_parameter(key)

    def write(self, key: int | str, value: float) -> None:
        """Write a stored offset or position into the machine, once the lines before have run."""
        self._catch_up()
        set_machine_parameter(self.machine, key, value)

    def fingerprint(self) -> bytes:
        """The held lines emulated, then what later lines can read or depend on: the machine's state,
        tools and probe results and the probes not yet written to the store (see ``MachineView``)."""
        self._catch_up()
        m = self.machine
        return pickle.dumps((m.state, m.tools, m._table_z, m._table_w, m.probe_result, m.out_of_budget,
                             m.probes - self.applied, self.probed))

    def _catch_up(self) -> None:
        """Emulate the held lines."""
        if not self.held:
            return
        self.runs += 1
        held, self.held = self.held, []
        try:
            self.emulate(read_source_lines(held, self.flavor, self.diagnostics), 0)
        except GcodeError as exc:  # strict mode: the machine's error, not the parameter stage's
            raise MachineStop(exc) from None

    def _store_probe_results(self) -> None:
        if self.machine.probes > self.applied:
            self.applied = self.machine.probes
            for number, value in zip(range(5061, 5067), self.machine.probe_result):
                self.store.set(number, float(value))
            for number in (5067, 5068, 5069, 5070):  # no U V W axes; never tripped
                self.store.set(number, 0.0)


class MachineStop(Exception):
    """A machine error raised (strict mode) while the parameter stage waited for probe results."""

    def __init__(self, error: GcodeError):
        super().__init__(str(error))
        self.error = error

    @staticmethod
    def read(lines: Iterator, flavor: Flavor, diagnostics: Diagnostics, n_lines: int) -> Iterator[tuple[Blocks, int]]:
        """Preprocessed ``lines`` read a chunk at a time; the last chunk carries the program's
        ``n_lines``."""
        try:
            chunks = iter_source_blocks(lines, flavor, diagnostics)
            blocks = next(chunks)
            for following in chunks:
                yield blocks, 0
                blocks = following
            yield blocks, n_lines
        except MachineStop as stop:
            raise stop.error from None
