"""The notebooks in notebooks/: executed headless with nbclient, exported to HTML and
opened offline in Chromium; the worksheets' exercises answered with values worked
out by hand, which their check cells must accept.  Also ``gcodekit notebook``
(from a built wheel: tests/test_packaging.py).
"""

import json
import math
from pathlib import Path

import pytest

pytest.importorskip("anywidget")
pytest.importorskip("nbclient")

import nbformat  # noqa: E402

from gcodekit.widgets.export import WIDGET_VIEW, execute, offline_html  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"

#: Answers worked out by hand (see each worksheet's program).
HAND_ANSWERS = {
    "01-what-the-controller-does": {
        # G1 X10 in G54 (origin X100 Y50) at Z-1 with a 25 mm tool
        "answer-1": (100 + 10, 50, -1 + 25),
        # two G91 steps X10 Y5 and X10 from X10 Y0
        "answer-2": (100 + 30, 50 + 5),
        # G20 G1 X1: 25.4 mm from the G54 origin
        "answer-3": 100 + 25.4,
    },
    "02-why-the-estimate-is-wrong": {
        # two ramps of v/a = 100/3000 s covering v^2/2a each, the rest at 100 mm/s
        "answer-1": 2 * 100 / 3000 + (100 - 100**2 / 3000) / 100,
        "answer-2": "planned",
    },
    "03-from-program-to-plain-moves": {
        "answer-1": 50 + 40 - 3,  # G54 origin + programmed side - tool radius (inside a CCW path)
        "answer-2": 1,  # an inside corner: no extra arc, one line
    },
    "04-beads-layers-and-heat": {
        "answer-1": 0.45 * 0.2 * 100,
        "answer-2": (math.sin(math.radians(30)), 0.0, math.cos(math.radians(30))),
    },
}

ALL = ["explore.ipynb", "freecad_path.ipynb"] + [f"worksheets/{name}.ipynb" for name in HAND_ANSWERS]


def _answered(path: Path):
    nb = nbformat.read(path, as_version=4)
    answers = HAND_ANSWERS.get(path.stem, {})
    for cell in nb.cells:
        for tag in cell.metadata.get("tags", []):
            if tag in answers:
                name = tag.replace("-", "_")
                assert cell.source.startswith(f"{name} = None"), cell.source
                cell.source = f"{name} = {answers[tag]!r}"
    return nb, len(answers)


def _outputs(nb):
    return [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]


@pytest.fixture(scope="module")
def executed():
    """Every notebook executed once with the hand answers filled in (name -> (notebook, answers))."""
    done = {}
    for name in ALL:
        path = NOTEBOOKS / name
        nb, answers = _answered(path)
        done[name] = (execute(nb, path.parent), answers)
    return done


@pytest.mark.parametrize("name", ALL)
def test_notebook_runs_and_its_widgets_carry_pictures(executed, name):
    nb, answers = executed[name]
    outputs = _outputs(nb)
    assert not [o for o in outputs if o.output_type == "error"]
    widgets = [o for o in outputs if WIDGET_VIEW in o.get("data", {})]
    assert widgets and all(o.data["image/png"] for o in widgets)
    checks = [o.data["text/plain"] for o in outputs if "gcodekit-check" in o.get("data", {}).get("text/html", "")]
    assert len(checks) == answers and all(text.startswith("Right") for text in checks), checks
    assert "widgets" in nb.metadata  # their state is kept: JupyterLab shows them when the file is opened


def test_html_shows_every_picture_offline(executed, tmp_path):
    from jupyter_browser import browser_page, chromium_path

    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    pages = {}
    for name, (nb, _) in executed.items():
        html = offline_html(nb)
        assert "https://" not in "".join(line for line in html.splitlines() if "<script" in line)
        pages[name] = tmp_path / (Path(name).stem + ".html")
        pages[name].write_text(html, encoding="utf-8")
    with browser_page() as page:
        page.context.set_offline(True)
        for name, file in pages.items():
            nb = executed[name][0]
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
