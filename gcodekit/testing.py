"""Testing helpers for code that builds on gcodekit: compare two Operations and say where they differ.

A failing comparison names the first differing waypoint (or command) with
its column, both values and its source line, so a broken refactor or a
changed dialect points at the line of G-code it got wrong.

Examples
--------
>>> import gcodekit
>>> from gcodekit.testing import assert_operations_equal
>>> a = gcodekit.gcode_to_operation("G1 X10 F600\\nG1 Y5\\n", "linuxcnc", plan=False)
>>> b = gcodekit.gcode_to_operation("G1 X10 F600\\nG1 Y5.001\\n", "linuxcnc", plan=False)
>>> assert_operations_equal(a, a)
>>> assert_operations_equal(a, b)
Traceback (most recent call last):
...
AssertionError: waypoint 1, column 'y' (line 2): 5.0 != 5.001
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .schema import WAYPOINT_COLUMNS

if TYPE_CHECKING:
    from .model import Operation

__all__ = ["assert_operations_equal"]


def assert_operations_equal(actual: "Operation", expected: "Operation", *, rtol: float = 1e-9,
                            atol: float = 1e-9, check_time: bool = True, check_lines: bool = True) -> None:
    """Assert two operations have the same commands and waypoints.

    Parameters
    ----------
    actual, expected : Operation
    rtol, atol : float, default: 1e-9
        Tolerances for the float columns (NaN equals NaN).
    check_time : bool, default: True
        Compare ``time`` too (leave out to compare emulations planned differently).
    check_lines : bool, default: True
        Compare source line numbers too (leave out for a program written
        again, whose lines move).

    Raises
    ------
    AssertionError
        Naming the first difference: the command or waypoint, the column,
        both values and the source line.
    """
    ta, tb = actual.table, expected.table
    if len(ta) != len(tb):
        raise AssertionError(f"{len(ta)} commands != {len(tb)} commands")
    checks = [("line", ta.line, tb.line)] if check_lines else []
    for name, a, b in checks + [("command", ta.name, tb.name), ("kind", ta.kind, tb.kind)]:
        bad = np.flatnonzero(np.asarray(a) != np.asarray(b))
        if bad.size:
            k = int(bad[0])
            raise AssertionError(f"command {k}, {name} (line {int(ta.line[k])}): {a[k].item()!r} != {b[k].item()!r}")
    wa, wb = actual.waypoints, expected.waypoints
    if (wa is None) != (wb is None):
        raise AssertionError("one operation is emulated and the other is not")
    if wa is None:
        return
    if wa["x"].size != wb["x"].size:
        raise AssertionError(f"{wa['x'].size} waypoints != {wb['x'].size} waypoints")
    rows = np.asarray(wa["command"])
    for column in WAYPOINT_COLUMNS:
        if column.name == "time" and not check_time:
            continue
        a, b = np.asarray(wa[column.name]), np.asarray(wb[column.name])
        if a.dtype.kind == "f":
            same = np.isclose(a, b, rtol=rtol, atol=atol, equal_nan=True)
        else:
            same = a == b
        bad = np.flatnonzero(~same)
        if bad.size:
            k = int(bad[0])
            line = int(ta.line[rows[k]]) if len(ta) else 0
            raise AssertionError(f"waypoint {k}, column {column.name!r} (line {line}): {a[k].item()!r} != "
                                 f"{b[k].item()!r}")
