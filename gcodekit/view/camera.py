"""Output stage: the orthographic camera every toolpath picture uses.

Z is up; ``azimuth`` turns the eye about Z (0: looking from +X), and
``elevation`` lifts it from the XY plane.  The view is centred on the
middle of the toolpath's work (:meth:`Toolpath.frame`) moved by ``target``
and shows the sphere around the work, ``zoom`` times larger.  The WebGL
viewer (``widgets/static/viewer.js``), the PyVista pictures and the
matplotlib pictures all place their view by these numbers.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..errors import check_choice

if TYPE_CHECKING:
    from .toolpath import Toolpath

#: Named views: (azimuth, elevation) in degrees.  ``iso`` looks down the diagonal from +X, -Y, +Z.
CAMERAS = {"iso": (-45.0, 35.264), "top": (-90.0, 90.0), "front": (-90.0, 0.0), "side": (0.0, 0.0)}


@dataclass
class Camera:
    """An orthographic orbit camera: angles in degrees, ``zoom`` 1 fits the work."""

    azimuth: float = -60.0
    elevation: float = 30.0
    zoom: float = 1.0
    #: where the camera looks, mm from the middle of the work (moved by panning)
    target: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    @classmethod
    def named(cls, name: str) -> "Camera":
        """One of :data:`CAMERAS`: ``iso``, ``top``, ``front`` or ``side``."""
        check_choice("camera", name, CAMERAS)
        azimuth, elevation = CAMERAS[name]
        return cls(azimuth, elevation)

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Screen right, screen up and towards-the-eye unit vectors."""
        az, el = np.radians(self.azimuth), np.radians(np.clip(self.elevation, -89.9, 89.9))
        eye = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        right = np.array([-np.sin(az), np.cos(az), 0.0])
        return right, np.cross(eye, right), eye

    def as_dict(self) -> dict:
        return {"azimuth": self.azimuth, "elevation": self.elevation, "zoom": self.zoom, "target": list(self.target)}

    def view(self, middle: np.ndarray, radius: float) -> tuple[np.ndarray, float]:
        """The point looked at and the half height of the view (mm), for work around ``middle`` of ``radius``."""
        return np.asarray(middle, float) + np.asarray(self.target, float), radius / max(self.zoom, 1e-6)

    def fitted(self, path: "Toolpath", aspect: float, margin: float = 0.05) -> "Camera":
        """This camera's angles with ``zoom`` and ``target`` set so the work's bounding box fills the view.

        ``aspect`` is the view's width over its height; ``margin`` the share left free around.  At zoom 1
        the view shows the sphere around the work whatever the angles (the notebook viewer's start, steady
        while turning); a still picture is framed tighter by this.
        """
        lo, hi = path.bounds()
        middle, radius = path.frame()
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        right, up, _ = self.axes()
        u, v = (corners - middle) @ right, (corners - middle) @ up
        half = max((v.max() - v.min()) / 2, (u.max() - u.min()) / 2 / aspect, 1e-3 * radius) * (1 + margin)
        target = right * (u.max() + u.min()) / 2 + up * (v.max() + v.min()) / 2
        return Camera(self.azimuth, self.elevation, float(radius / half), [float(v) for v in target])
