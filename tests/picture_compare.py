"""How alike two pictures of a toolpath are: where they put ink, and which colour.

Pictures drawn on white by different renderers differ in line width and
antialiasing, so the comparison is made tolerant of exactly those two:

* **where**: each picture's foreground mask (a pixel darker than near-white),
  both grown by ``grow`` pixels, compared as intersection over union;
* **which colour**: antialiasing blends a line's colour ``c`` with the white
  background, ``p = a c + (1 - a) white``, which keeps the direction of
  ``white - p`` (the *ink direction*) whatever the coverage ``a``.  Where both
  pictures have ink, the angle between their ink directions says whether they
  painted the same colour there (viridis' ends are 50-60 degrees apart, two
  palette colours at least 15).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: A pixel with less than this much ink (255 - darkest channel) is background.
INK = 20


def foreground(image: np.ndarray) -> np.ndarray:
    return (255 - np.asarray(image, int).min(axis=2)) >= INK


def grow(mask: np.ndarray, pixels: int) -> np.ndarray:
    out = mask.copy()
    for dy in range(-pixels, pixels + 1):
        for dx in range(-pixels, pixels + 1):
            out |= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    return out


def ink_direction(image: np.ndarray) -> np.ndarray:
    ink = 255.0 - np.asarray(image, float)
    return ink / np.maximum(np.linalg.norm(ink, axis=2, keepdims=True), 1e-9)


@dataclass
class Agreement:
    iou: float  # of the grown foreground masks
    matched: int  # pixels inked in both pictures (strong ink, where colours are compared)
    median_angle: float  # degrees between ink directions over the matched pixels
    within_10: float  # share of matched pixels whose ink directions are within 10 degrees

    def __str__(self) -> str:
        return (f"IoU {self.iou:.3f}, {self.matched} pixels compared, median colour angle {self.median_angle:.1f} deg, "
                f"{100 * self.within_10:.1f} % within 10 deg")


def agreement(a: np.ndarray, b: np.ndarray, grow_px: int = 2) -> Agreement:
    """How alike pictures ``a`` and ``b`` (same size, RGB on white) are."""
    assert a.shape == b.shape, f"pictures of different sizes: {a.shape} and {b.shape}"
    fa, fb = foreground(a), foreground(b)
    ga, gb = grow(fa, grow_px), grow(fb, grow_px)
    iou = float((ga & gb).sum() / max((ga | gb).sum(), 1))
    # colours where both have strong ink (a line's core, not its antialiased rim)
    strong = lambda image: (255 - np.asarray(image, int).min(axis=2)) >= 60  # noqa: E731
    both = strong(a) & strong(b)
    cos = np.clip(np.sum(ink_direction(a)[both] * ink_direction(b)[both], axis=1), -1.0, 1.0)
    angle = np.degrees(np.arccos(cos))
    return Agreement(iou, int(both.sum()), float(np.median(angle)) if angle.size else float("nan"),
                     float(np.mean(angle < 10.0)) if angle.size else 0.0)
