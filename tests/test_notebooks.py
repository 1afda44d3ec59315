"""The notebooks in notebooks/ (exploration, FreeCAD Path): executed headless with nbclient, exported to HTML and
opened offline in Chromium.  Also ``gcodekit notebook`` (from a built wheel: tests/test_packaging.py).
The worksheets are tested in tests/test_worksheets.py.
"""

import json
from pathlib import Path

import pytest

pytest.importorskip("anywidget")
pytest.importorskip("nbclient")

import nbformat  # noqa: E402

from gcodekit.widgets.export import WIDGET_VIEW, execute, offline_html  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"

ALL = ["explore.ipynb", "freecad_path.ipynb"]  # the worksheets: tests/test_worksheets.py


def _outputs(nb):
    return [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]


@pytest.fixture(scope="module")
def executed():
    """Every notebook executed once (name -> notebook)."""
    done = {}
    for name in ALL:
        path = NOTEBOOKS / name
        done[name] = execute(nbformat.read(path, as_version=4), path.parent)
    return done


@pytest.mark.parametrize("name", ALL)
def test_notebook_runs_and_its_widgets_carry_pictures(executed, name):
    nb = executed[name]
    outputs = _outputs(nb)
    assert not [o for o in outputs if o.output_type == "error"]
    widgets = [o for o in outputs if WIDGET_VIEW in o.get("data", {})]
    assert widgets and all(o.data["image/png"] for o in widgets)
    assert "widgets" in nb.metadata  # their state is kept: JupyterLab shows them when the file is opened


def test_html_shows_every_picture_offline(executed, tmp_path):
    from jupyter_browser import browser_page, chromium_path

    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    pages = {}
    for name, nb in executed.items():
        html = offline_html(nb)
        assert "https://" not in "".join(line for line in html.splitlines() if "<script" in line)
        pages[name] = tmp_path / (Path(name).stem + ".html")
        pages[name].write_text(html, encoding="utf-8")
    with browser_page() as page:
        page.context.set_offline(True)
        for name, file in pages.items():
            nb = executed[name]
            page.goto(file.as_uri())
            page.wait_for_load_state("load")
            sizes = page.evaluate("[...document.images].map(i => [i.naturalWidth, i.naturalHeight])")
            pictures = sum("image/png" in o.get("data", {}) for o in _outputs(nb))
            assert len(sizes) >= pictures and all(w > 100 and h > 100 for w, h in sizes), (name, sizes)
            # no widget output left blank: every widget view was replaced by its picture
            assert page.locator(".jupyter-widgets, script[type='application/vnd.jupyter.widget-view+json']").count() == 0
        assert page.console_errors == []


def test_gcodekit_notebook_writes_a_runnable_notebook(tmp_path):
    from gcodekit.cli import main

    out = tmp_path / "bracket.ipynb"
    assert main(["notebook", str(ROOT / "examples" / "bracket_mill.ngc"), "-o", str(out), "--html"]) == 0
    nb = json.loads(out.read_text())
    source = "".join(nb["cells"][1]["source"])
    assert "bracket_mill.ngc" in source and "machine = None" in source
    outputs = [o for c in nb["cells"] if c["cell_type"] == "code" for o in c["outputs"]]
    assert not [o for o in outputs if o["output_type"] == "error"]
    assert sum(WIDGET_VIEW in o.get("data", {}) for o in outputs) == 3  # viewer, plot, stages
    assert (tmp_path / "bracket.html").stat().st_size > 50_000
    assert main(["notebook", str(ROOT / "examples" / "bracket_mill.ngc"), "-o", str(out)]) == 2  # kept
    assert main(["notebook", str(tmp_path / "missing.ngc"), "-o", str(tmp_path / "m.ipynb")]) == 2
