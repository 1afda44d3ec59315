"""Emulate stage, lathe cycles: the profile's contour, a chain of segments normalised, offset and pocketed.

The contour is the lathe profile as geometry (:mod:`gcodekit.lathe_profile`
holds the same profile as the blocks the program wrote).  :class:`Contour`
is LinuxCNC's ``g7x`` class: it mirrors and rotates the chain so it always
descends in X and Z, offsets it step by step, and cuts the roughing passes
pocket by pocket.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .segments import TOLERANCE, Arc, LatheCycleError, Segment, Sink, intersect

__all__ = ["Contour"]


@dataclass
class Contour:
    """The segments of a profile and the mirror/rotation state it is in."""

    segments: list[Segment] = field(default_factory=list)
    state: int = 0
    delta: float = 0.5
    escape: complex = 0.3 + 0.3j
    pocket_starts: list[complex] = field(default_factory=list)

    def copy(self) -> "Contour":
        return Contour([s.copy() for s in self.segments], self.state, self.delta, self.escape, [])

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
                    segs.insert(k + 1, Arc(distance > 0, p.end, (a.end + b.start) / 2, n.start))
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
                    intersect(segs[k], segs[k + 1])
                k += 1
            done += step
        for p, n in zip(segs, segs[1:]):
            p.end = n.start = (p.end + n.start) / 2
        approach.end = segs[0].start
        segs.insert(0, approach)

    # -- cutting -----------------------------------------------------------------------

    def pocket(self, cycle: int, here: complex, k: int, out: Sink) -> None:
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
                # R0: no escape (rs274's distance / 2 / 0 is inf or NaN, and std::min makes either 1)
                scale = min(1.0, distance / 2 / self.escape.real) if self.escape.real else 1.0
                out.rapid(complex(z, here.imag) + scale * self.escape)
                out.rapid(here - (scale * self.escape).conjugate())
                (out.rapid if k == 0 else out.feed)(here)
                x -= self.delta
                break
