"""Make the README's pictures of the widgets: the real widgets in JupyterLab, in Debian's Chromium.

Run from the repository (needs the test extra and chromium, as the browser tests):
``.venv/bin/python docs/widget_pictures.py`` writes ``docs/widgets/*.png``.
"""

import shutil
import sys
import tempfile
from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_notebook

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from jupyter_browser import browser_page, jupyter_lab, open_and_run  # noqa: E402

CELLS = [
    "import gcodekit\nfrom gcodekit.widgets import LayerViewer, StageDiff, VelocityPlot\n"
    "op = gcodekit.gcode_to_operation('examples/cube20_prusaslicer_marlin.gcode')\n"
    "viewer = LayerViewer(op, color_by='feature')\nviewer.layers.value = (0, 62)\nviewer.moves.value = 40\nviewer",
    "VelocityPlot(op, layers=(30, 30))",
    "StageDiff('notebooks/worksheets/programs/pocket_wall.ngc', a=0, b=6, frame='machine', tool_table='notebooks/worksheets/programs/tools.tbl')",
]
NAMES = ["layer_viewer", "velocity_plot", "stage_diff"]


def main() -> None:
    root = Path(tempfile.mkdtemp(prefix="gcodekit-pictures-"))
    shutil.copytree(REPO / "examples", root / "examples")
    shutil.copytree(REPO / "notebooks", root / "notebooks")
    nb = new_notebook(cells=[new_code_cell(c) for c in CELLS])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, root / "pictures.ipynb")
    out = REPO / "docs" / "widgets"
    out.mkdir(exist_ok=True)
    with jupyter_lab(root) as url, browser_page(width=1300, height=2600) as page:
        open_and_run(page, url, "pictures.ipynb")
        page.wait_for_selector(".gk-status[data-frame]", state="attached")
        page.wait_for_timeout(1500)
        for k, name in enumerate(NAMES):
            page.locator(".jp-OutputArea-output").nth(k).screenshot(path=str(out / f"{name}.png"))
    shutil.rmtree(root, ignore_errors=True)
    print(f"pictures written to {out}")


if __name__ == "__main__":
    main()
