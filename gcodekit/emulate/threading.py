"""Emulate stage: LinuxCNC's G76 threading cycle as plain moves.

Behaviour mirrored: LinuxCNC 2.9 ``interp_convert.cc``
(``convert_threading_cycle`` and ``threading_pass``).  Lengths are in mm and
X is a radius; the drive line is the X where the cycle starts.

Each pass rapids back to the retract X, in to its depth (or feeds in along
the entry taper, ``L1``/``L3``), feeds along Z synchronized with the spindle
(out along the exit taper with ``L2``/``L3``), and rapids out.  The depth
of pass ``n`` is ``|I| + J * n ** (1/R)`` until ``|I| + K``; the full depth
is then cut once more per spring pass ``H``.  A compound angle ``Q`` moves
each pass's start along Z by ``(depth - |I|) * tan(Q)``.

Examples
--------
>>> moves = threading_moves((10.0, 0.0), -20.0, p=1.5, i=-0.5, j=0.25, k=0.75)
>>> [(kind, x, z) for kind, x, z, _ in moves[:4]]
[('rapid', 10.5, 0.0), ('rapid', 9.25, 0.0), ('feed', 9.25, -20.0), ('rapid', 10.5, -20.0)]
"""

from __future__ import annotations

import math

from ..errors import GcodeMachineError
from ..limits import MotionBudget


class ThreadingError(GcodeMachineError):
    """A G76 block the cycle refuses; the message is rs274's."""


def check_words(words: dict[str, float], compensating: bool) -> None:
    """rs274's refusals of a G76 block.

    Raises
    ------
    ThreadingError
    """
    if not any(letter in words for letter in "XYZABCUVW"):
        raise ThreadingError("All axes missing with motion code")
    if "P" not in words:
        raise ThreadingError("P word missing with G76")
    if not all(letter in words for letter in "IJK"):
        raise ThreadingError("I J or K words missing with G76")
    if compensating:
        raise ThreadingError("Cannot use G76 threading cycle with cutter radius compensation on")
    if words["I"] == 0:
        raise ThreadingError("In G76, I must not be 0")
    if words["J"] <= 0:
        raise ThreadingError("In G76, J must be greater than 0")
    if words["K"] <= words["J"]:
        raise ThreadingError("In G76, K must be greater than J")


def threading_moves(start: tuple[float, float], end_z: float, *, p: float, i: float, j: float, k: float,
                    q: float = 0.0, h: int = 0, r: float = 1.0, e: float = 0.0,
                    taper: int = 0, budget: MotionBudget | None = None) -> list[tuple[str, float, float, float | None]]:
    """The moves of one G76 cycle: (``"rapid"`` or ``"feed"``, X, Z, pitch of a spindle-synchronized feed).

    ``start`` is the (X, Z) where the cycle starts; ``p`` the pitch, ``i``
    the thread's peak from the drive line (negative: outside thread), ``j``
    the first cut's depth, ``k`` the full thread depth, ``q`` the compound
    angle (degrees), ``h`` spring passes, ``r`` the depth degression, ``e``
    the taper length along Z and ``taper`` the L flags (1 entry, 2 exit).
    Lengths in mm, X a radius.  The final rapid to the block's end point is
    not included.  ``budget``, when given, must have room for every pass
    (:class:`~gcodekit.limits.TooManyMotions` otherwise, before any is made).
    """
    safe_x, start_z = start
    boring = i > 0.0
    full_dia_depth = abs(i)
    cut_increment = abs(j)
    full_threadheight = abs(k)
    end_depth = abs(k) + abs(i)
    angle = math.radians(q)
    if end_z > start_z:
        angle, e = -angle, -max(e, 0.0)
    else:
        e = max(e, 0.0)
    taper_pitch = p * math.hypot(e, full_threadheight) / abs(e) if e else p
    degression = r if r >= 1.0 else 1.0
    entry, exit_ = bool(taper & 1), bool(taper & 2)
    target_z = end_z + full_threadheight * math.tan(angle)

    if budget is not None:  # pass n cuts to i + j * n**(1/r): (k/j)**r passes, then the spring passes
        exponent = degression * math.log(max(full_threadheight / cut_increment, 1.0))
        passes = math.inf if exponent > 700.0 else math.exp(exponent)
        budget.check(6 * (passes + max(h, 0) + 2))

    def x_at(depth: float) -> float:
        return safe_x + depth if boring else safe_x - depth

    moves: list[tuple[str, float, float, float | None]] = []

    def one_pass(depth: float) -> None:
        zoff = (depth - full_dia_depth) * math.tan(angle)
        moves.append(("rapid", x_at(depth - end_depth), start_z - zoff, None))  # back
        if e and entry:
            moves.append(("feed", x_at(depth - full_threadheight), start_z - zoff, taper_pitch))  # in
            moves.append(("feed", x_at(depth), start_z - zoff - e, taper_pitch))  # angled in
        else:
            moves.append(("rapid", x_at(depth), start_z - zoff, None))  # in
        if e and exit_:
            moves.append(("feed", x_at(depth), target_z - zoff + e, p))  # over
            moves.append(("feed", x_at(depth - full_threadheight), target_z - zoff, taper_pitch))  # angled out
        else:
            moves.append(("feed", x_at(depth), target_z - zoff, p))  # over
        moves.append(("rapid", x_at(depth - end_depth), target_z - zoff, None))  # out

    depth, n = full_dia_depth + cut_increment, 1
    while depth < end_depth:
        one_pass(depth)
        n += 1
        depth = full_dia_depth + cut_increment * n ** (1.0 / degression)
    for _ in range(max(int(h), 0) + 1):  # the full depth once, then the spring passes
        one_pass(end_depth)
    return moves
