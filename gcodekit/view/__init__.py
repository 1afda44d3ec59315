"""Output stage: the one toolpath and the one colouring every picture draws.

:class:`Toolpath` is a program's moves as straight segments (arcs in
chords), grouped by layer, Z level or source line; :class:`Coloring` is one
value per segment with its palette and legend.  The notebook's WebGL viewer
(:mod:`gcodekit.widgets`), the PyVista and matplotlib pictures
(:mod:`gcodekit.visualize`) and the report's figures
(:mod:`gcodekit.report.figures`) all draw from these, so the same program,
colouring and camera give the same picture in each.  The orthographic
:class:`Camera` they share is here too.

Examples
--------
::

    from gcodekit.view import Toolpath, coloring

    path = Toolpath.of(op)                  # op: an emulated Operation
    color = coloring(path, "speed")         # or "feature", "feed", "layer", a waypoint column
    a, b = path.group_slice(3, 5)           # the segments of layers 3 to 5
    rgb, vmin, vmax = color.segment_rgb(path, np.arange(a, b))
"""

from .camera import CAMERAS, Camera
from .coloring import (PALETTE, TITLES, TRAVEL_COLOR, Coloring, choices, colormap_table, coloring, default_coloring,
                       has_features, palette_rgb, waypoint_scalars)
from .overview import overview
from .toolpath import (CHORD_ANGLE_DEG, GROUP_BY, TRAVEL, WORK, Toolpath, ToolpathError, move_masks, move_rows,
                       move_segments, source_lines)

__all__ = ["CAMERAS", "CHORD_ANGLE_DEG", "GROUP_BY", "PALETTE", "TITLES", "TRAVEL", "TRAVEL_COLOR", "WORK", "Camera",
           "Coloring", "Toolpath", "ToolpathError", "choices", "colormap_table", "coloring", "default_coloring",
           "has_features", "move_masks", "move_rows", "move_segments", "overview", "palette_rgb", "source_lines",
           "waypoint_scalars"]
