"""Base: the shapes of cutting tools, as solids of revolution about the tool axis.

One definition serves every stage that needs a tool's body: the Path API's
ToolBits, the material-removal simulation and the pictures.  A shape is
described in the tool's own frame: the tip (the controlled point, where
LinuxCNC's tool length offset ends) at height 0, the axis pointing up
along +h, and the profile ``h(r)``, the height of the tool's lower surface
at radial distance ``r`` from the axis.  Everything is in millimetres and
degrees.

The shapes and their profiles (``R`` = diameter / 2):

===========  ==========================================  =================
kind         lower surface h(r), 0 <= r <= R              extra fields
===========  ==========================================  =================
``endmill``  0                                            --
``ballend``  R - sqrt(R^2 - r^2)                          --
``bullnose`` 0 for r <= R - rc, then the corner arc       ``corner_radius``
``vbit``     r / tan(angle / 2)                           ``angle``
``drill``    r / tan(angle / 2)                           ``angle``
``chamfer``  0 for r <= tip/2, then (r - tip/2)/tan(a/2)  ``angle``, ``tip_diameter``
===========  ==========================================  =================

Examples
--------
>>> ball = ToolShape("ballend", diameter=6.0)
>>> float(ball.height_at(3.0)), float(ball.height_at(0.0))
(3.0, 0.0)
>>> ToolShape("vbit", diameter=10.0, angle=90.0).height_at(5.0).round(6).item()
5.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ConfigError, did_you_mean

#: The tool shapes gcodekit knows, with the extra field each needs.
SHAPES: dict[str, tuple[str, ...]] = {
    "endmill": (),
    "ballend": (),
    "bullnose": ("corner_radius",),
    "vbit": ("angle",),
    "drill": ("angle",),
    "chamfer": ("angle", "tip_diameter"),
}

#: A twist drill's usual point angle, degrees (118 for general-purpose drills).
DRILL_POINT_ANGLE = 118.0


@dataclass(frozen=True)
class ToolShape:
    """A cutting tool's body: its kind, diameter and the shape of its end.

    Parameters
    ----------
    kind : str
        One of :data:`SHAPES` (``endmill``, ``ballend``, ``bullnose``,
        ``vbit``, ``drill``, ``chamfer``).
    diameter : float
        Cutting diameter, mm; must be positive.
    length : float, default: 30.0
        Cutting (flute) length above the tip, mm: how deep the tool can cut.
    corner_radius : float, default: 0.0
        Bull nose corner radius, mm (0 < corner_radius <= diameter / 2).
    angle : float, default: 0.0
        Included tip angle, degrees (V-bit, drill, chamfer); 0 means the
        kind's usual angle (90 for V-bits and chamfer mills, 118 for drills).
    tip_diameter : float, default: 0.0
        Flat at the tip of a chamfer mill, mm.

    Raises
    ------
    ConfigError
        A kind gcodekit does not know (with a did-you-mean), a diameter or
        length that is not positive, or a corner radius or angle out of range.
    """

    kind: str
    diameter: float
    length: float = 30.0
    corner_radius: float = 0.0
    angle: float = 0.0
    tip_diameter: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in SHAPES:
            raise ConfigError(f"unknown tool shape {self.kind!r}{did_you_mean(self.kind, SHAPES)}")
        if not (math.isfinite(self.diameter) and self.diameter > 0):
            raise ConfigError(f"a {self.kind}'s diameter must be a positive number of mm, not {self.diameter!r}")
        if not (math.isfinite(self.length) and self.length > 0):
            raise ConfigError(f"a {self.kind}'s length must be a positive number of mm, not {self.length!r}")
        if self.kind == "bullnose" and not (0 < self.corner_radius <= self.radius):
            raise ConfigError(
                f"a bull nose's corner_radius must be in (0, diameter/2 = {self.radius:g}] mm, "
                f"not {self.corner_radius!r}"
            )
        if self.kind in ("vbit", "drill", "chamfer"):
            if self.angle == 0.0:
                object.__setattr__(self, "angle", DRILL_POINT_ANGLE if self.kind == "drill" else 90.0)
            if not (0 < self.angle < 180):
                raise ConfigError(f"a {self.kind}'s angle must be in (0, 180) degrees, not {self.angle!r}")
        if self.kind == "chamfer" and not (0 <= self.tip_diameter < self.diameter):
            raise ConfigError(
                f"a chamfer mill's tip_diameter must be in [0, diameter) mm, not {self.tip_diameter!r}"
            )

    @property
    def radius(self) -> float:
        """Half the diameter, mm."""
        return self.diameter / 2.0

    @property
    def tip_height(self) -> float:
        """Height of the end's shaped part: where the profile reaches the full radius, mm."""
        return float(self.height_at(self.radius))

    def height_at(self, r: np.ndarray | float) -> np.ndarray:
        """Height of the tool's lower surface above its tip at radial distance ``r``, mm.

        NaN where ``r`` is beyond the tool's radius (the tool does not reach there).
        """
        r = np.abs(np.asarray(r, dtype=float))
        radius = self.radius
        if self.kind == "endmill":
            h = np.zeros_like(r)
        elif self.kind == "ballend":
            h = radius - np.sqrt(np.maximum(radius * radius - r * r, 0.0))
        elif self.kind == "bullnose":
            rc = self.corner_radius
            flat = radius - rc
            d = np.maximum(r - flat, 0.0)
            h = rc - np.sqrt(np.maximum(rc * rc - d * d, 0.0))
        else:
            flat = self.tip_diameter / 2.0 if self.kind == "chamfer" else 0.0
            h = np.maximum(r - flat, 0.0) / math.tan(math.radians(self.angle) / 2.0)
        return np.where(r <= radius * (1 + 1e-12), h, np.nan)

    def radius_at(self, h: np.ndarray | float) -> np.ndarray:
        """Radius of the tool's body at height ``h`` above its tip, mm (0 below the tip)."""
        h = np.asarray(h, dtype=float)
        radius = self.radius
        if self.kind == "endmill":
            r = np.full_like(h, radius)
        elif self.kind == "ballend":
            hc = np.minimum(h, radius)
            r = np.sqrt(np.maximum(2 * radius * hc - hc * hc, 0.0))
        elif self.kind == "bullnose":
            rc = self.corner_radius
            hc = np.minimum(h, rc)
            r = radius - rc + np.sqrt(np.maximum(2 * rc * hc - hc * hc, 0.0))
        else:
            flat = self.tip_diameter / 2.0 if self.kind == "chamfer" else 0.0
            r = np.minimum(flat + h * math.tan(math.radians(self.angle) / 2.0), radius)
        return np.where(h >= 0, r, 0.0)

    def profile(self, n: int = 32) -> np.ndarray:
        """The half-section from the tip's centre to the top of the cutting length: ``(k, 2)`` of (r, h), mm.

        It starts at (0, 0) and ends at (radius, length); revolving it about
        the axis gives the tool's cutting body (for pictures and meshes).
        """
        top = self.tip_height
        h = top * (1 - np.cos(np.linspace(0, math.pi / 2, n)))
        points = np.column_stack([self.radius_at(h), h])
        points = np.vstack([[0.0, 0.0], points, [self.radius, max(self.length, top)]])
        keep = np.ones(len(points), bool)
        keep[1:] = np.any(np.diff(points, axis=0) != 0, axis=1)
        return points[keep]

    def as_dict(self) -> dict[str, float | str]:
        """The fields a tool library file stores, only those the kind uses."""
        out: dict[str, float | str] = {"shape": self.kind, "diameter": self.diameter, "length": self.length}
        for name in SHAPES[self.kind]:
            out[name] = getattr(self, name)
        return out
