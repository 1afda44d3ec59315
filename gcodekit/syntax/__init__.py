"""Syntax stage: dialects ("flavors") as data, their loader and detection.

A :class:`Flavor` says how a dialect's text is cut into words and what its
codes mean in gcodekit's normalized vocabulary; one TOML file per dialect
lives in ``flavors/``.  :func:`load_flavor` reads and validates one,
:func:`detect_flavor` guesses which one a program is written in.
"""

from .detect import Detection, detect_flavor, guess_flavor
from .flavor import BLOCK_SPLITS, COMMANDS, PARAMETERS, DetectRules, Flavor
from .loader import list_flavors, load_flavor

__all__ = [
    "BLOCK_SPLITS",
    "COMMANDS",
    "PARAMETERS",
    "DetectRules",
    "Detection",
    "Flavor",
    "detect_flavor",
    "guess_flavor",
    "list_flavors",
    "load_flavor",
]
