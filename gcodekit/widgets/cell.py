"""Widgets stage: work a widget leaves until the notebook cell that made it has finished.

A widget's first picture reaches the browser only when its cell returns, so
what the picture does not need (reading a large program's source lines for
the panel beside the view) waits for IPython's ``post_run_cell`` event
instead of taking the cell's time.  Outside IPython it runs at once.
"""

from __future__ import annotations

from typing import Callable


def after_cell(callback: Callable[[], None]) -> None:
    """Call ``callback()`` once the running cell has finished (at once when no IPython shell runs)."""
    shell = None
    try:
        from IPython import get_ipython

        shell = get_ipython()
    except ImportError:  # widgets without IPython: nothing to wait for
        pass
    if shell is None or not hasattr(shell, "events"):
        callback()
        return

    def once(result=None) -> None:
        shell.events.unregister("post_run_cell", once)
        callback()

    shell.events.register("post_run_cell", once)
