"""Emulate stage: canned cycles (G73, G74, G81-G89) as plain moves.

Follows LinuxCNC 2.9's interpreter (interp_cycles.cc and the G-code manual):

* The cycle's plane picks the drilling axis (Z for G17, Y for G18, X for
  G19); "Z" below means that axis, "XY" the two others.
* R, Z, P and Q stay in force while the cycle mode lasts; a later block with
  only X/Y drills again at the new place.  A block that starts a cycle (the
  mode was another one, or none) must give R, Z and the cycle's own P, Q or
  I/J/K again, and R may not be below Z.
* The "old Z" of every block is the level where the cycle mode began (rs274's
  ``cycle_il``, one number: after a plane change it is still the level of
  the old drilling axis), kept until G80 or another motion mode ends it.
* Absolute mode: R and Z are coordinates.  Incremental mode (G91): R is
  measured from the old Z, Z from R, and X/Y are increments repeated L times.
* If the old Z is below R, every block first rapids up to R where the tool
  is (a zero-length move once it is there).  At the first hole, if the tool
  is above R: rapid over the hole at its level, then down to R.  Otherwise,
  and at every repeat: rapid over the hole at the clear height (from below
  it, a slanted move), then down to R if the clear height is above it.  Then
  the cycle's own moves, ending at the clear height: the old Z (G98, if that
  is above R) or R (G99).  rs274 2.9 emits every one of these moves, zero
  length or not.
* G84 and G74 feed out again (the spindle reversed).  Outside G17 rs274 2.9
  sends these two feeds with the axes mixed up: in G18 to (level, hole Z,
  hole X), in G19 to (hole Z, level, hole Y) as X Y Z (LinuxCNC's own
  tests/interp g84 output keeps it); gcodekit moves the same way, and
  rs274's idea of where the tool is afterwards stays the right one
  (:attr:`CycleMoves.end`).
* G85 feeds back to R, then rapids to the clear height; G89 dwells and feeds
  all the way to it.  G88 stops at the bottom for a
  manual retract, so the cycle itself never leaves the hole (rs274 takes the
  tool to be at the clear height afterwards); G87 steps aside
  by I/J, drops below the part, bores up to K (G91: K from Z) and back, then
  leaves the way it came.
* G83 pecks Q deeper each time, rapids back to R, then rapids back down to
  ``delta`` above the last depth; G73 only backs off by ``delta``.  LinuxCNC's
  ``delta`` is 0.010 in (0.254 mm).

Each move is returned as a :class:`Step`; the machine turns them into
waypoints of the block.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..limits import MotionBudget
from ..parse.table import CYCLE_NAMES, MOTION_LINEAR, MOTION_RAPID
from .arcs import PLANE_NAMES, PLANES

CYCLES = frozenset(CYCLE_NAMES)
PECK_DELTA_MM = 0.254  # LinuxCNC's G73/G83 back-off and approach, 0.010 in


TAPPING = ("cycle_tap", "cycle_tap_left")


class CycleMoves(NamedTuple):
    """The moves of a cycle block and the program point (mm) the interpreter then takes as current."""

    steps: list["Step"]
    end: np.ndarray


@dataclass
class Step:
    """One move of a cycle (machine coordinates, mm) and an optional dwell after it."""

    point: np.ndarray
    motion: int
    dwell: float = 0.0


@dataclass
class CycleState:
    """The sticky words of the cycle mode (program units converted to mm)."""

    name: str = ""
    r: float | None = None
    z: float | None = None
    p: float = 0.0
    q: float | None = None
    shift: np.ndarray | None = None  # G87: I/J, the side step off the hole centre (mm)
    k: float | None = None  # G87: the level the back bore reaches (program mm)
    retract_to_r: bool = False  # G99
    #: Drilling-axis level (program mm) when the cycle mode began (rs274's
    #: ``cycle_il``): the "old Z" of every block until the mode ends
    initial: float | None = None

    def keep_numbers(self, factor: float) -> None:
        """G20/G21: rs274 2.9 keeps the cycle's numbers as they are (``convert_length_units``
        converts none of them), so each length is now that many of the new units: times
        ``factor``, the new units' mm over the old ones'."""
        for name in ("r", "z", "q", "k", "initial"):
            if getattr(self, name) is not None:
                setattr(self, name, getattr(self, name) * factor)
        if self.shift is not None:
            self.shift = self.shift * factor


def run_cycle(name: str, params: dict, cycle: CycleState, *, program: np.ndarray,
              to_machine: Callable[[np.ndarray], np.ndarray], scale: np.ndarray, plane: int, incremental: bool,
              dwell_unit: float, same_mode: bool = True, budget: MotionBudget | None = None) -> CycleMoves:
    """Moves of one canned-cycle block (``params`` as written, in program units).

    The cycle works in program coordinates (mm) from ``program``, the
    current point; ``to_machine`` places each of its points on the machine.
    ``same_mode`` says the block continues the cycle mode in force (rs274's
    ``motion_mode == motion``), so that missing words keep their old values.
    ``budget``, when given, is checked against the most moves the block can
    make before any is made (L repeats times pecks can run into billions).

    Raises
    ------
    ValueError
        With the interpreter's reason (no R or Z in force, Q not positive, ...).
    TooManyMotions
        The block would make more moves than ``budget`` has room for.
    """
    _take_words(name, params, cycle, plane=plane, scale=scale, dwell_unit=dwell_unit, same_mode=same_mode)
    (a, b, axis), _ = PLANES[plane]
    letter = "XYZ"[axis]
    first, second = "XYZ"[a], "XYZ"[b]
    repeats = int(params.get("L", 1))
    if repeats == 0:
        raise ValueError("Cannot do zero repeats of cycle")
    if repeats < 1:
        return CycleMoves([], program.copy())
    if cycle.initial is None:
        cycle.initial = float(program[axis])
    # levels to 1e-9 mm: rs274 compares them exactly in program units, gcodekit's pass through mm and offsets
    old = round(cycle.initial, 9)  # the level where the cycle mode began, program coordinates (mm)
    r = round(old + cycle.r if incremental else cycle.r, 9)
    bottom = r + cycle.z if incremental else cycle.z
    if r < bottom:
        raise ValueError(f"R less than {letter.lower()} in cycle in {PLANE_NAMES[plane]} plane")
    if cycle.name in ("cycle_peck", "cycle_chip_break") and not (cycle.q and cycle.q > 0):
        raise ValueError("G73/G83 need a positive Q")
    if budget is not None:
        budget.check(repeats * _most_moves_per_hole(cycle, r, bottom) + 1)
    clear = r if cycle.retract_to_r or old < r else old
    below_r = old < r
    steps: list[Step] = []
    here = program.copy()
    level = round(here[axis], 9)  # where the tool is along the drilling axis (rs274's current_cc)

    def go(coord: float, motion: int, dwell: float = 0.0) -> None:
        here[axis] = coord
        steps.append(Step(to_machine(here), motion, dwell))

    def tap_feed(coord: float) -> None:  # G74/G84 outside G17, as rs274 2.9 sends it (see the module doc)
        here[axis] = coord
        sent = here.copy()
        sent[[0, 1, 2]] = (coord, here[2], here[0]) if plane == 18 else (here[2], coord, here[1])
        steps.append(Step(to_machine(sent), MOTION_LINEAR))

    def slide(aside: bool) -> None:  # G87: rapid to the side step off the hole centre, or back
        here[[a, b]] = target[[a, b]] + (cycle.shift if aside else 0.0)
        steps.append(Step(to_machine(here), MOTION_RAPID))

    if below_r:  # preliminary move up to the R plane
        go(r, MOTION_RAPID)
        level = r
    target = program.copy()
    for repeat in range(repeats):
        if "@" in params or "^" in params:
            target[[0, 1]] = polar_target(params, target[[0, 1]], scale[0], incremental)
        for ax, word in ((a, first), (b, second)):
            if word in params:
                target[ax] = target[ax] + params[word] * scale[ax] if incremental else params[word] * scale[ax]
        here[[a, b]] = target[[a, b]]  # rs274 emits it even when already there
        first_from_above = repeat == 0 and level > r
        here[axis] = level if first_from_above else clear  # else over the hole at the clear height
        steps.append(Step(to_machine(here), MOTION_RAPID))
        if first_from_above or clear > r:
            go(r, MOTION_RAPID)
        if cycle.name == "cycle_back_bore":
            _back_bore(bottom + cycle.k if incremental else cycle.k, bottom, clear, go, slide)  # G91: K from Z
        elif cycle.name in TAPPING and plane != 17:
            tap_feed(bottom)
            tap_feed(clear)
        else:
            _drill(cycle, r, bottom, clear, go)
    believed = here.copy()
    if cycle.name == "cycle_bore_manual":
        believed[axis] = clear  # rs274 sets its current point to the clear height after every cycle
    return CycleMoves(steps, believed)


def _take_words(name: str, params: dict, cycle: CycleState, *, plane: int, scale: np.ndarray, dwell_unit: float,
                same_mode: bool) -> None:
    """The block's sticky words (R, the drilling axis, P, Q, G87's I/J/K) into the cycle mode, in mm and s.

    Raises ValueError when R or the drilling-axis level is in force neither
    here nor from an earlier block of the mode.
    """
    if name:
        cycle.name = name
    axis = PLANES[plane][0][2]
    letter = "XYZ"[axis]
    if not same_mode:
        _check_new_mode_words(cycle.name, params, plane)
    if "R" in params:
        cycle.r = params["R"] * scale[axis]
    if letter in params:
        cycle.z = params[letter] * scale[axis]
    if "P" in params:
        cycle.p = params["P"] * dwell_unit
    if "Q" in params:
        cycle.q = params["Q"] * scale[axis]
    if cycle.name == "cycle_back_bore":
        _back_bore_words(cycle, params, plane, scale)
    if cycle.r is None or cycle.z is None:
        raise ValueError(f"canned cycle needs R and {letter} (none in force)")


#: The words a cycle needs in the block that starts it, besides R and the drilling axis (rs274's checks)
_OWN_WORDS = {"cycle_drill_dwell": ("P", "G82"), "cycle_bore_stop": ("P", "G86"), "cycle_bore_manual": ("P", "G88"),
              "cycle_bore_dwell": ("P", "G89"), "cycle_peck": ("Q", "G83"), "cycle_chip_break": ("Q", "G73")}


def _check_new_mode_words(name: str, params: dict, plane: int) -> None:
    """A block that starts a cycle mode gives R, the drilling axis and the cycle's own words (rs274 2.9)."""
    (a, b, axis), _ = PLANES[plane]
    if "R" not in params:
        raise ValueError("R clearance plane unspecified in cycle")
    if "XYZ"[axis] not in params:
        raise ValueError(f"{'XYZ'[axis]} value unspecified in {PLANE_NAMES[plane]} plane canned cycle")
    letter, code = _OWN_WORDS.get(name, ("", ""))
    if letter and letter not in params:
        raise ValueError(f"{'Dwell time P' if letter == 'P' else 'Q'} word missing with {code.lower()}")
    if name == "cycle_back_bore":
        for word in ("IJK"[a], "IJK"[b], "IJK"[axis]):
            if word not in params:
                raise ValueError(f"{word} word missing with g87")


def _most_moves_per_hole(cycle: CycleState, r: float, bottom: float) -> float:
    """An upper bound of the moves one hole takes: over it, to R, then the drilling (a
    peck cycle up to three moves per peck)."""
    if cycle.name in ("cycle_peck", "cycle_chip_break"):
        return 3 * (max(r - bottom, 0.0) / cycle.q + 1) + 4
    return 10


def _back_bore_words(cycle: CycleState, params: dict, plane: int, scale: np.ndarray) -> None:
    """G87's I/J side step (in the plane's two axes) and K level, kept while the cycle lasts."""
    (a, b, axis), letters = PLANES[plane]
    offset_letters = {0: "I", 1: "J", 2: "K"}
    first, second, level = offset_letters[a], offset_letters[b], offset_letters[axis]
    if first in params or second in params or cycle.shift is None:
        cycle.shift = np.array([params.get(first, 0.0) * scale[a], params.get(second, 0.0) * scale[b]])
    if level in params:
        cycle.k = params[level] * scale[axis]
    if cycle.k is None:
        raise ValueError(f"G87 needs {level}, the level to back-bore to")


def _back_bore(level: float, bottom: float, clear: float, go, slide) -> None:
    """G87 (LinuxCNC): step aside at R, drop below the part, centre, bore up to
    the K level and back, step aside again, rise to the clear height, centre."""
    slide(True)
    go(bottom, MOTION_RAPID)
    slide(False)
    go(level, MOTION_LINEAR)
    go(bottom, MOTION_LINEAR)
    slide(True)
    go(clear, MOTION_RAPID)
    slide(False)


def polar_target(params: dict, xy: np.ndarray, scale: float, incremental: bool) -> np.ndarray:
    """X/Y from LinuxCNC's polar words: ``@`` distance, ``^`` angle (degrees) about
    the origin; a missing word keeps the point's own, G91 adds to them."""
    radius, angle = float(np.hypot(*xy)), float(np.degrees(np.arctan2(xy[1], xy[0])))
    if "@" in params:
        radius = radius + params["@"] * scale if incremental else params["@"] * scale
    if "^" in params:
        angle = angle + params["^"] if incremental else params["^"]
    return np.array([radius * np.cos(np.radians(angle)), radius * np.sin(np.radians(angle))])


def _drill(cycle: CycleState, r: float, bottom: float, clear: float, go) -> None:
    """The moves after reaching R, ending at the clear height."""
    name = cycle.name
    if name in ("cycle_peck", "cycle_chip_break"):
        depth = r
        while depth > bottom:
            start = depth if name == "cycle_chip_break" or depth == r else depth + PECK_DELTA_MM
            if start != depth:
                go(start, MOTION_RAPID)  # G83: back down to just above the last depth
            depth = max(depth - cycle.q, bottom)
            go(depth, MOTION_LINEAR)
            if depth > bottom:
                go(r if name == "cycle_peck" else depth + PECK_DELTA_MM, MOTION_RAPID)
        go(clear, MOTION_RAPID)
    elif name in ("cycle_tap", "cycle_tap_left"):  # G84/G74: spindle reversed at the bottom, out at feed
        go(bottom, MOTION_LINEAR)
        go(clear, MOTION_LINEAR)
    elif name == "cycle_bore_manual":  # G88: the operator retracts by hand after the program stop
        go(bottom, MOTION_LINEAR, cycle.p)
    elif name == "cycle_bore":  # G85: feed back to R, then a rapid to the clear height (zero length or not)
        go(bottom, MOTION_LINEAR)
        go(r, MOTION_LINEAR)
        go(clear, MOTION_RAPID)
    elif name == "cycle_bore_dwell":  # G89: feed out all the way to the clear height
        go(bottom, MOTION_LINEAR, cycle.p)
        go(clear, MOTION_LINEAR)
    else:  # G81, G82 and G86 feed in and rapid out
        go(bottom, MOTION_LINEAR, cycle.p if name in ("cycle_drill_dwell", "cycle_bore_stop") else 0.0)
        go(clear, MOTION_RAPID)
