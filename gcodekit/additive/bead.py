"""Output stage: the cross-section of a deposited bead.

Examples
--------
>>> bead = Bead(width=0.45, height=0.2, shape="rectangle", density=1.24)
>>> round(bead.area, 4), round(bead.volume(100.0), 2)
(0.09, 9.0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError, check_choice

SHAPES = ("rectangle", "ellipse", "stadium")


def bead_area(width, height, shape: str = "stadium"):
    """Cross-section area of beads, mm^2 (arrays or scalars, mm).

    ``rectangle`` is width x height; ``ellipse`` has the width and height as
    axes; ``stadium`` is a rectangle with half-round ends of diameter
    ``height`` (the squashed extrudate of PrusaSlicer's flow model), so
    ``(width - height) * height + pi * height**2 / 4``.
    """
    check_choice("shape", shape, SHAPES)
    w, h = np.asarray(width, float), np.asarray(height, float)
    if shape == "rectangle":
        area = w * h
    elif shape == "ellipse":
        area = np.pi * w * h / 4.0
    else:
        area = (w - h) * h + np.pi * h * h / 4.0
    return area if area.ndim else float(area)


@dataclass(frozen=True)
class Bead:
    """A constant bead cross-section laid along the deposition paths.

    Attributes
    ----------
    width, height : float
        mm.
    shape : {"rectangle", "ellipse", "stadium"}, default: "stadium"
    density : float or None, default: None
        g/cm^3; None takes the machine's material density.
    """

    width: float
    height: float
    shape: str = "stadium"
    density: float | None = None

    def __post_init__(self):
        check_choice("shape", self.shape, SHAPES)
        if not (self.width > 0 and self.height > 0):
            raise ConfigError(f"bead width and height must be positive, not {self.width} x {self.height}")
        if self.shape == "stadium" and self.width < self.height:
            raise ConfigError(f"a stadium bead needs width >= height, not {self.width} < {self.height}")

    @property
    def area(self) -> float:
        """Cross-section, mm^2 (see :func:`bead_area`)."""
        return bead_area(self.width, self.height, self.shape)

    def volume(self, length):
        """Volume of ``length`` mm of bead, mm^3."""
        return self.area * np.asarray(length, float) if np.ndim(length) else self.area * float(length)
