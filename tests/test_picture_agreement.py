"""One program, one colouring, one camera: the PyVista picture, the report's matplotlib figure and the
notebook viewer's screenshot agree pixel for pixel (within line width and antialiasing).

All three draw :class:`gcodekit.view.Toolpath` coloured by :class:`gcodekit.view.Coloring` through
:class:`gcodekit.view.Camera`; before, each built its own segments and palette (and the report its own arc
chords), so a print's features came out in other colours in the report than in the notebook.  The WebGL
viewer's canvas is compared in the browser test (tests/test_widgets_browser.py).  How: tests/picture_compare.py.
"""

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyvista")
pytest.importorskip("anywidget")

import gcodekit  # noqa: E402
from gcodekit import visualize  # noqa: E402
from gcodekit.report import figures  # noqa: E402
from gcodekit.view import PALETTE, Toolpath  # noqa: E402
from gcodekit.widgets import LayerViewer  # noqa: E402
from gcodekit.widgets.picture import to_rgb  # noqa: E402
from picture_compare import agreement, foreground, ink_direction  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def layered_print(layers: int = 5) -> str:
    """A 20 mm square tower, 2 mm a layer: outer wall, inner wall, an arc of infill, travel between."""
    lines = ["M83", "G21 G90", "G1 Z2 F600"]
    for k in range(layers):
        z = 2.0 * (k + 1)
        lines += [";LAYER_CHANGE", f";Z:{z:g}", f"G1 Z{z:g} F600", "G0 X0 Y0 F6000", ";TYPE:External perimeter",
                  "G1 X20 Y0 E1 F1800", "G1 X20 Y20 E1", "G1 X0 Y20 E1", "G1 X0 Y0 E1", "G0 X3 Y3",
                  ";TYPE:Perimeter", "G1 X17 Y3 E1", "G1 X17 Y17 E1", "G1 X3 Y17 E1", "G1 X3 Y3 E1", "G0 X5 Y10",
                  ";TYPE:Solid infill", "G2 X15 Y10 I5 J0 E1"]
    return "\n".join(lines) + "\n"

#: The report's toolpath figure is 800 x 500 pixels; its view (left of the legend) 78 % of the width.
WIDTH, HEIGHT, VIEW = 800, 500, 624


def three_pictures(op, color_by: str, travel: bool):
    drawing = figures.toolpath_drawing(op, color_by)
    report = to_rgb(figures.toolpath_iso(drawing))[:, :VIEW]
    camera = visualize.fitted_camera("iso", drawing.path, VIEW / HEIGHT)  # what the report's view uses
    pyvista = visualize.plot_operation(op, color_by, camera=camera, window_size=(VIEW, HEIGHT), scalar_bar=False,
                                       show_travel=travel, line_width=1.0)
    viewer = LayerViewer(op, color_by, show_travel=travel)
    viewer.view.camera = camera.as_dict()  # as the browser sends it after a drag
    widget = to_rgb(viewer.figure(size=(WIDTH, HEIGHT)))[:, :VIEW]
    return report, pyvista, widget


@pytest.fixture(scope="module")
def tower():
    return gcodekit.gcode_to_operation(layered_print(), "marlin")


@pytest.fixture(scope="module")
def mill():
    return gcodekit.gcode_to_operation(EXAMPLES / "bracket_mill.ngc")


@pytest.mark.parametrize("program, color_by, travel", [
    ("tower", "feature", False),  # categories, an arc in chords
    ("mill", "feed", True),  # viridis, arcs in chords, rapids grey
])
def test_pyvista_report_and_viewer_agree(program, color_by, travel, request):
    op = request.getfixturevalue(program)
    report, pyvista, widget = three_pictures(op, color_by, travel)
    for other, label in ((pyvista, "PyVista"), (widget, "viewer screenshot")):
        result = agreement(report, other)
        print(f"{program}, {color_by}: report against {label}: {result}")
        assert result.iou > 0.8, f"{label}: {result}"
        assert result.matched > 1000 and result.median_angle < 8 and result.within_10 > 0.9, f"{label}: {result}"


def test_a_feature_is_the_same_colour_in_every_picture(tower):
    """The outer wall is the same palette colour in all three (it was tab10's third colour in two of them
    and a colormap sampled at its ends in the third)."""
    from gcodekit.view import coloring

    index = coloring(Toolpath.of(tower), "feature").categories.index("External perimeter")
    colour = np.array([int(PALETTE[index][i:i + 2], 16) for i in (1, 3, 5)], float)
    expected = (255 - colour) / np.linalg.norm(255 - colour)
    for image, label in zip(three_pictures(tower, "feature", False), ("report", "PyVista", "viewer screenshot")):
        ink = foreground(image)
        close = np.degrees(np.arccos(np.clip(ink_direction(image)[ink] @ expected, -1, 1))) < 12
        print(f"{label}: {close.mean():.2f} of the ink is the outer wall's colour")
        assert close.mean() > 0.3, label  # the outer wall is half of the lines' length


def test_a_different_camera_disagrees(mill):
    """The comparison can fail: the same program seen from the top is another picture."""
    report, _, _ = three_pictures(mill, "feed", True)
    path = Toolpath.of(mill)
    top = visualize.plot_operation(mill, "feed", camera=visualize.fitted_camera("top", path, VIEW / HEIGHT),
                                   window_size=(VIEW, HEIGHT), scalar_bar=False, show_travel=True, line_width=1.0)
    assert agreement(report, top).iou < 0.4


def test_a_dense_print_agrees_in_outline(request):
    """A 100-layer cube: lines a pixel apart, so colours mix differently with each renderer's line width and
    antialiasing; the outline still agrees (the colours are quoted, not bound)."""
    op = gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode")
    report, pyvista, widget = three_pictures(op, "feature", False)
    for other, label in ((pyvista, "PyVista"), (widget, "viewer screenshot")):
        result = agreement(report, other)
        print(f"cube20, feature: report against {label}: {result}")
        assert result.iou > 0.9, f"{label}: {result}"
