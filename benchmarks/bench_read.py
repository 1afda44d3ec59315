"""Benchmark: read, parse and emulate a large program, against gcodeparser's tokeniser.

The acceptance benchmark of the foundation issue: ``gcodekit.gcode_to_operation``
(with ``plan=False``: the motion planner is measured by ``bench_plan.py``) turns ``plate150_marlin2.gcode.gz`` (3.1 M lines) into the columnar operation in
at most 0.4x the wall time that gcodeparser 0.3.0 needs only to tokenise the
same file, with a peak memory of at most 300 bytes per input line.

Each run is a fresh interpreter, so its peak resident set size is its own; the
two libraries run alternately and the best time of each counts. Both timings
include reading and decompressing the file; neither includes the import, which
is reported on its own for gcodekit. The checks bind only on the acceptance
file: the exit status is 1 when one of them fails there, 2 when gcodeparser is
missing, else 0.

Examples
--------
The full benchmark (1-2 minutes), then a smoke run on a smaller file::

    python benchmarks/bench_read.py --json bench_read.json
    python benchmarks/bench_read.py --quick
"""

from __future__ import annotations

import argparse
import datetime
import gzip
import importlib.metadata
import importlib.util
import json
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

CORPUS = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "fff"
FULL_FILE = CORPUS / "plate150_marlin2.gcode.gz"
QUICK_FILE = CORPUS / "cylinder_marlin2.gcode"
MAX_RATIO = 0.4
MAX_BYTES_PER_LINE = 300
TOOLS = ("gcodekit", "gcodeparser")


def open_program(path: Path, mode: str = "rt"):
    """Open a plain or gzip program, as UTF-8 text (``"rt"``) or bytes (``"rb"``)."""
    text = {"encoding": "utf-8", "errors": "replace"} if "t" in mode else {}
    return (gzip.open if path.suffix == ".gz" else open)(path, mode, **text)


def count_lines(path: Path) -> int:
    """Number of lines of a program, a last line without newline included."""
    n, last = 0, b"\n"
    with open_program(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            n += chunk.count(b"\n")
            last = chunk[-1:]
    return n + (last != b"\n")


def max_rss() -> int:
    """Peak resident set size of this process so far, in bytes."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024


def measure(tool: str, path: Path) -> dict:
    """Import one tool, then read the program with it; run in a fresh interpreter.

    Parameters
    ----------
    tool : {"gcodekit", "gcodeparser"}
        gcodekit reads, parses and emulates into an operation; gcodeparser
        only tokenises into ``GcodeLine`` objects.
    path : Path
        The program, plain or gzip.

    Returns
    -------
    dict
        ``import_s`` and ``seconds`` (wall), ``baseline`` (peak RSS after the
        imports) and ``peak`` (peak RSS at the end) in bytes, and ``items``
        (commands of the operation, or ``GcodeLine`` objects).
    """
    start = time.perf_counter()
    if tool == "gcodekit":
        import gcodekit
    else:
        from gcodeparser import parse_gcode_lines
    import_s = time.perf_counter() - start
    baseline = max_rss()
    start = time.perf_counter()
    if tool == "gcodekit":
        items = len(gcodekit.gcode_to_operation(path, plan=False))
    else:
        with open_program(path) as f:
            items = sum(1 for _ in parse_gcode_lines(f))
    seconds = time.perf_counter() - start
    return {"import_s": import_s, "seconds": seconds, "baseline": baseline, "peak": max_rss(),
            "items": items}


def run_child(tool: str, path: Path) -> dict:
    """:func:`measure` in a fresh interpreter."""
    out = subprocess.run([sys.executable, __file__, "--child", tool, "--file", str(path)],
                         check=True, stdout=subprocess.PIPE, text=True).stdout
    return json.loads(out.splitlines()[-1])


def summarise(runs: list[dict], lines: int) -> dict:
    """Best time and worst peak memory of a tool's runs."""
    peak = max(r["peak"] for r in runs)
    above = max(r["peak"] - r["baseline"] for r in runs)
    return {"runs": len(runs), "seconds": min(r["seconds"] for r in runs),
            "import_s": min(r["import_s"] for r in runs), "items": runs[0]["items"],
            "peak_mb": peak / 1e6, "above_import_mb": above / 1e6,
            "bytes_per_line": peak / lines, "bytes_per_line_above_import": above / lines}


def report(result: dict) -> str:
    """The printed table of a benchmark result."""
    s, c = result["summary"], result["checks"]
    v = result["versions"]
    rows = [f"file  {result['file']}  {result['lines']:,} lines",
            f"      {result['date']}, Python {result['python']}, {result['cpus']} CPUs, "
            f"gcodekit {v['gcodekit']}, gcodeparser {v['gcodeparser']}",
            f"import gcodekit: {s['gcodekit']['import_s']:.3f} s (best fresh interpreter)",
            "",
            f"{'':12} {'runs':>4} {'best s':>8} {'peak MB':>8} {'above import MB':>16} "
            f"{'B/line':>7} {'B/line above import':>20} {'items':>10}"]
    for tool in TOOLS:
        t = s[tool]
        rows.append(f"{tool:12} {t['runs']:4d} {t['seconds']:8.2f} {t['peak_mb']:8.1f} "
                    f"{t['above_import_mb']:16.1f} {t['bytes_per_line']:7.0f} "
                    f"{t['bytes_per_line_above_import']:20.0f} {t['items']:10,}")
    rows.append("" if result["acceptance"] else
                f"\n(informative: the acceptance figures are defined on {FULL_FILE.name})")
    for name, check in c.items():
        rows.append(f"{name:42} {check['value']:8.2f} <= {check['limit']:<4} "
                    f"{'PASS' if check['pass'] else 'FAIL'}")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark from the command line; return the exit status."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    which = p.add_mutually_exclusive_group()
    which.add_argument("--file", type=Path, default=FULL_FILE, help="program, plain or gzip "
                       "(default: %(default)s)")
    which.add_argument("--quick", action="store_true", help=f"smoke run on {QUICK_FILE.name}")
    p.add_argument("--repeat", type=int, default=3, help="gcodekit runs (default: 3)")
    p.add_argument("--peer-repeat", type=int, default=1, help="gcodeparser runs (default: 1)")
    p.add_argument("--json", type=Path, metavar="OUT", help="also write the figures as JSON")
    p.add_argument("--child", choices=TOOLS, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    path = QUICK_FILE if args.quick else args.file
    if args.child:
        print(json.dumps(measure(args.child, path)))
        return 0
    if importlib.util.find_spec("gcodeparser") is None:
        print("gcodeparser is not installed: pip install gcodeparser==0.3.0", file=sys.stderr)
        return 2

    lines = count_lines(path)
    repeats = {"gcodekit": args.repeat, "gcodeparser": args.peer_repeat}
    runs: dict[str, list[dict]] = {tool: [] for tool in TOOLS}
    for i in range(max(repeats.values())):
        for tool in TOOLS:
            if i < repeats[tool]:
                runs[tool].append(run_child(tool, path))
                print(f"{tool} run {i + 1}/{repeats[tool]}: {runs[tool][-1]['seconds']:.2f} s",
                      file=sys.stderr)
    summary = {tool: summarise(runs[tool], lines) for tool in TOOLS}
    gk = summary["gcodekit"]
    checks = {
        "time gcodekit / gcodeparser": (gk["seconds"] / summary["gcodeparser"]["seconds"], MAX_RATIO),
        "gcodekit peak above import, B per line": (gk["bytes_per_line_above_import"], MAX_BYTES_PER_LINE),
        "gcodekit peak total, B per line": (gk["bytes_per_line"], MAX_BYTES_PER_LINE),
    }
    result = {
        "date": datetime.date.today().isoformat(), "file": path.name, "lines": lines,
        "acceptance": path.resolve() == FULL_FILE,
        "python": platform.python_version(), "cpus": os.cpu_count(),
        "versions": {tool: importlib.metadata.version(tool) for tool in TOOLS},
        "runs": runs, "summary": summary,
        "checks": {k: {"value": v, "limit": lim, "pass": v <= lim} for k, (v, lim) in checks.items()},
    }
    print(report(result))
    if args.json:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    failed = not all(c["pass"] for c in result["checks"].values())
    return 1 if result["acceptance"] and failed else 0


if __name__ == "__main__":
    sys.exit(main())
