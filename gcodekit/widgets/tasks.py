"""Widgets stage: checking a program a student wrote against what an exercise asks of it.

An exercise that asks for G-code names its requirements ("it cuts this
circle", "it finishes in under 5 s", "it deposits 4.5 mm³"); each is a
:class:`Requirement`, a sentence and a test of the emulated program that
returns what is wrong, or None.  :func:`check_program` runs the program
through gcodekit (a program it cannot read is reported with its line and
column) and tests every requirement; the result is a
:class:`~gcodekit.widgets.checks.Check` that names each unmet requirement
and what the program did instead.

Examples
--------
>>> check_program("G21 G90\\nM3 S1000\\nG1 X10 F100\\nM2\\n", [spindle_on_before_cutting()], "linuxcnc").ok
True
>>> check_program("G21 G90\\nG1 X10 F100\\nM3 S1000\\nM2\\n", [spindle_on_before_cutting()], "linuxcnc")
Not yet: 1 of 1 requirements not met.
- the spindle runs before the tool cuts: line 2 feeds with the spindle stopped
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Iterable, Mapping, Sequence

import numpy as np

from .checks import Check

if TYPE_CHECKING:
    from ..model.operation import Operation

#: Motion codes of the waypoint table's ``motion`` column.
RAPID, FEED, ARC_CW, ARC_CCW = 1, 2, 3, 4
_COMMENT = re.compile(r"\([^)]*\)|;.*")
_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


@dataclass
class Requirement:
    """One thing an exercise asks of a program: ``text`` says it, ``test(op, source)`` says what is wrong or None."""

    text: str
    test: Callable[["Operation", str], str | None]


@dataclass(repr=False)
class ProgramCheck(Check):
    """A :class:`Check` of a program, with the emulated operation (None when it could not be read)."""

    operation: "Operation | None" = field(default=None, repr=False)
    failed: list[str] = field(default_factory=list)

    def view(self, **options):
        """The program in a :class:`~gcodekit.widgets.LayerViewer` (a message in it when there is none to draw)."""
        from .layer_viewer import LayerViewer

        return LayerViewer(self.operation if self.operation is not None else "", **options)


def check_program(program: str | None, requirements: Sequence[Requirement], machine: str | None = None,
                  **options) -> ProgramCheck:
    """Run ``program`` (G-code text) through gcodekit and test each requirement.

    Parameters
    ----------
    program : str or None
        The student's program; None when not written yet.
    requirements : sequence of Requirement
    machine : str, optional
        The machine preset (``"linuxcnc"``, ``"klipper"``, ...).
    **options
        As for :func:`gcodekit.gcode_to_operation` (``tool_table=``, ``plan=``).
    """
    from ..pipeline import gcode_to_operation

    if program is None or not str(program).strip():
        return ProgramCheck(None, "Not answered yet: write your program in the cell above and run both cells again.")
    # a program written as """ + newline + lines: its first G-code line is line 1, as the student counts
    program = str(program)[1:] if str(program).startswith("\n") else str(program)
    try:
        op = gcode_to_operation(program, machine, **options)
    except Exception as exc:  # a program gcodekit refuses: say why, with its line
        return ProgramCheck(False, f"Not yet: gcodekit cannot run your program: {exc}")
    errors = [str(d).replace("<string>:", "line ", 1) for d in op.diagnostics.errors]
    if errors:
        return ProgramCheck(False, "Not yet: the controller would stop at an error in your program:\n- "
                            + "\n- ".join(errors[:3]), op, ["runs without errors"])
    failed = []
    for requirement in requirements:
        problem = requirement.test(op, program)
        if problem:
            failed.append(f"{requirement.text}: {problem}")
    if not failed:
        return ProgramCheck(True, "Right: your program meets every requirement ("
                            + "; ".join(r.text for r in requirements) + ").", op)
    return ProgramCheck(False, f"Not yet: {len(failed)} of {len(requirements)} requirements not met.\n- "
                        + "\n- ".join(failed), op, failed)


# -- what the program did, as arrays -------------------------------------------------------------------------------

def _moves(op: "Operation", kinds: Iterable[int]) -> np.ndarray:
    """Rows of the waypoints that end a move of one of ``kinds`` with a length."""
    w = op.waypoints
    motion = np.asarray(w["motion"])
    rows = np.flatnonzero(np.isin(motion, list(kinds)) & (np.asarray(w["distance"], float) > 0))
    return rows[rows > 0]


def path_points(op: "Operation", kinds: Iterable[int] = (FEED, ARC_CW, ARC_CCW),
                rows: np.ndarray | None = None) -> np.ndarray:
    """Points along the moves of ``kinds`` (or the moves ending at ``rows``), machine coordinates, arcs in
    5-degree steps; shape (n, 3)."""
    from ..emulate.arcs import waypoint_arc_points

    w = op.waypoints
    rows = _moves(op, kinds) if rows is None else rows
    if rows.size == 0:
        return np.zeros((0, 3))
    xyz = np.column_stack([np.asarray(w[k], float) for k in "xyz"])
    interior, _ = waypoint_arc_points(w, rows)
    return np.vstack([xyz[rows - 1], xyz[rows], interior])


def _line(op: "Operation", row: int) -> int:
    return int(op.table.line[op.waypoints["command"][row]])


def _xyz(point) -> str:
    return "X{:.4g} Y{:.4g} Z{:.4g}".format(*(float(v) for v in point))


# -- requirements ---------------------------------------------------------------------------------------------------

def starts_safely(words: Sequence[str] = ("G17", "G21", "G40", "G49", "G80", "G90")) -> Requirement:
    """The program states these modal words before its first move (a safe start block)."""

    def test(op, source):
        said = set()
        for line in source.splitlines():
            text = _COMMENT.sub("", line.upper())
            codes = {f"{letter}{float(value):g}" for letter, value in _WORD.findall(text)}
            if codes & {"G0", "G1", "G2", "G3"} or re.search(r"\b[XYZ]\s*[-+]?\d", text):
                break
            said |= codes
        missing = [w for w in words if f"{w[0]}{float(w[1:]):g}" not in said]
        return f"missing before the first move: {' '.join(missing)}" if missing else None

    return Requirement(f"a safe start block ({' '.join(words)}) before the first move", test)


def spindle_on_before_cutting() -> Requirement:
    """Every feed move and arc runs with the spindle turning."""

    def test(op, source):
        rows = _moves(op, (FEED, ARC_CW, ARC_CCW))
        stopped = rows[np.asarray(op.waypoints["spindle"], float)[rows] == 0]
        return f"line {_line(op, stopped[0])} feeds with the spindle stopped" if stopped.size else None

    return Requirement("the spindle runs before the tool cuts", test)


def rapids_above(z: float) -> Requirement:
    """No rapid move goes below machine ``z`` (rapids into the stock break tools)."""

    def test(op, source):
        rows = _moves(op, (RAPID,))
        low = rows[np.asarray(op.waypoints["z"], float)[rows] < z - 1e-9]
        return f"line {_line(op, low[0])} moves at rapid speed down to Z{float(op.waypoints['z'][low[0]]):.4g}" \
            if low.size else None

    return Requirement(f"no rapid move below Z{z:g}", test)


def passes_through(points: Sequence[Sequence[float]], *, cutting: bool = True, tolerance: float = 0.01,
                   says: str | None = None) -> Requirement:
    """The feed moves (or, with ``cutting=False``, any moves) pass through each point (machine X, Y, Z).

    ``says`` words the requirement without its points (when they would answer another exercise); the
    feedback then counts the points missed instead of naming them.
    """
    kinds = (FEED, ARC_CW, ARC_CCW) if cutting else (RAPID, FEED, ARC_CW, ARC_CCW)

    def test(op, source):
        from ..view import move_segments

        rows = _moves(op, kinds)
        missed = list(points)
        if rows.size:
            start, end, _ = move_segments(op.waypoints, rows)
            missed = [p for p in points if _distance_to_segments(np.asarray(p, float), start, end) > tolerance]
        if not missed:
            return None
        if says is not None:
            return "it never gets there" if len(points) == 1 else f"it misses {len(missed)} of the {len(points)} places"
        return ("the cut never reaches " if cutting else "the tool never reaches ") + ", ".join(_xyz(p) for p in missed)

    text = ("cuts through " if cutting else "goes through ") + ", ".join(_xyz(p) for p in points)
    return Requirement(says or text, test)


def _distance_to_segments(point: np.ndarray, start: np.ndarray, end: np.ndarray) -> float:
    """The shortest distance from ``point`` to the segments ``start[k]``-``end[k]``."""
    d = end - start
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("ij,ij->i", point - start, d) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    return float(np.min(np.linalg.norm(start + t[:, None] * d - point, axis=1)))


def on_circle(center: Sequence[float], radius: float, z: float, *, turn: str = "cw",
              tolerance: float = 0.01) -> Requirement:
    """Every cutting move at depth ``z`` lies on the circle, which is cut all the way round in the ``turn`` sense."""

    def test(op, source):
        w = op.waypoints
        rows = _moves(op, (FEED, ARC_CW, ARC_CCW))
        at_depth = rows[np.isclose(np.asarray(w["z"], float)[rows], z, atol=tolerance)
                        & np.isclose(np.asarray(w["z"], float)[rows - 1], z, atol=tolerance)]
        if at_depth.size == 0:
            return f"no cutting move at Z{z:g}"
        pts = path_points(op, rows=at_depth)
        r = np.hypot(pts[:, 0] - center[0], pts[:, 1] - center[1])
        if np.max(np.abs(r - radius)) > tolerance:
            worst = pts[np.argmax(np.abs(r - radius))]
            return f"the cut at Z{z:g} leaves the circle (at X{worst[0]:.4g} Y{worst[1]:.4g} it is " \
                   f"{abs(r[np.argmax(np.abs(r - radius))] - radius):.3g} mm off it)"
        swept = _swept_angle(op, at_depth, center)
        wanted = -2 * math.pi if turn == "cw" else 2 * math.pi
        if abs(swept - wanted) > 0.02:
            sense = "clockwise" if swept < 0 else "counter-clockwise"
            return f"the cut turns {abs(math.degrees(swept)):.0f} degrees {sense}, not once round " \
                   f"{'clockwise' if turn == 'cw' else 'counter-clockwise'}"
        return None

    sense = "clockwise" if turn == "cw" else "counter-clockwise"
    return Requirement(f"a full {sense} circle of radius {radius:g} about X{center[0]:g} Y{center[1]:g} at Z{z:g}", test)


def helix(center: Sequence[float], radius: float, z_from: float, z_to: float, turns: int, *, turn: str = "ccw",
          tolerance: float = 0.01) -> Requirement:
    """Arcs about ``center`` that go down from ``z_from`` to ``z_to`` in ``turns`` turns, evenly."""

    def test(op, source):
        w = op.waypoints
        rows = _moves(op, (ARC_CW, ARC_CCW))
        z = np.asarray(w["z"], float)
        rows = rows[(z[rows] < z[rows - 1] - 1e-9)]
        if rows.size == 0:
            return "no arc goes down (an arc with a Z word is a helix)"
        pts = path_points(op, rows=rows)
        r = np.hypot(pts[:, 0] - center[0], pts[:, 1] - center[1])
        if np.max(np.abs(r - radius)) > tolerance:
            return f"the helix is not on the circle of radius {radius:g} about X{center[0]:g} Y{center[1]:g}"
        top, bottom = z[rows[0] - 1], z[rows[-1]]
        if abs(top - z_from) > tolerance or abs(bottom - z_to) > tolerance:
            return f"the helix goes from Z{top:.4g} to Z{bottom:.4g}"
        swept = _swept_angle(op, rows, center)
        if (swept < 0) != (turn == "cw"):
            return "it turns the other way"
        if abs(abs(swept) - 2 * math.pi * turns) > 0.05:
            return f"it makes {abs(swept) / (2 * math.pi):.3g} turns"
        return None

    sense = "clockwise" if turn == "cw" else "counter-clockwise"
    return Requirement(f"a {sense} helix of radius {radius:g} about X{center[0]:g} Y{center[1]:g} from Z{z_from:g} "
                       f"to Z{z_to:g} in {turns} turns", test)


def tip_depth(depth: float, tool_lengths: dict[int, float], *, tolerance: float = 0.01) -> Requirement:
    """Each listed tool's tip reaches work Z ``depth`` and no lower (machine Z minus the tool's length)."""

    def test(op, source):
        w = op.waypoints
        rows = _moves(op, (FEED, ARC_CW, ARC_CCW))
        tool = np.asarray(w["tool"])[rows]
        z = np.asarray(w["z"], float)[rows]
        wrong = []
        for number, length in tool_lengths.items():
            mine = z[tool == number]
            if mine.size == 0:
                wrong.append(f"tool {number} never cuts")
                continue
            lowest = float(mine.min()) - length
            if abs(lowest - depth) > tolerance:  # said without the depth: that is another exercise's answer
                wrong.append(f"tool {number}'s tip goes {'deeper than' if lowest < depth else 'not as deep as'} "
                             f"Z{depth:g}")
        return "; ".join(wrong) or None

    return Requirement(f"the tip of each tool ({', '.join(f'T{t}' for t in tool_lengths)}) cuts down to Z{depth:g}",
                       test)


def drills(holes: Sequence[Sequence[float]], depth: float, *, tolerance: float = 0.01) -> Requirement:
    """Holes at these X, Y down to machine Z ``depth`` and nowhere else."""

    def test(op, source):
        w = op.waypoints
        rows = _moves(op, (FEED,))
        xyz = np.column_stack([np.asarray(w[k], float)[rows] for k in "xyz"])
        down = xyz[np.asarray(w["z"], float)[rows - 1] > xyz[:, 2] + 1e-9]
        bottoms = {}
        for x, y, z in down:
            key = (round(x, 3), round(y, 3))
            bottoms[key] = min(z, bottoms.get(key, z))
        wanted = {(round(float(x), 3), round(float(y), 3)) for x, y in holes}
        problems = [f"no hole at X{x:g} Y{y:g}" for x, y in sorted(wanted - set(bottoms))]
        problems += [f"a hole at X{x:g} Y{y:g} that was not asked for" for x, y in sorted(set(bottoms) - wanted)]
        problems += [f"the hole at X{x:g} Y{y:g} goes down to Z{bottoms[(x, y)]:.4g}" for x, y in sorted(wanted)
                     if (x, y) in bottoms and abs(bottoms[(x, y)] - depth) > tolerance]
        return "; ".join(problems) or None

    return Requirement(f"{len(holes)} holes at " + ", ".join(f"X{x:g} Y{y:g}" for x, y in holes) + f" down to Z{depth:g}",
                       test)


def clears(box: Sequence[float], height: float) -> Requirement:
    """No move crosses the XY box ``(xmin, ymin, xmax, ymax)`` below ``height`` (a clamp or a fixture)."""

    def test(op, source):
        path = path_points(op, (RAPID, FEED, ARC_CW, ARC_CCW))
        rows = _moves(op, (RAPID, FEED))
        xyz = np.column_stack([np.asarray(op.waypoints[k], float) for k in "xyz"])
        for row in rows:  # sample straight moves finely: a move may cross the box between its ends
            a, b = xyz[row - 1], xyz[row]
            t = np.linspace(0.0, 1.0, 200)[:, None]
            path = np.vstack([path, a + t * (b - a)])
        x0, y0, x1, y1 = box
        inside = (path[:, 0] >= x0) & (path[:, 0] <= x1) & (path[:, 1] >= y0) & (path[:, 1] <= y1)
        low = path[inside & (path[:, 2] < height - 1e-9)]
        return f"the tool passes over it at Z{low[:, 2].min():.4g}" if low.size else None

    return Requirement(f"the clamp at X{box[0]:g}..{box[2]:g} Y{box[1]:g}..{box[3]:g} is crossed at Z{height:g} "
                       "or higher", test)


def inside_box(box: Sequence[float], z_below: float, *, tolerance: float = 0.01,
               says: str | None = None) -> Requirement:
    """Every tool-centre point below ``z_below`` stays inside the XY box ``(xmin, ymin, xmax, ymax)``.

    ``says`` words the requirement without the box's numbers.
    """

    def test(op, source):
        path = path_points(op, (RAPID, FEED, ARC_CW, ARC_CCW))
        low = path[path[:, 2] < z_below]
        x0, y0, x1, y1 = box
        out = low[(low[:, 0] < x0 - tolerance) | (low[:, 0] > x1 + tolerance) | (low[:, 1] < y0 - tolerance)
                  | (low[:, 1] > y1 + tolerance)]
        if not out.size:
            return None
        rows = _moves(op, (RAPID, FEED, ARC_CW, ARC_CCW))
        xyz = np.column_stack([np.asarray(op.waypoints[k], float)[rows] for k in "xyz"])
        first = rows[np.flatnonzero(np.all(np.isclose(xyz[:, None, :], out[None, :, :]), axis=2).any(axis=1))]
        where = f" on line {_line(op, first[0])}" if first.size else ""
        return f"the tool centre leaves the box{where}"  # no coordinates: they could answer another exercise

    return Requirement(says or f"below Z{z_below:g} the tool centre stays within X{box[0]:g}..{box[2]:g} "
                       f"Y{box[1]:g}..{box[3]:g}", test)


def spindle_and_feed(*, rpm: tuple[float, float], feed: tuple[float, float]) -> Requirement:
    """Every cutting move runs at a spindle speed and a feed within these (low, high) ranges."""

    def test(op, source):
        w = op.waypoints
        rows = _moves(op, (FEED, ARC_CW, ARC_CCW))
        if rows.size == 0:
            return "the program makes no cutting move"
        s = np.abs(np.asarray(w["spindle"], float)[rows])
        f = np.asarray(w["feed"], float)[rows]
        problems = []
        if s.min() < rpm[0] or s.max() > rpm[1]:
            problems.append(f"the spindle turns at {s.min():.0f}" + (f"-{s.max():.0f}" if s.max() > s.min() else "")
                            + f" rpm: too {'slow' if s.min() < rpm[0] else 'fast'} for this cutter")
        if f.min() < feed[0] or f.max() > feed[1]:
            problems.append(f"the feed is {f.min():.0f}" + (f"-{f.max():.0f}" if f.max() > f.min() else "")
                            + f" mm/min: the chip load is too {'thin' if f.min() < feed[0] else 'thick'}")
        return "; ".join(problems) or None

    return Requirement("spindle speed and feed right for the cutter", test)


def finishes_within(seconds: float) -> Requirement:
    """The planned time of the whole program is below ``seconds``."""

    def test(op, source):
        t = float(op.get_statistics()["time_s"])
        return f"it takes {t:.2f} s" if t >= seconds else None

    return Requirement(f"it finishes in under {seconds:g} s", test)


def feed_at_most(feed: float) -> Requirement:
    """No feed word above ``feed`` (mm/min)."""

    def test(op, source):
        rows = _moves(op, (FEED, ARC_CW, ARC_CCW))
        f = np.asarray(op.waypoints["feed"], float)[rows]
        return f"line {_line(op, rows[np.argmax(f)])} asks for F{f.max():g}" if f.size and f.max() > feed else None

    return Requirement(f"no feed above F{feed:g}", test)


def prints_at_least(feed: float) -> Requirement:
    """Every move that lays material runs at ``feed`` (mm/min) or faster."""

    def test(op, source):
        w = op.waypoints
        laying = np.flatnonzero((np.asarray(w["distance"], float) > 0) & (np.asarray(w["de"], float) > 0))
        f = np.asarray(w["feed"], float)[laying]
        slow = laying[f < feed - 1e-9]
        return f"line {_line(op, slow[0])} prints at F{float(w['feed'][slow[0]]):g}" if slow.size else None

    return Requirement(f"every printed move at F{feed:g} or faster", test)


def visits_in_order(points: Sequence[Sequence[float]], *, tolerance: float = 0.01) -> Requirement:
    """The moves end at each of these XY points, in this order (other points may come between)."""

    def test(op, source):
        w = op.waypoints
        rows = _moves(op, (RAPID, FEED, ARC_CW, ARC_CCW))
        xy = np.column_stack([np.asarray(w["x"], float)[rows], np.asarray(w["y"], float)[rows]])
        k = 0
        for p in xy:
            if k < len(points) and np.hypot(*(p - np.asarray(points[k], float))) <= tolerance:
                k += 1
        return f"the path no longer passes X{points[k][0]:g} Y{points[k][1]:g} (point {k + 1} of {len(points)})" \
            if k < len(points) else None

    return Requirement(f"the path keeps its {len(points)} corners", test)


def deposits(volume: float, filament_diameter: float, *, relative: float = 0.03) -> Requirement:
    """The filament pushed while moving (net of retractions) is ``volume`` mm³ within ``relative``."""

    def test(op, source):
        w = op.waypoints
        de = np.asarray(w["de"], float)
        moving = np.asarray(w["distance"], float) > 0
        area = math.pi * filament_diameter**2 / 4
        laid = float(de[moving & (de > 0)].sum()) * area
        if abs(laid - volume) > relative * volume:
            return f"it lays {laid:.3g} mm³ while moving: too {'much' if laid > volume else 'little'}"
        return None

    return Requirement(f"it lays {volume:g} mm³ of plastic (within {relative:.0%})", test)


def retracts(length: float, *, tolerance: float = 0.01) -> Requirement:
    """Before each travel the filament is pulled back by ``length`` mm, and pushed back before printing again."""

    def test(op, source):
        w = op.waypoints
        de = np.asarray(w["de"], float)
        motion = np.asarray(w["motion"])
        travels = np.flatnonzero((motion > 0) & (np.asarray(w["distance"], float) > 0) & (de == 0))
        prints = np.flatnonzero((np.asarray(w["distance"], float) > 0) & (de > 0))
        problems = []
        for row in travels:
            if not (prints < row).any() or not (prints > row).any():
                continue  # travels before the first or after the last line need no retraction here
            back = de[prints[prints < row].max() + 1:row]
            forth = de[row + 1:prints[prints > row].min()]
            if abs(back[back < 0].sum() + length) > tolerance:
                problems.append(f"before the travel on line {_line(op, row)} the filament is pulled back "
                                f"{abs(back[back < 0].sum()):.3g} mm")
            if abs(forth[forth > 0].sum() - length) > tolerance:
                problems.append(f"after the travel on line {_line(op, row)} it is pushed back "
                                f"{forth[forth > 0].sum():.3g} mm")
        if not problems and not any(prints.size and (prints < r).any() and (prints > r).any() for r in travels):
            problems.append("there is no travel between two printed lines")
        return "; ".join(problems) or None

    return Requirement(f"a retraction of {length:g} mm around each travel", test)


def relative_e() -> Requirement:
    """The program extrudes in relative E (M83)."""

    def test(op, source):
        text = [_COMMENT.sub("", line.upper()) for line in source.splitlines()]
        m83 = next((k for k, t in enumerate(text) if re.search(r"\bM83\b", t)), None)
        first_e = next((k for k, t in enumerate(text) if re.search(r"\bE\s*[-+]?\d", t)), None)
        if m83 is None or (first_e is not None and first_e < m83):
            return "M83 does not come before the first E word"
        return None

    return Requirement("relative extrusion (M83) before the first E word", test)


def layer_time_at_least(seconds: float) -> Requirement:
    """Every layer takes at least ``seconds`` (planned), so it cools before the next is laid on it."""

    def test(op, source):
        times = op.time_by("layer")
        times = times[times.index >= 0] if hasattr(times, "index") else times
        col = times["time_s"] if "time_s" in times else times.iloc[:, 0]
        short = col[col < seconds]
        return f"layer {short.index[0]} takes {float(short.iloc[0]):.2f} s" if len(short) else None

    return Requirement(f"every layer takes at least {seconds:g} s", test)


#: The heater commands of the command table: the heater each sets, and whether it waits.
_HEATER_COMMANDS = {"set_hotend_temp": ("nozzle", False), "wait_hotend_temp": ("nozzle", True),
                    "set_bed_temp": ("bed", False), "wait_bed_temp": ("bed", True)}


def heater_waits(op: "Operation", rates: Mapping[str, float], room: float = 25.0) -> list[tuple[int, str, float]]:
    """How long each M109/M190 of the program waits, with heaters that change temperature at a constant rate.

    A teaching model, not a thermal one: each heater (``"nozzle"``, ``"bed"``) starts at ``room`` °C and moves
    towards the target its last M104/M109 (M140/M190) set at ``rates[heater]`` °C/s, from the moment that line
    runs (the planned time of the moves before it plus the waits so far). A wait (M109/M190 with S) lasts until
    the heater has reached its target from below, as Marlin's ``M109 S`` does; a target below the heater's
    temperature is not waited for.

    Parameters
    ----------
    op : Operation
    rates : mapping of str to float
        °C/s per heater (``{"nozzle": 2.5, "bed": 0.5}``); a heater left out is not modelled.
    room : float, default: 25.0
        Every heater's temperature at the start, °C.

    Returns
    -------
    list of (line, heater, seconds)
        One entry per wait, in program order.

    Examples
    --------
    Waiting for the bed before the nozzle's target is even set: 35 °C at 0.5 °C/s, then 185 °C at 2.5 °C/s.

    >>> from gcodekit.pipeline import gcode_to_operation
    >>> heater_waits(gcode_to_operation("M190 S60\\nM109 S210\\nG1 X10 F600\\n", "marlin"), {"nozzle": 2.5, "bed": 0.5})
    [(1, 'bed', 70.0), (2, 'nozzle', 74.0)]
    """
    w = op.waypoints
    command = np.asarray(w["command"])
    clock = np.cumsum(np.nan_to_num(np.asarray(w["time"], float)))
    at = {int(c): float(t) for c, t in zip(command, clock)}  # the last row of each command
    temp = {heater: float(room) for heater in rates}
    target = dict(temp)
    since = {heater: 0.0 for heater in rates}
    waited, waits = 0.0, []

    def now_temp(heater: str, t: float) -> float:
        step = rates[heater] * (t - since[heater])
        start = temp[heater]
        return min(target[heater], start + step) if target[heater] >= start else max(target[heater], start - step)

    for index, cmd in enumerate(op.commands):
        kind = _HEATER_COMMANDS.get(getattr(cmd, "name", None))
        if kind is None or kind[0] not in rates:
            continue
        heater, wait = kind
        t = at.get(index, 0.0) + waited
        value = cmd.params.get("S", cmd.params.get("R"))
        temp[heater], since[heater] = now_temp(heater, t), t
        if value is not None:
            target[heater] = float(value)
        if wait:
            seconds = max(0.0, (target[heater] - temp[heater]) / rates[heater])
            waits.append((int(cmd.line), heater, seconds))
            waited += seconds
    return waits


def waits_for_heaters(bed: float, nozzle: float) -> Requirement:
    """Before the first printed move the program waits for the bed (M190) to reach ``bed`` °C and then for the
    nozzle (M109) to reach ``nozzle`` °C."""

    def test(op, source):
        printing = np.flatnonzero(np.asarray(op.depositing))
        if printing.size == 0:
            return "the program prints nothing"
        first = int(np.asarray(op.waypoints["command"])[printing[0]])
        waits = {"wait_bed_temp": None, "wait_hotend_temp": None}
        wanted = {"wait_bed_temp": bed, "wait_hotend_temp": nozzle}
        for index, cmd in enumerate(op.commands[:first]):
            name = getattr(cmd, "name", None)
            if name in waits and waits[name] is None and cmd.params.get("S") is not None \
                    and abs(float(cmd.params["S"]) - wanted[name]) < 0.5:
                waits[name] = (index, int(cmd.line))
        line = int(op.commands[first].line)
        problems = []
        if waits["wait_bed_temp"] is None:
            problems.append(f"nothing waits for the bed to reach {bed:g} °C before the first printed line "
                            f"(line {line})")
        if waits["wait_hotend_temp"] is None:
            problems.append(f"nothing waits for the nozzle to reach {nozzle:g} °C before the first printed line "
                            f"(line {line})")
        if not problems and waits["wait_hotend_temp"][0] < waits["wait_bed_temp"][0]:
            problems.append(f"line {waits['wait_hotend_temp'][1]} waits for the nozzle before line "
                            f"{waits['wait_bed_temp'][1]} waits for the bed: the hot nozzle oozes while the bed heats")
        return "; ".join(problems) or None

    return Requirement(f"waits for the bed ({bed:g} °C), then the nozzle ({nozzle:g} °C), before printing", test)


def heats_within(seconds: float, rates: Mapping[str, float], room: float = 25.0) -> Requirement:
    """The program's waits for its heaters (:func:`heater_waits`) add up to less than ``seconds``."""

    def test(op, source):
        waits = heater_waits(op, rates, room)
        total = sum(s for _, _, s in waits)
        if total < seconds:
            return None
        return f"it waits {total:.0f} s for its heaters (" + ", ".join(f"line {line}: {s:.0f} s" for line, _, s in waits
                                                                      if s > 0) + ")"

    return Requirement(f"heating done in under {seconds:g} s", test)


def fan_from_layer(layer: int, speed: float = 255) -> Requirement:
    """Printed moves on layers below ``layer`` run with the part-cooling fan off, the others at ``speed`` (M106 S,
    0-255; M106 without S is full speed, M107 off)."""

    def test(op, source):
        fan = np.zeros(len(op.commands) + 1)
        value = 0.0
        for index, cmd in enumerate(op.commands):
            name = getattr(cmd, "name", None)
            if name == "fan_on":
                value = float(cmd.params.get("S", 255.0))
            elif name == "fan_off":
                value = 0.0
            fan[index] = value
        printing = np.flatnonzero(np.asarray(op.depositing))
        if printing.size == 0:
            return "the program prints nothing"
        layers = np.asarray(op.layers)[printing]
        at = fan[np.asarray(op.waypoints["command"])[printing]]
        wrong = np.flatnonzero(np.abs(at - np.where(layers < layer, 0.0, float(speed))) > 0.5)
        if wrong.size == 0:
            return None
        k = wrong[0]
        state = "off" if at[k] == 0 else f"at S{at[k]:g}"
        return f"layer {int(layers[k])} prints (line {_line(op, printing[k])}) with the fan {state}"

    return Requirement(f"the part fan off below layer {layer} and at S{speed:g} from it on", test)


def _swept_angle(op: "Operation", rows: np.ndarray, center: Sequence[float]) -> float:
    """Signed angle (rad, counter-clockwise positive) the moves ending at ``rows`` sweep about ``center``."""
    from ..emulate.arcs import waypoint_arc_points

    w = op.waypoints
    total = 0.0
    for row in rows:
        interior, _ = waypoint_arc_points(w, np.array([row]))
        pts = np.vstack([[float(w["x"][row - 1]), float(w["y"][row - 1]), 0.0], interior,
                         [float(w["x"][row]), float(w["y"][row]), 0.0]])
        angle = np.unwrap(np.arctan2(pts[:, 1] - center[1], pts[:, 0] - center[0]))
        total += float(angle[-1] - angle[0])
    return total
