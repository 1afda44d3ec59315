"""Widgets stage: the toolpath of what a widget was given (an Operation, an AdditivePart, a path or text).

The segments, groups and source lines are :mod:`gcodekit.view`'s, the ones
every picture draws; a widget also accepts a program's path or text, read
here by the pipeline, and turns what goes wrong into a :class:`ToolpathError`
whose message the widget shows.
"""

from __future__ import annotations

import os

from ..view import Toolpath, ToolpathError


def load_toolpath(source, group_by: str | None = None) -> Toolpath:
    """The :class:`~gcodekit.view.Toolpath` of an Operation, an AdditivePart, a path or program text.

    Raises
    ------
    ToolpathError
        When the source cannot be read or has no motion to draw.
    """
    from ..errors import GcodeError
    from ..model.operation import Operation

    if not (isinstance(source, Operation) or hasattr(source, "waypoint_layer")):
        if not isinstance(source, (str, os.PathLike)):
            raise ToolpathError(f"cannot draw a {type(source).__name__}: give an Operation, an AdditivePart or a path")
        if isinstance(source, str) and not source.strip():
            raise ToolpathError("the program is empty (no text)")
        from ..pipeline import gcode_to_operation

        try:
            source = gcode_to_operation(source)  # a path, or the program's text
        except (GcodeError, OSError, ValueError) as exc:
            raise ToolpathError(str(exc)) from exc
    return Toolpath.of(source, group_by)
