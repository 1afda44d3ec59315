"""Widgets stage: executing notebooks that hold widgets, and HTML that shows them offline.

An executed notebook keeps each widget's output as the live view *and* a PNG
(see :mod:`.display`).  A page converted by nbconvert would show the live
view first, which needs the widget manager, require.js and MathJax from
public CDNs: offline every widget would be blank.  :func:`offline_html`
keeps the PNG (or the HTML holding it) where an output has one and drops
the scripts that would be fetched, so the page is whole without a network.
"""

from __future__ import annotations

import copy
import os
import re
from pathlib import Path

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
_REMOTE_SCRIPT = re.compile(r'<script[^>]*\ssrc="https?://[^"]*"[^>]*>\s*</script>\s*')
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

    nb = copy.deepcopy(nb)
    nb.metadata.pop("widgets", None)  # no widget manager to load: the pictures stand in for the views
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if WIDGET_VIEW in data and ("image/png" in data or "text/html" in data):
                del data[WIDGET_VIEW]
                data.pop("text/plain", None)
    body, _ = HTMLExporter(template_name="lab").from_notebook_node(nb)
    return _REMOTE_SCRIPT.sub("", body)


def write_offline_html(nb, out: str | os.PathLike) -> Path:
    """:func:`offline_html` written to ``out``."""
    out = Path(out)
    out.write_text(offline_html(nb), encoding="utf-8")
    return out
