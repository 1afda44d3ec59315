"""Pipeline: a program as blocks, chunk by chunk, preprocessed when it needs it.

Plain programs stream from the file through the reader 256 KiB at a time.
Programs with parameters, O-word flow, Fanuc subprograms or wizards go
through the preprocess stages first; their output is read a chunk of lines
at a time, and lines of subroutine files are numbered apart so that
diagnostics name the file and line they came from.
"""

from __future__ import annotations

import dataclasses
import re
from typing import Callable, Iterator, Sequence

import numpy as np

from ..emulate.machine import Machine
from ..errors import Diagnostics
from ..limits import Limits
from ..parse import CommandTable
from ..read import COMPILED_AFTER_BYTES, Blocks, iter_counted_blocks, iter_lines, scans_without_gil
from ..read.ahead import read_ahead
from ..read.percent import until_closing_percent
from ..syntax import Flavor
from .feedback import MachineFeedback, MachineStop
from .program import Program

__all__ = ["program_blocks", "number_other_files", "restore_line_numbers", "until_first_error", "ELSEWHERE_LINES"]

_O_WORD_LINE = re.compile(r"(?im)^[ \t]*(?:/[ \t]*)?(?:n[0-9. \t]*)?o")
_SUBPROGRAM_M = re.compile(r"(?i)m\s*0*9\s*[89](?![\s.]*\d)")  # M98/M99: Fanuc-style subprogram flow
#: Line numbers from here up stand for lines of subroutine files (see number_other_files)
ELSEWHERE_LINES = 1 << 30
#: Program files from this size on disk are read on a second thread, ahead of the machine (see read.ahead),
#: when the compiled scanner reads them: the NumPy scanner holds the GIL too often to gain from a thread
READ_AHEAD_BYTES = COMPILED_AFTER_BYTES


def program_blocks(program: Program, flavor: Flavor, diagnostics: Diagnostics, bar=None,
            machine: tuple[Machine, Callable[[Blocks, int], None]] | None = None,
            search_path: Sequence[str] = (), limits: Limits = Limits(),
            fanuc_subs: bool = True) -> Iterator[tuple[Blocks, int]]:
    """Blocks of the program chunk by chunk, preprocessed when it needs it.

    With ``machine`` (the machine and a function that parses and emulates
    blocks), a program that probes is emulated up to its latest probe move
    whenever a line reads or writes the probe results (#5061-#5070), so they
    hold that probe's results, and state parameters (``#5420``, ``#<_x>``)
    read the machine (see :class:`MachineFeedback`).
    """
    if flavor.parameters or flavor.wizards:
        from ..preprocess import ControlFlowStage, ParameterStore, SourceLine, needs_parameters, run_stages
        from ..preprocess.wizards import WizardStage, needs_wizards

        text = b"".join(program.chunks(diagnostics)).decode("utf-8", "replace")
        if flavor.percent_delimiter:  # nothing after a closing % line is read, as in rs274
            text = b"".join(until_closing_percent(iter_lines(text))).decode("utf-8", "surrogateescape")
        # probes and reads of their results may sit in subroutine files: watch every program
        # (until a probe goes by, the watch only collects the lines)
        feedback = MachineFeedback(flavor, diagnostics, *machine) if machine is not None else None
        store = ParameterStore(system=feedback.system, system_writes=feedback) if feedback is not None else None
        stages = [ControlFlowStage(flavor, store, search_path=search_path, fanuc_subs=fanuc_subs,
                                   max_iterations=limits.max_iterations,
                                   max_motions=limits.max_motions, machine=feedback)] if flavor.parameters and (
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
                out = until_first_error(run_stages(source, stages, early), early)
                out = number_other_files(out, program.name, diagnostics)
                if feedback is not None:
                    out = feedback.watch(out, store)
                yield from MachineStop.read(out, flavor, diagnostics, len(lines))
                diagnostics.extend(d for d in early if d.severity != "error")
                early.raise_first()
                return
            out = number_other_files(run_stages(source, stages, diagnostics), program.name, diagnostics)
            if feedback is not None:
                out = feedback.watch(out, store)
            yield from MachineStop.read(out, flavor, diagnostics, len(lines))
            return
        chunks: Callable[[Diagnostics], Iterator[bytes]] = lambda _: iter_lines(text)
    else:
        chunks = program.chunks
    size = program.path.stat().st_size if program.path is not None and not program.preprocessed else 0

    def blocks(reported_to: Diagnostics) -> Iterator[tuple[Blocks, int]]:
        return _plain_blocks(chunks(reported_to), flavor, reported_to, bar, size)

    # a large file's next chunk is read on another thread while the machine runs this one
    ahead = size >= READ_AHEAD_BYTES and scans_without_gil(flavor)
    yield from read_ahead(blocks, diagnostics) if ahead else blocks(diagnostics)


def _plain_blocks(chunks: Iterator[bytes], flavor: Flavor, diagnostics: Diagnostics, bar=None,
                  size: int = 0) -> Iterator[tuple[Blocks, int]]:
    """The blocks of a program that needs no preprocessing (``size``: its file's, when known)."""
    if flavor.percent_delimiter:
        chunks = until_closing_percent(chunks)
    if bar is not None:
        chunks = _shown(chunks, bar)
    yield from iter_counted_blocks(chunks, flavor, diagnostics, size_hint=size)  # each holds every chunk taken so far


def _shown(chunks: Iterator[bytes], bar) -> Iterator[bytes]:
    """The chunks, each counted on the progress bar as it is taken."""
    for c in chunks:
        bar.update(len(c))
        yield c


def number_other_files(lines: Iterator, main: str, diagnostics: Diagnostics) -> Iterator:
    """Lines of other files (subroutine files) under numbers of their own.

    Reader, parser and machine know a line by its number only, so a line of
    a subroutine file would pass for the main file's line of that number.
    Such lines get numbers from :data:`ELSEWHERE_LINES` up, which
    ``diagnostics.elsewhere`` maps to their file and line, and which
    :func:`restore_line_numbers` turns back into the file's own numbers in
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


def restore_line_numbers(table: CommandTable, diagnostics: Diagnostics) -> None:
    """Rows from other files get their own files' line numbers back (see :func:`number_other_files`)."""
    if not diagnostics.elsewhere:
        return
    far = table.line >= ELSEWHERE_LINES
    own = np.array([line for _, line in diagnostics.elsewhere.values()], table.line.dtype)
    table.line[far] = own[table.line[far] - ELSEWHERE_LINES]


def until_first_error(lines: Iterator, diagnostics: Diagnostics) -> Iterator:
    """``lines`` up to, not including, the one being made when ``diagnostics`` first got an error."""
    for line in lines:
        if diagnostics.has_error:
            return
        yield line
