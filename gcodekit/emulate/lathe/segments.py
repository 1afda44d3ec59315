"""Emulate stage, lathe cycles: the profile's pieces -- lines, arcs, fillets and chamfers -- and the moves made.

Points are complex numbers ``z + x*1j`` (see :mod:`gcodekit.emulate.lathe`).
Each segment can be offset, flipped, clipped and drawn as the moves the
cycle sends (LinuxCNC ``interp_g7x.cc``: ``segment``, ``straight_segment``,
``round_segment``).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

from ...errors import GcodeMachineError

__all__ = ["TOLERANCE", "EQUAL", "LatheCycleError", "Move", "Sink", "Segment", "Line", "Arc", "Fillet", "Chamfer",
           "intersect"]

TOLERANCE = 1e-6  # LinuxCNC's g7x tolerance
#: rs274's ``equal`` (interp_internal.hh TOLERANCE_EQUAL): an arc to where the tool is is skipped
EQUAL = 0.0001


class LatheCycleError(GcodeMachineError):
    """A profile the cycle cannot cut; the message is rs274's."""



@dataclass
class Move:
    """One move of a cycle in program coordinates: kind "rapid", "feed" or "arc"."""

    kind: str
    end: complex
    centre: complex | None = None
    ccw: bool = False


# Maps of the eight mirror/rotation states back to the program's frame:
# (point map, arc direction reversed).  Bit 1 mirrors Z, bit 2 mirrors X,
# bit 4 turns the profile by 90 degrees.
_BACK = {
    0: (lambda p: p, False),
    1: (lambda p: -p.conjugate(), True),
    2: (lambda p: p.conjugate(), True),
    3: (lambda p: -p, False),
    4: (lambda p: 1j * p, False),
    5: (lambda p: (1j * p).conjugate(), True),
    6: (lambda p: -(1j * p).conjugate(), True),
    7: (lambda p: -1j * p, False),
}


class Sink:
    """Collects moves, mapped back to the program's frame by ``state``."""

    def __init__(self, moves: list[Move], state: int):
        self.moves = moves
        self.map, self.reverse = _BACK[state]

    def rapid(self, end: complex) -> None:
        self.moves.append(Move("rapid", self.map(end)))

    def feed(self, end: complex) -> None:
        self.moves.append(Move("feed", self.map(end)))

    def arc(self, ccw: bool, centre: complex, end: complex) -> None:
        self.moves.append(Move("arc", self.map(end), self.map(centre), ccw != self.reverse))



class Segment:
    """A profile piece from ``start`` to ``end``; ``finish`` is a corner's radius or chamfer."""

    def __init__(self, start: complex, end: complex):
        self.start, self.end = start, end
        self.finish = 0.0

    def copy(self):
        return copy.copy(self)

    def flip_z(self) -> None:
        self.start, self.end = -self.start.conjugate(), -self.end.conjugate()

    def flip_x(self) -> None:
        self.start, self.end = self.start.conjugate(), self.end.conjugate()

    def turn(self) -> None:
        self.start, self.end = -1j * self.start, -1j * self.end

    def shift(self, d: complex) -> None:
        self.start += d
        self.end += d

    def monotonic(self) -> bool:
        return (self.end - self.start).real <= 1e-3

    def finish_corner(self, prev: "Segment", nxt: "Segment") -> None:
        """Corner pieces (A/C) fit themselves between their neighbours."""

    def _corner(self, prev: "Segment", nxt: "Segment") -> complex:
        """Trim ``prev`` and ``nxt`` where a ``finish``-wide corner meets them; returns its centre."""
        p, n = prev.copy(), nxt.copy()
        p.offset(self.finish)
        n.offset(self.finish)
        if (p.end - n.start).real > 1e-2:  # offset to the wrong side: the corner is the other way
            self.finish = -self.finish
            p, n = prev.copy(), nxt.copy()
            p.offset(self.finish)
            n.offset(self.finish)
        if (p.end - n.start).real > 1e-2:
            raise LatheCycleError(f"Corner finish failed at {_show(prev.end)}")
        intersect(p, n)
        centre = (p.end + n.start) / 2
        p.offset(-self.finish)
        n.offset(-self.finish)
        self.start = prev.end = p.end
        self.end = nxt.start = n.start
        return centre


class Line(Segment):
    def offset(self, distance: float) -> None:
        d = 1j * distance * (self.start - self.end) / abs(self.start - self.end)
        self.start += d
        self.end += d

    def length(self) -> float:
        return abs(self.start - self.end)

    def crossings(self, x: float) -> list[float]:
        """Z where the segment reaches height ``x`` (both ends when it lies along it)."""
        s, e = self.start, self.end
        if min(s.imag, e.imag) > x + TOLERANCE or max(s.imag, e.imag) < x - TOLERANCE:
            return []
        if abs((s - e).imag) < TOLERANCE:
            return [s.real, e.real]
        return [(x - s.imag) / (e.imag - s.imag) * (e.real - s.real) + s.real]

    def draw(self, out: Sink) -> None:
        out.feed(self.end)

    def climb(self, here: complex, out: Sink) -> tuple[bool, complex]:
        if self.end.imag + TOLERANCE < self.start.imag:
            return True, here
        if abs(here - self.start) > TOLERANCE:
            raise LatheCycleError("How did we get here?")
        out.feed(self.end)
        return False, self.end

    def climb_only(self, here: complex, out: Sink) -> complex:
        if self.end.imag < self.start.imag:
            return here
        found = self.crossings(here.imag)
        if not found:
            return here
        here = complex(found[0], here.imag)
        out.feed(here)
        out.feed(self.end)
        return self.end

    def dive(self, here: complex, x: float, out: Sink, fast: bool) -> tuple[bool, complex]:
        if self.start.imag <= self.end.imag + TOLERANCE:
            return True, here
        go = out.rapid if fast else out.feed
        if x < self.end.imag:
            go(self.end)
            return False, self.end
        found = self.crossings(x)
        if not found:
            raise LatheCycleError("x too large in straight dive")
        point = complex(found[0], x)
        go(point)
        return False, point

    def intersect(self, prev: "Line") -> None:
        """A line after line ``prev``: move ``prev``'s end and this start to where they cross."""
        rot = (self.start - self.end).conjugate() / abs(self.start - self.end)
        ps, pe = (prev.start - self.end) * rot, (prev.end - self.end) * rot
        if (ps - pe).imag == 0:
            raise LatheCycleError("Cannot intersect parallel lines")
        f = ps.imag / (ps - pe).imag
        self.start = prev.end = (ps + f * (pe - ps)) / rot + self.end


class Arc(Segment):
    def __init__(self, ccw: bool, start: complex, centre: complex, end: complex):
        super().__init__(start, end)
        self.ccw, self.centre = ccw, centre

    def flip_z(self) -> None:
        super().flip_z()
        self.ccw, self.centre = not self.ccw, -self.centre.conjugate()

    def flip_x(self) -> None:
        super().flip_x()
        self.ccw, self.centre = not self.ccw, self.centre.conjugate()

    def turn(self) -> None:
        super().turn()
        self.centre = -1j * self.centre

    def shift(self, d: complex) -> None:
        super().shift(d)
        self.centre += d

    def offset(self, distance: float) -> None:
        r = abs(self.start - self.centre)
        factor = (r + (distance if self.ccw else -distance)) / r
        self.start = factor * (self.start - self.centre) + self.centre
        self.end = factor * (self.end - self.centre) + self.centre

    def length(self) -> float:  # LinuxCNC's "radius": the smaller of chord and radius
        return min(abs(self.start - self.end), abs(self.start - self.centre))

    def monotonic(self) -> bool:
        if self.finish != 0:
            return True
        entry, exit_ = (self.start - self.centre).imag, (self.end - self.centre).imag
        dz = (self.end - self.start).real
        if self.ccw:
            return entry >= -1e-3 and exit_ >= -1e-3 and dz <= -1e-3
        return entry <= 1e-3 and exit_ <= 1e-3 and dz <= -1e-3

    def _on(self, p: complex) -> bool:
        a = ((self.start - self.centre).conjugate() * (p - self.centre)).imag
        b = ((self.end - self.centre).conjugate() * (p - self.centre)).imag
        if self.ccw:
            return a >= -TOLERANCE and b <= TOLERANCE
        return a <= TOLERANCE and b >= -TOLERANCE

    def crossings(self, x: float) -> list[float]:
        r = abs(self.start - self.centre)
        s = -(x - r - self.centre.imag) * (x + r - self.centre.imag)
        if s < -TOLERANCE:
            return []
        s = math.sqrt(max(s, 0.0))
        return [z for z in (self.centre.real + s, self.centre.real - s) if self._on(complex(z, x))]

    def draw(self, out: Sink) -> None:
        out.arc(self.ccw, self.centre, self.end)

    def _top(self) -> complex:
        """Where a G3 climb stops: its end, or the top of the circle if it goes past it."""
        if self.end.real < self.centre.real:
            return complex(self.centre.real, self.centre.imag + abs(self.start - self.centre))
        return self.end

    def climb(self, here: complex, out: Sink) -> tuple[bool, complex]:
        if not self.ccw:
            if here.real > self.centre.real:
                return True, here
            if abs(here - self.end) > 1e-3:
                out.arc(False, self.centre, self.end)
            return False, self.end
        if here.real < self.centre.real:
            return True, here
        top = self._top()
        if abs(here - top) > 1e-3:
            out.arc(True, self.centre, top)
        return True, top

    def climb_only(self, here: complex, out: Sink) -> complex:
        found = self.crossings(here.imag)
        if not found:
            return here
        if not self.ccw:
            if found[-1] > self.centre.real:
                return here
            here = complex(found[-1], here.imag)
            out.feed(here)
            if abs(here - self.end) > 1e-3:
                out.arc(False, self.centre, self.end)
            return self.end
        if found[0] < self.centre.real:
            return here
        here = complex(found[0], here.imag)
        out.feed(here)
        top = self._top()
        if abs(here - top) > 1e-3:
            out.arc(True, self.centre, top)
        return top

    def dive(self, here: complex, x: float, out: Sink, fast: bool) -> tuple[bool, complex]:
        if abs(here - self.end) < TOLERANCE or (here - self.end).real <= TOLERANCE:
            return False, self.end
        found = self.crossings(x) or self.crossings(x - TOLERANCE)
        if self.ccw:
            if here.real - TOLERANCE > self.centre.real:
                return True, here
            if not found or found[-1] > self.centre.real:
                out.arc(True, self.centre, self.end)
                return False, self.end
            point = complex(found[-1], x)
            out.arc(True, self.centre, point)
            return False, point
        if here.real <= self.centre.real:
            return True, here  # already climbing
        if not found:
            out.arc(False, self.centre, self.end)
            return False, self.end
        if found[0] < self.centre.real:
            return False, here  # only the back of the arc is hit: the next pass goes lower
        point = complex(found[0], x)
        out.arc(False, self.centre, point)
        return False, point

    def intersect(self, prev: "Segment") -> None:
        if isinstance(prev, Line):  # a line followed by this arc
            if abs(self.start - prev.end) < TOLERANCE:
                return
            self.start = prev.end = _line_meets_circle(prev, self.centre, self.end, self.start)
            return
        a = abs(self.start - self.centre)
        b = abs(prev.start - prev.centre)
        c = abs(self.centre - prev.centre)
        cos_b = (c * c + a * a - b * b) / 2.0 / a / c
        rot = complex(cos_b, math.sqrt(1 - min(cos_b * cos_b, 1.0)))
        self.start = prev.end = rot * (prev.centre - self.centre) / c * a + self.centre


def _line_intersect_arc(line: Line, arc: Arc) -> None:
    """An arc followed by ``line``: move the arc's end and the line's start to where they meet."""
    if abs(line.start - arc.end) < TOLERANCE:
        return
    line.start = arc.end = _line_meets_circle(line, arc.centre, arc.end, line.start)


def _line_meets_circle(line: Line, centre: complex, on_circle: complex, near: complex) -> complex:
    """Where the line through ``line`` crosses the circle about ``centre``
    through ``on_circle``: of the two crossings, the one nearer ``near``
    (a miss gives the foot of the perpendicular from the centre)."""
    rot = (line.start - line.end).conjugate() / abs(line.start - line.end)
    pe, pc = (on_circle - line.end) * rot, (centre - line.end) * rot
    b = abs(pc - pe) ** 2 - pc.imag ** 2
    b = math.sqrt(b) if b >= 0 else 0.0
    s1, s2 = (pc.real + b) / rot + line.end, (pc.real - b) / rot + line.end
    return s1 if abs(near - s1) < abs(near - s2) else s2


class Fillet(Arc):
    """``A``: a round of radius ``finish`` at a profile corner."""

    def __init__(self, radius: float, at: complex):
        super().__init__(False, at, at, at)
        self.finish = radius

    def finish_corner(self, prev: Segment, nxt: Segment) -> None:
        self.centre = self._corner(prev, nxt)
        self.ccw = (self.start - self.centre).imag > 0 or (self.end - self.centre).imag > 0
        self.finish = 0.0


class Chamfer(Line):
    """``C``: a chamfer of width ``finish`` at a profile corner."""

    def __init__(self, width: float, at: complex):
        super().__init__(at, at)
        self.finish = width

    def finish_corner(self, prev: Segment, nxt: Segment) -> None:
        self._corner(prev, nxt)


def intersect(prev: Segment, nxt: Segment) -> None:
    """Join ``prev``'s end and ``nxt``'s start where the two curves meet."""
    if isinstance(nxt, Line) and isinstance(prev, Arc):
        _line_intersect_arc(nxt, prev)
    else:
        nxt.intersect(prev)


def _show(p: complex) -> str:
    return f"({p.real:g},{p.imag:g})"
