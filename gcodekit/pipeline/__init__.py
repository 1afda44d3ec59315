"""Pipeline: compose the stages, from a program's text to a planned Operation.

No stage calls another sideways; the pipeline chooses the flavor and the
machine (:mod:`.program`), streams the program through the read, parse and
emulate stages chunk by chunk (:mod:`.source`), joins the chunks into one
:class:`~gcodekit.model.operation.Operation` (:mod:`.assemble`), runs the
compensation pass and the planner, and returns it.  The one loop against
that flow, the machine's state read back by the parameter stage, is
:mod:`.feedback`.

Examples
--------
>>> import gcodekit
>>> df = gcodekit.gcode_file_to_dataframe("G1 X10 Y0 F600\\nG2 X0 Y0 I-5 J0\\n", machine="linuxcnc", plan=False)
>>> df[["motion", "x", "distance"]].round(3).values.tolist()
[['feed', 10.0, 10.0], ['arc_cw', 0.0, 15.708]]
"""

from __future__ import annotations

import dataclasses
import os
from typing import TYPE_CHECKING

import numpy as np

from ..emulate.compensation import compensate, uses_compensation
from ..emulate.presets import MachineConfig, load_machine
from ..errors import ConfigError, Diagnostics, GcodeError, check_choice
from ..limits import MAX_ITERATIONS, MAX_MOTIONS, Limits
from ..memory import release_freed_memory
from ..model import OPERATION_CLASSES, Operation
from ..model.derived import laser_power
from ..model.filament import relative_e_suspect, stated_diameter
from ..parse import GcodeParser
from ..parse.join import TableJoiner
from ..plan import machine_options as firmware_options
from ..plan import planner_settings, run_planner, times_every_move, times_to_plan
from ..read import Blocks
from ..syntax import Flavor
from .assemble import WaypointJoiner, empty_table, new_machine, raise_first_run, warn_implausible_time
from .program import (Program, as_program, check_program_end, note_other_dialect, note_unreadable, note_weak_detection,
                      progress_bar, quote_diagnostics, resolve)
from .source import program_blocks, restore_line_numbers

if TYPE_CHECKING:
    import pandas as pd

    from ..transpile import Transpiler

__all__ = ["gcode_to_operation", "gcode_file_to_dataframe", "parse_program", "emulate_operation",
           "export_event_series_from_gcode", "transpile_program", "resolve", "as_program", "Program"]


def parse_program(source: str | os.PathLike, flavor: str | Flavor | None = None, *,
                  mode: str = "lenient") -> Operation:
    """Read and parse a program without emulating it (no process data yet)."""
    program = as_program(source)
    fl, config, detection = resolve(program, None, flavor)
    diagnostics = Diagnostics(program.name, mode)
    note_weak_detection(detection, diagnostics)
    parser = GcodeParser(fl, diagnostics)
    joiner, n_lines = TableJoiner(), 0
    for blocks, lines in program_blocks(program, fl, diagnostics):
        joiner.add(parser.parse(blocks))
        n_lines += lines
    if detection is None:
        note_other_dialect(program, fl, diagnostics)
    cls = OPERATION_CLASSES[config.process]
    table = joiner.finish()
    if table is None:
        table = empty_table(parser, program)
    restore_line_numbers(table, diagnostics)
    return cls(table, file=program.name, flavor=fl, machine=config, diagnostics=diagnostics, n_lines=n_lines)


def emulate_operation(operation: Operation, machine: str | MachineConfig | None = None) -> Operation:
    """Run a parsed operation on a machine; returns the same operation, emulated."""
    config = operation.machine if machine is None else (
        machine if isinstance(machine, MachineConfig) else load_machine(machine))
    operation.waypoints = new_machine(operation.flavor, config, operation.diagnostics).run(operation.table)
    operation.machine = config
    return operation


def gcode_to_operation(source: str | os.PathLike, machine: str | MachineConfig | None = None, *,
                       flavor: str | Flavor | None = None, mode: str = "lenient",
                       progress: bool = False, machine_config: str | os.PathLike | None = None,
                       plan: bool = True, max_motions: int = MAX_MOTIONS, max_iterations: int = MAX_ITERATIONS,
                       **machine_options) -> Operation:
    """Read, parse and emulate a program into an :class:`Operation`.

    Parameters
    ----------
    source : path or str
        A program file (plain or compressed) or the program text itself.
    machine : str or MachineConfig, default: the preset for the flavor
        ``"linuxcnc"``, ``"marlin"``, ``"klipper"``, ``"grbl"``, ... (see
        :func:`gcodekit.list_machines`).
    flavor : str or Flavor, default: the machine's, else detected
    mode : {"lenient", "strict"}, default: "lenient"
        Lenient records problems in ``operation.diagnostics`` and goes on;
        strict raises the first as a :class:`~gcodekit.errors.GcodeError`.
    progress : bool, default: False
        Show a progress bar on standard error.
    machine_config : path, optional
        The firmware's own configuration (Klipper ``printer.cfg``) for the
        machine's planner; its values replace the preset's.
    plan : bool, default: True
        Time the moves with the machine's motion planner, if it has one.
    max_motions, max_iterations : int, default: 50 million, 100 000
        Limits on the motions the program may make and the loop iterations
        it may run; a program that passes one stops there with an error
        naming the line (see :mod:`gcodekit.limits`).
    **machine_options
        Override preset values (``rapid_feed=5000``).

    Returns
    -------
    Operation, AdditiveOperation or SubtractiveOperation (by the machine's process).

    Examples
    --------
    >>> op = gcode_to_operation("G21\\nG0 X10\\nG1 Y5 F300\\n", machine="linuxcnc", plan=False)
    >>> op.process_data[2].location[:2], op.process_data[2].duration
    ((10.0, 5.0), 1.0)
    """
    check_choice("mode", mode, ("lenient", "strict"))
    limits = Limits(max_motions, max_iterations)
    program = as_program(source)
    fl, config, detection = resolve(program, machine, flavor, **machine_options)
    if machine_config is not None:
        if not config.planner:
            raise ConfigError(f"machine {config.name!r} has no planner to read {os.fspath(machine_config)!r}")
        config = dataclasses.replace(config, **firmware_options(config.planner, machine_config))
    diagnostics = Diagnostics(program.name, mode)
    note_weak_detection(detection, diagnostics)
    if config.process == "additive" and machine_config is None and "filament_diameter" not in machine_options:
        config = _stated_filament(program, config, diagnostics)
    bar = progress_bar(program, progress)
    try:
        op, reading_error, machine_run = _emulated(program, fl, config, diagnostics, limits, bar, machine_config)
        if uses_compensation(op):
            compensate(op, machine_run.tools, machine_run.comp_profile_ends)
        if mode == "strict":
            raise_first_run(op, program, reading_error)
            diagnostics.extend(op.diagnostics)  # its warnings
            op.diagnostics = diagnostics
        if detection is None:  # the flavor was given, or came with the machine
            note_other_dialect(program, fl, op.diagnostics, machine=None if flavor is not None else config.name)
        note_unreadable(op.diagnostics, op.n_lines)
        if plan and config.planner:
            settings = planner_settings(config.planner, config.planner_settings, machine_config)
            if config.planner == "marlin" and machine_config is None:
                settings = _with_slicer_limits(op, settings, chosen=machine is not None)
            if bar is not None:
                bar.set_postfix_str(f"planning ({config.planner})")
            if times_every_move(config.planner):  # the plan replaces the other times: freed before it
                op.waypoints["time"] = times_to_plan(op.waypoints)
            op.attach_plan(run_planner(op, config.planner, settings))
    finally:
        if bar is not None:
            bar.close()
    if config.laser and op.waypoints is not None:
        op.waypoints["power"] = laser_power(op.waypoints)
    if config.process == "additive" and config.extruder_type == "filament" and op.waypoints is not None:
        _note_relative_e(op, fl)
    warn_implausible_time(op)
    restore_line_numbers(op.table, diagnostics)
    quote_diagnostics(op.diagnostics, program)
    return op


def _stated_filament(program: Program, config: MachineConfig, diagnostics: Diagnostics) -> MachineConfig:
    """The machine with the filament diameter the program's header or settings block states, said once."""
    stated = stated_diameter(program.head() + "\n" + program.tail())
    if stated is None or stated == config.filament_diameter:
        return config
    diagnostics.report(1, 1, f"filament diameter {stated:g} mm, as the program states (the {config.name} machine "
                       f"preset says {config.filament_diameter:g} mm); give filament_diameter= to choose otherwise",
                       severity="info")
    return dataclasses.replace(config, filament_diameter=stated)


def _note_relative_e(op: Operation, fl: Flavor) -> None:
    """A warning when E words written relative run as absolute positions (no M83: KISSlicer's files)."""
    suspect = relative_e_suspect(op)
    if suspect is not None and fl.extrusion == "absolute":
        line, falling, moving = suspect
        op.diagnostics.warn(line, 1, f"E falls on {falling} of {moving} extruding moves: the E words look relative "
                            "(as KISSlicer writes them), but the program never selects relative E (M83) and this "
                            f"firmware reads them as absolute positions, so the filament runs back and forth; "
                            "add M83 after the program's G90 if they are relative")


def _with_slicer_limits(op: Operation, settings, chosen: bool):
    """The Marlin planner's settings with the machine limits the slicer assumed, for a file that writes none.

    PrusaSlicer and its forks keep the printer's limits in the configuration
    block at the end of the file; when the program sets none itself (no
    M201, M203, M204 or M205, PrusaSlicer's ``time_estimate_only``), those
    are the limits its estimate assumed, and they replace the preset's.
    Cura keeps them in its printer definition, outside the file: when the
    user ``chosen`` no machine, an info says so.
    """
    from ..parse.table import NAME_ID, in_ids
    from ..plan.marlin import limits_from_slicer

    codes = [NAME_ID[n] for n in ("set_max_accel", "set_max_feed", "set_accel", "set_jerk")]
    if in_ids(op.table.name, codes).any():
        return settings
    figures = op.slicer_figures()
    limits = limits_from_slicer(figures.settings)
    if not limits:
        if figures.family == "cura" and not chosen and not op.machine.printer_names:
            op.diagnostics.report(1, 1, f"{figures.slicer} wrote no machine limits into the file (its estimate used "
                                  "its printer definition's); planned with the preset's: give the printer with "
                                  "--machine (machine=), e.g. creality_ender3", severity="info")
        return settings
    op.diagnostics.report(1, 1, "planned with the machine limits in the slicer's configuration block (the program "
                          "sets none with M201-M205)", severity="info")
    return dataclasses.replace(settings, **limits)


def _emulated(program: Program, fl: Flavor, config: MachineConfig, diagnostics: Diagnostics, limits: Limits, bar,
              machine_config: str | os.PathLike | None = None):
    """Read, parse and emulate the program chunk by chunk into one Operation.

    Returns the operation, the reading error strict mode holds back (the
    error of a line that ran earlier wins, see :func:`.assemble.raise_first_run`)
    and the machine, whose tool table and lathe profiles the compensation
    pass needs.  In strict mode the machine reports to a lenient collector,
    so that every line runs before the first error is chosen.
    """
    parser = GcodeParser(fl, diagnostics)
    machine_diagnostics = Diagnostics(program.name, "lenient") if diagnostics.mode == "strict" else diagnostics
    machine_diagnostics.elsewhere = diagnostics.elsewhere
    m = new_machine(fl, config, machine_diagnostics, limits, machine_config)
    tables, waypoints, n_lines = TableJoiner(), WaypointJoiner(), 0

    def emulate(blocks: Blocks, lines: int) -> None:
        nonlocal n_lines
        table = parser.parse(blocks)
        waypoints.add(m.run(table), len(table))
        tables.add(table)
        n_lines += lines

    reading_error = None
    try:
        for blocks, lines in program_blocks(program, fl, diagnostics, bar, machine=(m, emulate), limits=limits,
                                            search_path=config.subroutine_path + (m.ini.subroutine_path if m.ini else ()),
                                            fanuc_subs=m.ini.fanuc_subs if m.ini else True):
            emulate(blocks, lines)
    except GcodeError as exc:  # strict mode: raised later unless a line run before it failed
        reading_error = exc
    if bar is not None:
        bar.set_postfix_str(f"joining {n_lines:,} lines")
    table = tables.finish()
    if table is None:
        table = empty_table(parser, program)
        waypoints.add(m.run(table), 0)
    if fl.percent_delimiter and program.path is not None and not program.preprocessed and reading_error is None:
        check_program_end(program, table, n_lines, machine_diagnostics)  # rs274 finds it after the last line ran
    op = OPERATION_CLASSES[config.process](
        table, waypoints.finish(), file=program.name, flavor=fl, machine=config,
        diagnostics=machine_diagnostics, n_lines=n_lines, max_motions=limits.max_motions)
    release_freed_memory()  # the reader's per-chunk garbage, before the planner's arrays
    return op, reading_error, m


def gcode_file_to_dataframe(source: str | os.PathLike, machine: str | MachineConfig | None = None,
                            **kwargs) -> "pd.DataFrame":
    """The waypoint table of a program as a DataFrame (see ``Operation.to_dataframe``)."""
    return gcode_to_operation(source, machine, **kwargs).to_dataframe()


def export_event_series_from_gcode(path: str | os.PathLike, output_path: str | os.PathLike, *,
                                   source: str = "material", machine: str | MachineConfig | None = None,
                                   **options) -> "pd.DataFrame":
    """Write the Abaqus event series of a program (see :func:`gcodekit.export.events.write_event_series`)."""
    from ..export.events import write_event_series

    return write_event_series(gcode_to_operation(path, machine, **options), output_path, source=source)


def transpile_program(source: str | os.PathLike, machine: str | MachineConfig | None = None, *,
                      precision: int = 4, **options) -> "Transpiler":
    """The staged simplification of a program given by path or text (see :class:`gcodekit.transpile.Transpiler`).

    ``options`` go to :func:`gcode_to_operation` (``flavor``, ``tool_table``, ...);
    the transpiler works from the emulated, unplanned program.
    """
    from ..transpile import Transpiler

    return Transpiler(gcode_to_operation(source, machine, plan=False, **options), precision=precision)
