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


def bead_width(area, height, shape: str = "stadium"):
    """The width of beads of cross-section ``area`` (mm^2) and ``height`` (mm): :func:`bead_area` solved for it.

    A stadium narrower than it is high has no such shape: its width is then
    the height (a round bead, somewhat larger than ``area``).
    """
    check_choice("shape", shape, SHAPES)
    a, h = np.asarray(area, float), np.asarray(height, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        if shape == "rectangle":
            width = a / h
        elif shape == "ellipse":
            width = 4.0 * a / (np.pi * h)
        else:
            width = np.maximum((a - np.pi * h * h / 4.0) / h + h, h)
    return width if width.ndim else float(width)


def bead_outline(width, height, shape: str = "stadium", sides: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Points on the outline of beads' cross-sections, about the bead's centre: ``(lateral, vertical)``, mm.

    Each has shape ``(n, sides)`` for ``n`` beads (``width`` and ``height``
    arrays or scalars), going counter-clockwise seen along the bead from
    behind, at the angles ``pi / sides + 2 pi k / sides`` from the lateral
    axis (an even ``sides`` gives a flat top and bottom).  The stadium's
    points lie on its two half circles, the ellipse's on the ellipse; the
    rectangle's on its sides, starting at its corner (angle ``pi / 4``)
    when ``sides`` is a multiple of 4, so that it has its four corners.

    Examples
    --------
    >>> lateral, vertical = bead_outline(0.45, 0.2, "rectangle", sides=4)
    >>> lateral.round(3).tolist(), vertical.round(3).tolist()
    ([[0.225, -0.225, -0.225, 0.225]], [[0.1, 0.1, -0.1, -0.1]])
    """
    check_choice("shape", shape, SHAPES)
    if sides < 3:
        raise ConfigError(f"a bead's outline needs at least 3 sides, not {sides}")
    w, h = np.atleast_1d(np.asarray(width, float))[:, None], np.atleast_1d(np.asarray(height, float))[:, None]
    offset = np.pi / 4 if shape == "rectangle" and sides % 4 == 0 else np.pi / sides
    angle = offset + 2.0 * np.pi * np.arange(sides) / sides
    c, s = np.cos(angle), np.sin(angle)
    if shape == "stadium":
        lateral = np.sign(c) * (w - h) / 2.0 + h / 2.0 * c
        vertical = h / 2.0 * s + 0.0 * w
    elif shape == "ellipse":
        lateral, vertical = w / 2.0 * c, h / 2.0 * s
    else:
        # the circle's points pushed out to the square, then stretched to the rectangle
        scale = 1.0 / np.maximum(np.abs(c), np.abs(s))
        lateral, vertical = w / 2.0 * c * scale, h / 2.0 * s * scale
    return lateral, vertical


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
