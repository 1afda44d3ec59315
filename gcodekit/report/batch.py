"""Report stage: reports of many programs, on worker processes or a Dask cluster.

Each program is one job: emulate, draw, write its page (and notebook).  A
job never raises: a program that fails gets an error page and an error row,
so one bad file never stops a batch.  Jobs are handed out largest file first,
so two workers finish together rather than one waiting on the biggest
program at the end.

On this machine's processes the PDFs are printed by the calling process, as
pages arrive, with one Chromium for the whole batch: a browser costs about
2 CPU-seconds to start and its first page, which a second worker with its
own browser took from the other worker's core.  That browser is started
when the batch starts, so it boots beside the first program's work.  On a Dask cluster each
worker prints its own pages (the client may not have Chromium or the cores).
"""

from __future__ import annotations

import os
import re
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager, suppress
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Sequence

from ..errors import GcodeError, MissingDependencyError
from ..limits import MAX_ITERATIONS, MAX_MOTIONS

if TYPE_CHECKING:
    import multiprocessing.context

    from ..model.operation import Operation

#: The pictures a report draws in a forked child (:mod:`.forked`): the toolpath views, about as much CPU
#: time as the numbers (pandas imported) and the other pictures left to this process (the cylinder's: 1.1 s)
CHILD_FIGURES = ("iso", "top", "thumbnails")
#: Commands from which the layer thumbnails are drawn here instead: on large programs the two views alone
#: outweigh the rest (plate150, 3.1 M commands: the child about 7 CPU-s with the thumbnails against 4.5 here;
#: they and their PNG take about 1).  On the cylinder (0.15 M) the two sides are even with them in the child.
THUMBNAILS_HERE_FROM = 1_000_000


def child_figures(op: "Operation") -> tuple[str, ...]:
    """The pictures of ``op``'s report drawn in the forked child, the two sides about even."""
    if len(op) >= THUMBNAILS_HERE_FROM:
        return tuple(f for f in CHILD_FIGURES if f != "thumbnails")
    return CHILD_FIGURES


@dataclass(frozen=True)
class ReportOptions:
    """How to report each program of a batch.

    Parameters
    ----------
    machine, machine_config : as for :func:`gcodekit.gcode_to_operation`
    pdf : bool, default: True
        Print each page to PDF with headless Chromium.
    notebook : bool, default: False
        Also write the executed notebook ``name.ipynb``.
    notebook_html : bool, default: False
        Also convert that notebook to ``name.notebook.html``.
    strict : bool, default: False
        A program with an error gets an error page naming its line, instead
        of a report listing the error among its diagnostics.
    max_motions, max_iterations : as for :func:`gcodekit.gcode_to_operation`
    """

    machine: str | None = None
    machine_config: str | None = None
    pdf: bool = True
    notebook: bool = False
    notebook_html: bool = False
    strict: bool = False
    max_motions: int = MAX_MOTIONS
    max_iterations: int = MAX_ITERATIONS


def output_names(paths: Sequence[str | os.PathLike]) -> list[str]:
    """A distinct, file-system-safe base name per program (its file name, ``-2`` ... on a clash).

    >>> output_names(["a/part.gcode", "b/part.gcode", "x<y>.nc", "index"])
    ['part.gcode', 'part.gcode-2', 'x_y_.nc', 'index-2']
    """
    taken = {"index"}  # index.html is the batch's own page
    names = []
    for p in paths:
        base = re.sub(r"[^A-Za-z0-9._-]", "_", Path(p).name).lstrip(".") or "program"
        name, k = base, 1
        while name in taken:
            k += 1
            name = f"{base}-{k}"
        taken.add(name)
        names.append(name)
    return names


def planned_outputs(names: Iterable[str], options: ReportOptions) -> list[str]:
    """The files a batch writes into its directory, index included."""
    suffixes = [".html"] + [".pdf"] * options.pdf + [".ipynb"] * options.notebook \
        + [".notebook.html"] * (options.notebook and options.notebook_html)
    return ["index.html"] + [name + s for name in names for s in suffixes]


def report_program(path: str | os.PathLike, out_dir: str | os.PathLike, name: str | None = None,
                   options: ReportOptions = ReportOptions()) -> dict[str, Any]:
    """Write the report of one program into ``out_dir``; return its index row.

    A program that cannot be read or emulated gets an error page instead, and
    its row an ``error``; this function does not raise for a bad program.
    """
    from .build import key_figures, report_data
    from .figures import FIGURES, load_drawing_modules, report_figures
    from .forked import Forked
    from .html import program_page
    from ..pipeline import gcode_to_operation

    path, out_dir = Path(path), Path(out_dir)
    name = name or output_names([path])[0]
    row = _row(path, name)
    html_path = out_dir / row["html"]
    try:
        if not path.is_file():
            raise FileNotFoundError(f"no such program file: {path}")
        op = gcode_to_operation(path, options.machine, machine_config=options.machine_config,
                                mode="strict" if options.strict else "lenient", max_motions=options.max_motions,
                                max_iterations=options.max_iterations)
        # the pictures of the operation alone drawn in a forked child (one core more) while this process
        # computes the numbers and draws the rest; the child starts with matplotlib already imported
        load_drawing_modules()
        aside = child_figures(op)
        drawn_aside = Forked(partial(report_figures, op, None, aside))
        data = report_data(op)
        figures = report_figures(op, data, [f for f in FIGURES if f not in aside])
        html_path.write_text(program_page(data, {**figures, **drawn_aside.result()}), encoding="utf-8")
        row.update(key_figures(data))
    except Exception as exc:  # noqa: BLE001 -- any failure of one program becomes its error page
        return _failed(row, html_path, exc)
    if options.pdf:
        _print_pdf(row, out_dir)
    if options.notebook:
        from .notebook import write_notebook

        try:
            write_notebook(path, out_dir / f"{name}.ipynb", machine=options.machine,
                           machine_config=options.machine_config, html=options.notebook_html)
        except Exception as exc:  # noqa: BLE001
            row["error"] = f"notebook: {exc}"
    return row


def _print_pdf(row: dict[str, Any], out_dir: Path) -> None:
    """Print the page of ``row`` to PDF with this process's Chromium; a failure becomes the row's error."""
    from .pdf import html_to_pdf

    pdf = Path(row["html"]).stem + ".pdf"
    try:
        html_to_pdf(out_dir / row["html"], out_dir / pdf)
        row["pdf"] = pdf
    except Exception as exc:  # noqa: BLE001 -- the page is written; say why its PDF is not
        row["error"] = f"PDF: {exc}"


def _row(path: Path, name: str) -> dict[str, Any]:
    return {"name": path.name, "file": str(path), "html": f"{name}.html", "pdf": None, "error": None}


def _failed(row: dict[str, Any], html_path: Path, exc: BaseException) -> dict[str, Any]:
    from .html import error_page

    row["error"] = str(exc) if isinstance(exc, (GcodeError, OSError)) else (
        f"internal error (a bug in gcodekit, not in the program): {type(exc).__name__}: {exc}")
    html_path.write_text(error_page(row["name"], row["file"], exc), encoding="utf-8")
    return row


def _job(job: tuple[str, str, str, ReportOptions]) -> dict[str, Any]:
    return report_program(*job)


def write_reports(paths: Sequence[str | os.PathLike], out_dir: str | os.PathLike, *,
                  options: ReportOptions = ReportOptions(), workers: int = 1, dask: str | None = None,
                  progress: bool = False, force: bool = False) -> list[dict[str, Any]]:
    """Report every program into ``out_dir`` and write ``index.html`` linking them.

    Parameters
    ----------
    paths : program files
    out_dir : directory, made when missing
    options : ReportOptions
    workers : int, default: 1
        Worker processes; 1 runs in this process.
    dask : str, optional
        Address of a Dask scheduler (``tcp://host:8786``) to run the jobs on instead.
    progress : bool, default: False
        Show a progress bar on standard error.
    force : bool, default: False
        Overwrite existing reports; without it an existing file is an error.

    Returns
    -------
    One row per program, in the order given: its key figures, or ``error``.

    Raises
    ------
    FileExistsError
        Naming the files that exist, when ``force`` is not given.
    """
    from tqdm import tqdm

    from .html import index_page

    class Bar(tqdm):
        monitor_interval = 0  # no monitor thread: with one, a report could not fork (see .forked)

    out = Path(out_dir)
    names = output_names(paths)
    existing = [f for f in planned_outputs(names, options) if (out / f).exists()]
    if existing and not force:
        shown = ", ".join(existing[:5]) + (f" and {len(existing) - 5} more" if len(existing) > 5 else "")
        raise FileExistsError(f"{out} already holds {shown}; use --force to overwrite")
    out.mkdir(parents=True, exist_ok=True)
    # absolute paths: a Dask worker may run in another directory (it must see the same file system)
    print_here = options.pdf and not dask  # one Chromium for the batch: see the module's docstring
    job_options = replace(options, pdf=False) if print_here else options
    if print_here:
        from .pdf import start_browser

        with suppress(MissingDependencyError, OSError):  # without Chromium, each PDF says why in its row
            start_browser()
    jobs = [(os.path.abspath(p), os.path.abspath(out), n, job_options) for p, n in zip(paths, names)]
    jobs.sort(key=lambda j: os.path.getsize(j[0]) if os.path.isfile(j[0]) else 0, reverse=True)
    rows: dict[str, dict[str, Any]] = {}
    with _running(jobs, workers, dask) as results, \
            Bar(total=len(jobs), unit="program", disable=not progress, desc="reports") as bar:
        for job, row in results:
            if print_here and "time_s" in row:  # key figures: a report page, not an error page
                _print_pdf(row, out)
            rows[job[2]] = row
            bar.update()
    ordered = [rows[n] for n in names]
    (out / "index.html").write_text(index_page(ordered), encoding="utf-8")
    return ordered


@contextmanager
def _running(jobs: list[tuple], workers: int, dask: str | None) -> Iterator[Iterator[tuple[tuple, dict[str, Any]]]]:
    """Submit ``jobs`` and give the (job, row) pairs as they finish; a job whose worker died gets an error page.

    Worker processes start on entering, so before a progress bar's thread exists.
    """
    if dask:
        from distributed import Client
        from distributed import as_completed as dask_completed

        with Client(dask) as client:
            futures = {client.submit(_job, job, pure=False): job for job in jobs}
            yield ((futures[f], _result(f, futures[f])) for f in dask_completed(futures))
    elif workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=_start_method()) as pool:
            futures = {pool.submit(_job, job): job for job in jobs}  # with fork, every worker starts here
            yield ((futures[f], _result(f, futures[f])) for f in as_completed(futures))
    else:
        yield ((job, _job(job)) for job in jobs)


def _start_method() -> "multiprocessing.context.BaseContext":
    """fork on Linux when this process runs no other thread, else spawn.

    Forked workers start with gcodekit and NumPy already imported (0.3 s
    and 0.3 CPU-s each less than spawn, on a batch of 10 s); forking a
    process whose other threads (a Dask client, a notebook kernel) may hold a
    lock can hang the child, and macOS libraries do not survive a fork.
    """
    import multiprocessing
    import threading

    fork = sys.platform.startswith("linux") and threading.active_count() == 1
    return multiprocessing.get_context("fork" if fork else "spawn")


def _result(future, job: tuple) -> dict[str, Any]:
    try:
        return future.result()
    except Exception as exc:  # noqa: BLE001 -- a worker that died takes only its own program down
        path, out, name, _ = job
        row = _row(Path(path), name)
        return _failed(row, Path(out) / row["html"], exc)
