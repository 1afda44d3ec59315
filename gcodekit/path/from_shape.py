"""Front end (FreeCAD Path API): a path from a polyline or a shapely geometry.

FreeCAD's ``Path.fromShape(wire)`` follows a wire: a rapid to its first
point, then a feed move to each next point.  :func:`from_shape` does that
for a list of points or any shapely geometry (lines, rings, polygons with
holes, collections), and, beyond FreeCAD, cuts contours: offset by a
distance (shapely's ``buffer``/``offset_curve``, positive outside), at one
or more depths with a safe height between passes and separate feeds for
plunging and cutting.

Unlike FreeCAD 0.20 it writes every coordinate that changes: FreeCAD
writes only the non-zero ones, so its path back to a point with ``X0``
stays where it is.

Examples
--------
>>> p = from_shape([(0, 0, 0), (0, 2, 0), (2, 2, 0), (3, 3, 0)])
>>> print(p.toGCode(), end="")
G0 X0.000000 Y0.000000 Z0.000000
G1 Y2.000000
G1 X2.000000
G1 X3.000000 Y3.000000
>>> from shapely.geometry import box
>>> p = from_shape(box(0, 0, 10, 5), safe_height=5, final_depth=-2, step_down=1, feed=300)
>>> [c.toGCode() for c in p.Commands][:6]
['G0 Z5.000000', 'G0 X10.000000 Y0.000000', 'G1 F300.000000 Z-1.000000', 'G1 Y5.000000', 'G1 X0.000000', 'G1 Y0.000000']
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Sequence

import numpy as np

from ..errors import ConfigError, MissingDependencyError
from .command import Command
from .toolpath import Path

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

__all__ = ["from_shape", "fromShape"]


def _lines(shape, offset: float) -> list[np.ndarray]:
    """The polylines (``(n, 2 or 3)`` arrays) to follow, after the offset."""
    if isinstance(shape, (list, tuple, np.ndarray)):
        pts = np.asarray(shape, dtype=float)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3) or len(pts) < 2:
            raise ConfigError("a polyline is a list of at least two (x, y) or (x, y, z) points")
        if offset:
            return _lines(_shapely().LineString(pts), offset)
        return [pts]
    shapely = _shapely()
    if not isinstance(shape, shapely.geometry.base.BaseGeometry):
        raise TypeError(f"from_shape takes points or a shapely geometry, not {type(shape).__name__}")
    if shape.is_empty:
        return []
    kind = shape.geom_type
    if kind in ("LineString", "LinearRing"):
        if offset and kind == "LineString" and not shape.is_closed:
            shape = shape.offset_curve(offset)
            return _lines(shape, 0.0) if not shape.is_empty else []
        if offset:
            return _lines(shapely.Polygon(shape).buffer(offset), 0.0)
        return [np.asarray(shape.coords)]
    if kind == "Polygon":
        if offset:
            return _lines(shape.buffer(offset), 0.0)
        shape = shapely.geometry.polygon.orient(shape, 1.0)  # outside anticlockwise, holes clockwise
        return [np.asarray(r.coords) for r in (shape.exterior, *shape.interiors)]
    if hasattr(shape, "geoms"):
        return [line for part in shape.geoms for line in _lines(part, offset)]
    raise ConfigError(f"cannot follow a {kind}")


def _shapely():
    try:
        import shapely
        import shapely.geometry.polygon  # noqa: F401
    except ImportError as exc:  # pragma: no cover - shapely is a core dependency
        raise MissingDependencyError("from_shape needs shapely: pip install shapely") from exc
    return shapely


def _depths(start: float, final: float, step: float | None) -> list[float]:
    if step is None or step <= 0 or final >= start:
        return [final]
    n = max(1, math.ceil((start - final) / step - 1e-9))
    return [max(final, start - step * k) for k in range(1, n + 1)]


def _move(name: str, old: Sequence[float], new: Sequence[float], feed: float | None) -> Command | None:
    params = {a: float(v) for a, v, o in zip("XYZ", new, old) if v is not None and (o is None or v != o)}
    if not params:
        return None
    if feed is not None:
        params["F"] = float(feed)
    return Command(name, params)


def from_shape(shape: "Sequence | BaseGeometry", *, feed: float | None = None, vertical_feed: float | None = None,
               safe_height: float | None = None, start_depth: float = 0.0, final_depth: float | None = None,
               step_down: float | None = None, offset: float = 0.0) -> Path:
    """A path that follows a polyline or a shapely geometry.

    Parameters
    ----------
    shape : sequence of points or shapely geometry
        ``[(x, y), ...]`` or ``[(x, y, z), ...]``; or a LineString,
        LinearRing, Polygon (its outside and holes) or a collection.
    feed : float, optional
        Cutting feed, mm/min, written on the first cutting move of each pass.
    vertical_feed : float, default: ``feed``
        Plunging feed, mm/min.
    safe_height : float, optional
        Height for rapid moves between contours and passes, mm.
    start_depth : float, default: 0
        Top of the cut, mm; the first pass goes one ``step_down`` below.
    final_depth : float, optional
        Bottom of the cut, mm.  Without it the shape is followed at its own
        Z (0 for 2-D shapes), as FreeCAD's ``fromShape`` does.
    step_down : float, optional
        Depth of each pass, mm; the last pass is at ``final_depth``.
    offset : float, default: 0
        Distance to move the contour sideways, mm: positive outside a
        polygon (or left of a line), negative inside (e.g. the tool radius).

    Raises
    ------
    ConfigError
        Points that are not a polyline, or a geometry that cannot be followed.
    """
    lines = _lines(shape, float(offset))
    commands: list[Command] = []
    pos: list[float | None] = [None, None, None]
    if final_depth is None:  # FreeCAD's fromShape: follow the shape as it is
        for line in lines:
            pts = np.column_stack([line[:, :2], line[:, 2] if line.shape[1] == 3 else np.zeros(len(line))])
            first = _move("G0", pos, pts[0], None)
            commands += [first] if first else []
            pos = list(pts[0])
            for k, p in enumerate(pts[1:]):
                c = _move("G1", pos, p, feed if k == 0 else None)
                if c is not None:
                    commands.append(c)
                pos = list(p)
        return Path(commands)
    plunge = vertical_feed if vertical_feed is not None else feed
    for line in lines:
        xy = line[:, :2]
        for depth in _depths(float(start_depth), float(final_depth), step_down):
            if safe_height is not None:
                c = _move("G0", pos, [pos[0], pos[1], safe_height], None)
                commands += [c] if c else []
                pos[2] = safe_height
            c = _move("G0", pos, [xy[0, 0], xy[0, 1], pos[2]], None)
            commands += [c] if c else []
            pos[:2] = list(xy[0])
            commands.append(Command("G1", {"Z": depth, **({"F": float(plunge)} if plunge is not None else {})}))
            pos[2] = depth
            for k, p in enumerate(xy[1:]):
                c = _move("G1", pos, [p[0], p[1], depth], feed if k == 0 and feed != plunge else None)
                if c is not None:
                    commands.append(c)
                pos[:2] = list(p)
    if safe_height is not None and commands:
        commands.append(Command("G0", {"Z": float(safe_height)}))
    return Path(commands)


#: FreeCAD's name
fromShape = from_shape  # noqa: N816
