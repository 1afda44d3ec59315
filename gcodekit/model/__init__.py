"""Model: the Operation a program becomes, and what is derived from it once.

After emulation and planning a program is an :class:`~.operation.Operation`:
its command table and its waypoint columns (see :mod:`gcodekit.schema`).
This package holds that object, the columns derived from it once and kept
(layers, features, material laid), its bounds, statistics and filament use.
Outputs build on it; it builds on nothing after planning.
"""

from .operation import Operation
from .process_data import AdditiveProcessData, ProcessData, SubtractiveProcessData
from .processes import OPERATION_CLASSES, AdditiveOperation, SubtractiveOperation

__all__ = ["AdditiveOperation", "AdditiveProcessData", "OPERATION_CLASSES", "Operation", "ProcessData",
           "SubtractiveOperation", "SubtractiveProcessData"]
