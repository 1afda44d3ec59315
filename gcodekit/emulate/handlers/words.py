"""Emulate stage: where a block's axis words take the tool, for the handlers that move it.

All values are mm (degrees for A B C), by axis index; the program frame is
the state's (see :class:`~gcodekit.emulate.state.MachineState`).
"""

from __future__ import annotations

import numpy as np

from ..state import AXES, MachineState


def axis_values(s: MachineState, params: dict[str, float]) -> dict[int, float]:
    """The block's axis words, mm (degrees for A B C), by axis index."""
    scale = s.scale()
    return {ax: params[letter] * scale[ax] for ax, letter in enumerate(AXES) if letter in params}


def program_target(s: MachineState, params: dict[str, float], letters: str = "XY") -> np.ndarray:
    """The program position moved by the words ``letters`` (absolute or incremental), mm."""
    scale = s.scale()
    target = s.program_position()
    for letter in letters:
        if letter in params:
            ax = AXES.index(letter)
            target[ax] = (target[ax] if s.incremental else 0.0) + params[letter] * scale[ax]
    return target


def move_to(s: MachineState, program: np.ndarray, params: dict[str, float]) -> None:
    """Finish a move whose X/Y the caller worked out: other axes from their words."""
    scale = s.scale()
    for ax, letter in enumerate(AXES):
        if letter in params and letter not in "XY":
            program[ax] = program[ax] + params[letter] * scale[ax] if s.incremental else params[letter] * scale[ax]
    s.position = s.to_machine(program)
    s.program_shift[:] = 0.0
