"""The widgets in a real browser: JupyterLab started here, driven by Playwright in Debian's Chromium.

explore.ipynb is run; then the layer slider, the move slider, the colour
dropdown and the stage dropdowns are used with the keyboard and the mouse as
a person would, and each time the picture's pixels must show what was asked.
Then a program with HTML planted in its ``;TYPE:`` comments is opened: the
markup must show as text and run nothing, and the WebGL canvas must agree
with the PyVista and matplotlib pictures of the same program and camera.
"""

import io
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("anywidget")
pytest.importorskip("jupyterlab")
pytest.importorskip("playwright")

from jupyter_browser import browser_page, chromium_path, jupyter_lab, open_and_run  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
GREEN = (44, 160, 44)  # the external perimeter's colour when coloured by feature
# StageDiff's left stage (#1f77b4 at 45 % over white) and right stage (#ff7f0e)
PALE_BLUE, ORANGE = (154, 194, 221), (255, 127, 14)


def pixels(locator) -> np.ndarray:
    """What an element shows: a canvas's own drawing (not the legend laid over it), else a screenshot."""
    import base64

    from PIL import Image

    if locator.evaluate("e => e.tagName") == "CANVAS":
        url = locator.evaluate("c => c.toDataURL('image/png')")
        data = base64.b64decode(url.split(",", 1)[1])
    else:
        data = locator.screenshot()
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"), dtype=int)


def ink(image) -> np.ndarray:
    return image.min(axis=2) < 235


def near(image, rgb, tolerance=40) -> np.ndarray:
    return np.all(np.abs(image - np.array(rgb)) < tolerance, axis=2)


def ink_height(image) -> int:
    rows = np.flatnonzero(ink(image).any(axis=1))
    return int(rows[-1] - rows[0]) if rows.size else 0


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    root = tmp_path_factory.mktemp("lab")
    shutil.copytree(ROOT / "notebooks", root / "notebooks")
    shutil.copytree(ROOT / "examples", root / "examples")
    with jupyter_lab(root) as url, browser_page() as page:
        open_and_run(page, url, "notebooks/explore.ipynb")
        page.lab_url, page.lab_root = url, root
        yield page


def wait_status(area, text: str, selector: str = ".gk-status") -> None:
    try:
        area.locator(f"{selector}:has-text('{text}')").wait_for(state="attached", timeout=30_000)
    except Exception as exc:
        raise AssertionError(f"waited for {text!r}; the view says {area.locator(selector).inner_text()!r}") from exc


def test_layer_and_move_sliders_and_colours(lab):
    page = lab
    area = page.locator(".jp-OutputArea-child:has(.gcodekit-viewer)")
    canvas = area.locator(".gcodekit-viewer canvas")
    # the notebook left the viewer on layer 20 coloured by speed
    wait_status(area, "layer 20 · move")
    one = pixels(canvas)
    handles = area.locator(".noUi-handle")
    handles.nth(0).focus()
    page.keyboard.press("Home")
    handles.nth(1).focus()
    page.keyboard.press("End")
    wait_status(area, "layer 0 to layer 99 · move")
    page.wait_for_timeout(300)
    whole = pixels(canvas)
    assert ink(whole).sum() > 2 * ink(one).sum()  # a one-layer picture is not the whole part
    assert ink_height(whole) > 1.4 * ink_height(one)

    # steps down the part are drawn from the pictures kept at checkpoints: the same as drawn afresh
    for _ in range(3):
        page.keyboard.press("ArrowLeft")
    wait_status(area, "layer 0 to layer 96 · move")
    page.wait_for_timeout(300)
    stepped = pixels(canvas)
    travel = area.locator("input[type=checkbox]").first
    travel.click()
    travel.click()  # travel shown and hidden again: everything drawn anew
    page.wait_for_timeout(800)
    assert np.mean(np.any(stepped != pixels(canvas), axis=2)) < 0.001
    handles.nth(1).focus()
    page.keyboard.press("End")
    wait_status(area, "layer 0 to layer 99 · move")

    # the move slider: back to the first move of the top layer, then three steps with the keyboard
    code = area.locator(".gcodekit-code")
    last_line = int(code.get_attribute("data-line"))
    handles.nth(2).focus()
    page.keyboard.press("Home")
    wait_status(area, "· move 1 of")
    first = pixels(canvas)
    for _ in range(3):
        page.keyboard.press("ArrowRight")
    wait_status(area, "· move 4 of")
    assert ink(first).sum() < ink(whole).sum()  # the top layer is only begun
    page.wait_for_function("(l) => +document.querySelector('.gcodekit-code').dataset.line < l", arg=last_line,
                           timeout=30_000)  # the source line beside the view follows, back up the program

    # a new colouring changes the colours
    page.keyboard.press("End")
    wait_status(area, "layer 0 to layer 99 · move")
    by_speed = pixels(canvas)
    area.locator("select").first.select_option("feature")
    area.locator(".gk-legend:has-text('External perimeter')").wait_for(timeout=30_000)
    page.wait_for_timeout(300)
    by_feature = pixels(canvas)
    assert near(by_feature, GREEN).sum() > 500
    assert near(by_speed, GREEN).sum() < near(by_feature, GREEN).sum() / 4

    # the linked plot followed the range; hovering a point names its move and line, clicking one moves the viewer
    plot_area = page.locator(".jp-OutputArea-child:has(.gcodekit-velocity)")
    assert "every corner" not in plot_area.locator(".gk-plot-status").inner_text()  # whole part: envelope per bin
    plot_canvas = plot_area.locator("canvas")
    plot_canvas.hover(position={"x": 400, "y": 150})
    tip = plot_area.locator(".gk-tip")
    assert " · move " in tip.inner_text() and " · line " in tip.inner_text()
    plot_canvas.click(position={"x": 400, "y": 150})
    picked = plot_area.locator(".gcodekit-picked")
    picked.wait_for(timeout=30_000)
    move = int(picked.inner_text().split(",")[0].removeprefix("move "))
    assert f"move {move}" in tip.inner_text()
    page.wait_for_function("() => !document.querySelector('.gk-status').textContent.startsWith('layer 0 to layer 99')",
                           timeout=30_000)  # the viewer went to that move's layer

    # play steps through the moves of the top layer
    before = area.locator(".gk-status").inner_text()
    area.locator(".jupyter-widgets button").first.click()  # play
    page.wait_for_function("(t) => document.querySelector('.gk-status').textContent !== t", arg=before,
                           timeout=30_000)
    area.locator(".jupyter-widgets button").nth(1).click()  # stop
    assert page.console_errors == []


def test_stage_dropdowns(lab):
    page = lab
    area = page.locator(".jp-OutputArea-child:has(.gcodekit-diff)")
    summary = area.locator(".gcodekit-diff-summary")
    assert " changed" in summary.inner_text() and not summary.inner_text().startswith("0 changed")
    image = area.locator("img").first

    def apart(picture) -> int:
        """Pixels of the left stage with no pixel of the right stage within 6 px (where the paths differ)."""
        right = near(picture, ORANGE, 60)
        grown = right.copy()
        for dy in range(-6, 7):
            for dx in range(-6, 7):
                grown |= np.roll(np.roll(right, dy, axis=0), dx, axis=1)
        below_legend = slice(int(picture.shape[0] * 0.2), None)
        return int((near(picture, PALE_BLUE, 30) & ~grown)[below_legend].sum())

    before = pixels(image)
    area.locator("select").first.select_option(label="6: canned cycles")
    page.wait_for_function("() => document.querySelector('.gcodekit-diff-summary').textContent"
                           ".startsWith('0 changed, 0 only left, 0 only right')", timeout=30_000)
    page.wait_for_timeout(500)
    after = pixels(image)
    assert apart(before) > 200  # stage 0 in program coordinates: the boss's circle is elsewhere
    assert apart(after) < apart(before) / 5  # the same stage on both sides: one path
    assert page.console_errors == []


# -- program text is text; the WebGL picture is the other pictures' picture ------------------------

#: Markup a slicer comment could carry: run, it would set a flag on the page or add an element to it.
PLANTED = ("<img src=x onerror=window.gkPlanted=1>", "<b id=gk-planted>bold</b>")


def planted_program(layers: int = 5) -> str:
    """A 20 mm square tower, 2 mm a layer, whose two features are named by markup (and its last line ends
    with markup in a comment: the line the source panel shows)."""
    lines = ["M83", "G21 G90", "G1 Z2 F600"]
    for k in range(layers):
        z = 2.0 * (k + 1)
        lines += [";LAYER_CHANGE", f";Z:{z:g}", f"G1 Z{z:g} F600", "G0 X0 Y0 F6000", f";TYPE:{PLANTED[0]}",
                  "G1 X20 Y0 E1 F1800", "G1 X20 Y20 E1", "G1 X0 Y20 E1", "G1 X0 Y0 E1", "G0 X5 Y10",
                  f";TYPE:{PLANTED[1]}", "G2 X15 Y10 I5 J0 E1"]
    lines[-1] += " ; <img src=x onerror=window.gkPlanted=2>"
    return "\n".join(lines) + "\n"


def test_planted_markup_is_text_and_the_canvas_agrees(lab):
    import json
    import sys

    import gcodekit
    from gcodekit import visualize
    from gcodekit.view import Toolpath, coloring
    from gcodekit.widgets.picture import new_figure, to_rgb

    sys.path.insert(0, str(ROOT / "tests"))
    from picture_compare import agreement

    page, root = lab, lab.lab_root
    (root / "planted.gcode").write_text(planted_program())
    op = gcodekit.gcode_to_operation(root / "planted.gcode")
    path = Toolpath.of(op)
    camera = visualize.fitted_camera("iso", path, 1.0)
    cell = ("import gcodekit\nfrom gcodekit.widgets import LayerViewer\n"
            "viewer = LayerViewer('planted.gcode', color_by='feature', height=420)\n"
            f"viewer.view.camera = {camera.as_dict()!r}\nviewer")
    notebook = {"cells": [{"cell_type": "code", "metadata": {}, "execution_count": None, "outputs": [],
                           "source": cell}],
                "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"}},
                "nbformat": 4, "nbformat_minor": 5}
    (root / "planted.ipynb").write_text(json.dumps(notebook))
    open_and_run(page, page.lab_url, "planted.ipynb")
    area = page.locator(".jp-NotebookPanel:not(.lm-mod-hidden) .jp-OutputArea-child:has(.gcodekit-viewer)")
    legend = area.locator(".gk-legend")
    legend.locator(".gk-category").nth(1).wait_for(timeout=60_000)
    page.wait_for_timeout(500)

    # nothing ran, no element was made: the names are the legend's text, character for character
    assert page.evaluate("window.gkPlanted") is None
    assert page.locator("#gk-planted").count() == 0
    assert legend.locator("img, b").count() == 0
    assert [legend.locator(".gk-category").nth(k).inner_text() for k in range(2)] == sorted(PLANTED)
    # coloured by feed, every deposit at F1800: a swatch that says so, as the pictures say it (no scale)
    area.locator("select").first.select_option("feed")
    legend.locator(".gk-one-value").wait_for(timeout=30_000)
    assert legend.locator(".gk-one-value").inner_text() == "every move: 1800"
    area.locator("select").first.select_option("feature")
    legend.locator(".gk-category").nth(1).wait_for(timeout=30_000)
    page.wait_for_timeout(500)
    code = area.locator(".gcodekit-code")
    assert "<img src=x onerror=window.gkPlanted=2>" in code.inner_text() and code.locator("img").count() == 0
    assert page.console_errors == []  # an <img src=x> made would have failed to load

    # the canvas against PyVista and matplotlib, same program, colouring and camera, at the canvas's size
    webgl = pixels(area.locator(".gcodekit-viewer canvas"))
    height, width = webgl.shape[:2]
    color = coloring(path, "feature")
    pyvista = visualize.plot_operation(op, "feature", camera=camera, window_size=(width, height), scalar_bar=False,
                                       line_width=1.0)
    fig = new_figure((width, height))
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    visualize.draw_toolpath(ax, path, color, camera, np.flatnonzero(path.kind == 0), work_width=0.75)
    matplotlib_picture = to_rgb(fig)
    for other, label in ((pyvista, "PyVista"), (matplotlib_picture, "matplotlib")):
        result = agreement(webgl, other)
        print(f"WebGL canvas ({width} x {height}) against {label}: {result}")
        assert result.iou > 0.8 and result.median_angle < 8 and result.within_10 > 0.85, f"{label}: {result}"
