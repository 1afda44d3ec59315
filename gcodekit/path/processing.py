"""Front end (FreeCAD Path API): pre- and post-processing through gcodekit's pipeline and exporter.

* :func:`read` is a pre-processor for every dialect gcodekit reads: the
  program runs through the pipeline (parameters, subroutines, canned
  cycles, units, offsets: what FreeCAD 0.20's parser aborts on or misreads)
  and its motions become a FreeCAD-format :class:`~gcodekit.path.Path` of
  absolute millimetre moves; what the pipeline cannot read is in
  ``path.diagnostics``, never a crash.
* :func:`to_operation` runs a path (or job) through the pipeline: planned
  times, pictures, reports and widgets work on it like on any program.
* :func:`post_process` writes a path or job for LinuxCNC, GRBL, Fanuc,
  Marlin or GER through :class:`gcodekit.export.gcode.GcodeExporter`, with
  the header, units, tool changes, line numbers and ending each target
  expects (:data:`TARGETS`).

Examples
--------
>>> from gcodekit.path import Path
>>> print(post_process(Path("G0 X1 Y2 G1 Z-1 F100"), "grbl", header=False), end="")
G21 G90 G17
G0 X1 Y2
G1 Z-1 F100
M5
M2
>>> p = read("#<depth> = -1\\nG0 X1 Y2\\nG1 Z#<depth> F100\\n", machine="linuxcnc")
>>> print(p.toGCode(), end="")
G0 X1.000000 Y2.000000 Z0.000000
G1 F100.000000 X1.000000 Y2.000000 Z-1.000000
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Union

import numpy as np

from ..errors import ConfigError, did_you_mean
from ..export.gcode import GcodeExporter
from ..pipeline import gcode_to_operation, parse_program
from .command import Command
from .toolpath import Path

if TYPE_CHECKING:
    from ..model.operation import Operation
    from .job import Compound

__all__ = ["read", "from_operation", "to_operation", "post_process", "write_report", "TARGETS", "Target"]

Pathlike = Union[Path, "Compound"]


@dataclass(frozen=True)
class Target:
    """What a post-processor writes for one controller.

    ``tool_change`` is how a tool change is written: ``"m6"`` (``M6 T<n>``
    on one line), ``"pause"`` (spindle off, a comment naming the tool and
    ``M0``: controllers without a tool changer).  Without ``canned_cycles``
    the drilling cycles are written as the moves they make.
    """

    flavor: str
    machine: str
    preamble: tuple[str, ...]
    postamble: tuple[str, ...]
    tool_change: str = "m6"
    line_numbers: bool = False
    percent: bool = False  # '%' lines around the program, and an O number
    canned_cycles: bool = True


#: The post-processors gcodekit has, by name.
TARGETS: dict[str, Target] = {
    "linuxcnc": Target("rs274ngc", "linuxcnc", ("G21 G90 G17 G40 G80",), ("M5", "M2")),
    "grbl": Target("grbl", "grbl", ("G21 G90 G17",), ("M5", "M2"), tool_change="pause", canned_cycles=False),
    "fanuc": Target("fanuc", "fanuc", ("G21 G90 G17 G40 G80 G99",), ("M5", "M30"), line_numbers=True, percent=True),
    "marlin": Target("marlin", "marlin", ("G21", "G90"), ("M5",), tool_change="pause", canned_cycles=False),
    "ger": Target("ger", "ger", ("G21 G90 G17",), ("M5", "M2"), canned_cycles=False),
}


def _target(name: str) -> Target:
    if name not in TARGETS:
        raise ConfigError(f"unknown post-processor {name!r}{did_you_mean(name, TARGETS)}; "
                          f"gcodekit has {', '.join(TARGETS)}")
    return TARGETS[name]


def _as_path(obj: Pathlike) -> Path:
    if isinstance(obj, Path):
        return obj
    joined = getattr(obj, "Path", None)  # a Compound or Job (not imported: job.py imports the path)
    if isinstance(joined, Path):
        return joined
    raise TypeError(f"expected a Path or a Job, not {type(obj).__name__}")


# -- pre-processing ---------------------------------------------------------------------

def read(source: str | os.PathLike, *, machine: str | None = None, flavor: str | None = None,
         mode: str = "lenient", **options) -> Path:
    """A program of any dialect gcodekit reads, as a FreeCAD-format path (the pre-processor).

    Parameters
    ----------
    source : path or str
        A program file or its text.
    machine, flavor : str, optional
        As for :func:`gcodekit.gcode_to_operation` (detected when not given).
    mode : {"lenient", "strict"}, default: "lenient"
        Lenient puts what cannot be read into ``path.diagnostics`` and goes on.
    **options
        Further options for :func:`gcodekit.gcode_to_operation` (``tool_table``, ...).

    Returns
    -------
    Path
        The motions as absolute millimetre G0/G1/G2/G3 commands in machine
        coordinates (see :func:`from_operation`), with ``diagnostics``.
    """
    op = gcode_to_operation(source, machine, flavor=flavor, mode=mode, plan=False, **options)
    path = from_operation(op)
    path.diagnostics = op.diagnostics
    return path


def from_operation(op: "Operation") -> Path:
    """An emulated operation's motions as a FreeCAD-format path.

    Each motion becomes one command in machine coordinates (work offsets,
    G92 and tool length applied, millimetres, absolute): ``G0`` for
    rapids, ``G1`` with its feed, ``G2``/``G3`` with the centre as I/J/K
    relative to the start and a plane command where the plane changes;
    ``M6 T<n>`` where the tool changes and ``M3``/``M4 S``/``M5`` where the
    spindle does.  Canned cycles arrive as the moves they make.
    """
    w = op.waypoints
    if w is None:
        raise ConfigError("the operation is not emulated: use gcodekit.gcode_to_operation")
    motion, plane, tool, spindle = w["motion"], w["plane"], w["tool"], w["spindle"]
    x, y, z, feed = w["x"], w["y"], w["z"], w["feed"]
    commands: list[Command] = []
    last_plane, last_tool, last_spindle = 17, int(tool[0]) if len(tool) else 0, 0.0
    prev = np.zeros(3)
    for i in range(len(motion)):
        if int(tool[i]) != last_tool:
            last_tool = int(tool[i])
            commands.append(Command("M6", {"T": float(last_tool)}))
        s = float(spindle[i])
        if s != last_spindle:
            commands.append(Command("M5") if s == 0 else Command("M3" if s > 0 else "M4", {"S": abs(s)}))
            last_spindle = s
        m = int(motion[i])
        here = np.array([x[i], y[i], z[i]])
        if m == 0:
            prev = here
            continue
        params = dict(zip("XYZ", (float(v) for v in here)))
        if m >= 2 and math.isfinite(feed[i]):
            params["F"] = float(feed[i])
        if m in (3, 4):
            if int(plane[i]) != last_plane:
                last_plane = int(plane[i])
                commands.append(Command(f"G{last_plane}"))
            center = np.array([w["cx"][i], w["cy"][i], w["cz"][i]])
            for k, letter in enumerate("IJK"):
                if math.isfinite(center[k]):
                    params[letter] = float(center[k] - prev[k])
        commands.append(Command({1: "G0", 2: "G1", 3: "G2", 4: "G3"}[m], params))
        prev = here
    return Path(commands)


def to_operation(obj: Pathlike, machine: str = "linuxcnc", **options) -> "Operation":
    """Run a path or job through gcodekit's pipeline: a planned Operation (pictures, reports, widgets).

    The path's ``toGCode()`` text is read as RS274NGC (FreeCAD's format is
    its subset) on ``machine``; a command's line is its position in the
    path plus one.
    """
    path = _as_path(obj)
    options.setdefault("flavor", "rs274ngc")
    return gcode_to_operation(path.toGCode(), machine, **options)


def write_report(obj: Pathlike, out_dir: str | os.PathLike, *, name: str = "path",
                 target: str = "linuxcnc", pdf: bool = False) -> dict:
    """The HTML report of a path or job, as ``gcodekit report`` writes one for a program file.

    The path is post-processed for ``target`` into ``out_dir/<name>.ngc``
    (kept beside the report) and reported on the target's machine; ``pdf``
    also prints the page to PDF (needs Chromium).

    Returns
    -------
    dict
        The report's index row (``html``, key figures; ``error`` if it failed).
    """
    from ..report.batch import ReportOptions, report_program

    if not name or os.path.basename(name) != name or name.startswith("."):
        raise ConfigError(f"report name {name!r} must be a plain file name (no folders)")
    out = os.fspath(out_dir)
    os.makedirs(out, exist_ok=True)
    program = os.path.join(out, f"{name}.ngc")
    with open(program, "w", encoding="utf-8") as f:
        f.write(post_process(obj, target, name=name))
    return report_program(program, out, name, ReportOptions(machine=_target(target).machine, pdf=pdf))


# -- post-processing ------------------------------------------------------------------------

def post_process(obj: Pathlike, target: str = "linuxcnc", *, header: bool = True, line_numbers: bool | None = None,
                 program_number: int = 1, name: str = "program", precision: int = 4) -> str:
    """A path or job written for a controller: the post-processor.

    Parameters
    ----------
    obj : Path or Job
    target : {"linuxcnc", "grbl", "fanuc", "marlin", "ger"}, default: "linuxcnc"
    header : bool, default: True
        A comment block naming the program, the target and the tools.
    line_numbers : bool, default: the target's (Fanuc: yes)
    program_number : int, default: 1
        Fanuc's ``O`` number.
    name : str, default: "program"
        The program's name in the header.
    precision : int, default: 4
        Decimals of coordinates.

    Returns
    -------
    str
        The program text; the exporter's warnings (words a target cannot
        say) are comments in it and one :class:`UserWarning`.
    """
    t = _target(target)
    path = _as_path(obj)
    if not t.canned_cycles:
        path = _expand_cycles(path)
    body: list[Command] = []
    for c in path.Commands:
        if c.Name in ("M6", "M06") and t.tool_change == "pause" and c.T is not None:
            body += [Command("M5"), Command(f"(change to tool {int(c.T)})"), Command("M0")]
        else:
            body.append(c)
    text = Path(body).toGCode()
    op = parse_program(text, flavor="rs274ngc")
    exporter = GcodeExporter(t.flavor, precision=precision,
                             line_numbers=t.line_numbers if line_numbers is None else line_numbers)
    head = "".join(f"({line})\n" for line in _header(obj, target, name)) if header else ""
    # the header's comments go through the exporter too, for the target's comment syntax
    out = GcodeExporter(t.flavor).to_gcode(parse_program(head, flavor="rs274ngc")) if head else ""
    out += "".join(line + "\n" for line in t.preamble)
    out += exporter.to_gcode(op, source_flavor="rs274ngc")
    ends = {"M2", "M02", "M30"}
    if not any(c.Name in ends for c in body[-3:]):  # the path's own program end stays the end
        out += "".join(line + "\n" for line in t.postamble)
    if t.percent:
        out = f"%\nO{int(program_number):04d}\n{out}%\n"
    return out


_CYCLES = ("G81", "G82", "G83")


def _expand_cycles(path: Path) -> Path:
    """The path with each G81/G82/G83 drilling cycle written as the moves it makes (G98/G99 followed).

    Positions come from :func:`gcodekit.path.measure.walk`, which follows
    G90/G91, planes and omitted words; G80 goes, as nothing is left to cancel.
    """
    commands = path.Commands
    if not any(c.Name in _CYCLES for c in commands):
        return path
    drills = {s.index: s for s in path.segments() if s.kind == "drill"}
    out: list[Command] = []
    for i, c in enumerate(commands):
        if c.Name == "G80":
            continue
        seg = drills.get(i)
        if seg is None or c.Name not in _CYCLES:
            out.append(c)
            continue
        above, at_r, bottom = seg.points
        feed = {"F": c.F} if c.F is not None else {}
        out.append(Command(f"(from {c.toGCode()})"))
        out.append(Command("G0", dict(zip("XYZ", map(float, above)))))
        out.append(Command("G0", dict(zip("XYZ", map(float, at_r)))))
        if c.Name == "G83" and c.Q:  # pecks: down by Q, out to R, back to just above the last depth
            depth = at_r.copy()
            n = 2 if seg.plane == (0, 1, 2) else seg.plane[2]
            while depth[n] - c.Q > bottom[n]:
                depth[n] -= c.Q
                out.append(Command("G1", {**dict(zip("XYZ", map(float, depth))), **feed}))
                out.append(Command("G0", dict(zip("XYZ", map(float, at_r)))))
                out.append(Command("G0", dict(zip("XYZ", map(float, depth)))))
        out.append(Command("G1", {**dict(zip("XYZ", map(float, bottom))), **feed}))
        if c.Name == "G82" and c.P:
            out.append(Command("G4", {"P": c.P}))
        out.append(Command("G0", dict(zip("XYZ", map(float, seg.end)))))
    return Path(out)


def _header(obj: Pathlike, target: str, name: str) -> list[str]:
    lines = [f"{name}: post-processed by gcodekit for {target}", "units: mm, absolute"]
    table = getattr(obj, "Tooltable", None)
    if table is not None:
        for number, tool in table.Tools.items():
            lines.append(f"T{number}: {tool.Name}, {tool.ToolType}, D{tool.Diameter:g} mm")
    return [" ".join(line.replace("(", "[").replace(")", "]").split()) for line in lines]
