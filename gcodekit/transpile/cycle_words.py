"""Words of canned and lathe cycles as stages 1-5 rewrite them.

A cycle line stays a cycle until stage 6, so its words must take the units
(stage 1) and offsets (stage 2) like a move's; which words are lengths and
which waypoint shows the offset depend on the cycle:

* drilling cycles (G73, G74, G81-G89): X/Y (in the plane) are where the
  cycle ends, Z (along the plane's normal) is the feed end farthest from
  there (G87's, which backs up through the hole, the end of its last feed),
  and R is a level on the normal like Z, as is G87's K (in G17);
* lathe cycles (G70-G72): X/Z are the cycle point, the first rapid's end;
  ``Q`` names the profile subroutine and ``P`` counts passes (not lengths);
  the profile, written in the line's comment, is rewritten the same way,
  and the lengths G71/G72 default in program units (I 1, R 0.5) are written
  out when the units change;
* G76 threading: ``P`` (the pitch) is a length, I/J/K are diameters in G7
  like X; X/Z are where it ends.
"""

from __future__ import annotations

import numpy as np

from ..emulate.arcs import PLANES
from ..export.gcode import format_number
from ..lathe_profile import LatheProfile, ProfileWord
from ..parse.table import LATHE_CYCLE_NAMES

#: Words that are lengths, unless the command has its own set below
LENGTH_WORDS = frozenset("XYZUVWIJKRQ")
_OWN_LENGTH_WORDS = {**dict.fromkeys(LATHE_CYCLE_NAMES, frozenset("XZUWDEIR")),
                     "cycle_thread": frozenset("XZIJKPE"),
                     "coordinate_data": frozenset("XYZUVW")}  # G10 L2/L20: R is a rotation


def length_words(name: str) -> frozenset[str]:
    """The letters whose values are lengths on a command named ``name``."""
    return _OWN_LENGTH_WORDS.get(name, LENGTH_WORDS)


def cycle_offset(name: str, params: dict, scale: float, points: np.ndarray, feeds: np.ndarray,
                 plane: int) -> np.ndarray:
    """Offset (mm, X Y Z) from program to machine coordinates at a cycle line.

    ``points``: the machine positions (mm, rows of X Y Z) of the line's
    waypoints, ``feeds`` which of them end a feed move; ``scale``: mm per
    program unit.
    """
    if len(points) == 0:  # a cycle that was refused
        return np.zeros(3)
    (f, g, h), _ = PLANES[plane]
    if name in LATHE_CYCLE_NAMES:
        source = {axis: points[0] for axis in range(3)}
    elif name == "cycle_thread" or not feeds.any():
        source = {axis: points[-1] for axis in range(3)}
    else:
        if name == "cycle_back_bore":
            bottom = points[np.flatnonzero(feeds)[-1]]
        else:
            fed = points[feeds]
            bottom = fed[np.argmax(np.abs(fed[:, h] - points[-1, h]))]
        source = {f: points[-1], g: points[-1], h: bottom}
    offset = np.zeros(3)
    for axis, letter in enumerate("XYZ"):
        if letter in params:
            offset[axis] = source[axis][axis] - params[letter] * scale
    return offset


def diameter_words(name: str) -> str:
    """Words that are diameters in G7 (lathe diameter mode), as rs274 halves them."""
    return "XU" if name in LATHE_CYCLE_NAMES else "XIJK" if name == "cycle_thread" else "X"


def level_words(name: str, plane: int) -> str:
    """Words of a drilling cycle that are levels along the plane's normal (absolute, like Z)."""
    (_, _, h), _ = PLANES[plane]
    return "R" + ("IJK"[h] if name == "cycle_back_bore" else "")


def lathe_defaults(name: str, params: dict) -> dict:
    """The length words a lathe cycle leaves to rs274's defaults (in program units)."""
    defaults = {} if name == "lathe_finish" else {"I": 1.0, "R": 0.5}  # G70 moves by neither
    return {letter: value for letter, value in defaults.items() if letter not in params}


def rewrite_profile(profile: LatheProfile, *, scale: float, halve: bool, offset_x: float, offset_z: float,
                    arc_absolute: bool, precision: int) -> str:
    """The written form's body of a lathe profile in the output's units and frame.

    ``scale``: output units per program unit; ``halve``: X and U are
    diameters to write as radii; offsets (output units) move X and Z, and I
    and K when arc centres are absolute (G90.1).  Other words stay as written.
    """
    def word(w: ProfileWord) -> str | None:
        letter, value = w.letter, w.value
        if letter not in "XZUWIKRAC":
            return None
        value *= scale
        if halve and letter in "XU":
            value /= 2.0
        if letter == "X" or (letter == "I" and arc_absolute):
            value += offset_x
        elif letter == "Z" or (letter == "K" and arc_absolute):
            value += offset_z
        return f"{letter}{format_number(value, precision)}"

    return profile.text(word)
