"""The live bead view in a real browser: JupyterLab started here, Playwright in Debian's Chromium.

A notebook shows the bundled FFF example's beads in :class:`gcodekit.widgets.BeadView`
(shaded tubes from the part's bead geometry, PyVista's trame backend, vtk.js in
the browser).  The beads must show (their pixels, in the features' colours),
turn when dragged, and follow the move slider; the time from a key press on
the slider to the new picture is printed (and kept in ``bead_view_timing.txt``
in the test's folder).
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

from jupyter_browser import (browser_page, chromium_path, drag_turns, jupyter_lab, open_and_run, settled,  # noqa: E402
                             shot_when, trame_view, wait_for_picture)

ROOT = Path(__file__).resolve().parents[1]
PROGRAM = "cube20_prusaslicer_marlin.gcode"

CELLS = [
    "import gcodekit\nfrom gcodekit.widgets import BeadView",
    f"op = gcodekit.gcode_to_operation('examples/{PROGRAM}')\n"
    "view = BeadView(op, size=(700, 460))\nview",
]


def _notebook(path: Path) -> None:
    cells = [{"cell_type": "code", "metadata": {}, "execution_count": None, "outputs": [], "source": c}
             for c in CELLS]
    path.write_text(json.dumps({"cells": cells, "metadata": {"kernelspec": {"name": "python3",
                                                                            "display_name": "Python 3"}},
                                "nbformat": 4, "nbformat_minor": 5}))


def red(image) -> np.ndarray:
    """Pixels of the external perimeters: the palette's red (#d62728), shaded (the page is white)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (r > 70) & (r > 2 * g) & (r > 2 * b)


def ink(image) -> np.ndarray:
    return image.min(axis=2) < 235


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    root = tmp_path_factory.mktemp("lab")
    (root / "examples").mkdir()
    shutil.copy(ROOT / "examples" / PROGRAM, root / "examples" / PROGRAM)
    _notebook(root / "beads.ipynb")
    with jupyter_lab(root) as url, browser_page() as page:
        open_and_run(page, url, "beads.ipynb")
        yield page, root


def test_beads_show_turn_and_follow_the_slider(lab):
    import gcodekit
    from gcodekit.additive import AdditivePart, bead_tubes

    page, root = lab
    area, frame = trame_view(page, "bead")
    # every depositing move laid: the cube's walls, their outer perimeters red, drawn in the browser
    first = shot_when(frame, lambda picture: ink(picture).mean() > 0.08 and red(picture).mean() > 0.03)
    assert ink(first).mean() > 0.08, "the beads do not show"
    assert red(first).mean() > 0.03, "the external perimeters' colour does not show"
    # shaded, not flat: the red walls take many tones
    assert len(np.unique(first[red(first)] // 8, axis=0)) > 10

    # a drag turns it (in the browser: the kernel is not asked)
    first = settled(frame)
    turned = drag_turns(page, frame, first)
    assert np.mean(np.any(np.abs(turned - first) > 30, axis=2)) > 0.02
    assert ink(turned).mean() > 0.05

    # the slider's range: the moves that lay a bead
    part = AdditivePart(gcodekit.gcode_to_operation(ROOT / "examples" / PROGRAM))
    moves = np.unique(bead_tubes(part).triangle_row).size
    assert moves > 1000

    # the slider: Home shows the first move's bead only, End every bead again
    handle = area.locator(".widget-slider .noUi-handle, .widget-slider .slider-handle").first
    handle.focus()
    start = time.perf_counter()
    page.keyboard.press("Home")
    area.locator(".gcodekit-bead-status[data-move='1']").wait_for(state="attached", timeout=60_000)
    status_s = time.perf_counter() - start
    one, waited = wait_for_picture(frame, turned)
    home_s = time.perf_counter() - start - 0.5  # wait_for_picture lets the picture settle for 0.5 s
    assert ink(one).mean() < 0.2 * ink(turned).mean()
    start = time.perf_counter()
    page.keyboard.press("End")
    area.locator(f".gcodekit-bead-status[data-move='{moves}']").wait_for(state="attached", timeout=60_000)
    end_status_s = time.perf_counter() - start
    again, _ = wait_for_picture(frame, one)
    end_s = time.perf_counter() - start - 0.5
    assert ink(again).mean() > 0.8 * ink(turned).mean()
    assert red(again).mean() > 0.5 * red(turned).mean()
    # one step back: the status follows at once (the picture differs by one short bead)
    start = time.perf_counter()
    page.keyboard.press("ArrowLeft")
    area.locator(f".gcodekit-bead-status[data-move='{moves - 1}']").wait_for(state="attached", timeout=60_000)
    step_s = time.perf_counter() - start
    text = (f"Home (all {moves} moves to move 1): status {status_s:.2f} s, new picture {home_s:.2f} s; "
            f"End (back to all): status {end_status_s:.2f} s, new picture {end_s:.2f} s; "
            f"one step back: status {step_s:.2f} s\n")
    (root / "bead_view_timing.txt").write_text(text)
    print(text)
