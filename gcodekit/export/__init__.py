"""Output: writers of an Operation -- G-code in any flavor, VTK meshes, event series, motion tables.

Each writer takes an :class:`~gcodekit.model.Operation` (or what is built
from one, such as an :class:`~gcodekit.additive.AdditivePart`), never a path
to a program: reading programs is the pipeline's job.
"""

from .gcode import GcodeExporter, GcodeExportError
from .vtk import VTKExporter

__all__ = ["GcodeExporter", "GcodeExportError", "VTKExporter"]
