"""Emulate stage, lathe cycles: one G70-G72 block -- its words checked, its profile read, its moves made."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from ...lathe_profile import LatheProfile
from ...limits import MotionBudget
from .passes import build_profile, finish, rough
from .segments import LatheCycleError, Move

__all__ = ["LATHE_CYCLES", "CycleBlock", "LatheCycle", "run_lathe_cycle"]

#: Names of the lathe cycles: (cycle, sub-cycle) as rs274 numbers them
LATHE_CYCLES = {
    "lathe_finish": (70, 0), "lathe_rough": (71, 0), "lathe_rough_no_pockets": (71, 1),
    "lathe_rough_pockets": (71, 2), "lathe_face": (72, 0), "lathe_face_no_pockets": (72, 1),
    "lathe_face_pockets": (72, 2),
}
_MOTIONS = {0.0: 0, 1.0: 1, 2.0: 2, 3.0: 3}
_OTHER_MOTIONS = frozenset((5.0, 5.1, 5.2, 33.0, 33.1, 38.2, 38.3, 38.4, 38.5, 73.0, 74.0, 76.0, 80.0) +
                           tuple(float(g) for g in range(81, 90)))


@dataclass
class CycleBlock:
    """What a lathe cycle block needs from the machine (lengths in mm, X a radius)."""

    name: str
    params: dict
    profile: LatheProfile | None  # None: the Q subroutine was not found
    here: complex  # program position, z + x*1j
    scale: float  # mm per program unit
    incremental: bool
    arc_incremental: bool
    diameter: bool
    plane: int
    compensating: bool = False  # cutter compensation on: only G70 may run


class LatheCycle(NamedTuple):
    """A lathe cycle's moves, in program coordinates (mm, ``z + x*1j``)."""

    point: complex  # the cycle point, where the first rapid goes
    moves: list[Move]
    #: the profile's last point: rs274 leaves its current point there after reading the
    #: profile, which matters to a G70 under cutter compensation (see ``compensation``)
    profile_end: complex


def run_lathe_cycle(block: CycleBlock, budget: MotionBudget | None = None) -> LatheCycle:
    """The cycle point, the cycle's moves and where its profile ends.

    Raises
    ------
    LatheCycleError
        With rs274's message.
    TooManyMotions
        The passes would make more moves than ``budget`` has room for.
    """
    cycle, sub = LATHE_CYCLES[block.name]
    label = f"G{cycle}.{sub}"
    p = block.params
    if "Q" not in p:
        raise LatheCycleError("G7x.x  requires a Q word")
    if block.plane != 18:
        raise LatheCycleError(f"{label} can only be used in XZ plane (G18)")
    if block.compensating and cycle != 70:
        raise LatheCycleError(f"{label} cannot be used with cutter compensation enabled")
    if block.profile is None:
        raise LatheCycleError(f"G7x profile o{int(p['Q'])} was not read (its subroutine is missing)")
    k = block.scale
    here = block.here
    x = here.imag + p["X"] * k if block.incremental and "X" in p else p["X"] * k if "X" in p else here.imag
    z = here.real + p["Z"] * k if block.incremental and "Z" in p else p["Z"] * k if "Z" in p else here.real
    point = complex(z, x)
    blocks = _read_profile(block, point)
    segments = build_profile(point, blocks)
    end = blocks[-1]["end"] if blocks else point
    if len(segments) <= 1:
        return LatheCycle(point, [], end)
    i = p.get("I", 1.0) * k
    if i <= 0:
        raise LatheCycleError("G7X error: I must be greater than zero.")
    d, e = p.get("D", 0.0) * k, p.get("E", 0.0) * k
    if cycle == 70:
        return LatheCycle(point, finish(segments, point, d, e, p.get("P", 1.0), budget=budget), end)
    u = p.get("U", 0.0) * k / (2.0 if block.diameter else 1.0)
    return LatheCycle(point, rough(segments, point, turn=cycle == 72, subcycle=sub, d=d, i=i,
                                   r=p.get("R", 0.5) * k, u=u, w=p.get("W", 0.0) * k, budget=budget), end)


def _read_profile(block: CycleBlock, start: complex) -> list[dict]:
    """Profile blocks: motion, end point and centre (mm), corner finish."""
    # a block before the profile's first motion word is a line, whatever mode was in force before
    # the cycle (rs274 2.9, checked after G0, G1, G2 and G80)
    k, motion, here = block.scale, 1, start
    halve = 2.0 if block.diameter else 1.0
    out = []
    for profile_block in block.profile.blocks:
        words: dict[str, float] = {}
        for word in profile_block.words:
            if word.letter == "G":
                if word.value in _MOTIONS or word.value in _OTHER_MOTIONS:
                    motion = _MOTIONS.get(word.value, -1)
            else:
                words[word.letter] = word.value
        end = 0j if block.incremental else here
        if "U" in words:
            if block.incremental:
                raise LatheCycleError("G7x error: Cannot use U in incremental mode (G91)")
            if "X" in words:
                raise LatheCycleError("G7x error: Cannot use U and X in the same block")
            end += 1j * words["U"] * k / halve
        elif "X" in words:
            end = complex(end.real, words["X"] * k / halve)
        if "W" in words:
            if block.incremental:
                raise LatheCycleError("G7x error: Cannot use W in incremental mode (G91)")
            if "Z" in words:
                raise LatheCycleError("G7x error: Cannot use W and Z in the same block")
            end += words["W"] * k
        elif "Z" in words:
            end = complex(words["Z"] * k, end.imag)
        if block.incremental:
            end += here
        centre = complex(words.get("K", 0.0) * k, words.get("I", 0.0) * k)
        if motion in (2, 3) and end != here:
            if "R" in words:
                if "I" in words or "K" in words:
                    raise LatheCycleError("G7X error: both R and I or K flag used for arc")
                r = words["R"] * k
                chord = end - here
                bulge = 1j * math.sqrt((r * r - abs(chord) ** 2 / 4) / abs(chord) ** 2) * chord
                centre = (here + end) / 2 + (bulge if motion == 3 else -bulge)
            elif "I" not in words and "K" not in words:
                raise LatheCycleError("G7X error: either I or K must be present for arc")
            elif block.arc_incremental:
                centre += here
        if motion in (0, 1, 2, 3) and end != here:
            if "A" in words and "C" in words:
                raise LatheCycleError("G7X error: Both A and C parameters on a corner")
        entry = {"motion": motion, "end": end, "centre": centre}
        entry.update({c: words[c] * k for c in "AC" if c in words})
        out.append(entry)
        here = end
    return out
