"""Output stage for deposition processes: filament use, beads and parts.

:class:`Bead` is the cross-section laid down, :class:`AdditivePart` groups an
additive operation's waypoints into deposition and travel segments and
layers, and :class:`VTKExporter` writes a part for ParaView.
"""

from .bead import Bead, bead_area
from .filament import filament_used
from .part import AdditivePart
from .vtk import VTKExporter

__all__ = ["AdditivePart", "Bead", "VTKExporter", "bead_area", "filament_used"]
