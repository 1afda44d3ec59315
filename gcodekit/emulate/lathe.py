"""Emulate stage: LinuxCNC's lathe cycles G70 (finish) and G71/G72 (rough) as plain moves.

Behaviour mirrored: LinuxCNC 2.9 ``interp_g7x.cc`` (Debian 12 package
2.9.0~pre1, git 2023-02-08), whose output the golden cases record.

Points are complex numbers ``z + x*1j`` in program coordinates (X a
radius).  The profile is the chain of G0/G1/G2/G3 blocks of the ``Q``
subroutine (a :class:`~gcodekit.lathe_profile.LatheProfile`, read by the
preprocess stage), starting at the cycle point (the block's X/Z).  The cycle
mirrors and rotates the profile so that it always descends in X and Z
(``_Profile.normalise``), works there, and maps every move back.

* G71 cuts passes parallel to Z, G72 (the profile turned 90 degrees)
  parallel to X; ``I`` apart, leaving ``D`` to the profile.  Each pass is
  fed in, then the tool escapes by ``R`` at 45 degrees and rapids back.
  G71.1/G72.1 skip the pockets (they only follow the profile out of them),
  G71.2/G72.2 cut only the pockets.
* G70 follows the profile ``P`` times at distances going from ``D`` down
  to ``E``.
* ``A`` on a profile block rounds the corner at its end point with that
  radius, ``C`` chamfers it.

The offset profile is built by LinuxCNC's stepwise method: every segment is
moved by at most half the shortest segment's length at a time, arcs fill
the gaps at convex corners and neighbours are re-intersected.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from typing import NamedTuple

from ..lathe_profile import LatheProfile
from ..limits import MotionBudget

TOLERANCE = 1e-6  # LinuxCNC's g7x tolerance
#: rs274's ``equal`` (interp_internal.hh TOLERANCE_EQUAL): an arc to where the tool is is skipped
EQUAL = 0.0001


class LatheCycleError(ValueError):
    """A profile the cycle cannot cut; the message is rs274's."""


# -- moves --------------------------------------------------------------------------


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


class _Sink:
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


# -- segments -------------------------------------------------------------------------


class _Segment:
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

    def finish_corner(self, prev: "_Segment", nxt: "_Segment") -> None:
        """Corner pieces (A/C) fit themselves between their neighbours."""

    def _corner(self, prev: "_Segment", nxt: "_Segment") -> complex:
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
        _intersect(p, n)
        centre = (p.end + n.start) / 2
        p.offset(-self.finish)
        n.offset(-self.finish)
        self.start = prev.end = p.end
        self.end = nxt.start = n.start
        return centre


class _Line(_Segment):
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

    def draw(self, out: _Sink) -> None:
        out.feed(self.end)

    def climb(self, here: complex, out: _Sink) -> tuple[bool, complex]:
        if self.end.imag + TOLERANCE < self.start.imag:
            return True, here
        if abs(here - self.start) > TOLERANCE:
            raise LatheCycleError("How did we get here?")
        out.feed(self.end)
        return False, self.end

    def climb_only(self, here: complex, out: _Sink) -> complex:
        if self.end.imag < self.start.imag:
            return here
        found = self.crossings(here.imag)
        if not found:
            return here
        here = complex(found[0], here.imag)
        out.feed(here)
        out.feed(self.end)
        return self.end

    def dive(self, here: complex, x: float, out: _Sink, fast: bool) -> tuple[bool, complex]:
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

    def intersect(self, prev: "_Line") -> None:
        """A line after line ``prev``: move ``prev``'s end and this start to where they cross."""
        rot = (self.start - self.end).conjugate() / abs(self.start - self.end)
        ps, pe = (prev.start - self.end) * rot, (prev.end - self.end) * rot
        if (ps - pe).imag == 0:
            raise LatheCycleError("Cannot intersect parallel lines")
        f = ps.imag / (ps - pe).imag
        self.start = prev.end = (ps + f * (pe - ps)) / rot + self.end


class _Arc(_Segment):
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

    def draw(self, out: _Sink) -> None:
        out.arc(self.ccw, self.centre, self.end)

    def _top(self) -> complex:
        """Where a G3 climb stops: its end, or the top of the circle if it goes past it."""
        if self.end.real < self.centre.real:
            return complex(self.centre.real, self.centre.imag + abs(self.start - self.centre))
        return self.end

    def climb(self, here: complex, out: _Sink) -> tuple[bool, complex]:
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

    def climb_only(self, here: complex, out: _Sink) -> complex:
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

    def dive(self, here: complex, x: float, out: _Sink, fast: bool) -> tuple[bool, complex]:
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

    def intersect(self, prev: "_Segment") -> None:
        if isinstance(prev, _Line):  # a line followed by this arc
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


def _line_intersect_arc(line: _Line, arc: _Arc) -> None:
    """An arc followed by ``line``: move the arc's end and the line's start to where they meet."""
    if abs(line.start - arc.end) < TOLERANCE:
        return
    line.start = arc.end = _line_meets_circle(line, arc.centre, arc.end, line.start)


def _line_meets_circle(line: _Line, centre: complex, on_circle: complex, near: complex) -> complex:
    """Where the line through ``line`` crosses the circle about ``centre``
    through ``on_circle``: of the two crossings, the one nearer ``near``
    (a miss gives the foot of the perpendicular from the centre)."""
    rot = (line.start - line.end).conjugate() / abs(line.start - line.end)
    pe, pc = (on_circle - line.end) * rot, (centre - line.end) * rot
    b = abs(pc - pe) ** 2 - pc.imag ** 2
    b = math.sqrt(b) if b >= 0 else 0.0
    s1, s2 = (pc.real + b) / rot + line.end, (pc.real - b) / rot + line.end
    return s1 if abs(near - s1) < abs(near - s2) else s2


class _Fillet(_Arc):
    """``A``: a round of radius ``finish`` at a profile corner."""

    def __init__(self, radius: float, at: complex):
        super().__init__(False, at, at, at)
        self.finish = radius

    def finish_corner(self, prev: _Segment, nxt: _Segment) -> None:
        self.centre = self._corner(prev, nxt)
        self.ccw = (self.start - self.centre).imag > 0 or (self.end - self.centre).imag > 0
        self.finish = 0.0


class _Chamfer(_Line):
    """``C``: a chamfer of width ``finish`` at a profile corner."""

    def __init__(self, width: float, at: complex):
        super().__init__(at, at)
        self.finish = width

    def finish_corner(self, prev: _Segment, nxt: _Segment) -> None:
        self._corner(prev, nxt)


def _intersect(prev: _Segment, nxt: _Segment) -> None:
    """Join ``prev``'s end and ``nxt``'s start where the two curves meet."""
    if isinstance(nxt, _Line) and isinstance(prev, _Arc):
        _line_intersect_arc(nxt, prev)
    else:
        nxt.intersect(prev)


def _show(p: complex) -> str:
    return f"({p.real:g},{p.imag:g})"


# -- the profile ------------------------------------------------------------------------


@dataclass
class _Profile:
    """The segments of a profile and the mirror/rotation state it is in."""

    segments: list[_Segment] = field(default_factory=list)
    state: int = 0
    delta: float = 0.5
    escape: complex = 0.3 + 0.3j
    pocket_starts: list[complex] = field(default_factory=list)

    def copy(self) -> "_Profile":
        return _Profile([s.copy() for s in self.segments], self.state, self.delta, self.escape, [])

    def turn(self) -> None:
        for s in self.segments:
            s.turn()
        self.state ^= 4

    def normalise(self) -> None:
        """Mirror so that X and Z decrease from the first segment's end to the last one's."""
        d = self.segments[0].end - self.segments[-1].end
        if d.imag > 0:
            for s in self.segments:
                s.flip_x()
            self.state ^= 2
        if d.real < 0:
            for s in self.segments:
                s.flip_z()
            self.state ^= 1

    def check_monotonic(self) -> None:
        first = self.segments[0]
        if (first.end - first.start).real > 0:
            first.start = complex(first.end.real, first.start.imag)
        if not all(s.monotonic() for s in self.segments):
            raise LatheCycleError("Not monotonic")

    def finish_corners(self) -> None:
        segs = self.segments
        for k in range(1, len(segs) - 1):
            segs[k].finish_corner(segs[k - 1], segs[k + 1])
        self.segments = [s for s in segs if s.length() >= 1e-3]

    def add_distance(self, distance: float) -> None:
        """Offset all but the first (approach) segment by ``distance`` away from the part."""
        segs = self.segments
        v1 = segs[0].end - segs[0].start
        v2 = segs[-1].start - segs[0].start
        if (v1 / v2).imag < 0:
            distance = -distance
        approach = segs.pop(0)
        done = 0.0
        while done != distance:
            step = min([s.length() / 2 for s in segs] + [1e9, abs(distance - done)])
            if distance < 0:
                step = -step
            kept = []
            for s in segs:
                s.offset(step)
                if s.length() >= 1e-3:
                    kept.append(s)
            segs[:] = kept
            k = 0
            while k < len(segs) - 1:
                p, n = segs[k], segs[k + 1]
                if (p.end - n.start).real > 1e-2:  # a gap at a convex corner: bridge it with an arc
                    a, b = p.copy(), n.copy()
                    a.offset(-step)
                    b.offset(-step)
                    segs.insert(k + 1, _Arc(distance > 0, p.end, (a.end + b.start) / 2, n.start))
                    k += 1
                k += 1
            k = 0
            while k < len(segs) - 1:
                if not segs[k].monotonic():
                    # rs274 drops the shorter of this piece and the one before (list wraps at the start)
                    before = segs[k - 1]
                    del segs[k if segs[k].length() < before.length() else k - 1]
                    k = 0
                if segs[k].length() < 1e-3:
                    del segs[k]
                    k = 0
                else:
                    _intersect(segs[k], segs[k + 1])
                k += 1
            done += step
        for p, n in zip(segs, segs[1:]):
            p.end = n.start = (p.end + n.start) / 2
        approach.end = segs[0].start
        segs.insert(0, approach)

    # -- cutting -----------------------------------------------------------------------

    def pocket(self, cycle: int, here: complex, k: int, out: _Sink) -> None:
        """Rough from segment ``k`` on (LinuxCNC ``g7x::pocket``)."""
        segs = self.segments
        x = self.pocket_starts[-1].imag
        if cycle == 2:  # skip the first roughing pass
            while k < len(segs):
                stop, here = segs[k].dive(here, -1e9, out, k == 0)
                if stop:
                    break
                k += 1
            cycle = 3
        seen: set[tuple] = set()
        while k < len(segs):
            while x - TOLERANCE > here.imag:
                x -= self.delta
            state = (k, round(x, 9), round(here.real, 9), round(here.imag, 9))
            if state in seen:  # no pass makes progress: rs274 2.9 cuts the same spot forever
                raise LatheCycleError("G7x error: the roughing passes stop making progress "
                                      "(LinuxCNC 2.9 loops forever on this profile)")
            seen.add(state)
            stop, here = segs[k].dive(here, x, out, k == 0)
            if stop:
                if cycle == 1:
                    while k < len(segs):
                        here = segs[k].climb_only(here, out)
                        k += 1
                    return
                while k < len(segs):
                    up, here = segs[k].climb(here, out)
                    if up:
                        if cycle == 3:
                            if here.imag > self.pocket_starts[-1].imag and len(self.pocket_starts) > 1:
                                self.pocket_starts.pop()
                            if len(self.pocket_starts) == 1:
                                self.pocket_starts.append(here)
                        self.pocket(cycle, here, k, out)
                        return
                    k += 1
                return
            if abs(here.imag - x) > TOLERANCE:
                k += 1  # the pass height is beyond this segment
                continue
            for j in range(k, len(segs)):
                found = segs[j].crossings(here.imag)
                if not found:
                    continue
                z = found[0] if j != k else found[-1]
                distance = abs(z - here.real)
                if z - TOLERANCE > here.real:
                    continue  # only the diving segment's own start
                if distance < TOLERANCE:
                    if j == k:
                        continue
                    if abs(here - segs[j].start) < TOLERANCE:
                        k = j
                        break
                    x -= self.delta  # a zero-length piece: this pass is done
                    break
                out.feed(complex(z, here.imag))
                scale = min(1.0, distance / 2 / self.escape.real)
                out.rapid(complex(z, here.imag) + scale * self.escape)
                out.rapid(here - (scale * self.escape).conjugate())
                (out.rapid if k == 0 else out.feed)(here)
                x -= self.delta
                break


# -- the cycles ---------------------------------------------------------------------------


def build_profile(start: complex, blocks: list[dict]) -> list[_Segment]:
    """Segments of the profile blocks (dicts of "motion", "end", "centre", "A", "C")."""
    out: list[_Segment] = []
    here = start
    for b in blocks:
        end = b["end"]
        if end != here:
            if b["motion"] in (0, 1):
                out.append(_Line(here, end))
            elif b["motion"] in (2, 3):
                out.append(_Arc(b["motion"] == 3, here, b["centre"], end))
            if b["motion"] in (0, 1, 2, 3):
                if "A" in b:
                    out.append(_Fillet(b["A"], end))
                if "C" in b:
                    out.append(_Chamfer(b["C"], end))
            here = end
    return out


def finish(segments: list[_Segment], point: complex, d: float, e: float, passes: float, *,
           budget: MotionBudget | None = None) -> list[Move]:
    """G70: ``passes`` finishing passes from distance ``d`` down to ``e``."""
    base = _Profile([s.copy() for s in segments])
    base.segments[0].start = point
    probe = base.copy()
    probe.segments.pop(0)
    probe.normalise()
    if not all(s.monotonic() for s in probe.segments):
        probe.turn()
        probe.normalise()
    probe.check_monotonic()
    if probe.state & 4:
        base.turn()
    base.normalise()
    base.finish_corners()
    base.check_monotonic()
    moves: list[Move] = []
    out = _Sink(moves, base.state)
    count = int(passes)
    if budget is not None:
        budget.check(count * (len(base.segments) + 2))
    for k in range(count, 0, -1):
        path = base.copy()
        path.add_distance((k - 1) * (d - e) / passes + e)
        out.rapid(path.segments[0].start)
        out.rapid(path.segments[0].end)
        for s in path.segments[1:]:
            s.draw(out)
    return moves


def rough(segments: list[_Segment], point: complex, *, turn: bool, subcycle: int, d: float, i: float,
          r: float, u: float = 0.0, w: float = 0.0, budget: MotionBudget | None = None) -> list[Move]:
    """G71 (``turn`` False) or G72 (True): roughing passes ``i`` apart leaving ``d``.

    ``budget``, when given, must have room for the most moves the passes can
    make: each pass crosses every segment at most once.
    """
    p = _Profile([s.copy() for s in segments])
    p.segments[0].start = point
    if turn:
        p.turn()
    p.normalise()
    p.finish_corners()
    p.check_monotonic()
    p.add_distance(d)
    for s in p.segments:
        s.shift(complex(w, u))
    moves: list[Move] = []
    out = _Sink(moves, p.state)
    p.delta = max(i, 2 * TOLERANCE)
    if budget is not None:
        heights = [v for seg in p.segments for v in (seg.start.imag, seg.end.imag)]
        budget.check(((max(heights) - min(heights)) / p.delta + 2) * (len(p.segments) + 4))
    p.escape = r * (1 + 1j)
    first, last = p.segments[0], p.segments[-1]
    out.rapid(first.start)
    if last.end.imag < first.start.imag:
        p.segments.append(_Line(last.end, complex(last.end.real, first.start.imag)))
    p.pocket_starts.append(first.start)
    p.pocket(subcycle, first.start, 0, out)
    return moves


# -- a cycle block ----------------------------------------------------------------------------

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
