"""Benchmark: how long the commands take from start to finish, imports included (issue 25, item 2).

The targets, each the ``gcodekit`` command in a fresh interpreter, end to end:

* ``gcodekit info`` of a small file (``cube20_marlin2.gcode``, 8.7 k lines)
  within **0.5 s**;
* ``gcodekit report`` of ``cylinder_marlin2.gcode`` (147 k lines) within
  **3 s**, HTML only (``--no-pdf``) and HTML + PDF.

Each command runs once unmeasured (bytecode written, files in the page
cache, as for an installed package), then ``--repeat`` times with this
checkout's ``gcodekit`` first on the path, the commands taking turns; the
best time counts (the machine is
shared: the load average before each run is printed and kept, and so is
the CPU time each command and its children used, which a busy machine
changes far less than the wall time).  ``python -c
pass`` and ``import gcodekit`` are measured the same way, for what the
interpreter and the package cost before any work.  No peer: no other tool
writes these reports; the 50-line loop (``python_loop.py``) reading the
small file is given beside ``info`` as the floor of a Python G-code reader.

Examples
--------
::

    python benchmarks/bench_startup.py                 # 5 runs of each, about a minute
    python benchmarks/bench_startup.py --quick --json out.json
    python benchmarks/bench_startup.py --phases        # where the time goes, stage by stage
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO.parent / "shared" / "corpus" / "fff"
SMALL = CORPUS / "cube20_marlin2.gcode"
CYLINDER = CORPUS / "cylinder_marlin2.gcode"
MAX_INFO_S = 0.5
MAX_REPORT_S = 3.0
#: This checkout's gcodekit first, whatever the directory and whichever copy is installed; bytecode cached
#: as an installed package has it (pip compiles it; a shell with PYTHONDONTWRITEBYTECODE would compile every
#: module of gcodekit on every start, 0.15-0.2 CPU-s of an ``info``).
ENV = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},
       "PYTHONPATH": os.pathsep.join([str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])])}


def commands(out: str) -> list[dict]:
    """The measured commands: name, file, argument list, target seconds (None: for information)."""
    gk = [sys.executable, "-m", "gcodekit.cli"]
    report = [*gk, "report", str(CYLINDER), "-o", out, "--force", "--no-progress"]
    return [
        {"name": "python -c pass", "file": "", "cmd": [sys.executable, "-c", "pass"], "target": None},
        {"name": "import gcodekit", "file": "", "cmd": [sys.executable, "-c", "import gcodekit"], "target": None},
        {"name": "50-line loop", "file": SMALL.name,
         "cmd": [sys.executable, str(REPO / "benchmarks" / "python_loop.py"), str(SMALL)], "target": None},
        {"name": "gcodekit info", "file": SMALL.name, "cmd": [*gk, "info", str(SMALL)], "target": MAX_INFO_S},
        {"name": "gcodekit report (HTML)", "file": CYLINDER.name, "cmd": [*report, "--no-pdf"],
         "target": MAX_REPORT_S},
        {"name": "gcodekit report (HTML + PDF)", "file": CYLINDER.name, "cmd": report, "target": MAX_REPORT_S},
    ]


def run_once(cmd: list[str]) -> tuple[float, float, float]:
    """Wall time of one fresh process, the CPU time it and its children used (user + system: what a busy
    machine changes least), and the 1-minute load average just before it."""
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    # run from an empty folder: ``python -c`` and ``-m`` put the current directory first on the path,
    # where a checkout would take the place of the one measured
    with tempfile.TemporaryDirectory() as cwd:
        done = subprocess.run(cmd, capture_output=True, text=True, env=ENV, cwd=cwd)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stderr}")
    return seconds, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, load


def phases(json_out: str | None) -> int:
    """Run ``info`` and the report (HTML + PDF) once each (after an unmeasured run) through
    ``phases_hook.py`` and print each stage's start, wall and CPU seconds, per process."""
    hook = [sys.executable, str(REPO / "benchmarks" / "phases_hook.py")]
    result = {}
    with tempfile.TemporaryDirectory() as out:
        for c in commands(out):
            if c["name"] not in ("gcodekit info", "gcodekit report (HTML + PDF)"):
                continue
            cmd = hook + c["cmd"][3:]  # the command's arguments after ``python -m gcodekit.cli``
            records = Path(out, "phases.jsonl")
            run_once(cmd)
            records.unlink(missing_ok=True)
            ENV["GCODEKIT_PHASES"] = str(records)
            try:
                seconds, cpu, load = run_once(cmd)
            finally:
                del ENV["GCODEKIT_PHASES"]
            rows = [json.loads(line) for line in records.read_text().splitlines()]
            result[c["name"]] = {"seconds": seconds, "cpu_s": cpu, "load": load, "stages": rows}
            print(f"\n{c['name']} ({c['file']}): {seconds:.2f} s wall, {cpu:.2f} CPU-s with its children "
                  f"(Chromium's included), load average {load:.1f}")
            print(f"  {'process':14}{'stage':44}{'calls':>6}{'first at s':>11}{'wall s':>9}{'CPU s':>8}")
            stages: dict[tuple[str, str], list[dict]] = {}
            for r in rows:
                stages.setdefault((r["process"], r["stage"]), []).append(r)
            for (who, stage), calls in sorted(stages.items(), key=lambda kv: kv[1][0]["start_s"]):
                print(f"  {who.split()[0]:14}{stage:44}{len(calls):6d}{calls[0]['start_s']:11.2f}"
                      f"{sum(r['wall_s'] for r in calls):9.2f}{sum(r['cpu_s'] for r in calls):8.2f}")
    if json_out:
        Path(json_out).write_text(json.dumps(result, indent=2) + "\n")
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=5, help="runs of each command, best counts (default: 5)")
    p.add_argument("--quick", action="store_true", help="smoke run: 2 runs of each")
    p.add_argument("--json", metavar="OUT", help="also write the figures as JSON")
    p.add_argument("--checkout", type=Path, metavar="DIR",
                   help="measure the gcodekit of another checkout (say, main's, for a before and after)")
    p.add_argument("--phases", action="store_true",
                   help="instead: run info and the report (HTML + PDF) once each with their stages timed")
    args = p.parse_args(argv)
    if args.checkout:
        ENV["PYTHONPATH"] = str(args.checkout.resolve())
    if not CYLINDER.exists():
        sys.exit(f"corpus not found: {CORPUS}")
    if args.phases:
        return phases(args.json)
    repeat = 2 if args.quick else args.repeat
    with tempfile.TemporaryDirectory() as out:
        cmds = commands(out)
        runs: dict[str, list[tuple[float, float, float]]] = {c["name"]: [] for c in cmds}
        for c in cmds:  # not counted: writes the bytecode and reads the files into the page cache
            run_once(c["cmd"])
        for _ in range(repeat):
            for c in cmds:
                runs[c["name"]].append(run_once(c["cmd"]))
    rows = []
    print(f"{'command':30}{'file':26}{'best s':>8}{'median s':>10}{'best CPU s':>12}{'target s':>10}  load averages")
    for c in cmds:
        times = [s for s, _, _ in runs[c["name"]]]
        cpu = [u for _, u, _ in runs[c["name"]]]
        loads = [ld for _, _, ld in runs[c["name"]]]
        best = min(times)
        row = {"tool": c["name"], "file": c["file"], "seconds": best, "median_s": statistics.median(times),
               "cpu_s": min(cpu), "runs": times, "cpu_runs": cpu, "loads": loads, "target_s": c["target"],
               "pass": None if c["target"] is None else best <= c["target"]}
        rows.append(row)
        target = "" if c["target"] is None else f"{c['target']:.1f}"
        verdict = "" if row["pass"] is None else ("PASS" if row["pass"] else "FAIL")
        print(f"{c['name']:30}{c['file']:26}{best:8.2f}{row['median_s']:10.2f}{row['cpu_s']:12.2f}{target:>10}  "
              f"{' '.join(f'{ld:.1f}' for ld in loads)}  {verdict}")
    result = {"cpus": os.cpu_count(), "repeat": repeat, "rows": rows}
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n")
    return 0 if all(r["pass"] is not False for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
