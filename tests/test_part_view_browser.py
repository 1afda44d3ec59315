"""The live part view in a real browser: JupyterLab started here, Playwright in Debian's Chromium.

A notebook shows the bracket example's cut part in :class:`gcodekit.widgets.PartView`
(PyVista's trame backend, vtk.js in the browser).  The part must show (its
pixels), turn when dragged, and follow the move slider; the time from a key
press on the slider to the new picture is printed (and kept in
``part_view_timing.txt`` in the test's folder).
"""

import json
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("jupyterlab")
pytest.importorskip("playwright")
pytest.importorskip("trame_pyvista")

from jupyter_browser import (browser_page, chromium_path, jupyter_lab, open_and_run, shot_when, trame_view,  # noqa: E402
                             wait_for_picture)

ROOT = Path(__file__).resolve().parents[1]

CELLS = [
    "import gcodekit\nfrom gcodekit.cut import ToolLibrary\nfrom gcodekit.widgets import PartView",
    "op = gcodekit.gcode_to_operation('examples/bracket_mill.ngc')\n"
    "view = PartView(op, tools=ToolLibrary.read('examples/tools/bracket_mill.toml'), size=(700, 460))\nview",
]


def _notebook(path: Path) -> None:
    cells = [{"cell_type": "code", "metadata": {}, "execution_count": None, "outputs": [], "source": c}
             for c in CELLS]
    path.write_text(json.dumps({"cells": cells, "metadata": {"kernelspec": {"name": "python3",
                                                                            "display_name": "Python 3"}},
                                "nbformat": 4, "nbformat_minor": 5}))


def ink(image) -> np.ndarray:
    return image.min(axis=2) < 235


def cut_colour(image) -> np.ndarray:
    """Pixels of cut surfaces: viridis' greens and blues (uncut stock is its yellow end, the page white).

    The colour bar at the right is left out."""
    image = image[:, : int(0.85 * image.shape[1])]
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (b > r + 30) & (b > 60)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    root = tmp_path_factory.mktemp("lab")
    shutil.copytree(ROOT / "examples", root / "examples")
    _notebook(root / "part.ipynb")
    with jupyter_lab(root) as url, browser_page() as page:
        open_and_run(page, url, "part.ipynb")
        yield page, root


def test_part_shows_turns_and_follows_the_slider(lab):
    page, root = lab
    area, frame = trame_view(page, "part")
    # the whole program cut: a plate with cuts in it, drawn in the browser
    first = shot_when(frame, lambda picture: ink(picture).mean() > 0.05 and cut_colour(picture).mean() > 0.005)
    assert ink(first).mean() > 0.05, "the part does not show"
    assert cut_colour(first).mean() > 0.005, "no cut surfaces show"

    # a drag turns it (in the browser: the kernel is not asked)
    box = frame.bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(cx, cy)
    page.mouse.down()
    page.mouse.move(cx + 160, cy + 40, steps=12)
    page.mouse.up()
    turned, _ = wait_for_picture(frame, first, timeout_s=20)
    assert np.mean(np.any(np.abs(turned - first) > 30, axis=2)) > 0.02

    # the slider: Home shows the stock before the first cut, End the whole part again
    handle = area.locator(".widget-slider .noUi-handle, .widget-slider .slider-handle").first
    handle.focus()
    start = time.perf_counter()
    page.keyboard.press("Home")
    area.locator(".gcodekit-part-status[data-move='1']").wait_for(state="attached", timeout=60_000)
    uncut, waited = wait_for_picture(frame, turned)
    step_s = time.perf_counter() - start - 0.5
    assert cut_colour(uncut).mean() < 0.2 * cut_colour(turned).mean()
    page.keyboard.press("End")
    area.locator(".gcodekit-part-status[data-move='43']").wait_for(state="attached", timeout=60_000)
    again, _ = wait_for_picture(frame, uncut)
    assert cut_colour(again).mean() > 0.5 * cut_colour(turned).mean()
    # one step back from the end: cut again from the state kept before it, not from the start
    start_step = time.perf_counter()
    page.keyboard.press("ArrowLeft")
    area.locator(".gcodekit-part-status[data-move='42']").wait_for(state="attached", timeout=60_000)
    one_step_s = time.perf_counter() - start_step
    (root / "part_view_timing.txt").write_text(f"Home (to move 1): {step_s:.2f} s; one step back: "
                                               f"{one_step_s:.2f} s (status)\n")
    print(f"slider step to new picture: Home {step_s:.2f} s (picture polled), one step back {one_step_s:.2f} s")
