"""Output stage for deposition processes: beads and parts.

:class:`Bead` is the cross-section laid down and :class:`AdditivePart` groups
an additive operation's waypoints into deposition and travel segments and
layers; :func:`bead_tubes` makes its beads a triangle mesh (the live
:class:`~gcodekit.widgets.BeadView` shows it);
:class:`~gcodekit.export.vtk.VTKExporter` writes a part for ParaView
and :func:`~gcodekit.model.filament.filament_used` counts its filament.
"""

from .bead import Bead, bead_area
from .part import AdditivePart
from .tubes import BeadTubes, bead_tubes

__all__ = ["AdditivePart", "Bead", "BeadTubes", "bead_area", "bead_tubes"]
