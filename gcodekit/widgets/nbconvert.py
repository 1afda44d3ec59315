"""Widgets stage: a notebook with gcodekit widgets converted to HTML that shows every picture offline.

Every gcodekit widget's output carries its live view, a PNG of its state
and often HTML holding that picture (see :mod:`.display`).  nbconvert would
render the live view, which needs the widget manager, require.js and
MathJax from public CDNs, so a page read offline (a hand-in, an archive)
shows no picture.  :class:`WidgetPictures`, an nbconvert preprocessor,
keeps the picture instead and, when no live view is left, takes the
remote scripts off the page.

gcodekit registers it for plain ``jupyter nbconvert --to html`` (the file
``etc/jupyter/jupyter_nbconvert_config.json`` its wheel installs) and for
JupyterLab's File > Save and Export Notebook As > HTML (a Jupyter server
extension, enabled by ``etc/jupyter/jupyter_server_config.d/gcodekit.json``,
that adds it to the server's exporter configuration).  Notebooks without
gcodekit widgets convert as before.
"""

from __future__ import annotations

import re

from nbconvert.preprocessors import Preprocessor

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
#: Stands in for a script address: loads nothing and fails nothing.
NO_SCRIPT = "data:text/javascript,"
_CODE = re.compile(r"```.*?```|`[^`]*`", re.S)
#: The preprocessor's import path, as nbconvert's configuration names it.
PREPROCESSOR = "gcodekit.widgets.nbconvert.WidgetPictures"


def has_picture(data: dict) -> bool:
    """Whether an output's data holds a widget view together with a picture of it."""
    return WIDGET_VIEW in data and ("image/png" in data or "text/html" in data)


class WidgetPictures(Preprocessor):
    """Show each widget that carries a picture as that picture; drop remote scripts no output needs."""

    def preprocess(self, nb, resources):
        views = pictures = 0
        for cell in nb.cells:
            for output in cell.get("outputs", []):
                data = output.get("data", {})
                if has_picture(data):
                    del data[WIDGET_VIEW]
                    pictures += 1
                elif WIDGET_VIEW in data:
                    views += 1
        if pictures and not views:
            nb.metadata.pop("widgets", None)  # no widget manager to load: the pictures stand in for the views
            resources["require_js_url"] = NO_SCRIPT
            if not any("$" in _CODE.sub("", cell.source) for cell in nb.cells if cell.cell_type == "markdown"):
                resources["mathjax_url"] = NO_SCRIPT  # no mathematics to typeset (a $ in code is not one)
        return nb, resources


def _jupyter_server_extension_points() -> list[dict]:
    return [{"module": "gcodekit.widgets.nbconvert"}]


def _load_jupyter_server_extension(serverapp) -> None:
    """Add :class:`WidgetPictures` to the HTML export of a Jupyter server (JupyterLab's export menu)."""
    exporter = serverapp.config.HTMLExporter
    listed = list(exporter.get("preprocessors", []))
    if PREPROCESSOR not in listed:
        exporter.preprocessors = listed + [PREPROCESSOR]
