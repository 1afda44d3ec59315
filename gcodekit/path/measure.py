"""Front end (FreeCAD Path API): a path's length and extents, right, and as FreeCAD 0.20 computes them.

:func:`walk` follows the commands the way a controller does: omitted axes
keep their value, G91 makes X/Y/Z relative, arcs are centred at the start
plus I/J/K (G90.1: at I/J/K) in the plane of G17/G18/G19 (an R-form arc's centre found from its radius), drilling cycles
G81-G89 go down to Z and back to R (G99, LinuxCNC's start) or to the height
they started from (G98).  :func:`length` and :func:`bound_box` are
measured on it exactly: an arc's length is its radius times its swept angle
(a full circle is 2 pi r, a helix adds its rise), its box reaches the
circle's extreme points.

FreeCAD 0.20 answers differently, and :func:`freecad_length` and
:func:`freecad_bound_box` reproduce its answers so that tests can show the
difference is understood:

* ``Path.Length`` takes I/J/K as the arc's centre in absolute coordinates
  and the smaller angle between start and end, so a full circle measures 0,
  an arc over 180 degrees is short and most arcs not centred near the origin
  are wrong; it ignores G91 and drilling cycles.
* ``Path.BoundBox`` samples each arc at ``max(20, 15 * angle)`` points
  (angle in radians, from the ``MeshDeviation`` preference of 0.2), so a
  circle's box falls short of the circle by up to ``r (1 - cos(pi/n))``.

Examples
--------
>>> cmds = [("G0", {"X": 1.0, "Y": 1.0}), ("G2", {"X": 1.0, "Y": 1.0, "I": 1.0, "J": 0.0})]
>>> round(length(cmds), 6), round(freecad_length(cmds), 6)
(7.697399, 1.414214)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from .geometry import BoundBox

__all__ = ["Segment", "walk", "length", "bound_box", "freecad_length", "freecad_bound_box"]

_RAPID = ("G0", "G00")
_FEED = ("G1", "G01")
_CW = ("G2", "G02")
_CCW = ("G3", "G03")
_DRILL = ("G81", "G82", "G83", "G84", "G85", "G86", "G89")
_PROBE = ("G38.2", "G38.3", "G38.4", "G38.5")
#: plane -> (first axis, second axis, normal axis) indices into (x, y, z)
_PLANES = {"G17": (0, 1, 2), "G18": (2, 0, 1), "G19": (1, 2, 0)}

Commands = Iterable[tuple[str, dict[str, float]]]


@dataclass
class Segment:
    """One motion of a path: its kind, start and end points (mm) and, for arcs, centre and sweep."""

    kind: str  # "rapid", "feed", "arc_cw", "arc_ccw", "drill", "probe"
    index: int  # the command's position in the path
    start: np.ndarray
    end: np.ndarray
    center: np.ndarray | None = None
    sweep: float = 0.0  # radians, positive
    plane: tuple[int, int, int] = (0, 1, 2)
    points: list = field(default_factory=list)  # extra corners of a drilling cycle

    @property
    def length(self) -> float:
        if self.kind.startswith("arc"):
            a, b, n = self.plane
            r = math.hypot(self.start[a] - self.center[a], self.start[b] - self.center[b])
            return math.hypot(r * self.sweep, self.end[n] - self.start[n])
        pts = [self.start, *self.points, self.end]
        return float(sum(np.linalg.norm(q - p) for p, q in zip(pts, pts[1:])))

    def extreme_points(self) -> np.ndarray:
        """The points whose box is the segment's box: ends, drilling corners, an arc's quadrant points.

        An arc turns at its start's radius; an end off that circle (a radius
        LinuxCNC refuses, which printers and GRBL reach by a last straight
        step) adds where the arc itself ends.
        """
        pts = [self.start, *self.points, self.end]
        if self.kind.startswith("arc"):
            a, b, n = self.plane
            r = math.hypot(self.start[a] - self.center[a], self.start[b] - self.center[b])
            t0 = math.atan2(self.start[b] - self.center[b], self.start[a] - self.center[a])
            sign = -1.0 if self.kind == "arc_cw" else 1.0
            arc_end = np.array(self.end, dtype=float)
            arc_end[a] = self.center[a] + r * math.cos(t0 + sign * self.sweep)
            arc_end[b] = self.center[b] + r * math.sin(t0 + sign * self.sweep)
            pts.append(arc_end)
            for q in range(-8, 9):  # axis directions crossed within the sweep
                t = q * math.pi / 2
                d = (t - t0) * sign % (2 * math.pi)
                if 0 < d < self.sweep:
                    p = np.array(self.start, dtype=float)
                    p[a] = self.center[a] + r * math.cos(t)
                    p[b] = self.center[b] + r * math.sin(t)
                    p[n] = self.start[n] + (self.end[n] - self.start[n]) * d / self.sweep
                    pts.append(p)
        return np.array(pts)


def walk(commands: Commands) -> list[Segment]:
    """The motions of FreeCAD path commands, as a controller reads them (see the module)."""
    pos = np.zeros(3)
    # LinuxCNC starts in G99 (retract to R), as rs274 does
    absolute, center_absolute, plane, retract_initial = True, False, _PLANES["G17"], False
    out: list[Segment] = []
    for i, (name, p) in enumerate(commands):
        if name in _PLANES:
            plane = _PLANES[name]
            continue
        if name in ("G90", "G91", "G90.1", "G91.1", "G98", "G99"):
            absolute = name != "G91" if name in ("G90", "G91") else absolute
            center_absolute = name == "G90.1" if name in ("G90.1", "G91.1") else center_absolute
            retract_initial = name == "G98" if name in ("G98", "G99") else retract_initial
            continue
        moves = name in _RAPID + _FEED + _CW + _CCW + _DRILL + _PROBE
        if not moves:
            continue
        end = pos.copy()
        for k, axis in enumerate("XYZ"):
            if axis in p:
                end[k] = p[axis] if absolute else pos[k] + p[axis]
        if name in _CW + _CCW:
            a, b, _ = plane
            if "R" in p and not any(k in p for k in "IJK"):
                center = _r_centre(pos, end, p["R"], plane, name in _CW)
            else:
                offset = np.array([p.get("I", 0.0), p.get("J", 0.0), p.get("K", 0.0)])
                center = offset if center_absolute else pos + offset
            t0 = math.atan2(pos[b] - center[b], pos[a] - center[a])
            t1 = math.atan2(end[b] - center[b], end[a] - center[a])
            sign = -1.0 if name in _CW else 1.0
            sweep = (t1 - t0) * sign % (2 * math.pi)
            if sweep <= 1e-12 * (1 + abs(t0)):
                sweep = 2 * math.pi  # the end is the start: a whole circle
            kind = "arc_cw" if name in _CW else "arc_ccw"
            out.append(Segment(kind, i, pos, end, center, sweep, plane))
        elif name in _DRILL:
            n = plane[2]
            r = p.get("R", pos[n])
            above = pos.copy()
            above[[plane[0], plane[1]]] = end[[plane[0], plane[1]]]
            at_r = above.copy()
            at_r[n] = r
            bottom = at_r.copy()
            bottom[n] = end[n]
            back = at_r.copy()
            back[n] = max(pos[n], r) if retract_initial else r
            out.append(Segment("drill", i, pos, back, points=[above, at_r, bottom]))
            end = back
        else:
            out.append(Segment("rapid" if name in _RAPID else "feed" if name in _FEED else "probe", i, pos, end))
        pos = end
    return out


def _r_centre(start: np.ndarray, end: np.ndarray, radius: float, plane: tuple[int, int, int],
              clockwise: bool) -> np.ndarray:
    """An R-form arc's centre (RS274NGC): R > 0 the shorter way round, R < 0 the longer.

    A radius too short for the chord is taken as half the chord (a half
    circle), the nearest arc there is.
    """
    a, b, _ = plane
    dx, dy = end[a] - start[a], end[b] - start[b]
    chord = math.hypot(dx, dy)
    center = start.copy()
    if chord == 0:
        return center
    r = max(abs(radius), chord / 2)
    h = math.sqrt(max(r * r - chord * chord / 4, 0.0))
    # the centre lies right of the chord (seen from start to end) for a short clockwise arc
    side = -1.0 if clockwise == (radius > 0) else 1.0
    center[a] = start[a] + dx / 2 - side * h * dy / chord
    center[b] = start[b] + dy / 2 + side * h * dx / chord
    return center


def length(commands: Commands) -> float:
    """The path's length in mm: every motion measured exactly (see the module)."""
    return float(sum(s.length for s in walk(commands)))


def bound_box(commands: Commands) -> BoundBox:
    """The box around every point the tool passes, mm (exact for arcs)."""
    segments = walk(commands)
    if not segments:
        return BoundBox()
    return BoundBox.of_points(np.vstack([s.extreme_points() for s in segments]))


# -- FreeCAD 0.20's answers -------------------------------------------------------------

def _dot(u: Sequence[float], v: Sequence[float]) -> float:
    """``u * v`` as FreeCAD's ``Vector3d`` computes it: three products summed left to right in plain doubles.

    Not NumPy's dot, whose BLAS kernel (fused multiply-adds on some CPUs)
    rounds the last bit differently from machine to machine: near a straight
    angle ``acos`` magnifies that bit to a millionth of a millimetre.
    """
    return float(u[0]) * float(v[0]) + float(u[1]) * float(v[1]) + float(u[2]) * float(v[2])


def _length(u: Sequence[float]) -> float:
    """``Vector3d::Length``: the square root of the sum of the squares, in that order."""
    return math.sqrt(_dot(u, u))


def _freecad_angle(u: np.ndarray, v: np.ndarray) -> float:
    """FreeCAD's ``Vector3d::GetAngle``: the smaller angle, NaN for a zero vector."""
    norm = _length(u) * _length(v)
    if norm <= np.finfo(float).eps:
        return math.nan
    return math.acos(max(-1.0, min(1.0, _dot(u, v) / norm)))


def freecad_length(commands: Sequence[tuple[str, dict[str, float]]]) -> float:
    """``Path.Length`` as FreeCAD 0.20 computes it (wrong for arcs, G91 and cycles: see the module)."""
    total = 0.0
    last = np.zeros(3)
    for name, p in commands:
        if name not in _RAPID + _FEED + _CW + _CCW:
            continue
        nxt = np.array([p.get(a, last[k]) for k, a in enumerate("XYZ")])
        if name in _RAPID + _FEED:
            total += _length(nxt - last)
        else:
            center = np.array([p.get("I", 0.0), p.get("J", 0.0), p.get("K", 0.0)])
            total += _freecad_angle(nxt - center, last - center) * _length(last - center)
        last = nxt
    return total


#: FreeCAD's ``MeshDeviation`` preference (a C float) that sets how finely arcs are sampled
_DEVIATION = float(np.float32(0.2))


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                     [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                     [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]])


def freecad_bound_box(commands: Sequence[tuple[str, dict[str, float]]]) -> BoundBox:
    """``Path.BoundBox`` as FreeCAD 0.20 computes it with its default preferences.

    Arcs are sampled (see the module); rotary axes A/B/C are ignored here
    (FreeCAD turns the points about the path's centre).
    """
    last = np.zeros(3)
    absolute, center_absolute, pz = True, False, 2
    pts: list[np.ndarray] = []
    for name, p in commands:
        nxt = np.array([p.get(a, 0.0) for a in "XYZ"])
        if not absolute:
            nxt = last + nxt
        for k, a in enumerate("XYZ"):
            if a not in p:
                nxt[k] = last[k]
        if name in _RAPID + _FEED:
            pts += [last, nxt]
            last = nxt
        elif name in _CW + _CCW:
            offset = np.array([p.get("I", 0.0), p.get("J", 0.0), p.get("K", 0.0)])
            center = offset if center_absolute else last + offset
            next0, last0, center0 = nxt.copy(), last.copy(), center.copy()
            next0[pz] = last0[pz] = center0[pz] = 0.0
            angle = _freecad_angle(next0 - center0, last0 - center0)
            turn = np.cross(last0 - center0, next0 - center0)[pz]
            if turn < 0 and name in _CCW or turn > 0 and name in _CW:
                angle = 2 * math.pi - angle
            elif turn == 0 and angle == 0:
                angle = 2 * math.pi
            segments = 20.0 if not 20.0 < 3.0 / (_DEVIATION / angle) else 3.0 / (_DEVIATION / angle)
            segments = int(segments)
            normal = np.zeros(3)
            normal[pz] = -1.0 if name in _CW else 1.0
            dz = (nxt[pz] - last[pz]) / segments
            for j in range(1, segments):
                inter = _axis_rotation(normal, angle / segments * j) @ (last0 - center0)
                inter[pz] = last[pz] + dz * j
                pts.append(center0 + inter)
            pts += [last, nxt]
            last = nxt
        elif name in _DRILL:
            r = p.get("R", 0.0)
            top = nxt.copy()
            top[pz] = last[pz]
            at_r = nxt.copy()
            at_r[pz] = r
            pts += [last, nxt, top, at_r]
            q = p.get("Q", 0.0)
            if q > 0:
                step = at_r.copy()
                while step[pz] > nxt[pz]:
                    pts.append(step.copy())
                    step[pz] -= q
            last = top
        elif name in _PROBE:
            pts += [last, nxt]
            last = nxt
        elif name in ("G90", "G91"):
            absolute = name == "G90"
        elif name in ("G90.1", "G91.1"):
            center_absolute = name == "G90.1"
        elif name in _PLANES:
            pz = _PLANES[name][2]
    return BoundBox.of_points(np.array(pts)) if pts else BoundBox()
