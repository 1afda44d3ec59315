"""Command line: ``gcodekit info``, ``export``, ``render``, ``translate``, ``report``, ``notebook`` and ``cut``.

Examples
--------
::

    gcodekit info part.gcode --json
    gcodekit info part.ngc --machine linuxcnc
    gcodekit export part.ngc --to csv -o part.csv
    gcodekit export print.gcode --to vtk -o print.vtp
    gcodekit render print.gcode -o print.png --color-by speed --view top
    gcodekit report *.gcode -o reports/ --workers 2
    gcodekit notebook part.gcode -o part.ipynb
    gcodekit cut part.ngc --tools TOOLS.toml --stock 0,0,-10,60,40,0 -o part.stl
"""

from __future__ import annotations

import argparse
import atexit
import json
import math
import os
import signal
import sys
from pathlib import Path
from typing import Any, NoReturn, Sequence

from .errors import ConfigError, GcodeError, MissingDependencyError, NothingToShowError
from .limits import MAX_ITERATIONS, MAX_MOTIONS

#: Exit statuses: a program with errors, bad usage or options, and a bug in gcodekit itself.
EXIT_PROGRAM_ERROR, EXIT_USAGE, EXIT_INTERNAL = 1, 2, 3

EXPORT_FORMATS = ("csv", "parquet", "vtk", "events")
#: Output file name ending of each format when ``-o`` is not given (None: standard output).
_DEFAULT_SUFFIX = {"csv": None, "events": None, "parquet": ".parquet", "vtk": ".vtp"}


class UsageError(ConfigError):
    """A command-line argument that cannot work (exit status 2)."""


def _parser() -> argparse.ArgumentParser:
    from . import __version__

    p = argparse.ArgumentParser(prog="gcodekit", description="Read, emulate and summarise G-code programs.")
    p.add_argument("--version", action="version", version=f"gcodekit {__version__}")
    debug = argparse.ArgumentParser(add_help=False)
    debug.add_argument("--debug", action="store_true",
                       help="on an internal error, print the traceback (for a bug report)")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    add = lambda name, **kw: sub.add_parser(name, parents=[debug], **kw)  # noqa: E731

    info = add("info", help="summarise programs: flavor, moves, bounds, distances, time")
    info.add_argument("files", nargs="+", metavar="FILE")
    _common(info)
    info.add_argument("--json", action="store_true", help="one JSON object per file (a list when several)")

    export = add("export", help="write the motions of a program to a table, a VTK mesh or an event series")
    export.add_argument("file", metavar="FILE")
    _common(export)
    export.add_argument("--to", choices=EXPORT_FORMATS, default="csv",
                        help="csv or parquet: one row per motion; vtk: the deposition paths of an additive program, "
                             "the toolpath of any other (.vtp or .vtk); events: the Abaqus AM event series (default: csv)")
    export.add_argument("--source", choices=("material", "heat"), default="material",
                        help="events: material deposition or the laser/weld heat source (default: material)")
    export.add_argument("-o", "--output", metavar="OUT",
                        help="output file (default: standard output for csv and events, FILE's name with "
                             ".parquet or .vtp in the current directory otherwise)")
    export.add_argument("-f", "--force", action="store_true", help="overwrite OUT if it exists")

    render = add("render", help="draw the toolpath to a PNG, off-screen")
    render.add_argument("file", metavar="FILE")
    _common(render)
    render.add_argument("-o", "--output", metavar="OUT", required=True, help="PNG file to write")
    render.add_argument("--color-by", metavar="SCALAR",
                        help="feature, speed, layer, time or any waypoint column such as feed or z (default: feature "
                             "when the program marks features, else layer for additive programs and feed for others)")
    render.add_argument("--view", choices=("iso", "top", "front", "side"), default="iso",
                        help="camera (default: iso)")
    render.add_argument("--travel", action="store_true", help="also draw travel moves")
    render.add_argument("--tool-vectors", action="store_true", help="arrows along the head direction (5-axis)")
    render.add_argument("--size", default="1200x900", metavar="WxH", help="image size in pixels (default: 1200x900)")
    render.add_argument("-f", "--force", action="store_true", help="overwrite OUT if it exists")

    translate = add("translate", help="simplify a mill program stage by stage (GER's transpiler)")
    translate.add_argument("file", metavar="FILE")
    _common(translate)
    translate.add_argument("--stage", type=int, default=6, choices=range(7), metavar="K",
                           help="0 expanded, 1 units, 2 offsets, 3 polar, 4 absolute, 5 cutter comp, 6 cycles "
                                "(default: 6, plain G0-G3)")
    translate.add_argument("--to", metavar="FLAVOR", help="write in this dialect (default: rs274ngc)")
    translate.add_argument("-o", "--output", metavar="OUT", help="output file (default: standard output)")
    translate.add_argument("-f", "--force", action="store_true", help="overwrite OUT if it exists")

    report = add("report", help="an HTML and PDF report per program, and an index page")
    report.add_argument("files", nargs="+", metavar="PROGRAM")
    report.add_argument("-o", "--output", required=True, metavar="DIR", help="directory for the reports")
    report.add_argument("--machine", help="machine preset (default: the one for the flavor)")
    report.add_argument("--machine-config", metavar="FILE",
                        help="the firmware's own settings for the machine's planner (Klipper printer.cfg)")
    report.add_argument("--workers", type=_positive, default=1, metavar="N", help="worker processes (default: 1)")
    report.add_argument("--dask", metavar="ADDRESS", help="run on the Dask scheduler at ADDRESS instead")
    report.add_argument("--no-pdf", action="store_true", help="write the HTML pages only")
    report.add_argument("--notebook", action="store_true", help="also write each report as an executed notebook")
    report.add_argument("--notebook-html", action="store_true", help="with --notebook: also convert it to HTML")
    report.add_argument("--strict", action="store_true",
                        help="a program with an error gets an error page instead of a report")
    _limits(report)
    report.add_argument("-f", "--force", action="store_true", help="overwrite existing reports in DIR")
    report.add_argument("--no-progress", action="store_true", help="never show a progress bar")

    notebook = add("notebook", help="write a notebook exploring a program with the widgets")
    notebook.add_argument("file", metavar="PROGRAM")
    notebook.add_argument("-o", "--output", required=True, metavar="NAME.ipynb", help="notebook to write")
    notebook.add_argument("--machine", help="machine preset (default: the one for the flavor)")
    notebook.add_argument("--machine-config", metavar="FILE",
                          help="the firmware's own settings for the machine's planner (Klipper printer.cfg)")
    notebook.add_argument("--execute", action="store_true", help="run it, so it opens with its outputs")
    notebook.add_argument("--html", action="store_true",
                          help="also write NAME.html that shows its pictures offline (runs it)")
    notebook.add_argument("-f", "--force", action="store_true", help="overwrite NAME.ipynb if it exists")
    _limits(notebook)
    _cut_parser(add("cut", help="cut the stock with a mill program's tools: volumes, air cuts, the part"))
    return p


def _cut_parser(cut: argparse.ArgumentParser) -> None:
    cut.add_argument("file", metavar="PROGRAM")
    _common(cut)
    cut.add_argument("--stock", metavar="X0,Y0,Z0,X1,Y1,Z1",
                     help="stock box corners, mm (default: the box round the feed moves' tool envelopes)")
    cut.add_argument("--stock-file", metavar="STOCK.stl", help="stock as a closed mesh (STL, PLY, VTP)")
    cut.add_argument("--tools", metavar="TOOLS.toml", help="tool shapes, one [T<n>] table per tool")
    cut.add_argument("--tool-table", metavar="T.tbl",
                     help="LinuxCNC tool table: the machine's tool lengths, and flat end mills of its diameters")
    cut.add_argument("--tool-table-units", choices=("mm", "inch"), default="mm",
                     help="units of the tool table's numbers (default: mm)")
    cut.add_argument("--resolution", type=float, metavar="MM",
                     help="grid cell size, mm (default: 0.1, finer for tools under 2 mm)")
    cut.add_argument("--json", action="store_true", help="print the volumes and findings as JSON")
    cut.add_argument("-o", "--output", metavar="PART.vtp|PART.stl", help="write the cut part's mesh")
    cut.add_argument("-f", "--force", action="store_true", help="overwrite the part file if it exists")


def _positive(text: str) -> int:
    try:
        value = int(text.replace("_", "").replace(",", ""))
    except ValueError:
        raise argparse.ArgumentTypeError(f"needs a whole number, not {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"needs 1 or more, not {value}")
    return value


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--flavor", help="dialect (default: the machine's, else detected)")
    p.add_argument("--machine", help="machine preset (default: the one for the flavor)")
    p.add_argument("--machine-config", metavar="FILE",
                   help="the firmware's own settings for the machine's planner (Klipper printer.cfg)")
    p.add_argument("--strict", action="store_true", help="stop at the first error instead of reporting it")
    p.add_argument("--no-progress", action="store_true", help="never show a progress bar")
    _limits(p)


def _limits(p: argparse.ArgumentParser) -> None:
    p.add_argument("--max-motions", type=_positive, default=MAX_MOTIONS, metavar="N",
                   help=f"stop a program that makes more motions than this (default: {MAX_MOTIONS:,})")
    p.add_argument("--max-iterations", type=_positive, default=MAX_ITERATIONS, metavar="N",
                   help=f"stop a program whose loops run more iterations than this (default: {MAX_ITERATIONS:,})")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gcodekit`` command; returns the exit status.

    Problems with the programs or the arguments are one-line messages (status
    1 or 2); anything else is a bug in gcodekit, said to be one (status 3,
    the traceback with ``--debug``).
    """
    args = _parser().parse_args(argv)
    try:
        return _COMMANDS[args.command](args)
    except BrokenPipeError:  # the reader of the output has gone (``| head``): not an error of the command
        return 0
    except (GcodeError, UsageError, OSError) as exc:
        print(f"gcodekit: error: {exc}", file=sys.stderr)
        return EXIT_PROGRAM_ERROR if isinstance(exc, GcodeError) and not isinstance(
            exc, (ConfigError, MissingDependencyError)) else EXIT_USAGE
    except MemoryError:
        print("gcodekit: error: out of memory; the program is too large for this machine "
              "(--max-motions stops it earlier)", file=sys.stderr)
        return EXIT_PROGRAM_ERROR
    except KeyboardInterrupt:
        return 130
    except Exception as exc:  # noqa: BLE001 -- a bug, told apart from bad input
        return _internal_error(exc, args.debug)


def _without_huge_page_advice() -> None:
    """Turn NumPy's huge-page advice off for the command and its children, unless the environment chose.

    NumPy asks the kernel to back each array of 4 MB or more with
    transparent huge pages.  Where the kernel then compacts memory at the
    page fault (THP ``defrag`` set to ``madvise``, usual on virtual
    machines), a large program's run spends more time in those faults than
    in its work: ``gcodekit info`` of a 3 M-line print took 5.0 s with the
    advice and 2.6 s without on this project's machines.  NumPy reads
    ``NUMPY_MADVISE_HUGEPAGE`` when it is imported, which the command does
    later; the library leaves the setting to the program that imports it.
    """
    os.environ.setdefault("NUMPY_MADVISE_HUGEPAGE", "0")


def run() -> NoReturn:
    """The ``gcodekit`` command: :func:`main`, then a quick exit with its status.

    The exit handlers run (Chromium is ended, temporary folders removed) and
    the standard streams are flushed; then the process ends without tearing
    down every imported module (NumPy, Numba, matplotlib, VTK) one by one,
    which took a report command a quarter of a second after its work was done.
    Every file the command writes is closed by then.  A SIGTERM (``timeout``,
    a batch system, ``kill``) ends the command the same way, with status 143,
    instead of leaving its Chromium running.
    """
    signal.signal(signal.SIGTERM, _terminated)
    _without_huge_page_advice()
    try:
        status = main()
    except SystemExit as stop:  # argparse's --help, --version and usage errors, and a SIGTERM
        status = _exit_status(stop.code)
    atexit._run_exitfuncs()  # noqa: SLF001 -- what interpreter shutdown runs first, run before the quick exit
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (BrokenPipeError, ValueError):  # the reader has gone (``| head``), or the stream was closed
            pass
    os._exit(status)


def _terminated(signum: int, frame: object) -> None:
    raise SystemExit(128 + signum)


def _exit_status(code: object) -> int:
    """The status ``sys.exit(code)`` gives: 0 for None, the number, else 1 with the code said on stderr."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


def _internal_error(exc: Exception, debug: bool) -> int:
    from . import __version__

    if debug:
        import traceback

        traceback.print_exc()
    print(f"gcodekit: internal error: {type(exc).__name__}: {exc}\n"
          f"  This is a bug in gcodekit {__version__}, not a problem with the program; please report it "
          "with the program and the command." + ("" if debug else "\n  Run the command again with --debug "
                                                  "for the traceback."), file=sys.stderr)
    return EXIT_INTERNAL


def _load(path: str, args: argparse.Namespace):
    from .pipeline import gcode_to_operation

    if not os.path.exists(path):
        raise FileNotFoundError(f"no such file: {path}")
    if os.path.isdir(path):
        raise IsADirectoryError(f"{path} is a directory, not a program")
    progress = sys.stderr.isatty() and not args.no_progress and os.path.getsize(path) > 2_000_000
    return gcode_to_operation(Path(path), args.machine, flavor=args.flavor, machine_config=args.machine_config,
                              mode="strict" if args.strict else "lenient", progress=progress,
                              max_motions=args.max_motions, max_iterations=args.max_iterations)


def _info(args: argparse.Namespace) -> int:
    records = []
    for path in args.files:
        try:
            records.append(_load(path, args).summary())
        except (GcodeError, FileNotFoundError, IsADirectoryError, PermissionError) as exc:
            if len(args.files) == 1:
                raise
            records.append({"file": path, "error": str(exc)})
    if args.json:
        out = records[0] if len(records) == 1 else records
        json.dump(_json_safe(out), sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        for r in records:
            sys.stdout.write(_text(r) + "\n")
    return 1 if any("error" in r for r in records) else 0


def _json_safe(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_safe(v) for v in value]
    return value


def _text(r: dict[str, Any]) -> str:
    if "error" in r:
        return f"{r['file']}\n  error: {r['error']}\n"
    m, d = r["moves"], r["distance_mm"]
    b = r["bounds"] or {"min": [None] * 3, "max": [None] * 3}
    fmt = lambda v: "-" if v is None else f"{v:.3f}"  # noqa: E731
    lines = [
        r["file"],
        f"  flavor     {r['flavor']}   machine {r['machine']}",
        f"  lines      {r['lines']}   commands {r['commands']}",
        f"  moves      rapid {m['rapid']}  feed {m['feed']}  arc cw {m['arc_cw']}  arc ccw {m['arc_ccw']}"
        f"  extruding {m['extruding']}",
        f"  bounds     min {' '.join(fmt(v) for v in b['min'])}   max {' '.join(fmt(v) for v in b['max'])} mm",
        f"  distance   feed {d['feed']:.1f}  rapid {d['rapid']:.1f}  extruding {d['extrude']:.1f} mm",
        f"  time       {_duration(r['time_s'])}  "
        + (f"(planned like {r['planner']})" if r["planner"] else "(length / feed: no planner for this machine)")
        + (f", not counting {r['untimed_moves']} moves with no feed rate" if r.get("untimed_moves") else ""),
    ]
    if r["layers"] is not None:
        filament = f"   filament {r['filament_mm']:.1f} mm" if r["filament_mm"] is not None else ""
        lines.append(f"  layers     {r['layers']}{filament}")
    if r.get("slicer"):
        lines.append(_slicer_line(r))
    if r["tools"]:
        lines.append(f"  tools      {' '.join(map(str, r['tools']))}")
    diags = r["diagnostics"]
    errors = sum(1 for x in diags if x["severity"] == "error")
    lines.append(f"  diagnostics {len(diags) + r['diagnostics_dropped']} ({errors} errors)")
    for x in diags[:20]:
        quoted = f": {x['text']!r}" if x["text"] else ""
        lines.append(f"    {r['file']}:{x['line']}:{x['column']}: {x['severity']}: {x['message']}{quoted}")
    if len(diags) > 20:
        lines.append(f"    ... {len(diags) - 20} more (see --json)")
    return "\n".join(lines) + "\n"


def _slicer_line(r: dict[str, Any]) -> str:
    """What the slicer says beside gcodekit's figures, with the difference."""
    from .model.slicer import compare

    theirs = r["slicer"]
    name = " ".join(v for v in (theirs["slicer"], theirs["version"]) if v) or "slicer"
    shown = {"time": _duration, "model time": _duration, "filament": lambda v: f"{v:.1f} mm",
             "filament volume": lambda v: f"{v:.3f} cm3", "layers": str}
    parts = [f"{row['figure']} {shown[row['figure']](row['slicer'])}"
             + (f" (gcodekit {100 * row['difference']:+.1f} %)" if row["difference"] else " (gcodekit the same)")
             for row in compare(r)]
    return f"  slicer     {name} says: " + ("  ".join(parts) or "no figures")


def _duration(seconds: float) -> str:
    from .report.html import duration

    if seconds != seconds:
        return "unknown"
    return f"{duration(seconds)} ({seconds:.1f} s)"


def _exists(path: str | None, args: argparse.Namespace) -> bool:
    """Refuse to overwrite ``path`` without --force (True: refused, message printed)."""
    if path and os.path.exists(path) and not args.force:
        print(f"gcodekit: error: {path} exists; use --force to overwrite it", file=sys.stderr)
        return True
    return False


def _report_errors(op) -> int:
    """Print the program's first errors; the exit status: 1 when a limit stopped it (the output is
    partial), else 0."""
    for d in [d for d in op.diagnostics if d.severity == "error"][:10]:
        print(str(d), file=sys.stderr)
    return EXIT_PROGRAM_ERROR if op.diagnostics.limit_errors else 0


def _export(args: argparse.Namespace) -> int:
    output = args.output
    if output is None and _DEFAULT_SUFFIX[args.to]:
        output = Path(args.file).name.removesuffix(".gz")
        output = str(Path(output).with_suffix(_DEFAULT_SUFFIX[args.to]))
    if args.to == "vtk" and output and Path(output).suffix.lower() not in (".vtk", ".vtp"):
        raise UsageError(f"{output}: a VTK export is written to a .vtp or .vtk file")
    if _exists(output, args):
        return 2
    op = _load(args.file, args)
    status = _report_errors(op)  # first: a program a limit stopped may leave nothing to export
    target = output if output else sys.stdout
    if args.to == "csv":
        op.motions().to_csv(target, index=False, float_format="%.6f", lineterminator="\n")
    elif args.to == "parquet":
        try:
            op.motions().to_parquet(target, index=False)
        except ImportError as exc:
            raise MissingDependencyError("parquet export needs pyarrow: pip install 'gcodekit[parquet]'") from exc
    elif args.to == "events":
        from .analysis import gcode_dataframe_to_event_series

        events = gcode_dataframe_to_event_series(op.to_dataframe(), args.source)
        events.to_csv(target, header=False, index=False, float_format="%.6f", lineterminator="\n")
    else:
        from .additive import AdditivePart
        from .export.vtk import VTKExporter

        if op.process != "additive":
            VTKExporter.toolpath_to_vtk(op, output)
        else:
            part = AdditivePart(op)
            if part.depositions.empty:
                raise NothingToShowError(f"{args.file}: no deposition moves to export")
            VTKExporter.additive_part_to_vtk(part, output)
    return status


def _render(args: argparse.Namespace) -> int:
    from .visualize import plot_operation

    try:
        size = tuple(int(v) for v in args.size.lower().split("x"))
    except ValueError:
        size = ()
    if len(size) != 2 or min(size) < 16:
        raise UsageError(f"--size {args.size!r}: give width x height in pixels, e.g. 1200x900")
    if Path(args.output).suffix.lower() != ".png":
        raise UsageError(f"{args.output}: render writes a .png file")
    if _exists(args.output, args):
        return 2
    op = _load(args.file, args)
    status = _report_errors(op)  # first: a program a limit stopped may leave nothing to draw
    plot_operation(op, args.color_by, show_travel=args.travel, tool_vectors=args.tool_vectors, camera=args.view,
                   screenshot=args.output, window_size=size)
    return status


def _translate(args: argparse.Namespace) -> int:
    from .transpile import Transpiler

    if _exists(args.output, args):
        return 2
    op = _load(args.file, args)
    text = Transpiler(op).stage(args.stage)
    if args.to and args.to != "rs274ngc":
        from .export.gcode import GcodeExporter
        from .pipeline import parse_program

        text = GcodeExporter(args.to).to_gcode(parse_program(text, flavor="rs274ngc"))
    if args.output:
        Path(args.output).write_text(text)
    else:
        sys.stdout.write(text)
    return _report_errors(op)


def _report(args: argparse.Namespace) -> int:
    from .report import ReportOptions, write_reports

    if args.notebook_html and not args.notebook:
        print("gcodekit: error: --notebook-html needs --notebook", file=sys.stderr)
        return 2
    if args.machine:  # a wrong name fails once here, not once per program
        from .emulate.presets import load_machine

        load_machine(args.machine)
    if args.machine_config and not os.path.isfile(args.machine_config):
        raise FileNotFoundError(f"no such machine config file: {args.machine_config}")
    if not args.no_pdf:
        from .report.pdf import ChromiumNotFound, find_chromium

        try:
            find_chromium()
        except ChromiumNotFound as exc:
            print(f"gcodekit: error: {exc}", file=sys.stderr)
            return 2
    config = os.path.abspath(args.machine_config) if args.machine_config else None
    options = ReportOptions(machine=args.machine, machine_config=config, pdf=not args.no_pdf,
                            notebook=args.notebook, notebook_html=args.notebook_html, strict=args.strict,
                            max_motions=args.max_motions, max_iterations=args.max_iterations)
    rows = write_reports(args.files, args.output, options=options, workers=args.workers, dask=args.dask,
                         progress=sys.stderr.isatty() and not args.no_progress, force=args.force)
    for r in rows:
        if r["error"]:
            print(f"gcodekit: {r['file']}: {r['error']}", file=sys.stderr)
    failed = sum(1 for r in rows if r["error"])
    print(f"{len(rows) - failed} of {len(rows)} reports written to {os.path.join(args.output, 'index.html')}")
    return 1 if failed else 0


def _notebook(args: argparse.Namespace) -> int:
    from .widgets.notebook import write_exploration_notebook

    if Path(args.output).suffix != ".ipynb":
        raise UsageError(f"{args.output}: a notebook is written to a .ipynb file")
    if _exists(args.output, args):
        return 2
    if args.machine:
        from .emulate.presets import load_machine

        load_machine(args.machine)
    write_exploration_notebook(args.file, args.output, machine=args.machine, machine_config=args.machine_config,
                               execute=args.execute, html=args.html, max_motions=args.max_motions,
                               max_iterations=args.max_iterations)
    print(f"notebook written to {args.output}" + (" (and its .html)" if args.html else ""))
    return 0


def _cut(args: argparse.Namespace) -> int:
    from .cut import CutSimulation, Stock, ToolLibrary

    if args.output and Path(args.output).suffix.lower() not in (".vtp", ".stl", ".vtk", ".ply"):
        raise UsageError(f"{args.output}: the part is written to a .vtp, .stl, .vtk or .ply file")
    if args.stock and args.stock_file:
        raise UsageError("give --stock or --stock-file, not both")
    if _exists(args.output, args):
        return 2
    for path in (args.tools, args.tool_table, args.stock_file):
        if path and not os.path.isfile(path):
            raise FileNotFoundError(f"no such file: {path}")
    resolution = args.resolution
    if resolution is not None and not (math.isfinite(resolution) and resolution > 0):
        raise UsageError(f"--resolution {resolution:g}: give a positive cell size in mm")
    tools = ToolLibrary.read(args.tools) if args.tools else ToolLibrary()
    options = {}
    if args.tool_table:
        from .emulate.tooltable import ToolTable

        options = {"tool_table": args.tool_table, "tool_table_units": args.tool_table_units}
        tools = tools.merged(ToolLibrary.from_tool_table(ToolTable.read(args.tool_table,
                                                                        units=args.tool_table_units)))
    stock = None
    if args.stock:
        try:
            corners = [float(v) for v in args.stock.split(",")]
        except ValueError:
            corners = []
        if len(corners) != 6:
            raise UsageError(f"--stock {args.stock!r}: give six numbers X0,Y0,Z0,X1,Y1,Z1 in mm")
        stock = Stock.box(*corners, resolution=resolution or 0.1)
    elif args.stock_file:
        stock = Stock.from_mesh(args.stock_file, resolution=resolution or 0.1)
    if not os.path.isfile(args.file):
        raise FileNotFoundError(f"no such file: {args.file}")
    from .pipeline import gcode_to_operation

    op = gcode_to_operation(Path(args.file), args.machine, flavor=args.flavor, machine_config=args.machine_config,
                            mode="strict" if args.strict else "lenient", max_motions=args.max_motions,
                            max_iterations=args.max_iterations, **options)
    result = CutSimulation(op, stock=stock, tools=tools, resolution=resolution).run()
    if args.output:
        result.save(args.output)
    summary = result.summary()
    if args.json:
        print(json.dumps(_json_safe(summary), indent=1))
    else:
        x0, y0, z0, x1, y1, z1 = summary["stock"]
        print(f"{op.file}: stock {x0:g},{y0:g},{z0:g} to {x1:g},{y1:g},{z1:g} mm at {summary['resolution_mm']:g} mm\n"
              f"  stock {summary['stock_mm3']:,.1f} mm^3, removed {summary['removed_mm3']:,.1f} mm^3, "
              f"remaining {summary['remaining_mm3']:,.1f} mm^3\n"
              f"  air cuts: {summary['air_cuts']} moves, {_duration(summary['air_cut_s'])}; "
              f"rapids into stock: {len(summary['rapid_collisions'])}"
              + (f"\n  part written to {args.output}" if args.output else ""))
    for note in result.notes:
        print(str(note), file=sys.stderr)
    _report_errors(op)
    return 0


_COMMANDS = {"info": _info, "export": _export, "render": _render, "translate": _translate, "report": _report,
             "notebook": _notebook, "cut": _cut}

if __name__ == "__main__":
    run()
