"""Widgets stage: notebook widgets over an emulated program.

- :class:`LayerViewer`: the toolpath in 3D (rotate and zoom in the browser),
  a layer range, a move slider, colourings, the source line beside it;
- :class:`StageDiff`: two stages of the transpiler (or two programs) side by
  side, changed lines marked, both toolpaths in one picture;
- :class:`VelocityPlot`: commanded feed against planned speed, decimated,
  following a viewer's range;
- :class:`PartView`: the part a mill program cuts, in a live 3D view (trame,
  vtk.js in the browser), with a slider over the moves;
- :class:`BeadView`: the beads an additive program lays, as shaded tubes in
  the same kind of live view, with a slider over the depositing moves.

They need the ``widgets`` extra (``pip install 'gcodekit[widgets]'``), load
on first use (``import gcodekit`` does not import them) and are plain Python
objects too: a test drives their controls and calls ``screenshot()``.  Each
widget's display also carries a PNG of its state, so an exported notebook
shows it offline.
"""

from __future__ import annotations

from importlib import import_module

_WIDGETS = {"LayerViewer": ".layer_viewer", "StageDiff": ".stage_diff", "VelocityPlot": ".velocity",
            "PartView": ".part_view", "BeadView": ".bead_view"}

__all__ = list(_WIDGETS)


def __getattr__(name: str):
    if name not in _WIDGETS:
        raise AttributeError(f"module 'gcodekit.widgets' has no attribute {name!r}")
    try:
        module = import_module(_WIDGETS[name], __name__)
    except ImportError as exc:
        raise ImportError(f"gcodekit.widgets.{name} needs the widgets extra: pip install 'gcodekit[widgets]' "
                          f"({exc})") from exc
    return getattr(module, name)
