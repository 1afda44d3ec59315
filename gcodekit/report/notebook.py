"""Report stage: the report as an executed notebook, for users who go on exploring.

The template ``reports/program_report.ipynb`` holds the same report as the
HTML page, drawn by the same functions; its cell tagged ``parameters`` is
replaced by the program and machine, then nbclient runs it in a fresh kernel
(keeping the widgets' state) and nbconvert can turn the result into HTML that
shows the widgets' pictures offline (:mod:`gcodekit.widgets.export`).
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

#: The notebook template: ``reports/program_report.ipynb``, shipped as package data (:mod:`gcodekit.reports`).
TEMPLATE = Path(str(resources.files("gcodekit.reports") / "program_report.ipynb"))
#: Seconds one cell may run: emulating a large print takes seconds, not minutes.
CELL_TIMEOUT_S = 600


def write_notebook(program: str | os.PathLike, out: str | os.PathLike, *, machine: str | None = None,
                   machine_config: str | os.PathLike | None = None, html: bool = False,
                   template: str | os.PathLike = TEMPLATE) -> Path:
    """Execute the report notebook for ``program`` and write it to ``out`` (``.ipynb``).

    Parameters
    ----------
    program : path of the program
    out : path of the executed notebook
    machine, machine_config : as for :func:`gcodekit.gcode_to_operation`
    html : bool, default: False
        Also write ``out`` with the suffix ``.notebook.html`` (nbconvert's lab template, offline).
    template : path, default: ``reports/program_report.ipynb``

    Raises
    ------
    FileNotFoundError
        When the template is missing.
    nbclient.exceptions.CellExecutionError
        When a cell fails; the message holds the cell's traceback.
    """
    import nbformat

    from ..widgets.export import execute, write_offline_html

    template, out = Path(template), Path(out)
    if not template.is_file():
        raise FileNotFoundError(f"notebook template not found: {template}")
    nb = nbformat.read(template, as_version=4)
    cell = next(c for c in nb.cells if "parameters" in c.metadata.get("tags", []))
    config = str(Path(machine_config).resolve()) if machine_config else None
    # repr() writes the values as Python literals: a file name cannot become code
    cell.source = (f"program = {str(Path(program).resolve())!r}\nmachine = {machine!r}\n"
                   f"machine_config = {config!r}")
    execute(nb, out.parent, timeout=CELL_TIMEOUT_S)
    nbformat.write(nb, out)
    if html:
        write_offline_html(nb, out.with_name(out.name.removesuffix(".ipynb") + ".notebook.html"))
    return out
