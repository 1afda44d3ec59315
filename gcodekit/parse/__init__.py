"""Parse stage: blocks of words to typed commands (see :mod:`.commands`)."""

from .commands import (
    Arc, ArcExtrude, ArcMill, AbsolutePosition, Command, Comment, Config, Dwell, Extrude, FeedRate,
    G, IncrementalPosition, Kind, M, MachineCoordinates, Mill, Move, MoveExtrude, MoveMill, Purge,
    WorkCoordinates,
)
from .parser import GcodeParser
from .table import CommandTable, MOTION_NAMES, NAMES

__all__ = [
    "Arc", "ArcExtrude", "ArcMill", "AbsolutePosition", "Command", "Comment", "Config", "Dwell",
    "Extrude", "FeedRate", "G", "IncrementalPosition", "Kind", "M", "MachineCoordinates", "Mill",
    "Move", "MoveExtrude", "MoveMill", "Purge", "WorkCoordinates", "GcodeParser", "CommandTable",
    "MOTION_NAMES", "NAMES",
]
