"""Off-screen pictures: numbers about the pixels first (STYLE.md item 13), no display needed."""

from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit import visualize

pytest.importorskip("pyvista")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
WHITE = 255


def part_pixels(image: np.ndarray) -> np.ndarray:
    """Mask of the non-background pixels left of the colour bar (the right 12 %)."""
    left = image[:, : int(image.shape[1] * 0.85)]
    return np.any(left < WHITE - 10, axis=2)


def check_picture(image: np.ndarray, min_colours: int) -> None:
    mask = part_pixels(image)
    assert mask.mean() > 0.08, "the part covers too little of the frame"
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    # the part fills the frame: its bounding box spans most of the picture
    assert (rows[-1] - rows[0]) > 0.6 * image.shape[0]
    assert (cols[-1] - cols[0]) > 0.5 * mask.shape[1]
    colours = np.unique((image[:, : mask.shape[1]][mask] // 32).reshape(-1, 3), axis=0)
    assert len(colours) >= min_colours


@pytest.fixture(scope="module")
def cube():
    return gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode")


@pytest.fixture(scope="module")
def dome():
    return gcodekit.gcode_to_operation(EXAMPLES / "dome_ded_beckhoff.nc")


def test_cube_render(cube, tmp_path):
    png = tmp_path / "cube.png"
    image = visualize.plot_operation(cube, "feature", screenshot=png, window_size=(600, 450))
    assert png.stat().st_size > 10_000
    assert image.shape == (450, 600, 3)
    check_picture(image, min_colours=5)  # feature colours and the bar


def test_dome_render_with_tool_vectors(dome, tmp_path):
    image = visualize.plot_operation(dome, "layer", tool_vectors=True, window_size=(600, 450))
    check_picture(image, min_colours=8)  # a viridis ramp over 20 layers, red arrows
    arrows = (image[..., 0] > 100) & (image[..., 1] < 60) & (image[..., 2] < 60)
    assert arrows.sum() > 200


def test_top_view_is_square_for_a_cube(cube):
    image = visualize.plot_operation(cube, "speed", camera="top", window_size=(600, 600), scalar_bar=False)
    mask = np.any(image < WHITE - 10, axis=2)
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    assert (rows[-1] - rows[0]) == pytest.approx(cols[-1] - cols[0], rel=0.05)


def test_bad_choices_are_named(cube):
    with pytest.raises(ValueError, match="camera"):
        visualize.plot_operation(cube, camera="fisheye")
    with pytest.raises(ValueError, match="did you mean 'speed'"):
        visualize.plot_operation(cube, "sped")


def test_layer_plot_draws_the_layer_moves(cube):
    import matplotlib

    matplotlib.use("Agg")
    from gcodekit.analysis import layers

    ax = visualize.plot_layer(cube, 10)
    w = cube.waypoints
    moves = (layers(cube) == 10) & (w["de"] > 0) & (w["distance"] > 0)
    work = ax.collections[0]
    assert len(work.get_segments()) == moves.sum()
    x0, x1 = ax.get_xlim()
    assert x0 < w["x"][moves].min() and x1 > w["x"][moves].max()
    with pytest.raises(ValueError, match="layer 1000"):
        visualize.plot_layer(cube, 1000)


def test_import_does_not_load_the_plotting_libraries():
    import subprocess
    import sys

    code = "import sys, gcodekit.visualize; print(any(m in sys.modules for m in ('pyvista', 'vtk', 'matplotlib')))"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip() == "False"


def test_one_value_gets_a_swatch_not_a_scale_over_an_invented_range():
    # every cut at F500: the legend says so, in the colour the moves are drawn in; two feeds get a colour bar
    import matplotlib
    import matplotlib.colors

    matplotlib.use("Agg")
    from gcodekit.report import figures

    one = gcodekit.gcode_to_operation("G21 G90 G0 X0 Y0 Z1\nG1 Z-1 F500\nG1 X10\nG1 Y10\nM2\n", "linuxcnc")
    drawing = figures.toolpath_drawing(one)
    fig = figures.toolpath_iso(drawing)
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["every move: 500"]
    assert legend.get_title().get_text() == drawing.color.title
    swatch = legend.legend_handles[0].get_facecolor()[:3]
    np.testing.assert_allclose(swatch, drawing.color.rgb(np.array([500.0]), 500.0, 500.0)[0], atol=1e-6)
    assert len(fig.axes) == 1  # the picture alone: no colour bar axes
    two = gcodekit.gcode_to_operation("G21 G90 G0 X0 Y0 Z1\nG1 Z-1 F500\nG1 X10\nG1 Y10 F800\nM2\n", "linuxcnc")
    fig = figures.toolpath_iso(figures.toolpath_drawing(two))
    assert not fig.legends and len(fig.axes) == 2
    assert fig.axes[1].get_ylim() == (500.0, 800.0)


def test_a_layer_of_one_speed_gets_a_swatch_too():
    import matplotlib

    matplotlib.use("Agg")
    op = gcodekit.gcode_to_operation("G21 G90 M83\nG1 Z0.2 F1200\nG1 X10 E1\nG1 Y10 E1\nG1 X0 E1\n", "marlin")
    ax = visualize.plot_layer(op, 0, scalars="feed")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["every move: 1200"]
    assert len(ax.figure.axes) == 1
