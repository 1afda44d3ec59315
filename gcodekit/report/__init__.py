"""Report stage: an HTML and PDF report per program, an index, batches and notebooks.

One module per job: :mod:`.build` computes the numbers, :mod:`.figures` draws
the pictures (matplotlib, off-screen), :mod:`.html` renders the pages
(Jinja2), :mod:`.pdf` prints them with headless Chromium, :mod:`.batch` runs
many programs on worker processes or a Dask cluster and :mod:`.notebook`
writes the same report as an executed notebook.  Nothing heavy is imported
until a report is made.

Examples
--------
::

    from gcodekit.report import write_reports
    rows = write_reports(["part.gcode", "plate.ngc"], "out/", workers=2)
"""

from __future__ import annotations

from .batch import ReportOptions, report_program, write_reports

__all__ = ["ReportOptions", "report_program", "write_reports"]
