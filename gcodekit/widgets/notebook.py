"""Widgets stage: a ready exploration notebook for one program (``gcodekit notebook``).

The notebook is built here, in code that ships with the package, so the
command works from an installed wheel: a summary, the tables, a
:class:`LayerViewer` with a linked :class:`VelocityPlot`, and for mill
programs the transpiler's stages in a :class:`StageDiff`.
"""

from __future__ import annotations

import html
import os
import re
from pathlib import Path

from ..limits import MAX_ITERATIONS, MAX_MOTIONS

_MARKDOWN_PUNCTUATION = re.compile(r"([\\`*_{}\[\]()#+\-.!|~])")


def markdown_text(text: str) -> str:
    """``text`` as Markdown that shows it literally: no HTML, no emphasis, no links."""
    return _MARKDOWN_PUNCTUATION.sub(r"\\\1", html.escape(text, quote=False))


def exploration_notebook(program: str | os.PathLike, *, machine: str | None = None,
                         machine_config: str | os.PathLike | None = None, relative_to: str | os.PathLike = ".",
                         max_motions: int = MAX_MOTIONS, max_iterations: int = MAX_ITERATIONS):
    """The notebook (an ``nbformat`` node) exploring ``program``.

    The program is named relative to ``relative_to`` (the notebook's folder)
    when it lies below it, else by its absolute path; the notebook reads it
    under ``max_motions`` and ``max_iterations`` (see :mod:`gcodekit.limits`).
    """
    from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

    def where(path) -> str:
        path = Path(path).resolve()
        try:
            return os.path.relpath(path, Path(relative_to).resolve())
        except ValueError:  # another drive
            return str(path)

    config = where(machine_config) if machine_config else None
    name = Path(program).name
    cells = [
        new_markdown_cell(f"# {markdown_text(name)}\n\nWritten by `gcodekit notebook`: the program read and "
                          "emulated, its tables and the widgets wired to it. Run all cells (a kernel with `gcodekit[widgets]`)."),
        # repr() writes the values as Python literals: a file name cannot become code
        new_code_cell(f"program = {where(program)!r}\nmachine = {machine!r}\nmachine_config = {config!r}\n"
                      f"max_motions = {int(max_motions)!r}\nmax_iterations = {int(max_iterations)!r}",
                      metadata={"tags": ["parameters"]}),
        new_code_cell("import gcodekit\nfrom gcodekit.widgets import LayerViewer, StageDiff, VelocityPlot\n\n"
                      "op = gcodekit.gcode_to_operation(program, machine, machine_config=machine_config,\n"
                      "                                 max_motions=max_motions, max_iterations=max_iterations)\n"
                      "stats = op.get_statistics()\n"
                      "{k: stats[k] for k in (\"lines\", \"moves\", \"distance_mm\", \"time_s\", \"layers\", \"filament_mm\", "
                      "\"bounds\")}"),
        new_code_cell("# diagnostics: file, line, column and what is wrong\n[str(d) for d in op.diagnostics][:20]"),
        new_markdown_cell("## Tables\n\nOne row per waypoint (`to_dataframe`), per motion (`motions`), and time by "
                          "layer, feature or tool."),
        new_code_cell("df = op.to_dataframe()\ndf.head()"),
        new_code_cell("op.time_by(\"layer\" if stats[\"layers\"] else \"tool\")"),
        new_markdown_cell("## Toolpath\n\nDrag to rotate, shift-drag to pan, wheel to zoom; the sliders pick the "
                          "layers (or Z levels) and the moves of the top one; arrow keys step in the view."),
        new_code_cell("viewer = LayerViewer(op)\nviewer"),
        new_markdown_cell("## Speed\n\nCommanded feed against the planner's speed, following the viewer's range."),
        new_code_cell("plot = VelocityPlot(op).link(viewer)\nplot"),
        new_markdown_cell("## Transpiler stages (mill programs)"),
        new_code_cell("StageDiff(op, a=0, b=6) if op.machine.process != \"additive\" else "
                      "\"an additive program: no transpiler stages\""),
    ]
    nb = new_notebook(cells=cells)
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.metadata["language_info"] = {"name": "python"}
    return nb


def write_exploration_notebook(program: str | os.PathLike, out: str | os.PathLike, *, machine: str | None = None,
                               machine_config: str | os.PathLike | None = None, execute: bool = False,
                               html: bool = False, max_motions: int = MAX_MOTIONS,
                               max_iterations: int = MAX_ITERATIONS) -> Path:
    """Write :func:`exploration_notebook` to ``out``; ``execute`` runs it, ``html`` also writes
    ``out`` with ``.html`` that shows its pictures offline (implies ``execute``)."""
    import nbformat

    out = Path(out)
    if not Path(program).is_file():
        raise FileNotFoundError(f"no such program file: {os.fspath(program)!r}")
    nb = exploration_notebook(program, machine=machine, machine_config=machine_config, relative_to=out.parent,
                              max_motions=max_motions, max_iterations=max_iterations)
    if execute or html:
        from .export import execute as run, write_offline_html

        run(nb, out.parent)
        if html:
            write_offline_html(nb, out.with_suffix(".html"))
    nbformat.write(nb, out)
    return out
