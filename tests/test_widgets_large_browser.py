"""LayerViewer on a program larger than its budget, in a real browser: the overview and the layers sent on demand.

A tower of 30 layers (a circle of 240 short chords and a zigzag infill per
layer, about 9 000 segments) is opened with ``max_segments=2000``, so the
browser gets an overview of at most 2 000 chords and asks the kernel for the
top layer's own segments.  The canvas must then agree, pixel by pixel, with
matplotlib's picture of every segment of the same range and camera; a step
of the layer slider must bring that layer's segments (the view says it draws
the top layer in full, which only an answer from the kernel allows), and
the picture of the new range must agree again.  The test program is made
here (small and quick); ``benchmarks/bench_widgets.py`` measures the same
path on the 3 M-line plate.
"""

import json
import math
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("anywidget")
pytest.importorskip("jupyterlab")
pytest.importorskip("playwright")

from jupyter_browser import browser_page, chromium_path, jupyter_lab, open_and_run  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
LAYERS, BUDGET = 30, 2000


def tower(layers: int = LAYERS) -> str:
    """A 40 mm circle (240 chords) around a zigzag infill, 0.3 mm a layer, as a slicer writes it."""
    lines = ["M83", "G21 G90", "G28"]
    for k in range(layers):
        z = 0.3 * (k + 1)
        lines += [";LAYER_CHANGE", f";Z:{z:.1f}", f"G1 Z{z:.1f} F600", "G0 X20 Y0 F6000", ";TYPE:External perimeter"]
        for j in range(1, 241):
            a = 2 * math.pi * j / 240
            lines.append(f"G1 X{20 * math.cos(a):.4f} Y{20 * math.sin(a):.4f} E0.02 F1800")
        lines += ["G0 X-12 Y-12", ";TYPE:Internal infill"]
        for i in range(13):  # across and back, 2 mm apart, turned a quarter every other layer
            y = -12 + 2 * i
            ends = [(-12, y), (12, y)] if i % 2 == 0 else [(12, y), (-12, y)]
            if k % 2:
                ends = [(b, a) for a, b in ends]
            for x, yy in ends:
                lines.append(f"G1 X{x} Y{yy} E0.3")
    return "\n".join(lines) + "\n"


def pixels(locator) -> np.ndarray:
    import base64
    import io

    from PIL import Image

    url = locator.evaluate("c => c.toDataURL('image/png')")
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGB"), dtype=int)


def full_picture(path, lo: int, hi: int, camera, size: tuple[int, int]) -> np.ndarray:
    """matplotlib's picture of every work segment of layers lo..hi (no overview), at the canvas's size."""
    from gcodekit import visualize
    from gcodekit.view import coloring
    from gcodekit.widgets.picture import new_figure, to_rgb

    a, b = path.group_slice(lo, hi)
    keep = np.arange(a, b)
    keep = keep[path.kind[keep] == 0]
    fig = new_figure(size)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    visualize.draw_toolpath(ax, path, coloring(path, "feature"), camera, keep, work_width=0.75)
    return to_rgb(fig)


@pytest.fixture(scope="module")
def page_and_path(tmp_path_factory):
    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    import gcodekit
    from gcodekit import visualize
    from gcodekit.view import Toolpath

    root = tmp_path_factory.mktemp("large")
    (root / "tower.gcode").write_text(tower())
    op = gcodekit.gcode_to_operation(root / "tower.gcode")
    path = Toolpath.of(op)
    assert path.n_groups == LAYERS and path.n_segments > 4 * BUDGET  # the overview is needed
    camera = visualize.fitted_camera("iso", path, 1.0)
    cell = ("from gcodekit.widgets import LayerViewer\n"
            f"viewer = LayerViewer('tower.gcode', color_by='feature', height=420, max_segments={BUDGET})\n"
            f"viewer.view.camera = {camera.as_dict()!r}\nviewer")
    notebook = {"cells": [{"cell_type": "code", "metadata": {}, "execution_count": None, "outputs": [],
                           "source": cell}],
                "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"}},
                "nbformat": 4, "nbformat_minor": 5}
    (root / "tower.ipynb").write_text(json.dumps(notebook))
    with jupyter_lab(root) as url, browser_page() as page:
        # the bytes the kernel sends the page, to check the budget
        page.received = []
        page.on("websocket", lambda ws: ws.on("framereceived", lambda p: page.received.append(len(p)))
                if "/channels" in ws.url else None)
        open_and_run(page, url, "tower.ipynb")
        yield page, path, camera


def wait_full(page, text: str) -> None:
    """Until the view shows ``text`` with its top layer drawn from the layer's own segments."""
    page.wait_for_function(
        "(t) => { const s = document.querySelector('.gk-status');"
        " return s && s.textContent.startsWith(t) && s.dataset.detail === 'full'; }", arg=text, timeout=60_000)
    page.wait_for_timeout(300)


def check_agreement(page, path, camera, lo: int, hi: int) -> None:
    sys.path.insert(0, str(ROOT / "tests"))
    from picture_compare import agreement

    webgl = pixels(page.locator(".gcodekit-viewer canvas"))
    height, width = webgl.shape[:2]
    result = agreement(webgl, full_picture(path, lo, hi, camera, (width, height)))
    print(f"layers {lo}-{hi}: overview and detail in WebGL against every segment in matplotlib: {result}")
    assert result.iou > 0.8 and result.median_angle < 8 and result.within_10 > 0.85, result


def test_overview_then_the_top_layer_in_full(page_and_path):
    page, path, camera = page_and_path
    status = page.locator(".gk-status")
    wait_full(page, f"layer 0 to layer {LAYERS - 1}")
    assert "(layers below: overview)" in status.inner_text()
    # the overview's chords and the top layer's segments, no more
    drawn = int(status.get_attribute("data-segments"))
    a, b = path.group_slice(LAYERS - 1, LAYERS - 1)
    assert drawn <= BUDGET + (b - a) < path.n_segments
    check_agreement(page, path, camera, 0, LAYERS - 1)
    assert page.console_errors == []


def test_a_layer_step_brings_that_layer(page_and_path):
    page, path, camera = page_and_path
    status = page.locator(".gk-status")
    before = sum(page.received)
    page.locator(".noUi-handle-upper").first.focus()
    for _ in range(6):  # down to layer 23: neither the first top layer nor the one next to it
        page.keyboard.press("ArrowLeft")
    target = LAYERS - 7
    wait_full(page, f"layer 0 to layer {target}")
    # layer 23's segments came from the kernel when asked: at least their positions
    a, b = path.group_slice(target, target)
    assert sum(page.received) - before > (b - a) * 24
    check_agreement(page, path, camera, 0, target)
    # the move slider steps through the layer's own segments: its first move alone, then all of it
    page.locator(".jupyter-widgets .noUi-handle").nth(2).focus()
    page.keyboard.press("Home")
    wait_full(page, f"layer 0 to layer {target} · move 1 of {path.moves_in(target)}")
    page.keyboard.press("End")
    wait_full(page, f"layer 0 to layer {target} · move {path.moves_in(target)} of")
    assert page.console_errors == []
