"""Output stage for deposition processes: beads and parts.

:class:`Bead` is the cross-section laid down and :class:`AdditivePart` groups
an additive operation's waypoints into deposition and travel segments and
layers; :class:`~gcodekit.export.vtk.VTKExporter` writes a part for ParaView
and :func:`~gcodekit.model.filament.filament_used` counts its filament.
"""

from .bead import Bead, bead_area
from .part import AdditivePart

__all__ = ["AdditivePart", "Bead", "bead_area"]
