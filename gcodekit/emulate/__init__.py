"""Emulate stage: the modal machine and its presets (the Operation it feeds is in :mod:`gcodekit.model`)."""

from .machine import Machine
from .presets import MachineConfig, list_machines, load_machine

__all__ = ["Machine", "MachineConfig", "list_machines", "load_machine"]
