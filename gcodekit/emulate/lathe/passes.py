"""Emulate stage, lathe cycles: the profile built from its blocks, and the finishing and roughing passes."""

from __future__ import annotations

from ...limits import MotionBudget
from .contour import Contour
from .segments import TOLERANCE, Arc, Chamfer, Fillet, Line, Move, Segment, Sink

__all__ = ["build_profile", "finish", "rough"]


def build_profile(start: complex, blocks: list[dict]) -> list[Segment]:
    """Segments of the profile blocks (dicts of "motion", "end", "centre", "A", "C")."""
    out: list[Segment] = []
    here = start
    for b in blocks:
        end = b["end"]
        if end != here:
            if b["motion"] in (0, 1):
                out.append(Line(here, end))
            elif b["motion"] in (2, 3):
                out.append(Arc(b["motion"] == 3, here, b["centre"], end))
            if b["motion"] in (0, 1, 2, 3):
                if "A" in b:
                    out.append(Fillet(b["A"], end))
                if "C" in b:
                    out.append(Chamfer(b["C"], end))
            here = end
    return out


def finish(segments: list[Segment], point: complex, d: float, e: float, passes: float, *,
           budget: MotionBudget | None = None) -> list[Move]:
    """G70: ``passes`` finishing passes from distance ``d`` down to ``e``."""
    base = Contour([s.copy() for s in segments])
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
    out = Sink(moves, base.state)
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


def rough(segments: list[Segment], point: complex, *, turn: bool, subcycle: int, d: float, i: float,
          r: float, u: float = 0.0, w: float = 0.0, budget: MotionBudget | None = None) -> list[Move]:
    """G71 (``turn`` False) or G72 (True): roughing passes ``i`` apart leaving ``d``.

    ``budget``, when given, must have room for the most moves the passes can
    make: each pass crosses every segment at most once.
    """
    p = Contour([s.copy() for s in segments])
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
    out = Sink(moves, p.state)
    p.delta = max(i, 2 * TOLERANCE)
    if budget is not None:
        heights = [v for seg in p.segments for v in (seg.start.imag, seg.end.imag)]
        budget.check(((max(heights) - min(heights)) / p.delta + 2) * (len(p.segments) + 4))
    p.escape = r * (1 + 1j)
    first, last = p.segments[0], p.segments[-1]
    out.rapid(first.start)
    if last.end.imag < first.start.imag:
        p.segments.append(Line(last.end, complex(last.end.real, first.start.imag)))
    p.pocket_starts.append(first.start)
    p.pocket(subcycle, first.start, 0, out)
    return moves
