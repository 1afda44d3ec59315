"""Emulate stage: what the passes after the machine read of a program (a protocol, for types).

Cutter compensation and the motion planners work on an emulated program:
its command table and the machine's waypoint columns.  The model stage's
:class:`~gcodekit.model.operation.Operation` is one, but these passes come
before the model in the pipeline, so they name only what they use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import numpy as np

    from ..errors import Diagnostics
    from ..parse.table import CommandTable

__all__ = ["EmulatedProgram"]


class EmulatedProgram(Protocol):
    """A program after the machine ran it.

    Attributes
    ----------
    table : CommandTable
        The parsed commands, one row each.
    waypoints : dict of str to ndarray
        The machine's columns (see :mod:`gcodekit.schema`); passes may rewrite them.
    diagnostics : Diagnostics
        Where the program's problems are recorded.
    max_motions : int
        The moves a pass may cut the program into (see :mod:`gcodekit.limits`).
    """

    table: "CommandTable"
    waypoints: "dict[str, np.ndarray]"
    diagnostics: "Diagnostics"
    max_motions: int
