"""Benchmark: read + emulate + plan at scale, against the 50-line Python loop (issue 25).

The acceptance benchmark of issue 25, items 1 and 3:

* on ``plate150_marlin2.gcode.gz`` (3.1 M lines), gcodekit's read, emulate
  and plan (the Marlin and the Klipper model) in at most **half** the time
  of ``benchmarks/python_loop.py`` (the per-line ceiling: a plain Python
  loop that tokenises and tracks position), measured side by side in one
  run, with a peak memory of at most **150 bytes per input line**;
* a 30 M-line program (ten plates one after another, written by this
  script into a temporary folder as one gzip file of ten members, not
  kept) read, emulated and planned within the machine's memory.

Every measurement runs in a fresh interpreter (its peak resident set size,
``ru_maxrss``, is its own), the tools take turns (loop, Marlin, Klipper,
loop, Klipper, Marlin, ...), the best time and the worst peak count.  The checks use wall
time; the CPU time of each run is printed beside it, because on a shared
machine other jobs slow the two sides differently (the Python loop more
than gcodekit's array code).  gcodekit's time is
``gcode_to_operation(path, machine)``: decompressing, reading, parsing,
emulating and planning, with whatever it imports on the way (Numba, when
the compiled scanner is used); ``import gcodekit`` itself is left out, as
the loop's interpreter start is.  Bytes per line are the whole peak over
the file's lines.  The system time (``sys s``) is mostly the kernel giving
the process fresh pages: on a virtual machine whose host takes back freed
memory (as these do), every megabyte first touched costs about 2 ms, so a
peak of 750 MB is also over a second of the run, and the same run's time
moves with how much memory the host has reclaimed.

    python benchmarks/bench_scale.py                      # plate150 and the cylinder, 3 runs each
    python benchmarks/bench_scale.py --big                # and the 30 M-line file (one run each)
    python benchmarks/bench_scale.py --json out.json      # records: tool, file, seconds, peak_mb, bytes_per_line, lines
    python benchmarks/bench_scale.py --quick              # smoke run: the cylinder, once
"""

from __future__ import annotations

import argparse
import gzip
import json
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
CORPUS = HERE.parents[1] / "shared" / "corpus" / "fff"
PLATE = CORPUS / "plate150_marlin2.gcode.gz"
CYLINDER = CORPUS / "cylinder_marlin2.gcode"
MAX_TIME_RATIO = 0.5
MAX_BYTES_PER_LINE = 150.0
TOOLS = ("python_loop", "gcodekit marlin", "gcodekit klipper")


def child(tool: str, path: str) -> dict:
    """One measurement, inside a fresh interpreter: seconds, the peak resident set size and the runtime's share.

    ``runtime_mb`` is what the process still holds once the result is
    dropped and freed memory handed back: the interpreter, the libraries
    (Numba's LLVM among them) and the loaded kernels, which no input line
    costs.  The checks bind on the whole peak; the share is printed beside
    it to show how much of the peak the data is.
    """
    if tool == "python_loop":
        sys.path.insert(0, str(HERE))
        import python_loop

        t0, c0 = time.perf_counter(), time.process_time()
        result = python_loop.run(path)
    else:
        import gcodekit

        machine = tool.split()[1]
        t0, c0 = time.perf_counter(), time.process_time()
        result = gcodekit.gcode_to_operation(Path(path), machine)
        assert result.plan is not None
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    usage = resource.getrusage(resource.RUSAGE_SELF)
    del result
    return {"seconds": seconds, "cpu_seconds": cpu, "peak_mb": usage.ru_maxrss / 1024,
            "system_seconds": usage.ru_stime, "page_faults": usage.ru_minflt, "runtime_mb": _held_mb()}


def _held_mb() -> float:
    """The resident set size, MB, after a garbage collection and (on glibc) the heap's free pages handed back.

    ``gcodekit.memory.release_freed_memory`` does the same, but importing
    gcodekit (and NumPy) would add to the loop's runtime what it never used.
    """
    import ctypes
    import gc

    gc.collect()
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):  # not glibc: the free pages stay counted
        pass
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) / 1024 for line in f if line.startswith("VmRSS:"))


def _run_child(tool: str, path: Path) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", tool, str(path)], capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{tool} on {path.name} failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def count_lines(path: Path) -> int:
    opener = gzip.open if path.suffix == ".gz" else open
    lines = 0
    with opener(path, "rb") as f:
        while block := f.read(1 << 24):
            lines += block.count(b"\n")
    return lines


def ten_plates(folder: Path) -> Path:
    """The 30 M-line program: plate150 ten times over, as one gzip file of ten members."""
    path = folder / "ten_plates_marlin2.gcode.gz"
    with open(path, "wb") as out:
        for _ in range(10):
            with open(PLATE, "rb") as member:
                shutil.copyfileobj(member, out)
    return path


def _turns(tools, round_: int) -> list[str]:
    """The loop first, then gcodekit's tools in an order that turns each round.

    On these virtual machines the host takes back memory a process freed a
    few seconds earlier, so the tool that runs right after the loop (whose
    45 MB frees nothing) pays about a second more in page faults than one
    that runs right after a gcodekit run; turning the order gives every
    tool both places.
    """
    rest = [t for t in tools if t != "python_loop"]
    shift = round_ % len(rest) if rest else 0
    return [t for t in tools if t == "python_loop"] + rest[shift:] + rest[:shift]


def measure(path: Path, repeat: int, tools=TOOLS, warm_up: bool = True) -> list[dict]:
    """Each tool ``repeat`` times, taking turns; the best time and the worst peak of each.

    With ``warm_up``, each gcodekit tool first runs once unmeasured: the first
    run on a machine compiles Numba's kernels into its cache (seconds of CPU
    and about 70 MB more peak, once per installation, as pip compiles the
    bytecode), and reads the file into the page cache, as the loop's first run
    does for it.
    """
    lines = count_lines(path)
    runs: dict[str, list[dict]] = {t: [] for t in tools}
    for tool in tools if warm_up else ():
        if tool != "python_loop":
            r = _run_child(tool, path)
            print(f"  {tool:18s} {r['seconds']:7.2f} s {r['peak_mb']:8.1f} MB  (warm-up, not counted)", file=sys.stderr)
    for round_ in range(repeat):
        for tool in _turns(tools, round_):
            runs[tool].append(_run_child(tool, path))
            r = runs[tool][-1]
            print(f"  {tool:18s} {r['seconds']:7.2f} s {r['peak_mb']:8.1f} MB  system {r['system_seconds']:5.2f} s, "
                  f"{r['page_faults']:,} page faults", file=sys.stderr)
    records = []
    for tool in tools:
        peak = max(r["peak_mb"] for r in runs[tool])
        runtime = min(r["runtime_mb"] for r in runs[tool])
        records.append({"tool": tool, "file": path.name, "seconds": min(r["seconds"] for r in runs[tool]),
                        "cpu_seconds": min(r.get("cpu_seconds", float("nan")) for r in runs[tool]),
                        "system_seconds": min(r["system_seconds"] for r in runs[tool]),
                        "peak_mb": peak, "bytes_per_line": peak * 2**20 / lines, "lines": lines,
                        "runtime_mb": runtime, "data_bytes_per_line": (peak - runtime) * 2**20 / lines,
                        "runs": len(runs[tool])})
    return records


def report(records: list[dict]) -> bool:
    """Print the table and the checks (which bind on plate150 only); True when they pass."""
    ok = True
    for name in dict.fromkeys(r["file"] for r in records):
        rows = [r for r in records if r["file"] == name]
        loop = next(r for r in rows if r["tool"] == "python_loop")
        print(f"\n{name}  {loop['lines']:,} lines")
        print(f"  {'':18s} {'runs':>4s} {'best s':>8s} {'x loop':>7s} {'CPU s':>7s} {'x loop':>7s} {'sys s':>6s} "
              f"{'peak MB':>9s} {'B/line':>7s} {'runtime MB':>10s} {'data B/line':>11s}")
        for r in rows:
            print(f"  {r['tool']:18s} {r['runs']:4d} {r['seconds']:8.2f} {r['seconds'] / loop['seconds']:7.2f} "
                  f"{r['cpu_seconds']:7.2f} {r['cpu_seconds'] / loop['cpu_seconds']:7.2f} "
                  f"{r.get('system_seconds', float('nan')):6.2f} {r['peak_mb']:9.1f} {r['bytes_per_line']:7.1f} "
                  f"{r['runtime_mb']:10.1f} {r['data_bytes_per_line']:11.1f}")
        if name != PLATE.name:
            continue
        for r in rows:
            if r["tool"] == "python_loop":
                continue
            ratio = r["seconds"] / loop["seconds"]
            time_ok, mem_ok = ratio <= MAX_TIME_RATIO, r["bytes_per_line"] <= MAX_BYTES_PER_LINE
            ok &= time_ok and mem_ok
            print(f"  {r['tool']}: time {ratio:.2f} of the loop (<= {MAX_TIME_RATIO})  {'PASS' if time_ok else 'FAIL'};"
                  f" peak {r['bytes_per_line']:.0f} B/line (<= {MAX_BYTES_PER_LINE:.0f})  {'PASS' if mem_ok else 'FAIL'}")
    return ok


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--child", nargs=2, metavar=("TOOL", "FILE"), help=argparse.SUPPRESS)
    parser.add_argument("--repeat", type=int, default=3, help="runs of each tool on each file (default 3)")
    parser.add_argument("--big", action="store_true", help="also the 30 M-line file (one run of each tool)")
    parser.add_argument("--skip-cylinder", action="store_true")
    parser.add_argument("--file", type=Path, help="measure this file instead of plate150")
    parser.add_argument("--quick", action="store_true", help="a smoke run: the cylinder alone, once")
    parser.add_argument("--json", type=Path, metavar="OUT", help="write the records as JSON")
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(child(*args.child)))
        return 0
    files = [args.file or PLATE] + ([] if args.skip_cylinder or args.file else [CYLINDER])
    if args.quick:
        files, args.repeat, args.big = [CYLINDER], 1, False
    records = []
    for path in files:
        print(f"{path.name}:", file=sys.stderr)
        records += measure(path, args.repeat)
    if args.big:
        with tempfile.TemporaryDirectory(prefix="gcodekit-bench-") as folder:
            path = ten_plates(Path(folder))
            print(f"{path.name}:", file=sys.stderr)
            records += measure(path, 1, warm_up=False)  # the kernels were compiled on plate150
    ok = report(records)
    if args.json:
        args.json.write_text(json.dumps(records, indent=1))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
