"""The level of detail of still pictures (gcodekit.view.lod): what it keeps, what it drops, and that a
picture drawn from it looks as the full drawing does, pixel by pixel."""

from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit import visualize
from gcodekit.view import Camera
from gcodekit.view.lod import last_drawn, painter_order, polylines
from shared_corpus import CORPUS as SHARED_CORPUS

CORPUS = SHARED_CORPUS / "fff"


# -- painter's order ------------------------------------------------------------------------------------------------

def test_from_above_the_lower_segments_come_first_and_program_order_stays_within_a_height():
    p0 = np.array([[0, 0, 2.0], [5, 5, 1.0], [9, 0, 2.0], [0, 9, 1.0]])
    p1 = p0 + [1.0, 0, 0]
    _, _, eye = Camera.named("iso").axes()
    assert painter_order(p0, p1, eye).tolist() == [1, 3, 0, 2]
    assert painter_order(p0, p1, -eye).tolist() == [0, 2, 1, 3]  # from below: the higher ones are farther


def test_a_horizontal_camera_orders_by_depth():
    _, _, eye = Camera.named("front").axes()  # looking along +Y: nearer is lower Y
    p0 = np.array([[0, 1.0, 0], [0, 5.0, 9], [0, -3.0, 4]])
    assert painter_order(p0, p0 + [1.0, 0, 0], eye).tolist() == [1, 0, 2]


# -- visibility -----------------------------------------------------------------------------------------------------

def test_a_segment_under_as_many_later_ones_as_the_depth_is_dropped():
    a = np.array([[1.0, 5.5], [1.0, 5.5], [1.0, 5.5]])
    b = np.array([[9.0, 5.5], [9.0, 5.5], [9.0, 5.5]])
    assert last_drawn(a, b, 20, 20, depth=1).tolist() == [False, False, True]
    assert last_drawn(a, b, 20, 20, depth=2).tolist() == [False, True, True]
    assert last_drawn(a, b, 20, 20, depth=6).tolist() == [True, True, True]


def test_a_segment_showing_anywhere_is_kept_and_one_outside_the_picture_is_dropped():
    # the first runs 0.5..18.5 along row 3; the second covers only its first half; the third is off the picture
    a = np.array([[0.5, 3.5], [0.5, 3.5], [30.0, 3.5]])
    b = np.array([[18.5, 3.5], [9.0, 3.5], [40.0, 3.5]])
    assert last_drawn(a, b, 20, 10, depth=1).tolist() == [True, True, False]


def test_a_short_segment_inside_one_pixel_counts_there():
    a = np.array([[2.2, 2.2], [2.1, 2.1]])
    b = np.array([[2.3, 2.3], [2.9, 2.9]])
    assert last_drawn(a, b, 4, 4, depth=1).tolist() == [False, True]


def test_many_samples_are_handled_in_chunks_alike(monkeypatch):
    rng = np.random.default_rng(3)
    a, b = rng.uniform(0, 50, (400, 2)), rng.uniform(0, 50, (400, 2))
    whole = last_drawn(a, b, 50, 50, depth=2)
    import gcodekit.view.lod as lod

    monkeypatch.setattr(lod, "CHUNK_SAMPLES", 97)
    assert np.array_equal(lod.last_drawn(a, b, 50, 50, depth=2), whole)
    assert 0 < whole.sum() < 400


# -- polylines ------------------------------------------------------------------------------------------------------

def test_segments_joined_end_to_start_with_one_style_become_one_run():
    a = np.array([[0, 0], [1, 0], [1, 1], [5, 5], [6, 5]], float)
    b = np.array([[1, 0], [1, 1], [0, 1], [6, 5], [7, 5]], float)
    style = np.array([0, 0, 0, 0, 1])
    runs = polylines(a, b, style)
    assert [r.tolist() for r in runs.runs()] == [[[0, 0], [1, 0], [1, 1], [0, 1]], [[5, 5], [6, 5]], [[6, 5], [7, 5]]]
    assert runs.first.tolist() == [0, 3, 4] and runs.segments == 5


def test_a_dropped_segment_ends_a_run():
    a = np.array([[0, 0], [1, 0], [2, 0]], float)
    b = np.array([[1, 0], [2, 0], [3, 0]], float)
    runs = polylines(a, b, np.zeros((3, 4)), keep=np.array([True, False, True]))
    assert [r.tolist() for r in runs.runs()] == [[[0, 0], [1, 0]], [[2, 0], [3, 0]]]
    assert runs.first.tolist() == [0, 2]


# -- the picture ----------------------------------------------------------------------------------------------------

def _picture(op, view: str, lod: bool, reference_order: bool = False) -> np.ndarray:
    """The report's toolpath view of ``op`` as RGB; ``reference_order``: every segment on its own, in the painter's
    order the level of detail uses (the full drawing it stands for)."""
    from matplotlib.collections import LineCollection

    from gcodekit.report import figures
    from gcodekit.widgets.picture import to_rgb

    drawing = figures.toolpath_drawing(op)
    fig = figures._figure(5.0)
    ax = fig.add_axes((0.0, 0.0, 0.78, 1.0))
    ax.set_axis_off()
    camera = visualize.fitted_camera(view, drawing.path, 0.78 * figures.WIDTH_IN / 5.0)
    visualize.draw_toolpath(ax, drawing.path, drawing.color, camera, drawing.segments, work_width=0.6, lod=lod)
    if reference_order:  # the same limits, the segments replaced by the full drawing in the painter's order
        right, up, eye = camera.axes()
        centre = camera.view(*drawing.path.frame())[0]
        p0, p1 = drawing.path.start[drawing.segments] - centre, drawing.path.end[drawing.segments] - centre
        order = painter_order(p0, p1, eye)
        lines = np.stack([np.column_stack([p0 @ right, p0 @ up]), np.column_stack([p1 @ right, p1 @ up])], axis=1)
        rgb = drawing.color.segment_rgb(drawing.path, drawing.segments)[0]
        ax.collections[0].remove()
        ax.add_collection(LineCollection(lines[order], colors=rgb[order], linewidths=0.6))
    return to_rgb(fig).astype(int)


@pytest.fixture(scope="module")
def cube():
    path = CORPUS / "cube20_marlin2.gcode"
    if not path.exists():
        pytest.skip("the shared corpus is not next to the repository")
    return gcodekit.gcode_to_operation(path)


@pytest.mark.parametrize("view", ["iso", "top"])
def test_the_picture_looks_as_the_full_drawing_does(cube, view):
    full = _picture(cube, view, lod=False, reference_order=True)
    reduced = _picture(cube, view, lod=True)
    ink = (full < 250).any(axis=2)
    assert ink.mean() > 0.2  # a picture with a part in it
    diff = np.abs(full - reduced).max(axis=2)
    # the differences are anti-aliased edges at the vertices (a polyline's joint is drawn once, two
    # segments' ends blend twice): faint (half the part's pixels differ by at most 3 of 255), few strong
    assert np.median(diff[ink]) <= 4
    assert diff.mean() < 6.0, diff.mean()
    assert (diff > 64).mean() < 0.1 * ink.mean()
    # the same colours in the same amounts: each channel's mean over the picture within 1 of 255
    assert np.abs(full.mean(axis=(0, 1)) - reduced.mean(axis=(0, 1))).max() < 1.0


def test_the_top_view_is_the_old_full_drawing_to_the_eye(cube):
    """From above the painter's order is the old one (by depth = by height): the level of detail against the
    very drawing the report made before."""
    old = _picture(cube, "top", lod=False)
    new = _picture(cube, "top", lod=True)
    diff = np.abs(old - new).max(axis=2)
    assert diff.mean() < 6.0 and (diff > 64).mean() < 0.1 * (old < 250).any(axis=2).mean()
    assert np.abs(old.mean(axis=(0, 1)) - new.mean(axis=(0, 1))).max() < 1.0


def test_the_iso_view_no_longer_shows_lower_layers_through_the_walls(cube):
    """Sorted by each segment's mean depth, a long infill line of a lower layer came out nearer than the short
    wall segments in front of it and was drawn over them (a red band down the front corner of the cube); sorted
    by height, the wall covers it: fewer infill-red pixels in the picture."""
    red = lambda img: ((img[..., 0] > 180) & (img[..., 1] < 90) & (img[..., 2] < 90)).sum()  # noqa: E731
    assert red(_picture(cube, "iso", lod=True)) < 0.5 * red(_picture(cube, "iso", lod=False))


def test_chunks_give_the_one_pass_answer_and_a_chunk_outside_the_picture_is_nothing(monkeypatch):
    from gcodekit.view import lod

    rng = np.random.default_rng(11)
    a = rng.uniform(-100, 700, (4000, 2))
    b = a + rng.normal(0, 150, (4000, 2))
    whole = last_drawn(a, b, 600, 500)  # one chunk: every (pixel, segment) sorted at once
    for chunk in (1 << 10, 1 << 14):
        monkeypatch.setattr(lod, "CHUNK_SAMPLES", chunk)
        np.testing.assert_array_equal(last_drawn(a, b, 600, 500), whole)
    # the first segments wholly outside the picture: their chunk has no sample in it
    monkeypatch.setattr(lod, "CHUNK_SAMPLES", 4)
    kept = last_drawn(np.array([[-50.0, -50.0], [10.0, 10.0]]), np.array([[-40.0, -50.0], [20.0, 10.0]]), 600, 500)
    assert kept.tolist() == [False, True]


def test_memory_stays_the_pictures_however_many_samples():
    # found by explore.sh (seed 496090969): a do-while loop of 200 k rapids across the picture made 100 M
    # samples, and the report's picture took 5.3 GB to sort them all; 50 k such segments took 1.2 GB more
    import subprocess
    import sys

    code = ("import resource, numpy as np\nfrom gcodekit.view.lod import last_drawn\n"
            "a = np.column_stack([np.full(50000, 20.0), np.linspace(100, 400, 50000)]); b = a + [560.0, 0.0]\n"
            "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
            "kept = last_drawn(a, b, 600, 500)\n"
            "print(int(kept.sum()), (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) // 1024)\n")
    kept, grown_mb = map(int, subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                             check=True).stdout.split())
    # 50 k horizontal lines 560 px long from y = 100 to 400: rows 100-399 keep their last six lines each, and the
    # last line is alone on row 400: 300 x 6 + 1
    assert kept == 1801 and grown_mb < 600
