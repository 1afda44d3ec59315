"""Report stage: HTML pages from Jinja2 templates, every value escaped.

Autoescaping is on for every template, so a comment or file name such as
``<script>`` shows as text; pictures arrive as ``data:`` URIs and the style
sheet is inlined, so a page needs nothing but itself.
"""

from __future__ import annotations

import datetime
import math
from functools import lru_cache
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import jinja2


def duration(seconds: float | None) -> str:
    """``h:mm:ss`` of a time in seconds, ``—`` when unknown.

    >>> duration(3725.4)
    '1:02:05'
    """
    if seconds is None or not math.isfinite(seconds):
        return "—"
    h, rest = divmod(int(round(seconds)), 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}"


def fixed(value: float | None, digits: int = 1) -> str:
    """A number with ``digits`` decimals, ``—`` when missing."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    return f"{value:,.{digits}f}"


@lru_cache(maxsize=1)
def environment() -> "jinja2.Environment":
    """The templates (``reports/``, shipped as :mod:`gcodekit.reports`) with autoescaping on for all of them."""
    import jinja2

    env = jinja2.Environment(loader=jinja2.PackageLoader("gcodekit.reports", ""), autoescape=True,
                             undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    env.filters.update(duration=duration, fixed=fixed)
    return env


def _common() -> dict[str, str]:
    from .. import __version__

    return {"version": __version__, "generated": datetime.datetime.now().strftime("%Y-%m-%d %H:%M")}


def program_page(data: dict[str, Any], figures: dict[str, str]) -> str:
    """The report page of one program (``data`` from :func:`~gcodekit.report.build.report_data`)."""
    return environment().get_template("program.html").render(data=data, figures=figures, **_common())


def error_page(name: str, file: str, exc: BaseException) -> str:
    """The page of a program that failed: the error, and its line when gcodekit located it."""
    d = getattr(exc, "diagnostic", None)
    return environment().get_template("error.html").render(
        name=name, file=file, kind=type(exc).__name__, message=d.message if d else str(exc),
        line=d.line if d else None, column=d.column if d else None, text=d.text.strip() if d else "",
        **_common())


def index_page(rows: list[dict[str, Any]]) -> str:
    """The index of a batch: one row per program with its key figures, or its error."""
    return environment().get_template("index.html").render(
        rows=rows, failed=sum(1 for r in rows if r.get("error")), **_common())
