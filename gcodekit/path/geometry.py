"""Front end (FreeCAD Path API): the small geometry FreeCAD scripts pass around.

``Vector``, ``Rotation`` (yaw-pitch-roll, degrees), ``Placement`` and
``BoundBox`` with FreeCAD's names, so that a script written against
``FreeCAD.Vector`` and ``FreeCAD.Placement`` runs unchanged on gcodekit.
Only what the Path API needs is here: positions, rotations about the
origin, composition and the box's extents.

Examples
--------
>>> p = Placement(Vector(3, 2, 1), Rotation())
>>> p
Placement [Pos=(3,2,1), Yaw-Pitch-Roll=(0,0,0)]
>>> p.Base.x
3.0
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

__all__ = ["Vector", "Rotation", "Placement", "BoundBox"]

_BIG = sys.float_info.max  # FreeCAD's empty box (DBL_MAX), kept so its answers compare equal


def _g(value: float) -> str:
    """A number as FreeCAD's reprs print it: up to 6 significant digits, no trailing zeros."""
    return f"{value:.6g}" if value != 0 else "0"


class Vector:
    """A point or direction in mm: ``x``, ``y``, ``z`` (``FreeCAD.Vector``)."""

    __slots__ = ("x", "y", "z")

    def __init__(self, x: float = 0.0, y: float = 0.0, z: float = 0.0):
        self.x, self.y, self.z = float(x), float(y), float(z)

    def __iter__(self):
        return iter((self.x, self.y, self.z))

    def __add__(self, other: "Vector") -> "Vector":
        return Vector(self.x + other.x, self.y + other.y, self.z + other.z)

    def __sub__(self, other: "Vector") -> "Vector":
        return Vector(self.x - other.x, self.y - other.y, self.z - other.z)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Vector) and tuple(self) == tuple(other)

    @property
    def Length(self) -> float:  # noqa: N802 (FreeCAD's name)
        return math.sqrt(self.x * self.x + self.y * self.y + self.z * self.z)

    def __repr__(self) -> str:
        return f"Vector ({self.x!r}, {self.y!r}, {self.z!r})"


class Rotation:
    """A rotation given by yaw (about Z), pitch (about Y) and roll (about X), degrees.

    The matrix is ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``, FreeCAD's
    ``Rotation.setYawPitchRoll`` convention.
    """

    __slots__ = ("matrix",)

    def __init__(self, yaw: float = 0.0, pitch: float = 0.0, roll: float = 0.0):
        y, p, r = (math.radians(float(v)) for v in (yaw, pitch, roll))
        rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
        ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
        rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
        self.matrix = rz @ ry @ rx

    @classmethod
    def _of(cls, matrix: np.ndarray) -> "Rotation":
        rot = cls()
        rot.matrix = matrix
        return rot

    def getYawPitchRoll(self) -> tuple[float, float, float]:  # noqa: N802
        """The angles (yaw, pitch, roll) in degrees that make this rotation."""
        m = self.matrix
        pitch = math.asin(max(-1.0, min(1.0, -m[2, 0])))
        if abs(m[2, 0]) < 1 - 1e-12:
            yaw, roll = math.atan2(m[1, 0], m[0, 0]), math.atan2(m[2, 1], m[2, 2])
        else:  # gimbal lock: put everything in yaw
            yaw, roll = math.atan2(-m[0, 1], m[1, 1]), 0.0
        return tuple(0.0 if abs(v) < 1e-12 else math.degrees(v) for v in (yaw, pitch, roll))

    def multVec(self, v: Vector) -> Vector:  # noqa: N802
        return Vector(*(self.matrix @ np.array(tuple(v))))

    def __mul__(self, other: "Rotation") -> "Rotation":
        return Rotation._of(self.matrix @ other.matrix)

    def isIdentity(self) -> bool:  # noqa: N802
        return bool(np.allclose(self.matrix, np.eye(3), rtol=0, atol=1e-12))

    def __repr__(self) -> str:
        return "Rotation (yaw-pitch-roll: %s)" % ",".join(_g(v) for v in self.getYawPitchRoll())


class Placement:
    """A position (``Base``) and an orientation (``Rotation``): ``FreeCAD.Placement``."""

    def __init__(self, base: Vector | None = None, rotation: Rotation | None = None):
        self.Base = Vector(*base) if base is not None else Vector()
        self.Rotation = rotation if rotation is not None else Rotation()

    def multiply(self, other: "Placement") -> "Placement":
        """This placement applied after ``other`` (FreeCAD's ``Placement.multiply``)."""
        return Placement(self.Base + self.Rotation.multVec(other.Base), self.Rotation * other.Rotation)

    def multVec(self, v: Vector) -> Vector:  # noqa: N802
        return self.Base + self.Rotation.multVec(v)

    def __repr__(self) -> str:
        ypr = ",".join(_g(v) for v in self.Rotation.getYawPitchRoll())
        pos = ",".join(_g(v) for v in self.Base)
        return f"Placement [Pos=({pos}), Yaw-Pitch-Roll=({ypr})]"


@dataclass(frozen=True)
class BoundBox:
    """The extents of a path, mm (``FreeCAD.BoundBox``).

    An empty box is FreeCAD's: every minimum the largest float, every
    maximum its negative.
    """

    XMin: float = _BIG
    YMin: float = _BIG
    ZMin: float = _BIG
    XMax: float = -_BIG
    YMax: float = -_BIG
    ZMax: float = -_BIG

    @classmethod
    def of_points(cls, points: np.ndarray) -> "BoundBox":
        """The box around an ``(n, 3)`` array of points (empty for no points)."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        if len(points) == 0 or np.isnan(points).all():
            return cls()
        with np.errstate(invalid="ignore"):  # a NaN coordinate is passed over, as FreeCAD's box does
            lo, hi = np.nanmin(points, axis=0), np.nanmax(points, axis=0)
        return cls(*(float(v) for v in lo), *(float(v) for v in hi))

    def isValid(self) -> bool:  # noqa: N802
        return self.XMin <= self.XMax and self.YMin <= self.YMax and self.ZMin <= self.ZMax

    @property
    def XLength(self) -> float:  # noqa: N802
        return self.XMax - self.XMin if self.isValid() else 0.0

    @property
    def YLength(self) -> float:  # noqa: N802
        return self.YMax - self.YMin if self.isValid() else 0.0

    @property
    def ZLength(self) -> float:  # noqa: N802
        return self.ZMax - self.ZMin if self.isValid() else 0.0

    def as_list(self) -> list[float]:
        """``[XMin, YMin, ZMin, XMax, YMax, ZMax]``."""
        return [self.XMin, self.YMin, self.ZMin, self.XMax, self.YMax, self.ZMax]

    def __repr__(self) -> str:
        return "BoundBox (%s)" % ", ".join(_g(v) for v in self.as_list())
