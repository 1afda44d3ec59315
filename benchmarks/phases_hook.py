"""Run a ``gcodekit`` command with its stages timed: where the time of ``bench_startup.py --phases`` goes.

Wraps the functions a report or ``info`` goes through (imports, reading,
the numbers, each picture, the page, the PDF) and appends one JSON line per
call to the file ``$GCODEKIT_PHASES``: process (the forked child that draws
pictures has its own), stage, start since the interpreter started, wall and
CPU seconds of that process.  A benchmark helper, not part of gcodekit:
renaming a wrapped function only drops its line.

    GCODEKIT_PHASES=out.jsonl python benchmarks/phases_hook.py report part.gcode -o out/ --force
"""

from __future__ import annotations

import functools
import json
import os
import sys
import time

START = time.perf_counter()
OUT = os.environ.get("GCODEKIT_PHASES")  # unset: the command runs, nothing is written
PARENT = os.getpid()


def _record(stage: str, began: float, wall: float, cpu: float) -> None:
    if not OUT:
        return
    who = "main" if os.getpid() == PARENT else f"child {os.getpid()}"
    with open(OUT, "a") as f:
        f.write(json.dumps({"process": who, "stage": stage, "start_s": began - START, "wall_s": wall,
                            "cpu_s": cpu}) + "\n")


def timed(module, name: str, stage: str | None = None) -> None:
    """Replace ``module.name`` by a wrapper recording each call."""
    inner = getattr(module, name, None)
    if inner is None:
        return

    @functools.wraps(inner)
    def wrapper(*args, **kwargs):
        began, cpu = time.perf_counter(), time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            _record(stage or name, began, time.perf_counter() - began, time.process_time() - cpu)

    setattr(module, name, wrapper)


def main() -> int:
    import importlib

    # the interpreter's own start is before this script: only its CPU time is seen
    _record("python start-up (CPU only)", START, 0.0, time.process_time())
    began, cpu = time.perf_counter(), time.process_time()
    import gcodekit.cli as cli
    _record("import gcodekit.cli", began, time.perf_counter() - began, time.process_time() - cpu)
    stages = {
        "gcodekit.pipeline": [("gcode_to_operation", "read + emulate + plan")],
        "gcodekit.report.build": [("report_data", "the numbers (report_data)")],
        "gcodekit.report.figures": [("load_drawing_modules", "import matplotlib, PIL"), ("toolpath_iso", None),
                                    ("toolpath_top", None), ("layer_thumbnails", None), ("velocity", None),
                                    ("layer_times", None), ("breakdown_chart", None),
                                    ("data_uri", "PNG (render + encode)"), ("report_figures", None)],
        "gcodekit.report.html": [("program_page", "HTML page (Jinja2)")],
        "gcodekit.report.pdf": [("start_browser", "start Chromium (not waited for)"),
                                ("html_to_pdf", "print the PDF")],
        "gcodekit.report.batch": [("report_program", "one program's report")],
    }
    report = sys.argv[1:2] == ["report"]
    began, cpu = time.perf_counter(), time.process_time()
    for module_name, names in stages.items():
        if report or module_name == "gcodekit.pipeline":  # info imports no report module but html's duration
            module = importlib.import_module(module_name)
            for name, stage in names:
                timed(module, name, stage)
    if report:
        import gcodekit.report.forked as forked

        timed(forked.Forked, "result", "wait for the forked pictures")
    _record("import the timed modules (NumPy, ...)", began, time.perf_counter() - began, time.process_time() - cpu)
    began, cpu = time.perf_counter(), time.process_time()
    try:
        return cli.main(sys.argv[1:])
    finally:
        _record("the command (from cli.main)", began, time.perf_counter() - began, time.process_time() - cpu)


if __name__ == "__main__":
    sys.exit(main())
