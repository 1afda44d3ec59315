"""Pipeline: compose the stages (syntax, preprocess, read, parse, emulate).

No stage calls another sideways; this module chooses the flavor and the
machine, streams the program through the stages chunk by chunk, and joins
the chunks into one :class:`~gcodekit.model.operation.Operation`.

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
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator, Sequence

import numpy as np

from .emulate.machine import Machine
from .model.operation import OPERATION_CLASSES, Operation
from .emulate.presets import MachineConfig, default_machine_for, load_machine, with_options
from .emulate.state_parameters import is_state_parameter, is_stored_parameter, machine_parameter, set_machine_parameter
from .errors import ConfigError, Diagnostics, GcodeError, check_choice
from .limits import MAX_ITERATIONS, MAX_MOTIONS, Limits
from .memory import release_freed_memory
from .parse import CommandTable, GcodeParser
from .parse.table import NAME_ID
from .read import CHUNK_LINES, Blocks, iter_blocks, iter_lines, iter_source_blocks, read_source_lines
from .read.percent import until_closing_percent
from .syntax import Detection, Flavor, detect_flavor, load_flavor

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["gcode_to_operation", "gcode_file_to_dataframe", "parse_program", "emulate_operation", "resolve"]

_O_WORD_LINE = re.compile(r"(?im)^[ \t]*(?:/[ \t]*)?(?:n[0-9. \t]*)?o")
_SUBPROGRAM_M = re.compile(r"(?i)m\s*0*9\s*[89](?![\s.]*\d)")  # M98/M99: Fanuc-style subprogram flow
_PROBE_LINE = re.compile(r"(?i)g\s*0*3\s*8\s*\.\s*[2-5]")  # G38.2 .. G38.5 in a preprocessed line
_PROBE_RESULTS = range(5061, 5071)
#: Line numbers from here up stand for lines of subroutine files (see _number_other_files)
ELSEWHERE_LINES = 1 << 30
_PROGRAM_SUFFIXES = (".gcode", ".gco", ".g", ".nc", ".ngc", ".tap", ".cnc", ".gz", ".txt")


@dataclasses.dataclass
class Program:
    """Where a program comes from: a file path, or text given directly."""

    name: str
    path: Path | None = None
    text: str | None = None
    preprocessed: bool = False  # the preprocess stage ran (and checked how the file ends)

    def chunks(self, diagnostics: Diagnostics | None = None) -> Iterator[bytes]:
        """The program's chunks of whole lines; problems with the file go to ``diagnostics``, if given."""
        return iter_lines(self.path if self.path is not None else self.text, diagnostics)

    def head(self, size: int = 65536) -> str:
        if self.text is not None:
            return self.text[:size]
        for chunk in self.chunks():
            return chunk[:size].decode("utf-8", "replace")
        return ""


def as_program(source: str | os.PathLike) -> Program:
    """A path names a file; a string with a newline, or no such file, is program text."""
    if isinstance(source, os.PathLike):
        if not os.path.isfile(source):
            raise FileNotFoundError(f"no such program file: {os.fspath(source)!r}")
        return Program(str(source), path=Path(source))
    if not isinstance(source, str):
        raise TypeError(f"expected a path or program text, not {type(source).__name__}")
    if "\n" not in source and os.path.isfile(source):
        return Program(source, path=Path(source))
    if "\n" not in source and (os.sep in source or source.lower().endswith(_PROGRAM_SUFFIXES)):
        raise FileNotFoundError(f"no such program file: {source!r}")
    return Program("<string>", text=source)


def resolve(program: Program, machine: str | MachineConfig | None, flavor: str | Flavor | None,
            **machine_options) -> tuple[Flavor, MachineConfig, Detection | None]:
    """Choose flavor and machine: explicit ones first, else detection.

    Returns the flavor, the machine and the detection (None when the flavor
    was given or came with the machine).
    """
    config = None
    if isinstance(machine, MachineConfig):
        config = machine
    elif machine is not None:
        config = load_machine(machine)
    detection = None
    if flavor is not None:
        fl = load_flavor(flavor) if isinstance(flavor, (str, os.PathLike)) else flavor
    elif config is not None:
        fl = load_flavor(config.flavor)
    else:
        detection = detect_flavor(program.head(), program.name if program.path else None)
        fl = load_flavor(detection.name)
    if config is None:
        config = load_machine(default_machine_for(fl.name))
    if machine_options:
        config = with_options(config, **machine_options)
    return fl, config, detection


def _note_weak_detection(detection: Detection | None, diagnostics: Diagnostics) -> None:
    """An info diagnostic naming the flavor detection chose, and why, when its evidence was thin."""
    if detection is not None and detection.weak:
        diagnostics.report(1, 1, f"flavor {detection.name!r} chosen on thin evidence ({'; '.join(detection.reasons)}); "
                           "give the flavor (flavor=, --flavor) if the program is in another dialect", severity="info")


def parse_program(source: str | os.PathLike, flavor: str | Flavor | None = None, *,
                  mode: str = "lenient") -> Operation:
    """Read and parse a program without emulating it (no process data yet)."""
    program = as_program(source)
    fl, config, detection = resolve(program, None, flavor)
    diagnostics = Diagnostics(program.name, mode)
    _note_weak_detection(detection, diagnostics)
    parser = GcodeParser(fl, diagnostics)
    parts, n_lines = [], 0
    for blocks, lines in _blocks(program, fl, diagnostics):
        parts.append(parser.parse(blocks))
        n_lines += lines
    cls = OPERATION_CLASSES[config.process]
    table = CommandTable.concat(parts) if parts else _empty_table(parser, program)
    _restore_line_numbers(table, diagnostics)
    return cls(table, file=program.name, flavor=fl, machine=config, diagnostics=diagnostics, n_lines=n_lines)


def emulate_operation(operation: Operation, machine: str | MachineConfig | None = None) -> Operation:
    """Run a parsed operation on a machine; returns the same operation, emulated."""
    config = operation.machine if machine is None else (
        machine if isinstance(machine, MachineConfig) else load_machine(machine))
    fl = operation.flavor
    m = Machine(config, operation.diagnostics, rapid_is_feed=fl.rapid_is_feed, initial_units=fl.units,
                initial_extrusion=fl.extrusion, rs274_blocks=fl.block_split == "modal",
                polar_incremental_only=fl.polar_incremental_only)
    operation.waypoints = m.run(operation.table)
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
        A program file (plain or gzip) or the program text itself.
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
        from .plan import machine_options as firmware_options

        config = dataclasses.replace(config, **firmware_options(config.planner, machine_config))
    diagnostics = Diagnostics(program.name, mode)
    _note_weak_detection(detection, diagnostics)
    parser = GcodeParser(fl, diagnostics)
    # strict mode raises the machine's first error once the program has run (see _raise_first_run)
    machine_diagnostics = Diagnostics(program.name, "lenient") if mode == "strict" else diagnostics
    machine_diagnostics.elsewhere = diagnostics.elsewhere
    m = Machine(config, machine_diagnostics, rapid_is_feed=fl.rapid_is_feed, initial_units=fl.units,
                initial_extrusion=fl.extrusion, rs274_blocks=fl.block_split == "modal",
                polar_incremental_only=fl.polar_incremental_only, max_motions=limits.max_motions)
    tables, waypoints, n_lines = [], [], 0
    bar = _progress(program, progress)

    def emulate(blocks: Blocks, lines: int) -> None:
        nonlocal n_lines
        table = parser.parse(blocks)
        tables.append(table)
        waypoints.append(m.run(table))
        n_lines += lines

    reading_error = None
    try:
        for blocks, lines in _blocks(program, fl, diagnostics, bar, machine=(m, emulate), limits=limits,
                                     search_path=config.subroutine_path + (m.ini.subroutine_path if m.ini else ()),
                                     fanuc_subs=m.ini.fanuc_subs if m.ini else True):
            emulate(blocks, lines)
    except GcodeError as exc:  # strict mode: raised below unless a line run before it failed
        reading_error = exc
    if bar is not None:
        bar.close()
    cls = OPERATION_CLASSES[config.process]
    sizes = [len(t) for t in tables]
    table = CommandTable.concat(tables) if tables else _empty_table(parser, program)
    if not tables:
        waypoints, sizes = [m.run(table)], [0]
    if fl.percent_delimiter and program.path is not None and not program.preprocessed and reading_error is None:
        _check_program_end(program, table, n_lines, machine_diagnostics)  # rs274 finds it after the last line ran
    op = cls(table, _concat_waypoints(waypoints, sizes), file=program.name, flavor=fl, machine=config,
             diagnostics=machine_diagnostics, n_lines=n_lines, max_motions=limits.max_motions)
    del tables, waypoints
    release_freed_memory()  # the reader's per-chunk garbage, before the planner's arrays
    from .emulate.compensation import compensate, uses_compensation

    if uses_compensation(op):
        compensate(op, m.tools, m.comp_profile_ends)
    if mode == "strict":
        _raise_first_run(op, program, reading_error)
        diagnostics.extend(machine_diagnostics)  # its warnings
        op.diagnostics = diagnostics
    if plan and config.planner:
        from .plan import planner_settings, run_planner

        run_planner(op, config.planner, planner_settings(config.planner, config.planner_settings, machine_config))
    _restore_line_numbers(op.table, diagnostics)
    quote_diagnostics(op.diagnostics, program)
    return op


def gcode_file_to_dataframe(source: str | os.PathLike, machine: str | MachineConfig | None = None,
                            **kwargs) -> "pd.DataFrame":
    """The waypoint table of a program as a DataFrame (see ``Operation.to_dataframe``)."""
    return gcode_to_operation(source, machine, **kwargs).to_dataframe()


# -- helpers -----------------------------------------------------------------------


def _blocks(program: Program, flavor: Flavor, diagnostics: Diagnostics, bar=None,
            machine: tuple[Machine, Callable[[Blocks, int], None]] | None = None,
            search_path: Sequence[str] = (), limits: Limits = Limits(),
            fanuc_subs: bool = True) -> Iterator[tuple[Blocks, int]]:
    """Blocks of the program chunk by chunk, preprocessed when it needs it.

    With ``machine`` (the machine and a function that parses and emulates
    blocks), a program that probes is emulated up to its latest probe move
    whenever a line reads or writes the probe results (#5061-#5070), so they
    hold that probe's results, and state parameters (``#5420``, ``#<_x>``)
    read the machine (see :class:`_MachineFeedback`).
    """
    if flavor.parameters or flavor.wizards:
        from .preprocess import ControlFlowStage, ParameterStore, SourceLine, needs_parameters, run_stages
        from .preprocess.wizards import WizardStage, needs_wizards

        text = b"".join(program.chunks(diagnostics)).decode("utf-8", "replace")
        if flavor.percent_delimiter:  # nothing after a closing % line is read, as in rs274
            text = b"".join(until_closing_percent(iter_lines(text))).decode("utf-8", "surrogateescape")
        # probes and reads of their results may sit in subroutine files: watch every program
        # (until a probe goes by, the watch only collects the lines)
        feedback = _MachineFeedback(flavor, diagnostics, *machine) if machine is not None else None
        store = ParameterStore(system=feedback.system, system_writes=feedback) if feedback is not None else None
        stages = [ControlFlowStage(flavor, store, search_path=search_path, fanuc_subs=fanuc_subs,
                                   max_iterations=limits.max_iterations,
                                   max_motions=limits.max_motions)] if flavor.parameters and (
            needs_parameters(text) or _O_WORD_LINE.search(text) or _SUBPROGRAM_M.search(text)) else []
        if not stages:
            feedback = None  # no parameters for the machine to give
        stages += [WizardStage(flavor, max_motions=limits.max_motions)] if flavor.wizards and needs_wizards(text) else []
        if stages:
            program.preprocessed = True
            lines = text.split("\n")
            if lines and lines[-1] == "":
                lines.pop()
            source = (SourceLine(t.rstrip("\r"), k + 1, program.name) for k, t in enumerate(lines))
            if diagnostics.mode == "strict":
                # The interpreter runs a line at a time: a line before the first
                # preprocess error, in execution order, may fail first.
                early = Diagnostics(diagnostics.file, "lenient")
                out = _until_first_error(run_stages(source, stages, early), early)
                out = _number_other_files(out, program.name, diagnostics)
                if feedback is not None:
                    out = feedback.watch(out, store)
                yield from _MachineStop.read(out, flavor, diagnostics, len(lines))
                diagnostics.extend(d for d in early if d.severity != "error")
                early.raise_first()
                return
            out = _number_other_files(run_stages(source, stages, diagnostics), program.name, diagnostics)
            if feedback is not None:
                out = feedback.watch(out, store)
            yield from _MachineStop.read(out, flavor, diagnostics, len(lines))
            return
        chunks: Iterator[bytes] = iter_lines(text)
    else:
        chunks = program.chunks(diagnostics)
    if flavor.percent_delimiter:
        chunks = until_closing_percent(chunks)
    sizes: list[int] = []

    def counted():
        for c in chunks:
            sizes.append(c.count(b"\n"))
            if bar is not None:
                bar.update(len(c))
            yield c

    for blocks in iter_blocks(counted(), flavor, diagnostics):
        yield blocks, sizes[-1]


def _number_other_files(lines: Iterator, main: str, diagnostics: Diagnostics) -> Iterator:
    """Lines of other files (subroutine files) under numbers of their own.

    Reader, parser and machine know a line by its number only, so a line of
    a subroutine file would pass for the main file's line of that number.
    Such lines get numbers from :data:`ELSEWHERE_LINES` up, which
    ``diagnostics.elsewhere`` maps to their file and line, and which
    :func:`_restore_line_numbers` turns back into the file's own numbers in
    the finished operation.
    """
    numbers: dict[tuple[str, int], int] = {}
    for sl in lines:
        if sl.file != main:
            key = (sl.file, sl.line)
            number = numbers.get(key)
            if number is None:
                number = numbers[key] = ELSEWHERE_LINES + len(numbers)
                diagnostics.elsewhere[number] = key
            sl = dataclasses.replace(sl, line=number)
        yield sl


def _restore_line_numbers(table: CommandTable, diagnostics: Diagnostics) -> None:
    """Rows from other files get their own files' line numbers back (see :func:`_number_other_files`)."""
    if not diagnostics.elsewhere:
        return
    far = table.line >= ELSEWHERE_LINES
    own = np.array([line for _, line in diagnostics.elsewhere.values()], table.line.dtype)
    table.line[far] = own[table.line[far] - ELSEWHERE_LINES]


class _MachineFeedback:
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

    def _catch_up(self) -> None:
        """Emulate the held lines."""
        if not self.held:
            return
        held, self.held = self.held, []
        try:
            self.emulate(read_source_lines(held, self.flavor, self.diagnostics), 0)
        except GcodeError as exc:  # strict mode: the machine's error, not the parameter stage's
            raise _MachineStop(exc) from None

    def _store_probe_results(self) -> None:
        if self.machine.probes > self.applied:
            self.applied = self.machine.probes
            for number, value in zip(range(5061, 5067), self.machine.probe_result):
                self.store.set(number, float(value))
            for number in (5067, 5068, 5069, 5070):  # no U V W axes; never tripped
                self.store.set(number, 0.0)


class _MachineStop(Exception):
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
        except _MachineStop as stop:
            raise stop.error from None


def _raise_first_run(op: Operation, program: Program, reading_error: GcodeError | None) -> None:
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


def _check_program_end(program: Program, table: CommandTable, n_lines: int, diagnostics: Diagnostics) -> None:
    """A program file must end with M2/M30 or be wrapped in ``%`` lines (rs274's ``read_text``,
    interp_read.cc); the error names the file's last line."""
    if (table.name == NAME_ID["program_end"]).any() or n_lines == 0:
        return
    marks = []
    for k, raw in enumerate(b"".join(program.chunks()).splitlines()):
        stripped = raw.strip()
        if stripped == b"%":
            marks.append(k)
        elif stripped and not marks:
            break  # text before any '%': the program is not wrapped
    if len(marks) >= 2:
        return
    diagnostics.report(n_lines, 1, "File ended with no percent sign" + (" or program end (M2 or M30)" * (not marks)),
                       kind="machine")


def _until_first_error(lines: Iterator, diagnostics: Diagnostics) -> Iterator:
    """``lines`` up to, not including, the one being made when ``diagnostics`` first got an error."""
    for line in lines:
        if diagnostics.has_error:
            return
        yield line


def _progress(program: Program, enabled: bool):
    if not enabled:
        return None
    from tqdm import tqdm

    total = program.path.stat().st_size if program.path is not None and program.path.suffix != ".gz" else None
    return tqdm(total=total, unit="B", unit_scale=True, desc=Path(program.name).name, file=sys.stderr,
                leave=False)


def _empty_table(parser: GcodeParser, program: Program) -> CommandTable:
    return parser.parse(Blocks.empty(program.name))


def _concat_waypoints(parts: list[dict], sizes: list[int]) -> dict[str, np.ndarray]:
    """Join per-chunk waypoint columns, one column at a time to bound memory."""
    if len(parts) == 1:
        return parts[0]
    if any("command" in p for p in parts):
        shift = np.cumsum([0] + sizes[:-1])
        for p, s, n in zip(parts, shift, sizes):
            p["command"] = p.get("command", np.arange(n)) + s
    out = {}
    for key in list(parts[0]):
        cols = [p.pop(key) for p in parts]
        first = cols[0][0] if cols[0].size else None
        if key != "command" and first is not None and all(c.strides == (0,) for c in cols) and all(
                (c[0] == first) or (c[0] != c[0] and first != first) for c in cols if c.size):
            out[key] = np.broadcast_to(first, (sum(c.size for c in cols),))
        else:
            out[key] = np.concatenate(cols)
    return out


def quote_diagnostics(diagnostics: Diagnostics, program: Program, limit: int = 1000) -> None:
    """Fill in the source text of diagnostics that were made without it (from the file each names)."""
    wanted: dict[str, set[int]] = {}
    for d in diagnostics.items[:limit]:
        if not d.text:
            wanted.setdefault(d.file, set()).add(d.line)
    found: dict[tuple[str, int], str] = {}
    for file, lines in wanted.items():
        source = program if file == diagnostics.file else Program(file, path=Path(file))
        if source.path is not None and not source.path.is_file():
            continue
        line_no = 0
        for chunk in source.chunks():
            for raw in chunk.split(b"\n")[:-1]:
                line_no += 1
                if line_no in lines:
                    found[file, line_no] = raw[:200].decode("utf-8", "replace").rstrip("\r")
            if line_no >= max(lines):
                break
    diagnostics.items = [
        dataclasses.replace(d, text=found.get((d.file, d.line), "")) if not d.text else d for d in diagnostics.items
    ]
