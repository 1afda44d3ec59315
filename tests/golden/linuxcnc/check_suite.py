"""Compare gcodekit with rs274 on a suite of programs kept outside the repository.

Issue 4 asks that further suites be checked the way the golden cases are.
For every ``.ngc`` under DIR (LinuxCNC's ``tests/interp`` layout: a test's
``test.sh`` may name its tool table ``-t``, INI ``-i`` and var file ``-v``)
this runs rs274, then gcodekit with the same tool table, and prints one line
per program:

* ``ok``: same motions (type, end point, arc centre; ``test_linuxcnc_golden``'s
  comparison) and no error;
* ``ERR-ok``: rs274 refused it and gcodekit reports an error on the same line
  (found as ``errors.py`` finds it);
* ``DIFF``, ``ERR-MISS``, ``ERR?`` (rs274's error line not found in the
  file), ``HARNESS`` (timeout or crash), with what differs.

With ``--detect`` gcodekit reads each program as a user would, with the
flavor it detects (no ``flavor``/``machine`` given; the rs274-standalone
options still apply), and each line also names that flavor.

Usage::

    .venv/bin/python tests/golden/linuxcnc/check_suite.py DIR [--detect] [--skip PREFIX ...]

Each program runs in its own process under a time and memory limit.  Needs
``/usr/bin/rs274`` and LinuxCNC's ``gcode`` module (see README.md).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
SHARED_TOOLS = HERE.parents[3] / "shared" / "tools" / "linuxcnc"
DEFAULT_TABLE = "/usr/share/doc/linuxcnc/examples/sample-configs/common/tool.tbl"


def options(program: Path) -> list[Path | None]:
    """The INI, tool table and var file the program's ``test.sh`` names (or its folder's only one)."""
    script = program.parent / "test.sh"
    text = script.read_text(errors="replace") if script.exists() else ""
    found = []
    for flag, suffix in (("-i", "*.ini"), ("-t", "*.tbl"), ("-v", "*.var")):
        match = re.search(rf"{flag}\s+(\S+)", text)
        path = program.parent / match.group(1) if match else None
        if path is None:
            candidates = list(program.parent.glob(suffix))
            path = candidates[0] if len(candidates) == 1 and flag != "-v" else None
        found.append(path if path is not None and path.exists() else None)
    return found


def check(program: Path, workdir: Path, detect: bool = False) -> tuple[str, str]:
    """(verdict, detail) for one program; with ``detect``, gcodekit detects the flavor."""
    sys.path.insert(0, str(HERE.parents[2]))
    sys.path.insert(0, str(HERE.parents[1]))
    sys.path.insert(0, str(HERE))
    import gcodekit
    from errors import expected_line
    from test_linuxcnc_golden import AXES, CENTRE, RS274_STANDALONE, first_difference, ours_like_canon, reference_motions

    ini, table, var = options(program)
    command = ["bash", str(SHARED_TOOLS / "run_rs274.sh"), *(["-i", str(ini)] if ini else []),
               *(["-v", str(var)] if var else []), str(program), *([str(table)] if table else [])]
    rs274 = subprocess.run(command, capture_output=True, text=True, timeout=120)
    canon = workdir / "out.canon"
    canon.write_text(rs274.stdout)
    csv = workdir / "out.canon.csv"
    subprocess.run(["/usr/bin/python3", str(SHARED_TOOLS / "canon_to_csv.py"), str(canon), "-o", str(csv),
                    "--src", str(program)], capture_output=True, text=True)
    emulation = {k: v for k, v in RS274_STANDALONE.items() if not (detect and k == "machine")}
    op = gcodekit.gcode_to_operation(program, plan=False, tool_table=str(table or DEFAULT_TABLE),
                                     ini_file=str(ini or ""), **emulation)
    if detect:
        workdir.joinpath("flavor").write_text(op.flavor.name)
    errors = [d for d in op.diagnostics.items if d.severity == "error"]
    shown = [str(d) for d in errors[:2]]
    if rs274.returncode != 0:
        lines = [line for line in rs274.stderr.splitlines() if line.strip()]
        message, block = (lines + ["?", ""])[:2]
        line, how = expected_line(program, message, block) if csv.exists() else (None, "no motions table")
        if line is None:
            return "ERR?", f"rs274: {message} ({how}); ours: {shown}"
        if any(d.line == line for d in errors):
            return "ERR-ok", f"line {line}: {message}"
        return "ERR-MISS", f"rs274 line {line}: {message} {block!r}; ours: {shown}"
    ours, ref = ours_like_canon(op), reference_motions(csv)
    problem = first_difference(ours, ref, ["motion", "units", "plane"], AXES + CENTRE)
    if problem is None and not errors:
        return "ok", f"{len(ref)} motions"
    return "DIFF", f"{(problem or '').splitlines()[0] if problem else ''} ours: {shown}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("suite", type=Path)
    ap.add_argument("--skip", nargs="*", default=[], help="programs (paths under the suite) to leave out")
    ap.add_argument("--detect", action="store_true", help="let gcodekit detect each program's flavor")
    ap.add_argument("--one", help=argparse.SUPPRESS)  # the child process's program
    args = ap.parse_args(argv)
    if args.one:
        with tempfile.TemporaryDirectory() as workdir:
            verdict, detail = check(args.suite / args.one, Path(workdir), args.detect)
            flavor = Path(workdir, "flavor")
            detail = f"[{flavor.read_text()}] {detail}" if flavor.exists() else detail
        print(f"{args.one}\t{verdict}\t{detail}")
        return 0
    verdicts: Counter[str] = Counter()
    for program in sorted(args.suite.rglob("*.ngc")):
        name = str(program.relative_to(args.suite))
        if "subs" in Path(name).parts[:-1] or name.startswith(tuple(args.skip)):
            continue  # subroutine files, and programs rs274 loops on
        child = subprocess.run(f"ulimit -v 4000000; exec timeout 300 {sys.executable} {__file__} {args.suite} "
                               f"--one {name!r}" + " --detect" * args.detect, shell=True, capture_output=True, text=True)
        line = next((out for out in child.stdout.splitlines() if out.startswith(name + "\t")),
                    f"{name}\tHARNESS\texit {child.returncode}: {child.stderr[-200:]!r}")
        print(line, flush=True)
        verdicts[line.split("\t")[1]] += 1
    print(dict(verdicts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
