"""Emulate stage: the modal machine, its presets, and the Operation it produces."""

from .machine import FLOAT_COLUMNS, SMALL_COLUMNS, Machine
from .operation import (
    AdditiveOperation,
    AdditiveProcessData,
    Operation,
    ProcessData,
    SubtractiveOperation,
    SubtractiveProcessData,
)
from .presets import MachineConfig, list_machines, load_machine

__all__ = [
    "FLOAT_COLUMNS", "SMALL_COLUMNS", "Machine", "AdditiveOperation", "AdditiveProcessData", "Operation",
    "ProcessData", "SubtractiveOperation", "SubtractiveProcessData", "MachineConfig", "list_machines",
    "load_machine",
]
