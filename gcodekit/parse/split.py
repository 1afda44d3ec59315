"""Parse stage: cut a compound block into commands in execution order.

Most blocks hold one code and its words and are parsed in bulk by
:mod:`.parser`.  The rest (``G17 G2 X1 I1``, ``T1 M6``, ``G90 X0``, named
commands) come here, one block at a time, and are split by the flavor's
``block_split`` rule:

* ``modal`` follows LinuxCNC's order of execution: feed mode, F, S, T,
  M6, spindle, coolant, other M, dwell, plane, units, compensation, tool
  length, coordinate system, path mode, distance mode, position and offset
  commands, motion, then program stops.  Axis words go to the one command
  that consumes them.
* ``single`` is printer firmware: the first code is the command and every
  other word is its parameter.
* ``sequential`` is GER: each code starts a new command in text order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..syntax import Flavor
from ..syntax.flavor import code_label

AXIS_LETTERS = frozenset("XYZABCUVW@^")  # @ and ^: LinuxCNC's polar X/Y
CYCLES = frozenset({"cycle_chip_break", "cycle_drill", "cycle_drill_dwell", "cycle_peck", "cycle_bore",
                    "cycle_bore_stop", "cycle_bore_dwell", "cycle_tap", "cycle_tap_left", "cycle_back_bore",
                    "cycle_bore_manual", "cycle_thread", "lathe_finish", "lathe_rough", "lathe_rough_no_pockets",
                    "lathe_rough_pockets", "lathe_face", "lathe_face_no_pockets", "lathe_face_pockets"})
#: Commands that take axis words in the same block.
AXIS_CONSUMERS = frozenset(
    {"rapid", "linear", "arc_cw", "arc_ccw", "set_position", "home", "home_secondary",
     "machine_coordinates", "probe", "coordinate_data", "local_offset", "tool_length_offset_dynamic",
     "spline_cubic", "spline_quadratic", "nurbs_start", "thread", "rigid_tap"}
) | CYCLES
MOTIONS = frozenset({"rapid", "linear", "arc_cw", "arc_ccw", "probe", "cancel_cycle", "spline_cubic",
                     "spline_quadratic", "nurbs_start", "nurbs_end", "thread"}) | CYCLES

# Rank of each normalized command in LinuxCNC's order of execution
# (LinuxCNC 2.9 docs, "G-code overview: order of execution").
_RANK = {
    "feed_inverse_time": 3, "feed_per_minute": 3, "feed_per_rev": 3,
    "tool_change": 8, "spindle_cw": 9, "spindle_ccw": 9, "spindle_off": 9,
    "coolant_mist": 11, "coolant_flood": 11, "coolant_off": 11,
    "dwell": 14, "plane_xy": 15, "plane_zx": 15, "plane_yz": 15,
    "units_inch": 16, "units_mm": 16,
    "cutter_comp_off": 17, "cutter_comp_left": 17, "cutter_comp_right": 17,
    "cutter_comp_left_dynamic": 17, "cutter_comp_right_dynamic": 17,
    "tool_length_offset": 18, "tool_length_offset_dynamic": 18, "tool_length_offset_add": 18,
    "cancel_tool_length": 18,
    **{f"work_offset_{k}": 19 for k in range(1, 10)},
    "exact_stop": 20, "path_blending": 20, "retract_initial": 22, "retract_r": 22,
    "distance_absolute": 21, "distance_incremental": 21, "diameter_mode": 21, "radius_mode": 21,
    "arc_distance_absolute": 21, "arc_distance_incremental": 21,
    "set_position": 23, "clear_position_offset": 23, "suspend_position_offset": 23,
    "restore_position_offset": 23, "home": 23, "home_secondary": 23,
    "store_home": 23, "store_home_secondary": 23, "coordinate_data": 23, "local_offset": 23,
    "machine_coordinates": 24, "rapid": 24, "linear": 24, "arc_cw": 24, "arc_ccw": 24,
    "probe": 24, "cancel_cycle": 24, **dict.fromkeys(CYCLES, 24),
    "spline_cubic": 24, "spline_quadratic": 24, "nurbs_start": 24, "nurbs_end": 24, "thread": 24,
    "program_stop": 25, "optional_stop": 25, "program_end": 25,
}
_RANK_OTHER_M = 13
_RANK_OTHER_G = 22

#: RS274NGC's modal groups (LinuxCNC 2.9 "Modal Groups"; group 1, motion, is
#: checked on its own), by normalized command.  Group 0 holds the non-modal
#: codes; rs274 2.9 lets G92.1/G92.2/G92.3 share a block with one of them.
_MODAL_GROUPS = {
    **dict.fromkeys(("dwell", "coordinate_data", "home", "home_secondary", "store_home", "store_home_secondary",
                     "machine_coordinates", "set_position", "local_offset"), "non-modal"),
    **dict.fromkeys(("clear_position_offset", "suspend_position_offset", "restore_position_offset"),
                    "G92 offset switch"),
    **dict.fromkeys(("plane_xy", "plane_zx", "plane_yz"), "plane"),
    **dict.fromkeys(("distance_absolute", "distance_incremental"), "distance mode"),
    **dict.fromkeys(("arc_distance_absolute", "arc_distance_incremental"), "arc distance mode"),
    **dict.fromkeys(("feed_inverse_time", "feed_per_minute", "feed_per_rev"), "feed mode"),
    **dict.fromkeys(("units_inch", "units_mm"), "units"),
    **dict.fromkeys(("cutter_comp_off", "cutter_comp_left", "cutter_comp_right", "cutter_comp_left_dynamic",
                     "cutter_comp_right_dynamic"), "cutter compensation"),
    **dict.fromkeys(("tool_length_offset", "tool_length_offset_dynamic", "tool_length_offset_add",
                     "cancel_tool_length"), "tool length offset"),
    **dict.fromkeys(("retract_initial", "retract_r"), "canned cycle return"),
    **{f"work_offset_{k}": "coordinate system" for k in range(1, 10)},
    **dict.fromkeys(("exact_stop", "path_blending"), "path control"),
    **dict.fromkeys(("diameter_mode", "radius_mode"), "lathe diameter mode"),
    **dict.fromkeys(("program_stop", "optional_stop", "program_end"), "stopping"),
    **dict.fromkeys(("spindle_cw", "spindle_ccw", "spindle_off"), "spindle"),
    **dict.fromkeys(("coolant_mist", "coolant_flood", "coolant_off"), "coolant"),
}


@dataclass
class Part:
    """One command cut from a block."""

    letter: str  # "G", "M", "T", "@" (named) or "" (no code)
    number: float = -1.0
    params: dict[str, float] = field(default_factory=dict)
    motion: str = ""  # for G53: the motion code of the block, if any
    named: tuple[str, str] | None = None  # (name, argument text) of a named command
    text: str = ""  # string arguments (M117 message, P"MK3S")


def code_name(flavor: Flavor, letter: str, number: float) -> str:
    """Normalized name of a code given by letter and value, ``""`` if unknown."""
    return flavor.codes.get(code_label(letter, round(number * 10)), "")


def split_block(words: list[tuple[str, float]], flavor: Flavor, line_number_letter: str) -> tuple[list[Part], list[str]]:
    """Commands of one block and the problems found (as messages)."""
    words = [w for w in words if w[0] != line_number_letter]
    if flavor.block_split == "single":
        return _split_single(words)
    if flavor.block_split == "sequential":
        return _split_sequential(words, flavor), []
    return _split_modal(words, flavor)


def _split_single(words):
    problems = []
    codes = [i for i, (l, _) in enumerate(words) if l in "GM"]
    if not codes:
        codes = [i for i, (l, _) in enumerate(words) if l == "T"]
    if not codes:
        return ([Part("", params=dict(words))] if words else []), problems
    head = codes[0]
    part = Part(words[head][0], words[head][1])
    for i, (letter, value) in enumerate(words):
        if i == head:
            continue
        if letter in "GM":
            problems.append(f"only one command per line: {letter}{value:g} is ignored")
        elif letter not in part.params:
            part.params[letter] = value
    return [part], problems


def _split_sequential(words, flavor):
    """GER: each code starts a statement; axis words after a code that takes
    none (``G20 X1``) are a modal move of their own."""
    parts: list[Part] = []
    current = Part("")

    def takes_axes(part: Part) -> bool:
        return not part.letter or code_name(flavor, part.letter, part.number) in AXIS_CONSUMERS

    for letter, value in words:
        if letter in "GM" or (letter in AXIS_LETTERS and not takes_axes(current)) or letter in current.params:
            if current.letter or current.params:
                parts.append(current)
            current = Part(letter, value) if letter in "GM" else Part("", params={letter: value})
        else:
            current.params[letter] = value
    if current.letter or current.params:
        parts.append(current)
    return parts


def _split_modal(words, flavor):
    problems: list[str] = []
    codes = [(l, v) for l, v in words if l in "GM"]
    rest: dict[str, float] = {}
    for letter, value in words:
        if letter in "GM":
            continue
        if letter in rest:
            problems.append(f"more than one {letter} word in the block; the first is used")
            continue
        rest[letter] = value
    named = [(code_name(flavor, l, v), l, v) for l, v in codes]
    motion = [n for n in named if n[0] in MOTIONS]
    if len(motion) > 1 and not (len(motion) == 2 and "cancel_cycle" in (motion[0][0], motion[1][0])):
        # rs274 takes "G80 G0": the G80 only says what the G0 does anyway
        problems.append("more than one motion code in the block; the last is used")
    if flavor.rs274ngc_block_checks:
        problems += _group_conflicts(named)
    g53 = [n for n in named if n[0] == "machine_coordinates"]
    parts: list[tuple[int, Part]] = []
    for name, letter, value in named:
        if g53 and name in MOTIONS:
            continue  # folded into the G53 command below
        rank = _RANK.get(name, _RANK_OTHER_M if letter == "M" else _RANK_OTHER_G)
        part = Part(letter, value)
        if name == "machine_coordinates" and motion:
            part.motion = motion[-1][0]
        parts.append((rank, part))
    parts.sort(key=lambda rp: rp[0])
    ordered = [p for _, p in parts]
    by_name = {code_name(flavor, p.letter, p.number): p for p in ordered}

    def give(letter: str, target: Part) -> None:
        target.params[letter] = rest.pop(letter)

    consumer = next((by_name[n] for n in by_name if n in AXIS_CONSUMERS), None)
    has_axes = any(l in AXIS_LETTERS for l in rest)
    if consumer is None and (has_axes or "E" in rest):
        consumer = Part("")  # a move in the modal motion mode
        ordered.insert(_insert_at(ordered, flavor, 24), consumer)
    special = {"P": ("dwell", "coordinate_data"),
               "H": ("tool_length_offset", "tool_length_offset_add"),
               "D": ("cutter_comp_left", "cutter_comp_right", "cutter_comp_left_dynamic",
                     "cutter_comp_right_dynamic"),
               "L": ("coordinate_data", "cutter_comp_left_dynamic", "cutter_comp_right_dynamic"),
               "T": ("tool_change",),
               "S": ("spindle_cw", "spindle_ccw")}
    for letter in list(rest):
        owner = next((by_name[n] for n in special.get(letter, ()) if n in by_name), None)
        if owner is not None:
            give(letter, owner)
    for letter in list(rest):
        if letter == "T":
            ordered.insert(_insert_at(ordered, flavor, 6), Part("T", rest.pop("T")))
        elif letter in "FS" and consumer is None:
            rank = 4 if letter == "F" else 5
            ordered.insert(_insert_at(ordered, flavor, rank), Part("", params={letter: rest.pop(letter)}))
        elif consumer is not None:
            give(letter, consumer)
        elif ordered:
            give(letter, ordered[-1])
        else:
            ordered.append(Part("", params={letter: rest.pop(letter)}))
    return ordered, problems


def _group_conflicts(named: list[tuple[str, str, float]]) -> list[str]:
    """Messages for codes that share a modal group with an earlier code of the block."""
    first: dict[str, str] = {}
    problems = []
    for name, letter, value in named:
        group = _MODAL_GROUPS.get(name)
        code = code_label(letter, round(value * 10))
        if group is None:
            continue
        if group in first:
            problems.append(f"two codes from the same modal group ({group}): {first[group]} and {code}")
        else:
            first[group] = code
    return problems


def _insert_at(ordered: list[Part], flavor: Flavor, rank: int) -> int:
    for i, p in enumerate(ordered):
        if p.letter and _RANK.get(code_name(flavor, p.letter, p.number),
                                  _RANK_OTHER_M if p.letter == "M" else _RANK_OTHER_G) > rank:
            return i
    return len(ordered)
