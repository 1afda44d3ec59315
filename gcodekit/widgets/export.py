"""Widgets stage: executing notebooks that hold widgets, and HTML that shows them offline.

An executed notebook keeps each widget's output as the live view *and* a PNG
(see :mod:`.display`).  :func:`offline_html` converts it with nbconvert and
:class:`.nbconvert.WidgetPictures`, which keeps the pictures and drops the
scripts that would be fetched, so the page is whole without a network (plain
``jupyter nbconvert --to html`` does the same where gcodekit is installed).
"""

from __future__ import annotations

import copy
import os
from pathlib import Path

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
#: Seconds one cell may run: emulating a large print takes seconds, not minutes.
CELL_TIMEOUT_S = 600


def execute(notebook, cwd: str | os.PathLike, *, timeout: int = CELL_TIMEOUT_S):
    """Run every cell of ``notebook`` (a path or NotebookNode) in a fresh kernel in ``cwd``; returns it.

    The widgets' state is stored in the notebook, so JupyterLab shows them
    again when the file is opened.

    Raises
    ------
    nbclient.exceptions.CellExecutionError
        When a cell raises; the message holds the cell's traceback.
    """
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(notebook, as_version=4) if isinstance(notebook, (str, os.PathLike)) else notebook
    NotebookClient(nb, timeout=timeout, kernel_name="python3", store_widget_state=True,
                   resources={"metadata": {"path": str(Path(cwd).resolve())}}).execute()
    return nb


def offline_html(nb) -> str:
    """The executed notebook ``nb`` as one HTML page that shows every picture without a network."""
    from nbconvert import HTMLExporter

    from .nbconvert import WidgetPictures

    exporter = HTMLExporter(template_name="lab")
    exporter.register_preprocessor(WidgetPictures(), enabled=True)
    body, _ = exporter.from_notebook_node(copy.deepcopy(nb))
    return body


def write_offline_html(nb, out: str | os.PathLike) -> Path:
    """:func:`offline_html` written to ``out``."""
    out = Path(out)
    out.write_text(offline_html(nb), encoding="utf-8")
    return out
