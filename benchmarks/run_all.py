"""Run the whole benchmark suite, side by side with the peers, and write one table (markdown and JSON).

Each benchmark script runs in its own process with ``--json`` (and
``--quick`` for a smoke run); this script reads what each wrote and makes one
row per figure: file, tool, seconds, peak MB, the ratio to the peer measured
in the same run, the target and whether it is met.  A benchmark whose peer
library is missing, or whose script is not in this checkout, gets a row that
says so and how to get it; the others still run.

The peers are the ``bench`` extra (``pip install -e '.[bench]'``:
gcodeparser, pyGCodeDecode); the browser benchmark needs the test tools
(JupyterLab, Playwright: ``pip install -e '.[test]'``, which
``./scripts/run-tests.sh`` installs).

Examples
--------
::

    python benchmarks/run_all.py --quick          # smoke run on small files, a few minutes
    python benchmarks/run_all.py                  # the acceptance figures, about half an hour on 2 cores
    python benchmarks/run_all.py --out results/   # where benchmarks.md and benchmarks.json go
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

HERE = Path(__file__).resolve().parent
BENCH_EXTRA = "pip install -e '.[bench]'"
TEST_EXTRA = "pip install -e '.[test]' (./scripts/run-tests.sh installs it)"
COLUMNS = ("benchmark", "file", "tool", "seconds", "peak_mb", "ratio", "target", "pass", "note")


def row(benchmark: str, file: str, tool: str, seconds: float | None = None, peak_mb: float | None = None,
        ratio: float | None = None, target: str = "", passed: bool | None = None, note: str = "") -> dict[str, Any]:
    """One line of the table (None: not measured or no target)."""
    return {"benchmark": benchmark, "file": file, "tool": tool, "seconds": seconds, "peak_mb": peak_mb,
            "ratio": ratio, "target": target, "pass": passed, "note": note}


# -- from each benchmark's JSON to rows ---------------------------------------------------------------------------

def read_rows(r: dict) -> list[dict]:
    """bench_read.py: read + parse + emulate against gcodeparser's tokenising."""
    s, check = r["summary"], r["checks"]["time gcodekit / gcodeparser"]
    memory = r["checks"]["gcodekit peak total, B per line"]
    binds = r["acceptance"]
    note = f"{memory['value']:.0f} B/line (<= {memory['limit']})" + ("" if binds else "; target binds on plate150")
    return [row("read", r["file"], "gcodeparser 0.3.0 (tokenise)", s["gcodeparser"]["seconds"],
                s["gcodeparser"]["peak_mb"]),
            row("read", r["file"], "gcodekit read + emulate", s["gcodekit"]["seconds"], s["gcodekit"]["peak_mb"],
                check["value"], f"<= {check['limit']}x gcodeparser", check["pass"] if binds else None, note)]


def plan_rows(r: dict) -> list[dict]:
    """bench_plan.py: read + emulate + plan against pyGCodeDecode's simulation."""
    ours, peer = r["gcodekit"], r["pygcodedecode"]
    binds = r.get("acceptance", True)
    ratio = ours["seconds"] / peer["seconds"]
    rows = [row("plan", r["file"], "pyGCodeDecode 1.5.1", peer["seconds"], peer["peak_mb"]),
            row("plan", r["file"], f"gcodekit ({r['machine']} planner)", ours["seconds"], ours["peak_mb"], ratio,
                "<= 0.02x pyGCodeDecode (50x faster)", ratio <= 0.02 if binds else None,
                f"memory used {r['memory_share']:.3f} of the peer's (<= 0.1)"
                + ("" if binds else "; target binds on the cylinder"))]
    if "plate150" in r:
        p = r["plate150"]
        rows.append(row("plan", "plate150_marlin2.gcode.gz", "gcodekit planning alone", p["plan_s"], None,
                        p["share"], "<= 0.6x read + emulate", p["share"] <= 0.6))
    return rows


def scale_rows(r: Any) -> list[dict]:
    """bench_scale.py: read + emulate + plan against the 50-line loop (rows with tool/file/seconds/peak_mb)."""
    found = r if isinstance(r, list) else r.get("rows", [r])
    loops = {x.get("file"): x for x in found if "loop" in str(x.get("tool", "")).lower()}
    rows = []
    for x in found:
        loop = loops.get(x.get("file"))
        ours = loop is not None and x is not loop
        ratio = x["seconds"] / loop["seconds"] if ours and loop["seconds"] else None
        bpl = x.get("bytes_per_line")
        binds = "plate150" in str(x.get("file", ""))  # the targets are defined on the 3 M-line plate
        data = x.get("data_bytes_per_line")
        note = ((f"{bpl:.0f} B/line" if bpl is not None else "")
                + (f" ({data:.0f} above the {x['runtime_mb']:.0f} MB runtime)" if data is not None and ours else "")
                + ("" if binds or not ours else "; target binds on plate150"))
        rows.append(row("scale", x.get("file", ""), str(x.get("tool", "")), x.get("seconds"), x.get("peak_mb"), ratio,
                        "<= 0.5x the loop, <= 150 B/line" if ours else "",
                        (ratio <= 0.5 and (bpl is None or bpl <= 150)) if ratio is not None and binds else None,
                        note))
    return rows


def startup_rows(r: dict) -> list[dict]:
    """bench_startup.py: commands end to end, imports included."""
    return [row("start-up", x["file"], x["tool"], x["seconds"], None, None,
                f"<= {x['target_s']:g} s" if x["target_s"] is not None else "", x["pass"],
                f"median {x['median_s']:.2f} s of {len(x['runs'])}"
                + (f", CPU {x['cpu_s']:.2f} s" if "cpu_s" in x else "")) for x in r["rows"]]


def report_rows(r: dict) -> list[dict]:
    """bench_report.py: reports (HTML + PDF) end to end, and a batch on two workers against one."""
    rows = []
    for key in ("single", "plate"):
        if key in r:
            x = r[key]
            rows.append(row("report", x["file"], "gcodekit report (HTML + PDF)", x["seconds"], None, None,
                            f"<= {x['target_s']:g} s", x["seconds"] <= x["target_s"]))
    if "mill" in r:
        x = r["mill"]
        rows.append(row("report", f"mill surfacing, {x['moves']:,} moves", "gcodekit report (HTML + PDF)",
                        x["seconds"], note="informative: the transpiler's stage table over every command"))
    if "batch" in r:
        b = r["batch"]
        rows.append(row("report", f"FFF corpus ({b['programs']} programs)", "gcodekit report --workers 2",
                        b["two_workers_s"], None, 1 / b["speedup"], f"<= {1 / b['min_speedup']:.3g}x one worker",
                        b["speedup"] >= b["min_speedup"], f"one worker {b['one_worker_s']:.2f} s"))
    return rows


def widgets_rows(r: list) -> list[dict]:
    """bench_widgets.py: a layer-slider step in the browser against drawing the step as a PNG in Python."""
    rows = []
    for x in r:
        shown, png = x["shown_ms"] / 1000, x["peer_png_ms"] / 1000
        rows.append(row("widgets", x["file"], "PNG per step in Python (peer)", png))
        rows.append(row("widgets", x["file"], "LayerViewer step, key to frame shown", shown, None, shown / png,
                        f"<= {x['limit_ms'] / 1000:g} s, and the plot's redraw", x["pass"],
                        f"VelocityPlot redrawn in {x['plot_ms']:.0f} ms (median of {x['steps']} steps)"))
    return rows


def cut_rows(r: dict) -> list[dict]:
    """bench_cut.py: material removal of a raster finishing program (no peer)."""
    full = r["moves"] > 100_000
    ok = r["cut_s"] < 30 and r["peak_mb"] < 2048
    return [row("cut", f"raster {r['moves']:,} moves", "gcodekit cut", r["cut_s"], r["peak_mb"], None,
                "< 30 s, < 2048 MB", ok if full else None, "" if full else "target binds on 100 k moves")]


def additive_rows(r: dict) -> list[dict]:
    """bench_additive.py: the additive part and its VTK export (no peer)."""
    best, worst, name = r["best"], r["worst"], r.get("file", "")
    return [row("additive", name, "read + emulate", best["read_emulate_s"], worst["operation_mb"]),
            row("additive", name, "AdditivePart + layers", best["part_s"], worst["part_mb"]),
            row("additive", name, "VTK export (.vtp)", best["vtk_s"], worst["vtk_mb"])]


@dataclass
class Benchmark:
    """A benchmark script: its arguments (full and quick), what it needs, and how its JSON becomes rows."""

    name: str
    script: str
    rows: Callable[[Any], list[dict]]
    full: list[str] = field(default_factory=list)
    quick: list[str] = field(default_factory=list)
    needs: tuple[str, ...] = ()
    how: str = BENCH_EXTRA


SUITE = [
    Benchmark("read", "bench_read.py", read_rows, quick=["--quick"], needs=("gcodeparser",)),
    Benchmark("plan", "bench_plan.py", plan_rows, quick=["--quick"], needs=("pyGCodeDecode",)),
    Benchmark("scale", "bench_scale.py", scale_rows, quick=["--quick"]),
    Benchmark("start-up", "bench_startup.py", startup_rows, quick=["--quick"]),
    Benchmark("report", "bench_report.py", report_rows, full=["--plate", "--mill"], quick=["--quick"]),
    Benchmark("widgets", "bench_widgets.py", widgets_rows, quick=["--quick"], needs=("playwright", "jupyterlab"),
              how=TEST_EXTRA),
    Benchmark("cut", "bench_cut.py", cut_rows, quick=["--passes", "20"]),
    Benchmark("additive", "bench_additive.py", additive_rows,
              quick=["--file", str(HERE.parent.parent / "shared" / "corpus" / "fff" / "cylinder_marlin2.gcode"),
                     "--repeat", "1"]),
]


def missing(bench: Benchmark) -> list[str]:
    """The modules a benchmark needs that are not installed."""
    return [m for m in bench.needs if importlib.util.find_spec(m) is None]


def quick_args(bench: Benchmark, script: Path) -> list[str]:
    """``bench.quick`` when the script offers ``--quick`` (another branch's script may not), else nothing."""
    if "--quick" not in bench.quick:
        return bench.quick
    help_text = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True).stdout
    return bench.quick if "--quick" in help_text else []


def run(bench: Benchmark, quick: bool, folder: Path) -> list[dict]:
    """Run one benchmark and give its rows (one row saying why when it could not run)."""
    script = HERE / bench.script
    if not script.exists():
        return [row(bench.name, "", bench.script, note=f"skipped: {bench.script} is not in this checkout")]
    lacking = missing(bench)
    if lacking:
        return [row(bench.name, "", bench.script, note=f"skipped: {', '.join(lacking)} missing; {bench.how}")]
    out = folder / f"{bench.name}.json"
    out.unlink(missing_ok=True)  # a figure from an earlier run is never read as this run's
    cmd = [sys.executable, str(script), *(quick_args(bench, script) if quick else bench.full), "--json", str(out)]
    print(f"== {bench.name}: {' '.join(cmd[1:])}", flush=True)
    start = time.perf_counter()
    done = subprocess.run(cmd)  # its own table on this terminal as it goes
    print(f"   ({time.perf_counter() - start:.0f} s, exit status {done.returncode})", flush=True)
    if not out.exists():
        return [row(bench.name, "", bench.script, note=f"failed: exit status {done.returncode}, no JSON written")]
    return bench.rows(json.loads(out.read_text()))


def _cell(value: Any, column: str) -> str:
    if value is None:
        return ""
    if column == "pass":
        return "PASS" if value else "FAIL"
    if column == "seconds":
        return f"{value:.3f}" if value < 1 else f"{value:.2f}"
    if column == "peak_mb":
        return f"{value:.0f}"
    if column == "ratio":
        return f"{value:.3g}x"
    return str(value).replace("|", "\\|")


def markdown(rows: list[dict], meta: dict[str, Any]) -> str:
    """The table as markdown, with a line saying when and where it was measured."""
    head = ["benchmark", "file", "tool", "seconds", "peak MB", "ratio to peer", "target", "result", "note"]
    lines = [f"Measured {meta['date']} ({'quick' if meta['quick'] else 'full'} run), {meta['cpus']} CPUs, "
             f"Python {meta['python']}, load average {meta['load_before']:.1f} before and "
             f"{meta['load_after']:.1f} after.", "",
             "| " + " | ".join(head) + " |", "|" + "|".join(" --- " for _ in head) + "|"]
    lines += ["| " + " | ".join(_cell(r[c], c) for c in COLUMNS) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def write_table(rows: list[dict], meta: dict[str, Any], out: Path) -> tuple[Path, Path]:
    """Write ``benchmarks.md`` and ``benchmarks.json`` into ``out`` (each benchmark's own JSON is in
    ``out/raw/``); return their paths."""
    out.mkdir(parents=True, exist_ok=True)
    md, js = out / "benchmarks.md", out / "benchmarks.json"
    md.write_text(markdown(rows, meta), encoding="utf-8")
    js.write_text(json.dumps({**meta, "rows": rows}, indent=2) + "\n", encoding="utf-8")
    return md, js


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="smoke run on small files (targets shown, most not binding)")
    p.add_argument("--out", type=Path, default=HERE / "results", help="folder for the table (default: %(default)s)")
    p.add_argument("--only", nargs="+", choices=[b.name for b in SUITE], metavar="NAME",
                   help="run only these: " + ", ".join(b.name for b in SUITE))
    args = p.parse_args(argv)
    suite = [b for b in SUITE if not args.only or b.name in args.only]
    lacking = sorted({m for b in suite for m in missing(b) if b.how == BENCH_EXTRA})
    if lacking:
        print(f"peer libraries missing: {', '.join(lacking)}; their benchmarks are skipped. "
              f"Install them with: {BENCH_EXTRA}", file=sys.stderr)
    meta = {"date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M"), "quick": args.quick,
            "cpus": os.cpu_count(), "python": platform.python_version(), "load_before": os.getloadavg()[0]}
    rows: list[dict] = []
    raw = args.out / "raw"  # each benchmark's own JSON, kept beside the table
    raw.mkdir(parents=True, exist_ok=True)
    for bench in suite:
        rows += run(bench, args.quick, raw)
    meta["load_after"] = os.getloadavg()[0]
    md, js = write_table(rows, meta, args.out)
    print("\n" + markdown(rows, meta))
    print(f"written: {md} and {js}")
    return 1 if any(r["pass"] is False for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
