"""Pipeline: where a program comes from, which flavor and machine read it, and quoting its lines.

A program is a file (plain or compressed) or text given directly;
:func:`resolve` picks the flavor and machine the caller named, or detects
them.  The file-level checks that need the whole file (how it ends) and the
quoting of diagnostics' source lines live here too, since they read the
program again by its path.
"""

from __future__ import annotations

import dataclasses
import os
import sys
from pathlib import Path
from typing import Iterator

from ..emulate.presets import MachineConfig, default_machine_for, load_machine, machine_named_in, with_options
from ..errors import HEAD_LINES, Diagnostics
from ..parse import CommandTable
from ..parse.table import NAME_ID
from ..read import iter_lines
from ..syntax import Detection, Flavor, detect_flavor, load_flavor

__all__ = ["Program", "as_program", "resolve", "note_weak_detection", "note_other_dialect", "note_unreadable",
           "check_program_end",
           "quote_diagnostics", "progress_bar"]

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


    def tail(self, size: int = 65536) -> str:
        """The end of a plain program file or text ('' for a compressed file): where slicers put their settings."""
        if self.text is not None:
            return self.text[-size:]
        with open(self.path, "rb") as f:
            if f.read(6).startswith((b"\x1f\x8b", b"BZh", b"\xfd7zXZ")):
                return ""
            f.seek(0, os.SEEK_END)
            f.seek(max(f.tell() - size, 0))
            return f.read().decode("utf-8", "replace")


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
        config = load_machine(machine_named_in(program.head(), fl.name) or default_machine_for(fl.name))
    if machine_options:
        config = with_options(config, **machine_options)
    return fl, config, detection


def note_weak_detection(detection: Detection | None, diagnostics: Diagnostics) -> None:
    """An info diagnostic naming the flavor detection chose, and why, when its evidence was thin."""
    if detection is not None and detection.weak:
        diagnostics.report(1, 1, f"flavor {detection.name!r} chosen on thin evidence ({'; '.join(detection.reasons)}); "
                           "give the flavor (flavor=, --flavor) if the program is in another dialect", severity="info")


def note_other_dialect(program: Program, flavor: Flavor, diagnostics: Diagnostics, *,
                       machine: str | None = None) -> None:
    """A note, ahead of the others, when a program read as a given flavor plainly is in another dialect.

    Said only when it explains something and is true: the reading gave
    errors, warnings or codes the flavor gives no meaning, and the
    program's head names strongly a dialect the flavor cannot read (not
    the flavor itself nor one it inherits from, and no close candidate
    that is: :meth:`Detection.rules_out`; a Marlin program read as Klipper
    gets none, a Klipper program read as Marlin does, but between dialects
    of one family only when the reading gave errors).  It is a warning, or
    an info when it explains only infos (codes without meaning, which
    firmware add freely).  Detection reads the head only, and only for a
    program with such diagnostics.  ``machine`` names the preset the
    flavor came with, when the caller gave a machine and no flavor.
    """
    if diagnostics.has_error:
        found, severity = "the errors", "warning"
    elif any(d.severity == "warning" for d in diagnostics.items):
        found, severity = "the warnings", "warning"
    elif diagnostics.unknown_codes:  # infos, so an info too
        found, severity = f"the codes unknown to {flavor.name!r}", "info"
    else:
        return
    detection = detect_flavor(program.head(), program.name if program.path else None)
    if not detection.rules_out(flavor):
        return
    if load_flavor(detection.name).family == flavor.family and not diagnostics.has_error:
        return  # a relative's codes it lacks (Prusa's M862 on Marlin) are only noted: the choice may be the user's
    name = detection.name
    if machine:
        preset = default_machine_for(name)
        read_as = f"the {machine} machine's flavor"
        advice = f"a machine for it, e.g. --machine {preset} (machine={preset!r})"
    else:
        read_as, advice = "the flavor given", f"--flavor {name} (flavor={name!r})"
    diagnostics.report_first(1, 1, f"the program looks written for {name!r} ({'; '.join(detection.evidence)}), but "
                             f"was read as {flavor.name!r} ({read_as}): {found} may come from that; to read it "
                             f"as {name!r}, give {advice}", severity=severity)


def note_unreadable(diagnostics: Diagnostics, n_lines: int) -> None:
    """A warning, ahead of the others, when most of a file's lines could not be read (a text file, a table,
    another language, codes of a dialect the flavor lacks): its summary describes only the little that could.

    Lines are counted among the first :data:`~gcodekit.errors.HEAD_LINES`, whether their errors are listed
    or counted into a summary."""
    unreadable, head = len(diagnostics.unreadable_lines), min(n_lines, HEAD_LINES)
    if unreadable >= 3 and 2 * unreadable > head:
        lines = f"its {head:,} lines" if head == n_lines else f"its first {head:,} lines"
        diagnostics.report_first(1, 1, f"{unreadable:,} of {lines} could not be read (each has an error below): the "
                                 "summary describes only the rest; is the file a G-code program, in a dialect "
                                 "gcodekit reads (--flavor)?", severity="warning")


def check_program_end(program: Program, table: CommandTable, n_lines: int, diagnostics: Diagnostics) -> None:
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


def progress_bar(program: Program, enabled: bool):
    """A bar on standard error counting the program's bytes as they are read (out of the file's size
    when it is plain text; a compressed file's text size is not known before it is read); the
    pipeline names the later steps (joining, planning) in it."""
    if not enabled:
        return None
    from tqdm import tqdm

    total = None
    if program.path is not None:
        with open(program.path, "rb") as f:
            head = f.read(6)
        if not head.startswith((b"\x1f\x8b", b"BZh", b"\xfd7zXZ")):  # the containers read/source.py opens
            total = program.path.stat().st_size
    return tqdm(total=total, unit="B", unit_scale=True, desc=Path(program.name).name, file=sys.stderr,
                leave=False)
