"""Pipeline: one Operation from the chunks -- the machine, joined columns, strict mode's first error."""

from __future__ import annotations

import numpy as np

from ..emulate.machine import Machine
from ..emulate.presets import MachineConfig
from ..errors import Diagnostics, GcodeError
from ..limits import PLAUSIBLE_TIME_S, Limits
from ..memory import release_freed_memory
from ..model.operation import Operation
from ..parse import CommandTable, GcodeParser
from ..read import Blocks
from ..syntax import Flavor
from .program import Program, quote_diagnostics

__all__ = ["new_machine", "empty_table", "concat_waypoints", "raise_first_run", "warn_implausible_time"]


def new_machine(flavor: Flavor, config: MachineConfig, diagnostics: Diagnostics, limits: Limits = Limits()) -> Machine:
    """The machine that runs a program of ``flavor`` (the flavor says how it reads blocks)."""
    return Machine(config, diagnostics, rapid_is_feed=flavor.rapid_is_feed, initial_units=flavor.units,
                   initial_extrusion=flavor.extrusion, rs274_blocks=flavor.block_split == "modal",
                   polar_incremental_only=flavor.polar_incremental_only, max_motions=limits.max_motions)


def empty_table(parser: GcodeParser, program: Program) -> CommandTable:
    return parser.parse(Blocks.empty(program.name))


def concat_waypoints(parts: list[dict], sizes: list[int]) -> dict[str, np.ndarray]:
    """Join per-chunk waypoint columns, one column at a time to bound memory."""
    if len(parts) == 1:
        return parts[0]
    shift = np.cumsum([0] + sizes[:-1])
    for p, s in zip(parts, shift):  # each chunk counts its commands from 0
        p["command"] = p["command"] + np.int32(s)  # int32: max_motions keeps the rows far below 2**31
    out = {}
    for key in list(parts[0]):
        cols = [p.pop(key) for p in parts]
        first = cols[0][0] if cols[0].size else None
        if key != "command" and first is not None and all(c.strides == (0,) for c in cols) and all(
                (c[0] == first) or (c[0] != c[0] and first != first) for c in cols if c.size):
            out[key] = np.broadcast_to(first, (sum(c.size for c in cols),))
        else:
            out[key] = np.concatenate(cols)
        del cols
        release_freed_memory()  # the chunks' column, freed amid the live ones: give its pages back now
    return out


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
    time = np.nan_to_num(np.asarray(op.waypoints["time"], float))
    total = float(time.sum())
    if not total > PLAUSIBLE_TIME_S:
        return
    longest = int(np.argmax(time))
    row = int(op.waypoints["command"][longest])
    years = total / (365.25 * 86400.0)
    op.diagnostics.warn(int(op.table.line[row]), 1, f"the program would run for {years:,.1f} years (more than a "
                        f"year, no real job); this step alone takes {time[longest] / 86400.0:,.1f} days")
