"""Pipeline: one Operation from the chunks -- the machine, joined columns, strict mode's first error."""

from __future__ import annotations

import os

import numpy as np

from ..columns import Column, GrowingRuns, Waypoints, stored
from ..emulate.machine import Machine
from ..emulate.presets import MachineConfig
from ..errors import Diagnostics, GcodeError
from ..growing import GrowingColumn
from ..limits import PLAUSIBLE_TIME_S, Limits
from ..model.operation import Operation
from ..parse import CommandTable, GcodeParser
from ..parse.join import GrowingDecimals
from ..plan import planner_settings
from ..read import Blocks
from ..syntax import Flavor
from .program import Program, quote_diagnostics

__all__ = ["new_machine", "empty_table", "WaypointJoiner", "WRITTEN", "raise_first_run", "warn_implausible_time"]


def new_machine(flavor: Flavor, config: MachineConfig, diagnostics: Diagnostics, limits: Limits = Limits(),
                machine_config: str | os.PathLike | None = None) -> Machine:
    """The machine that runs a program of ``flavor`` (the flavor says how it reads blocks)."""
    return Machine(config, diagnostics, rapid_is_feed=flavor.rapid_is_feed, initial_units=flavor.units,
                   initial_extrusion=flavor.extrusion, rs274_blocks=flavor.block_split == "modal",
                   polar_incremental_only=flavor.polar_incremental_only, max_motions=limits.max_motions,
                   zero_feed=flavor.zero_feed,
                   minimum_feed=minimum_feed(config, machine_config) if flavor.zero_feed == "minimum_speed" else 0.0)


def minimum_feed(config: MachineConfig, machine_config: str | os.PathLike | None = None) -> float:
    """The slowest the machine's planner moves, mm/min (RepRapFirmware's ``minimum_movement_speed``, M203 I,
    from the preset or the firmware's own config file); 0 when its planner has none."""
    if not config.planner:
        return 0.0
    settings = planner_settings(config.planner, config.planner_settings, machine_config)
    return float(getattr(settings, "minimum_movement_speed", 0.0))


def empty_table(parser: GcodeParser, program: Program) -> CommandTable:
    return parser.parse(Blocks.empty(program.name))


#: The columns that hold the program's own numbers where it writes absolute positions (relative E too): kept
#: as decimal units while every value comes back from them bit for bit (see :class:`.parse.join.GrowingDecimals`)
WRITTEN = ("x", "y", "z", "a", "b", "c", "de")


class WaypointJoiner:
    """The waypoint columns of a program's chunks, joined as each chunk is emulated.

    Gives what joining them all at the end would, value for value: a single
    chunk's columns as they are; otherwise, in a :class:`~.columns.Waypoints`
    mapping, each column either as its runs of equal values (a
    :class:`~.columns.RunColumn`, while it has few: a print's feed, layer
    height and flow), a zero-stride view where the whole column is one value,
    decimal units (the positions of :data:`WRITTEN`, while they hold them
    bit for bit), or one array (a :class:`~gcodekit.growing.GrowingColumn`:
    no second copy of the program's columns, no page touched twice), with
    ``command`` counting the rows of the whole program.
    """

    def __init__(self) -> None:
        self._first: tuple[dict[str, np.ndarray], int] | None = None  # a lone chunk is kept as it is
        self._keys: list[str] = []
        self._rows = 0  # command rows of the chunks joined so far
        self._size = 0  # their waypoints
        self._columns: dict[str, GrowingColumn | GrowingDecimals] = {}
        self._runs: dict[str, GrowingRuns] = {}  # the columns kept as runs so far

    def add(self, part: dict[str, np.ndarray], rows: int) -> None:
        """The next chunk's columns (its ``command`` counting from 0) and its number of command rows."""
        if not self._keys and self._first is None:
            self._first = (part, rows)
            return
        if self._first is not None:  # a second chunk: from now on, joined
            (first, first_rows), self._first = self._first, None
            self._keys = list(first)
            self._runs = {k: GrowingRuns(first[k].dtype) for k in self._keys if k != "command"}
            self._take(first, first_rows)
        self._take(part, rows)

    def _take(self, part: dict[str, np.ndarray], rows: int) -> None:
        for key in self._keys:
            col = part[key]
            if key == "command":
                self._column(key, col.dtype).append(col + np.int32(self._rows))  # int32: max_motions bounds the rows
                continue
            runs = self._runs.get(key)
            if runs is not None and runs.add(col):
                continue
            if runs is not None:  # too many runs to be worth keeping: the values so far written out
                del self._runs[key]
                self._column(key, runs.dtype).append(np.asarray(runs.finish()))
            self._column(key, col.dtype).append(col)
        self._size += part["command"].size
        self._rows += rows

    def _column(self, key: str, dtype: np.dtype) -> GrowingColumn | GrowingDecimals:
        column = self._columns.get(key)
        if column is None:
            written = key in WRITTEN and dtype == np.float64
            column = self._columns[key] = GrowingDecimals() if written else GrowingColumn(dtype)
        return column

    def finish(self) -> dict[str, np.ndarray] | Waypoints:
        """The joined columns (the joiner is spent)."""
        if self._first is not None:
            return self._first[0]
        out: dict[str, Column] = {}
        for key in self._keys:
            runs = self._runs.get(key)
            out[key] = runs.finish() if runs is not None else self._columns[key].finish()
        return Waypoints(out)


def raise_first_run(op: Operation, program: Program, reading_error: GcodeError | None) -> None:
    """Strict mode: raise the error of the line that ran first, as rs274 stops there.

    The machine's errors (some found only by the compensation pass, after
    the whole program ran) are ranked by the first row of their line; the
    reader's or parameter stage's error came after every line emulated.
    """
    found = op.diagnostics
    errors = [k for k, d in enumerate(found.items) if d.severity == "error"]
    if not errors:
        if reading_error is not None:
            raise reading_error
        return
    quote_diagnostics(found, program)
    lines = op.table.line
    numbers, first_rows = np.unique(lines, return_index=True)
    first_row = dict(zip(numbers.tolist(), first_rows.tolist()))
    raw = {key: number for number, key in found.elsewhere.items()}  # (file, line) -> the number rows carry

    def ran_at(k: int) -> tuple[int, int]:
        d = found.items[k]
        number = d.line if d.file == found.file else raw.get((d.file, d.line), -1)
        return first_row.get(number, len(lines)), k

    found.raise_item(min(errors, key=ran_at))


def warn_implausible_time(op: Operation) -> None:
    """A warning, at its longest step, when the program would run longer than
    :data:`~gcodekit.limits.PLAUSIBLE_TIME_S` (a year): a runaway arc, dwell or feed, not a real job."""
    time = stored(op.waypoints, "time")  # a block at a time: planned times stay computed when read
    total, longest, most = 0.0, 0, -np.inf
    for lo in range(0, len(time), 1 << 16):
        block = np.nan_to_num(np.asarray(time[lo:lo + (1 << 16)], float))  # NaN as 0, inf as the largest float
        total += float(block.sum())
        k = int(np.argmax(block)) if block.size else 0
        if block.size and block[k] > most:
            longest, most = lo + k, float(block[k])
    if not total > PLAUSIBLE_TIME_S:
        return
    row = int(op.waypoints["command"][longest])
    years = total / (365.25 * 86400.0)
    op.diagnostics.warn(int(op.table.line[row]), 1, f"the program would run for {years:,.1f} years (more than a "
                        f"year, no real job); this step alone takes {most / 86400.0:,.1f} days")
