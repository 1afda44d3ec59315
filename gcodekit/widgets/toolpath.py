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
    return Toolpath.of(load_source(source), group_by)


def load_source(source):
    """An Operation or AdditivePart as given, or the Operation of a path or program text (read here).

    Raises
    ------
    ToolpathError
        When the source cannot be read, or is neither an Operation, an AdditivePart nor a path.
    """
    from ..errors import GcodeError
    from ..model.operation import Operation

    if isinstance(source, Operation) or hasattr(source, "waypoint_layer"):
        return source
    if not isinstance(source, (str, os.PathLike)):
        raise ToolpathError(f"cannot draw a {type(source).__name__}: give an Operation, an AdditivePart or a path")
    if isinstance(source, str) and not source.strip():
        raise ToolpathError("the program is empty (no text)")
    from ..pipeline import gcode_to_operation

    try:
        return gcode_to_operation(source)  # a path, or the program's text
    except (GcodeError, OSError, ValueError) as exc:
        raise ToolpathError(str(exc)) from exc
