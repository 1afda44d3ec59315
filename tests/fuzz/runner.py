"""Run fuzz cases one process each, with a time and a memory limit, and judge the outcome.

The runner imports gcodekit once and forks a child per case, so a case
costs milliseconds to start rather than the second an interpreter takes to
import NumPy and pandas.  The child runs the command (``gcodekit.cli.main``,
or the library's entry points for ``api`` cases) in the case's own folder;
the parent waits at most ``timeout`` seconds and reads the child's peak
memory from the kernel (``wait4``).

Outcomes:

* ``clean``: exit 0, nothing to report;
* ``diagnosed``: exit 0 with diagnostics (lenient mode reads what it can);
* ``rejected``: exit 1 or 2 with a message naming the file (and line and
  column when a line is at fault);
* ``crash``: a traceback, an internal error, another exit status or a signal;
* ``unlocated``: a rejection whose message names no file;
* ``hang``: still running after ``timeout``;
* ``memory``: peak memory above ``memory_mb``.

The last four are failures.
"""

from __future__ import annotations

import importlib
import json
import os
import re
import resource
import signal
import sys
import tempfile
import time
import traceback
from dataclasses import asdict, dataclass
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before NumPy: one thread's buffers per child
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

from .cases import FUZZ_MAX_MOTIONS, Case  # noqa: E402

FAILURES = ("crash", "unlocated", "hang", "memory")
_CAPTURE = 20_000  # characters of each output kept for the verdict


@dataclass
class Outcome:
    name: str
    kind: str
    command: str
    verdict: str
    status: int | None
    seconds: float
    peak_mb: float
    stderr: str


def run_cases(cases: list[Case], *, timeout: float = 60.0, memory_mb: float = 2048.0, jobs: int = 1,
              keep: Path | None = None) -> list[Outcome]:
    """Run every case; ``keep`` saves the folders of failing cases for a rerun."""
    for module in ("gcodekit.cli", "gcodekit.pipeline"):  # imported once, shared by every child
        importlib.import_module(module)

    outcomes: list[Outcome] = []
    waiting = list(reversed(cases))
    running: dict[int, tuple[Case, Path, float]] = {}
    with tempfile.TemporaryDirectory(prefix="gcodekit-fuzz-") as tmp:
        while waiting or running:
            while waiting and len(running) < jobs:
                case = waiting.pop()
                folder = _materialize(case, Path(tmp))
                running[_fork(case, folder)] = (case, folder, time.monotonic())
            pid, status, usage = os.wait4(-1, os.WNOHANG)
            if pid == 0:
                for child, (case, folder, started) in list(running.items()):
                    if time.monotonic() - started > timeout:
                        os.kill(child, signal.SIGKILL)
                time.sleep(0.005)
                continue
            case, folder, started = running.pop(pid)
            outcome = _judge(case, folder, status, usage, time.monotonic() - started, timeout, memory_mb)
            outcomes.append(outcome)
            if keep is not None and outcome.verdict in FAILURES:
                _save(case, keep)
    order = {c.name: k for k, c in enumerate(cases)}
    return sorted(outcomes, key=lambda o: order[o.name])


def _materialize(case: Case, tmp: Path) -> Path:
    folder = tmp / re.sub(r"[^\w.-]", "_", case.name)
    (folder / "out").mkdir(parents=True)
    for name, data in case.files.items():
        (folder / name).write_bytes(data)
    for name, target in case.links.items():
        (folder / name).symlink_to(target)
    return folder


def _fork(case: Case, folder: Path) -> int:
    pid = os.fork()
    if pid:
        return pid
    status = 99
    try:
        os.chdir(folder)
        # A guard, not the measure: a runaway meets MemoryError here instead of the machine's limit.
        resource.setrlimit(resource.RLIMIT_AS, (8 << 30, 8 << 30))
        for fd, name in ((1, "stdout.txt"), (2, "stderr.txt")):
            os.dup2(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644), fd)
        sys.stdout = open(1, "w", closefd=False)
        sys.stderr = open(2, "w", closefd=False)
        args = [a.replace("{out}", "out") for a in case.args]
        status = _api(args[1]) if args[0] == "api" else _cli(args)
    except BaseException:  # noqa: BLE001 -- whatever escapes is the verdict
        traceback.print_exc()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)


def _cli(args: list[str]) -> int:
    from gcodekit.cli import main

    return main(args)


def _api(program: str) -> int:
    """The library's front door: lenient reading never raises; strict raises gcodekit's errors only."""
    import gcodekit
    from gcodekit.errors import GcodeError

    limit = int(FUZZ_MAX_MOTIONS)
    try:
        op = gcodekit.gcode_to_operation(program, max_motions=limit)
    except (GcodeError, OSError) as exc:
        print(f"gcodekit: error: {exc}", file=sys.stderr)
        return 1
    op.to_dataframe()
    op.get_statistics()
    op.motions()
    for d in op.diagnostics:
        assert d.line >= 1 and d.column >= 1 and d.file, d
        print(str(d), file=sys.stderr)
    if op.machine.process == "additive":
        gcodekit.AdditivePart(op).depositions
    try:
        gcodekit.gcode_to_operation(program, mode="strict", max_motions=limit)
    except (GcodeError, OSError) as exc:
        print(f"strict: {exc}", file=sys.stderr)
        return 1
    return 0


def _judge(case: Case, folder: Path, status: int, usage, seconds: float, timeout: float,
           memory_mb: float) -> Outcome:
    err = _read(folder / "stderr.txt")
    out = _read(folder / "stdout.txt")
    peak = usage.ru_maxrss / 1024.0  # kB on Linux
    code = os.waitstatus_to_exitcode(status)
    if code == -signal.SIGKILL and seconds >= timeout:
        verdict = "hang"
    elif peak > memory_mb or "out of memory" in err or "MemoryError" in err:
        verdict = "memory"
    elif code not in (0, 1, 2) or "Traceback (most recent call last)" in err or "internal error" in err:
        verdict = "crash"
    elif code in (1, 2):
        verdict = "rejected" if case.program in err else "unlocated"
    else:
        verdict = "diagnosed" if err.strip() or re.search(r":\d+:\d+: (error|warning)", out) else "clean"
    return Outcome(case.name, case.kind, " ".join(case.args), verdict, code, round(seconds, 3), round(peak, 1),
                   err[-2000:])


def _read(path: Path) -> str:
    try:
        with open(path, "rb") as f:
            data = f.read(_CAPTURE)
    except FileNotFoundError:
        return ""
    return data.decode("utf-8", "replace")


def _save(case: Case, keep: Path) -> None:
    folder = keep / re.sub(r"[^\w.-]", "_", case.name)
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in case.files.items():
        (folder / name).write_bytes(data)
    (folder / "case.json").write_text(json.dumps({"kind": case.kind, "args": case.args, "links": case.links},
                                                 indent=1))


def load_case(folder: Path) -> Case:
    """A case saved by ``keep``, to run again."""
    meta = json.loads((folder / "case.json").read_text())
    files = {p.name: p.read_bytes() for p in folder.iterdir() if p.name != "case.json" and not p.is_symlink()}
    program = next(a for a in meta["args"][1:] if a in files)
    return Case(folder.name, meta.get("kind", "saved"), program, files, meta["links"], meta["args"])


def summary(outcomes: list[Outcome], seconds: float) -> dict:
    """Counts by verdict and by kind, and the extremes."""
    by_kind: dict[str, dict[str, int]] = {}
    for o in outcomes:
        by_kind.setdefault(o.kind, {}).setdefault(o.verdict, 0)
        by_kind[o.kind][o.verdict] += 1
    verdicts: dict[str, int] = {}
    for o in outcomes:
        verdicts[o.verdict] = verdicts.get(o.verdict, 0) + 1
    slowest = max(outcomes, key=lambda o: o.seconds) if outcomes else None
    biggest = max(outcomes, key=lambda o: o.peak_mb) if outcomes else None
    return {
        "cases": len(outcomes), "seconds": round(seconds, 1), "verdicts": verdicts, "by_kind": by_kind,
        "failures": [asdict(o) for o in outcomes if o.verdict in FAILURES],
        "slowest": slowest and {"name": slowest.name, "command": slowest.command, "seconds": slowest.seconds},
        "peak_memory": biggest and {"name": biggest.name, "command": biggest.command, "mb": biggest.peak_mb},
    }
