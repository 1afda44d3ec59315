"""gcodekit: read, emulate and analyse G-code and NC programs.

The pipeline runs text -> blocks -> commands -> machine states -> operation
(see ``docs/life-of-a-program.md``).  The functions most users need:

>>> import gcodekit
>>> op = gcodekit.gcode_to_operation("G21\\nG1 X10 F600\\n", machine="linuxcnc")
>>> op.process_data[-1].location[0]
10.0
"""

from .model.operation import (
    AdditiveOperation,
    AdditiveProcessData,
    Operation,
    ProcessData,
    SubtractiveOperation,
    SubtractiveProcessData,
)
from .additive import AdditivePart, Bead
from .export.vtk import VTKExporter
from . import visualize
from .analysis import export_event_series_from_gcode, gcode_dataframe_to_event_series
from .export.gcode import GcodeExporter
from .emulate.presets import MachineConfig, list_machines, load_machine
from .errors import (
    ConfigError,
    Diagnostic,
    GcodeError,
    GcodeExpressionError,
    GcodeLimitError,
    GcodeMachineError,
    GcodeSyntaxError,
)
from .parse import GcodeParser
from .pipeline import emulate_operation, gcode_file_to_dataframe, gcode_to_operation, parse_program
from .syntax import detect_flavor, list_flavors, load_flavor

__version__ = "0.1.0"

__all__ = [
    "AdditiveOperation", "AdditivePart", "AdditiveProcessData", "Bead", "VTKExporter", "ConfigError", "GcodeExporter", "Diagnostic", "GcodeError",
    "GcodeExpressionError", "GcodeLimitError", "GcodeMachineError", "GcodeParser", "GcodeSyntaxError",
    "MachineConfig", "Operation", "ProcessData", "SubtractiveOperation", "SubtractiveProcessData",
    "detect_flavor", "emulate_operation", "export_event_series_from_gcode", "gcode_dataframe_to_event_series", "gcode_file_to_dataframe", "gcode_to_operation", "list_flavors",
    "list_machines", "load_flavor", "load_machine", "parse_program",
]
