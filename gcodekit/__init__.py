"""gcodekit: read, emulate and analyse G-code and NC programs.

The pipeline runs text -> blocks -> commands -> machine states -> operation
(see ``docs/life-of-a-program.md``).  The functions most users need:

>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G21\\nG1 X10 F600\\n", machine="linuxcnc")
>>> op.process_data[-1].location[0]
10.0

The names below load their module on first use (PEP 562), so ``import
gcodekit`` and a command that needs only the pipeline (``gcodekit info``)
do not pay for the pictures, exporters and additive parts.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .errors import (
    ConfigError,
    Diagnostic,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    GcodeMachineError,
    GcodeSyntaxError,
    MissingDependencyError,
    NothingToShowError,
    ProgramFileError,
)
from .limits import MAX_ITERATIONS, MAX_MOTIONS

if TYPE_CHECKING:
    from . import visualize
    from .additive import AdditivePart, Bead
    from .analysis import time_by, velocity_profile
    from .emulate.presets import MachineConfig, list_machines, load_machine
    from .export.events import event_series, gcode_dataframe_to_event_series
    from .export.gcode import GcodeExporter
    from .export.vtk import VTKExporter
    from .model import (AdditiveOperation, AdditiveProcessData, Operation, ProcessData, SubtractiveOperation,
                        SubtractiveProcessData)
    from .parse import GcodeParser
    from .pipeline import (emulate_operation, export_event_series_from_gcode, gcode_file_to_dataframe,
                           gcode_to_operation, parse_program, transpile_program)
    from .plan.motion_profile import BAAMMotionProfile, MotionProfile
    from .schema import COLUMNS
    from .syntax import detect_flavor, list_flavors, load_flavor

#: The one version string: pyproject.toml reads it from here.
__version__ = "0.1.0"

#: Where each lazily loaded public name lives (module relative to this package).
_LAZY = {
    "visualize": ".visualize",
    "AdditivePart": ".additive", "Bead": ".additive",
    "time_by": ".analysis", "velocity_profile": ".analysis",
    "MachineConfig": ".emulate.presets", "list_machines": ".emulate.presets", "load_machine": ".emulate.presets",
    "event_series": ".export.events", "gcode_dataframe_to_event_series": ".export.events",
    "GcodeExporter": ".export.gcode", "VTKExporter": ".export.vtk",
    **dict.fromkeys(("AdditiveOperation", "AdditiveProcessData", "Operation", "ProcessData", "SubtractiveOperation",
                     "SubtractiveProcessData"), ".model"),
    "GcodeParser": ".parse",
    **dict.fromkeys(("emulate_operation", "export_event_series_from_gcode", "gcode_file_to_dataframe",
                     "gcode_to_operation", "parse_program", "transpile_program"), ".pipeline"),
    "BAAMMotionProfile": ".plan.motion_profile", "MotionProfile": ".plan.motion_profile",
    "COLUMNS": ".schema",
    "detect_flavor": ".syntax", "list_flavors": ".syntax", "load_flavor": ".syntax",
}


def __getattr__(name: str) -> Any:
    """Load a public name's module on first use and keep the name here."""
    where = _LAZY.get(name)
    if where is None:
        raise AttributeError(f"module 'gcodekit' has no attribute {name!r}")
    module = importlib.import_module(where, __name__)
    value = module if where == f".{name}" else getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "AdditiveOperation", "AdditivePart", "AdditiveProcessData", "BAAMMotionProfile", "Bead", "COLUMNS", "ConfigError",
    "Diagnostic", "GcodeError", "GcodeExporter", "GcodeExpressionError", "GcodeLimitError", "GcodeMachineError",
    "GcodeParser", "GcodeSyntaxError", "MAX_ITERATIONS", "MAX_MOTIONS", "MachineConfig", "MissingDependencyError",
    "MotionProfile", "NothingToShowError", "Operation", "ProcessData", "ProgramFileError", "SubtractiveOperation",
    "SubtractiveProcessData", "VTKExporter", "detect_flavor", "emulate_operation", "event_series",
    "export_event_series_from_gcode", "gcode_dataframe_to_event_series", "gcode_file_to_dataframe",
    "gcode_to_operation", "list_flavors", "list_machines", "load_flavor", "load_machine", "parse_program", "time_by",
    "transpile_program", "velocity_profile", "visualize",
]
