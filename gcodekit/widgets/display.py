"""Widgets stage: what every widget shows in a notebook besides its live view.

A widget's rich display holds the live view (for JupyterLab and Notebook 7),
a PNG of its current state (for a notebook read without a kernel: nbconvert's
HTML, GitHub) and a line of text.  Bad input becomes a message box, never a
traceback.
"""

from __future__ import annotations

import html
from typing import Any

import numpy as np


class PictureDisplay:
    """Mixin: ``widget`` (an ipywidgets box), ``figure()`` and ``screenshot()``."""

    widget: Any

    def figure(self):  # pragma: no cover - each widget draws its own
        raise NotImplementedError

    def screenshot(self) -> np.ndarray:
        """The current picture as an (height, width, 3) uint8 RGB array, drawn without a browser."""
        from .picture import to_rgb

        return to_rgb(self.figure())

    def png(self) -> bytes:
        """The current picture as PNG bytes."""
        from .picture import to_png

        return to_png(self.figure())

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict:
        bundle = dict(self.widget._repr_mimebundle_(include=include, exclude=exclude) or {})
        bundle["image/png"] = self.png()
        bundle["text/plain"] = repr(self)
        return bundle


def message_html(message: str) -> str:
    """A message box's HTML: what went wrong, in the widget, instead of a traceback."""
    return ('<div class="gcodekit-message" style="border-left:4px solid #c0392b;background:#fdf1f0;'
            f'padding:6px 10px;font-family:monospace;white-space:pre-wrap">{html.escape(message)}</div>')


def friendly(exc: BaseException) -> str:
    """One line saying what failed, from an exception a reader or emulator raised."""
    text = str(exc).strip() or type(exc).__name__
    return text if isinstance(exc, (ValueError, OSError, LookupError)) else f"{type(exc).__name__}: {text}"
