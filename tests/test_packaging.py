"""What a user gets from ``pip install gcodekit[...]``: a built wheel, installed in a fresh virtual environment.

The wheel must carry everything the commands read at run time (flavors,
machine presets, report and notebook templates, widget scripts, the
``py.typed`` marker), and ``gcodekit report --notebook`` and ``gcodekit
notebook`` must run from it, not only from this checkout.  The fresh
environment borrows the test environment's third-party libraries through a
``.pth`` file (installing VTK and Jupyter again would need the network and
minutes) but has its own gcodekit, installed from the wheel.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_folder_is_in_the_wheel_list():
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    folders = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "gcodekit").rglob("__init__.py")}
    assert folders | {"gcodekit.reports"} == listed


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(python, gcodekit command) of a fresh virtual environment with the wheel installed."""
    pytest.importorskip("nbclient")
    tmp = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w",
                    str(tmp / "dist"), str(ROOT)], check=True, capture_output=True)
    wheel = next((tmp / "dist").glob("gcodekit-*.whl"))
    env = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(env)], check=True)
    python = env / "bin" / "python"
    site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               check=True, capture_output=True, text=True).stdout.strip())
    (site / "borrowed.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")  # numpy, pandas, VTK, Jupyter ...
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "-q", str(wheel)],
                   check=True, capture_output=True)
    return python, env / "bin" / "gcodekit", wheel


def test_the_wheel_holds_the_data_files(installed):
    _, _, wheel = installed
    names = set(zipfile.ZipFile(wheel).namelist())
    assert {"gcodekit/py.typed", "gcodekit/reports/program_report.ipynb", "gcodekit/reports/program.html",
            "gcodekit/reports/style.css", "gcodekit/syntax/flavors/marlin.toml", "gcodekit/emulate/machines/linuxcnc.toml",
            "gcodekit/widgets/static/viewer.js"} <= names
    assert not any(n.startswith(("tests/", "notebooks/", "reports/")) for n in names)


def test_the_installed_package_is_the_wheel_and_has_one_version(installed, tmp_path):
    python, _, _ = installed
    out = subprocess.run([str(python), "-I", "-c", "import gcodekit, importlib.metadata as m; "
                          "print(gcodekit.__file__); print(gcodekit.__version__, m.version('gcodekit'))"],
                         check=True, capture_output=True, text=True, cwd=tmp_path).stdout.split()
    assert not out[0].startswith(str(ROOT / "gcodekit")) and out[1] == out[2]


def test_report_with_notebook_runs_from_the_wheel(installed, tmp_path):
    python, gcodekit, _ = installed
    program = tmp_path / "cube.gcode"
    shutil.copy(ROOT / "examples" / "cube20_prusaslicer_marlin.gcode", program)
    env = {**os.environ, "PYTHONNOUSERSITE": "1", "VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRenderWindow",
           "PATH": f"{gcodekit.parent}:{os.environ['PATH']}"}  # the notebook's kernel is this environment's python
    done = subprocess.run([str(gcodekit), "report", str(program), "-o", str(tmp_path / "out"), "--notebook",
                           "--no-pdf"], env=env, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    notebook = json.loads((tmp_path / "out" / "cube.gcode.ipynb").read_text())
    outputs = [o for c in notebook["cells"] if c["cell_type"] == "code" for o in c["outputs"]]
    assert outputs and not [o for o in outputs if o["output_type"] == "error"]
    # PrusaSlicer sliced this 20 mm cube in 100 layers of 0.2 mm; the page and the notebook say so
    assert "Layers</th><td>100" in (tmp_path / "out" / "cube.gcode.html").read_text()
    assert any("100" in "".join(o.get("data", {}).get("text/plain", "")) for o in outputs)


def test_notebook_command_runs_from_the_wheel(installed, tmp_path):
    python, gcodekit, _ = installed
    program = tmp_path / "cube.gcode"
    shutil.copy(ROOT / "examples" / "cube20_prusaslicer_marlin.gcode", program)
    done = subprocess.run([str(gcodekit), "notebook", str(program), "-o", str(tmp_path / "cube.ipynb")],
                          cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "LayerViewer(op)" in (tmp_path / "cube.ipynb").read_text()


def test_plain_nbconvert_shows_widget_pictures_where_the_wheel_is_installed(installed, tmp_path):
    """The wheel's etc/jupyter config registers gcodekit's preprocessor: no widget view, no remote script."""
    import base64

    import nbformat
    from nbformat.v4 import new_code_cell, new_notebook, new_output

    python, _, wheel = installed
    names = zipfile.ZipFile(wheel).namelist()
    assert any(n.endswith(".data/data/etc/jupyter/jupyter_nbconvert_config.json") for n in names)
    assert any(n.endswith(".data/data/etc/jupyter/jupyter_server_config.d/gcodekit.json") for n in names)
    from gcodekit.widgets.picture import message_figure, to_png

    png = to_png(message_figure("a widget's picture"))
    view = {"version_major": 2, "version_minor": 0, "model_id": "m1"}
    output = new_output("display_data", {"application/vnd.jupyter.widget-view+json": view,
                                         "image/png": base64.b64encode(png).decode(), "text/plain": "<LayerViewer>"})
    nb = new_notebook(cells=[new_code_cell("LayerViewer(op)", outputs=[output], execution_count=1)])
    state = {"m1": {"model_name": "VBoxModel", "model_module": "@jupyter-widgets/controls",
                    "model_module_version": "2.0.0", "state": {}}}
    nb.metadata["widgets"] = {"application/vnd.jupyter.widget-state+json": {"version_major": 2, "version_minor": 0,
                                                                           "state": state}}
    nbformat.write(nb, tmp_path / "handin.ipynb")
    done = subprocess.run([str(python), "-m", "nbconvert", "--to", "html", "handin.ipynb"], cwd=tmp_path,
                          capture_output=True, text=True,
                          # nbconvert's templates are data of the borrowed environment; its config is the wheel's
                          env={**os.environ, "PYTHONNOUSERSITE": "1", "JUPYTER_PATH": f"{sys.prefix}/share/jupyter"})
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "handin.html").read_text()
    assert page.count('src="data:image/png;base64,') == 1
    assert "widget-view+json" not in page and not re.search(r"<script[^>]*\ssrc=\"https?:", page)


def test_freecad_path_api_runs_from_the_wheel(installed, tmp_path):
    """gcodekit.path (a front end) ships: a job post-processed and pre-processed from the installed wheel."""
    python, _, _ = installed
    script = ("import gcodekit.path as Path\n"
              "job = Path.Job(tooltable=Path.Tooltable([Path.Tool('e', tooltype='EndMill', diameter=3)]))\n"
              "job.add(Path.Path('G0 Z5 G1 X10 F100 G2 X10 Y0 I-5 J0'), tool=1)\n"
              "text = Path.post_process(job, 'fanuc')\n"
              "print(Path.__file__); print(round(Path.read(text, machine='fanuc').Length, 4))\n")
    out = subprocess.run([str(python), "-I", "-c", script], check=True, capture_output=True, text=True,
                         cwd=tmp_path).stdout.split()
    assert not out[0].startswith(str(ROOT / "gcodekit"))
    assert float(out[1]) == pytest.approx(5 + 10 + 10 * 3.141592653589793, abs=1e-3)  # up, along, a whole circle
