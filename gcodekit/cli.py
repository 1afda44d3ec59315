"""Command line: ``gcodekit info``, ``export``, ``translate`` and ``report``.

Examples
--------
::

    gcodekit info part.gcode --json
    gcodekit info part.ngc --machine linuxcnc
    gcodekit export part.ngc --to csv -o part.csv
    gcodekit report *.gcode -o reports/ --workers 2
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path
from typing import Any, Sequence

from .errors import ConfigError, GcodeError

EXPORT_FORMATS = ("csv",)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gcodekit", description="Read, emulate and summarise G-code programs.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    info = sub.add_parser("info", help="summarise programs: flavor, moves, bounds, distances, time")
    info.add_argument("files", nargs="+", metavar="FILE")
    _common(info)
    info.add_argument("--json", action="store_true", help="one JSON object per file (a list when several)")

    export = sub.add_parser("export", help="write the motions of a program to a table")
    export.add_argument("file", metavar="FILE")
    _common(export)
    export.add_argument("--to", choices=EXPORT_FORMATS, default="csv", help="output format (default: csv)")
    export.add_argument("-o", "--output", metavar="OUT", help="output file (default: standard output)")
    export.add_argument("-f", "--force", action="store_true", help="overwrite OUT if it exists")

    translate = sub.add_parser("translate", help="simplify a mill program stage by stage (GER's transpiler)")
    translate.add_argument("file", metavar="FILE")
    _common(translate)
    translate.add_argument("--stage", type=int, default=6, choices=range(7), metavar="K",
                           help="0 expanded, 1 units, 2 offsets, 3 polar, 4 absolute, 5 cutter comp, 6 cycles "
                                "(default: 6, plain G0-G3)")
    translate.add_argument("--to", metavar="FLAVOR", help="write in this dialect (default: rs274ngc)")
    translate.add_argument("-o", "--output", metavar="OUT", help="output file (default: standard output)")
    translate.add_argument("-f", "--force", action="store_true", help="overwrite OUT if it exists")

    report = sub.add_parser("report", help="an HTML and PDF report per program, and an index page")
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
    report.add_argument("-f", "--force", action="store_true", help="overwrite existing reports in DIR")
    report.add_argument("--no-progress", action="store_true", help="never show a progress bar")
    return p


def _positive(text: str) -> int:
    value = int(text)
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


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gcodekit`` command; returns the exit status."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "info":
            return _info(args)
        if args.command == "translate":
            return _translate(args)
        if args.command == "report":
            return _report(args)
        return _export(args)
    except (GcodeError, FileNotFoundError, FileExistsError, IsADirectoryError, PermissionError) as exc:
        print(f"gcodekit: error: {exc}", file=sys.stderr)
        return 1 if isinstance(exc, GcodeError) and not isinstance(exc, ConfigError) else 2
    except BrokenPipeError:
        return 0


def _load(path: str, args: argparse.Namespace):
    from .pipeline import gcode_to_operation

    if not os.path.exists(path):
        raise FileNotFoundError(f"no such file: {path}")
    if os.path.isdir(path):
        raise IsADirectoryError(f"{path} is a directory, not a program")
    progress = sys.stderr.isatty() and not args.no_progress and os.path.getsize(path) > 2_000_000
    return gcode_to_operation(Path(path), args.machine, flavor=args.flavor, machine_config=args.machine_config,
                              mode="strict" if args.strict else "lenient", progress=progress)


def summary(op) -> dict[str, Any]:
    """The ``info`` record of an emulated operation (what ``--json`` prints)."""
    stats = op.get_statistics()
    bounds = stats["bounds"] or {"min": [None] * 3, "max": [None] * 3}
    return {
        "file": op.file,
        "flavor": op.flavor.name,
        "machine": op.machine.name,
        "lines": stats["lines"],
        "commands": stats["commands"],
        "moves": stats["moves"],
        "bounds": bounds,
        "distance_mm": stats["distance_mm"],
        "time_s": stats["time_s"],
        "planner": op.machine.planner or None,
        "layers": stats["layers"],
        "filament_mm": stats["filament_mm"],
        "tools": stats["tools"],
        "diagnostics": [d.as_dict() for d in op.diagnostics],
        "diagnostics_dropped": op.diagnostics.dropped,
    }


def _info(args: argparse.Namespace) -> int:
    records = []
    for path in args.files:
        try:
            records.append(summary(_load(path, args)))
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
    m, d, b = r["moves"], r["distance_mm"], r["bounds"]
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
        + (f"(planned like {r['planner']})" if r["planner"] else "(length / feed: no planner for this machine)"),
    ]
    if r["layers"] is not None:
        lines.append(f"  layers     {r['layers']}   filament {r['filament_mm']:.1f} mm")
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


def _duration(seconds: float) -> str:
    from .report.html import duration

    if seconds != seconds:
        return "unknown"
    return f"{duration(seconds)} ({seconds:.1f} s)"


def _export(args: argparse.Namespace) -> int:
    if args.output and os.path.exists(args.output) and not args.force:
        print(f"gcodekit: error: {args.output} exists; use --force to overwrite it", file=sys.stderr)
        return 2
    op = _load(args.file, args)
    frame = op.motions()
    target = args.output if args.output else sys.stdout
    frame.to_csv(target, index=False, float_format="%.6f", lineterminator="\n")
    errors = [d for d in op.diagnostics if d.severity == "error"]
    for d in errors[:10]:
        print(str(d), file=sys.stderr)
    return 0


def _translate(args: argparse.Namespace) -> int:
    from .transpile import Transpiler

    if args.output and os.path.exists(args.output) and not args.force:
        print(f"gcodekit: error: {args.output} exists; use --force to overwrite it", file=sys.stderr)
        return 2
    op = _load(args.file, args)
    text = Transpiler(op).stage(args.stage)
    if args.to and args.to != "rs274ngc":
        from .emulate.exporters import GcodeExporter
        from .pipeline import parse_program

        text = GcodeExporter(args.to).to_gcode(parse_program(text, flavor="rs274ngc"))
    if args.output:
        Path(args.output).write_text(text)
    else:
        sys.stdout.write(text)
    for d in [d for d in op.diagnostics if d.severity == "error"][:10]:
        print(str(d), file=sys.stderr)
    return 0


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
                            notebook=args.notebook, notebook_html=args.notebook_html, strict=args.strict)
    rows = write_reports(args.files, args.output, options=options, workers=args.workers, dask=args.dask,
                         progress=sys.stderr.isatty() and not args.no_progress, force=args.force)
    for r in rows:
        if r["error"]:
            print(f"gcodekit: {r['file']}: {r['error']}", file=sys.stderr)
    failed = sum(1 for r in rows if r["error"])
    print(f"{len(rows) - failed} of {len(rows)} reports written to {os.path.join(args.output, 'index.html')}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
