"""Report stage: an HTML and PDF report per program, an index, batches and notebooks.

One module per job: :mod:`.build` computes the numbers, :mod:`.figures` draws
the pictures (matplotlib, off-screen), :mod:`.html` renders the pages
(Jinja2), :mod:`.pdf` prints them with headless Chromium, :mod:`.batch` runs
many programs on worker processes or a Dask cluster, :mod:`.forked` draws
some of one program's pictures in a forked child (a second core) and
:mod:`.notebook` writes the same report as an executed notebook.  Nothing heavy is imported
until a report is made (the batch module
included).

Examples
--------
::

    from gcodekit.report import write_reports
    rows = write_reports(["part.gcode", "plate.ngc"], "out/", workers=2)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .batch import ReportOptions, report_program, write_reports


def __getattr__(name: str) -> Any:
    """The batch functions, loaded on first use: ``gcodekit info`` formats durations with
    :mod:`.html` and needs no worker pools."""
    if name in __all__:
        from . import batch

        return getattr(batch, name)
    raise AttributeError(f"module 'gcodekit.report' has no attribute {name!r}")


__all__ = ["ReportOptions", "report_program", "write_reports"]
