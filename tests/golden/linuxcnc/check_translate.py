"""Run ``gcodekit translate``'s last stage of every golden case through rs274.

Issue 4 asks that the transpiler's output also runs in LinuxCNC with the same
motions.  For each case in ``cases/`` this writes stage 6 (with a leading G21:
the stage is in millimetres and carries no units word), runs rs274 on it with
the tool table the case used, and compares the end points of every motion
with gcodekit's own, in machine millimetres, to rs274's printed precision.

Usage::

    .venv/bin/python tests/golden/linuxcnc/check_translate.py

Needs ``/usr/bin/rs274`` and LinuxCNC's ``gcode`` module (see README.md).
Prints one line per case and exits 1 if any differs.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TOLERANCE_MM = 0.0001 * 25.4 * 2  # rs274 prints 4 decimals of inches or mm

sys.path.insert(0, str(HERE.parents[2]))  # this checkout's gcodekit, not an installed one
sys.path.insert(0, str(HERE.parents[1]))  # tests/, for the golden test's helpers
sys.path.insert(0, str(HERE))  # regenerate.py, which runs rs274

import gcodekit  # noqa: E402
from gcodekit.transpile import Transpiler  # noqa: E402
from regenerate import rerun  # noqa: E402
from test_linuxcnc_golden import reference_motions, tool_table  # noqa: E402


def check(case: Path, workdir: Path) -> str | None:
    """None when the translation moves like the original, else what differs."""
    table = tool_table(case.name)
    op = gcodekit.gcode_to_operation(case, "linuxcnc", plan=False, tool_table=table, tool_table_units="inch")
    translated = workdir / case.name
    translated.write_text(Transpiler(op).stage(6))
    canon = translated.with_suffix(".canon")
    try:
        rerun(translated, table, canon)
    except subprocess.CalledProcessError as exc:
        return f"rs274 refused it ({exc})"
    ref = reference_motions(Path(f"{canon}.csv"))
    w = op.waypoints
    moved = np.flatnonzero(np.asarray(w["motion"]) > 0)
    ours = np.column_stack([np.asarray(w[k], float)[moved] for k in "xyz"])
    if len(ref) != len(ours):
        return f"{len(ref)} motions in rs274, {len(ours)} in gcodekit"
    worst = float(np.abs(ref[["x", "y", "z"]].to_numpy() - ours).max(initial=0.0))
    return None if worst <= TOLERANCE_MM else f"end points differ by up to {worst:.4g} mm"


def main() -> int:
    failures = 0
    # cases have a reference table; other .ngc files there are subroutines a case calls
    cases = sorted(p for p in (HERE / "cases").glob("*.ngc") if p.with_name(p.name + ".canon.csv").exists())
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases:
            problem = check(case, Path(tmp))
            failures += problem is not None
            print(f"{case.name}: {problem or 'same motions'}")
    print(f"{failures} of {len(cases)} translations differ")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
