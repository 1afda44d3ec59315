"""Benchmark: AdditivePart construction and VTK export of a large print.

The speed figure of the additive issue: on ``plate150_marlin2.gcode.gz``
(3.1 M lines) how long do building the :class:`~gcodekit.AdditivePart` and
writing it as VTK (``.vtp``) take, and how much memory do they need on top
of the emulated operation?

Each measurement runs in a fresh interpreter, so its peak resident set size
is its own.  One child reads and emulates the program (without planning,
which these steps do not need), then times the part, its layer table and the
export; peak RSS is read after each step.  Runs are repeated and the best
time counts, the worst memory (this VM pays for the first touch of memory).

Examples
--------
::

    python benchmarks/bench_additive.py                 # plate150, 3 runs, about a minute
    python benchmarks/bench_additive.py --file F.gcode --repeat 1
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PLATE = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "fff" / "plate150_marlin2.gcode.gz"


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def child(path: str, machine: str) -> dict:
    """One measurement, inside a fresh interpreter."""
    t0 = time.perf_counter()
    import gcodekit
    from gcodekit.export.vtk import import_pyvista

    import_pyvista()  # import time is not export time
    figures = {"import_s": time.perf_counter() - t0, "import_mb": _peak_mb()}
    t0 = time.perf_counter()
    op = gcodekit.gcode_to_operation(Path(path), machine, plan=False)
    figures.update(read_emulate_s=time.perf_counter() - t0, operation_mb=_peak_mb(), waypoints=int(op.waypoints["x"].size))
    t0 = time.perf_counter()
    part = gcodekit.AdditivePart(op)
    part.layer_times()
    figures.update(part_s=time.perf_counter() - t0, part_mb=_peak_mb(), segments=len(part.summary),
                   depositions=len(part.depositions), layers=part.n_layers)
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / "part.vtp"
        t0 = time.perf_counter()
        gcodekit.VTKExporter.additive_part_to_vtk(part, target)
        figures.update(vtk_s=time.perf_counter() - t0, vtk_mb=_peak_mb(), vtk_bytes=target.stat().st_size)
    return figures


def run_child(path: Path, machine: str) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", str(path), machine],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--file", type=Path, default=PLATE, help="program to measure (default: plate150)")
    parser.add_argument("--machine", default="marlin", help="gcodekit machine preset (default: marlin)")
    parser.add_argument("--repeat", type=int, default=3, help="fresh-interpreter runs (default: 3)")
    parser.add_argument("--json", metavar="OUT", help="also write the figures as JSON")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(child(*args.child)))
        return 0
    if not args.file.exists():
        print(f"{args.file} not found (the shared corpus sits next to the repository)", file=sys.stderr)
        return 2
    runs = []
    for i in range(args.repeat):
        runs.append(run_child(args.file, args.machine))
        r = runs[-1]
        print(f"run {i + 1}: read+emulate {r['read_emulate_s']:.2f} s, part {r['part_s']:.2f} s, "
              f"vtk {r['vtk_s']:.2f} s", flush=True)
    best = {k: min(r[k] for r in runs) for k in ("read_emulate_s", "part_s", "vtk_s")}
    worst = {k: max(r[k] for r in runs) for k in ("import_mb", "operation_mb", "part_mb", "vtk_mb")}
    r = runs[0]
    print(f"\n{args.file.name}: {r['waypoints']:,} waypoints, {r['segments']:,} segments "
          f"({r['depositions']:,} depositions), {r['layers']} layers; .vtp {r['vtk_bytes'] / 1e6:.1f} MB")
    print(f"{'step':22}{'best s':>9}{'peak MB':>10}{'added MB':>10}")
    rows = [("read + emulate", best["read_emulate_s"], worst["operation_mb"], worst["operation_mb"] - worst["import_mb"]),
            ("AdditivePart + layers", best["part_s"], worst["part_mb"], worst["part_mb"] - worst["operation_mb"]),
            ("VTK export (.vtp)", best["vtk_s"], worst["vtk_mb"], worst["vtk_mb"] - worst["part_mb"])]
    for name, seconds, peak, added in rows:
        print(f"{name:22}{seconds:9.2f}{peak:10.1f}{added:10.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"file": args.file.name, "runs": runs, "best": best, "worst": worst},
                                              indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
