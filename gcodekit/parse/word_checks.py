"""Parse stage: RS274NGC's rule that every word of a block has a code to use it.

rs274 refuses ``G1 X1 R5`` or ``G64 P1 R0.5``: no code of the block (nor
the motion mode in force, for a block of axis words) takes an R there
(``check_other_codes`` in LinuxCNC 2.9's interp_check.cc).  Other firmware
ignores such a word, so the check runs only for flavors with
``rs274ngc_block_checks``.

Examples
--------
>>> stray_letters({"R"}, ["G1"], modal_motion=None)
['R']
>>> stray_letters({"R", "P"}, ["G10"], modal_motion=None), stray_letters({"I", "J"}, [], modal_motion="arc")
([], [])
"""

from __future__ import annotations

import functools
from collections.abc import Iterable

import numpy as np

_LATHE = ("G70", "G71", "G71.1", "G71.2", "G72", "G72.1", "G72.2")
_DRILLING = ("G73", "G81", "G82", "G83", "G84", "G85", "G86", "G87", "G88", "G89")
_USER_M = tuple(f"M{k}" for k in range(100, 200))

#: Codes that take each checked word when they are in the block.
WORD_USERS: dict[str, frozenset[str]] = {letter: frozenset(codes + _LATHE) for letter, codes in {
    "D": ("G41", "G42", "G41.1", "G42.1", "G96"),
    "E": ("G76", "M66", "M67", "M68"),
    "H": ("G43", "G43.2", "G76"),
    "I": ("G2", "G3", "G5", "G5.1", "G10", "G33.1", "G76", "G87"),
    "J": ("G2", "G3", "G5", "G5.1", "G10", "G76", "G87"),
    "K": ("G2", "G3", "G33", "G33.1", "G76", "G87"),
    "L": ("G5.2", "G10", "G41", "G41.1", "G42", "G42.1", "G76", "M66", "M98") + _DRILLING,
    "P": ("G2", "G3", "G4", "G5", "G5.2", "G10", "G64", "G74", "G76", "G82", "G84", "G86", "G88", "G89", "M19",
          "M50", "M51", "M52", "M53", "M62", "M63", "M64", "M65", "M66", "M98") + _USER_M,
    "Q": ("G5", "G10", "G64", "G73", "G76", "G83", "M19", "M61", "M66", "M67", "M68") + _USER_M,
    "R": ("G2", "G3", "G10", "G41.1", "G42.1", "G74", "G76", "M19") + _DRILLING,
}.items()}

#: Words the motion mode in force takes in a block of axis words alone
#: (a canned cycle's words all count: which cycle is in force is not checked;
#: after G5/G5.1 the spline module reports axis words alone itself).
MODAL_USERS: dict[str, frozenset[str]] = {
    "arc": frozenset("IJKRP"), "thread": frozenset("K"), "cycle": frozenset("DIJKLPQR"), "nurbs": frozenset("PL"),
    "spline": frozenset("IJPQ"),
}


def stray_letters(letters: Iterable[str], codes: Iterable[str], modal_motion: str | None) -> list[str]:
    """The ``letters`` of a block that neither its ``codes`` nor ``modal_motion`` use, sorted.

    ``modal_motion`` names the motion mode a block without a motion code
    moves in (a key of :data:`MODAL_USERS`), or None.
    """
    codes = set(codes)
    modal = MODAL_USERS.get(modal_motion or "", frozenset())
    return sorted(c for c in letters if c in WORD_USERS and c not in modal and not codes & WORD_USERS[c])


def stray_word_message(letter: str) -> str:
    """rs274's complaint about a stray ``letter``."""
    return f"{letter} word with no g code that uses it (no code of the block takes {letter})"


@functools.cache
def user_code_keys(letter: str) -> np.ndarray:
    """The codes that take ``letter`` as the parser keys them: letter code * 1e6 + number in tenths."""
    return np.array(sorted(ord(code[0]) * 1_000_000 + round(float(code[1:]) * 10) for code in WORD_USERS[letter]),
                    np.int64)
