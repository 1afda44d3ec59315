"""Widgets on large programs without a browser: the overview's chords, the layers sent on demand, the raster picture.

References are computed here by hand: a chord must start where its first
segment starts and end where its last ends, cover the segments once in
order, never join two colours or groups, and keep every corner sharper than
``CORNER_DEG``; a layer sent on demand must be exactly the toolpath's
segments of that layer; the NumPy raster must agree with matplotlib's
picture of the same segments.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("anywidget")

import gcodekit  # noqa: E402
from gcodekit.view import Toolpath, coloring, overview  # noqa: E402
from gcodekit.view.overview import CORNER_DEG, chords, runs  # noqa: E402
from gcodekit.widgets import LayerViewer, VelocityPlot  # noqa: E402
from gcodekit.widgets.layer_viewer import SEGMENT_BYTES  # noqa: E402
from shared_corpus import CORPUS as SHARED_CORPUS

ROOT = Path(__file__).resolve().parents[1]
CORPUS = SHARED_CORPUS / "fff"
CUBE = CORPUS / "cube20_marlin2.gcode"


@pytest.fixture(scope="module")
def cube():
    if not CUBE.is_file():
        pytest.skip(f"{CUBE} is missing")
    return gcodekit.gcode_to_operation(CUBE)


def polyline(points) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(points, float)
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    return p[:-1].copy(), p[1:].copy()


def check_partition(first, last, n):
    assert first[0] == 0 and last[-1] == n - 1
    assert np.array_equal(first[1:], last[:-1] + 1)  # each segment in exactly one chord, in order
    assert np.all(last >= first)


def test_a_gentle_curve_is_cut_into_longer_chords():
    t = np.linspace(0, np.pi, 181)  # a half circle in 180 chords of 1 degree
    start, end = polyline(np.column_stack([10 * np.cos(t), 10 * np.sin(t)]))
    first, last, stride = overview(start, end, np.zeros(180), budget=20)
    check_partition(first, last, 180)
    assert stride == 9 and first.size == 20
    # the chords run through every 9th point of the curve: within r (1 - cos 4.5 deg) of it
    assert np.allclose(start[first], start[::9])
    assert np.allclose(end[last[-1]], [-10, 0, 0], atol=1e-12)
    assert 10 * (1 - np.cos(np.radians(4.5))) < 0.04


def test_corners_and_colours_are_kept():
    zigzag = [(0, 0), (10, 0), (10, 1), (0, 1), (0, 2), (10, 2)]  # every joint turns 90 degrees
    start, end = polyline(zigzag)
    assert runs(start, end, np.zeros(5)).tolist() == [0, 1, 2, 3, 4]
    first, last = chords(start, end, np.zeros(5), stride=8)
    assert first.tolist() == last.tolist() == [0, 1, 2, 3, 4]  # nothing merged over a corner
    # a turn just within the limit joins, just beyond it splits
    for turn, joined in ((CORNER_DEG - 1, True), (CORNER_DEG + 1, False)):
        a = np.radians(turn)
        start, end = polyline([(0, 0), (1, 0), (1 + np.cos(a), np.sin(a))])
        assert (runs(start, end, np.zeros(2)).size == 1) == joined
    # a colour change or a gap splits a run too
    start, end = polyline([(0, 0), (1, 0), (2, 0), (3, 0)])
    assert runs(start, end, np.array([0, 0, 1])).tolist() == [0, 2]
    end[0, 0] = 0.5
    assert runs(start, end, np.zeros(3)).tolist() == [0, 1]


def test_the_budget_holds_when_runs_alone_exceed_it():
    rng = np.random.default_rng(1)
    start, end = rng.random((500, 3)), rng.random((500, 3))  # no segment joins the next: 500 runs
    first, last, stride = overview(start, end, np.zeros(500), budget=50)
    assert stride == 0 and first.size == 50 and np.array_equal(first, last)
    assert first[0] == 0 and first[-1] == 499 and np.all(np.diff(first) > 0)
    every, same, one = overview(start, end, np.zeros(500), budget=500)
    assert one == 1 and np.array_equal(every, np.arange(500)) and np.array_equal(every, same)


def test_viewer_sends_at_most_its_budget_and_layers_on_demand(cube, monkeypatch):
    viewer = LayerViewer(cube, max_segments=4200)  # the cube's square layers: 3 767 runs in 4 731 segments
    path, view = viewer.path, viewer.view
    assert path.n_segments > 4200 and view.stride > 1
    chords_sent = len(view.positions) // 24
    assert chords_sent <= 4200
    state = sum(len(getattr(view, k)) for k in ("positions", "kinds", "values", "seg_move"))
    assert state == chords_sent * SEGMENT_BYTES
    first, last = viewer._chords
    check_partition(first, last, path.n_segments)
    color = coloring(path, "feature")
    # a chord stands for segments of one colour, kind and layer; it starts and ends where they do
    chord_of = np.repeat(np.arange(first.size), last - first + 1)
    for column in (color.values, path.kind, path.segment_group):
        assert np.array_equal(column, column[first][chord_of])
    middle, _ = path.frame()
    xyz = np.frombuffer(view.positions, np.float32).reshape(-1, 2, 3)
    assert np.allclose(xyz[:, 0], path.start[first] - middle, atol=1e-4)
    assert np.allclose(xyz[:, 1], path.end[last] - middle, atol=1e-4)
    # each layer's chords are one slice, in layer order
    group_seg = np.frombuffer(view.group_seg, np.int32)
    assert np.array_equal(group_seg, np.searchsorted(path.segment_group[first], np.arange(path.n_groups + 1)))

    # the view asks for layer 40: the answer is every segment of it, with the colouring in force
    sent = []
    monkeypatch.setattr(view, "send", lambda content, buffers=None: sent.append((content, buffers)))
    viewer._on_message(view, {"detail": 40}, [])
    viewer._on_message(view, {"detail": 10 ** 6}, [])  # no such layer: no answer
    viewer._on_message(view, {"something": "else"}, [])
    assert len(sent) == 1 and sent[0][0] == {"detail": 40, "version": view.color_version}
    positions, kinds, values, move_seg = sent[0][1]
    a, b = path.group_slice(40, 40)
    xyz = np.frombuffer(positions, np.float32).reshape(-1, 2, 3)
    assert xyz.shape[0] == b - a and np.allclose(xyz[:, 1], path.end[a:b] - middle, atol=1e-4)
    assert np.array_equal(np.frombuffer(kinds, np.uint8), path.kind[a:b])
    assert np.array_equal(np.frombuffer(values, np.float32), color.values[a:b])
    moves = path.group_move[40], path.group_move[41]
    assert np.array_equal(np.frombuffer(move_seg, np.int32), path.move_seg[moves[0]:moves[1] + 1] - a)

    # a new colouring: new chords and a new version (answers to the old one are ignored by the view)
    version = view.color_version
    viewer.color_by.value = "speed"
    assert view.color_version == version + 1
    speed = coloring(path, "speed").values
    first, last = viewer._chords
    assert np.array_equal(speed[first], np.frombuffer(view.values, np.float32))


def test_fewer_chords_than_runs(cube):
    viewer = LayerViewer(cube, max_segments=1000)
    first, last = viewer._chords
    assert viewer.view.stride == 0 and first.size == len(viewer.view.positions) // 24 == 1000
    # whole runs, evenly spread over the program, each of one colour and layer
    path, values = viewer.path, coloring(viewer.path, "feature").values
    assert np.all(np.diff(first) > 0) and np.all(last >= first)
    for a, b in zip(first[::50], last[::50]):
        assert np.all(values[a:b + 1] == values[a]) and np.all(path.segment_group[a:b + 1] == path.segment_group[a])


def test_small_programs_are_sent_whole(cube):
    viewer = LayerViewer(cube)
    assert viewer.view.stride == 1 and len(viewer.view.positions) == viewer.path.n_segments * 24
    assert np.array_equal(np.frombuffer(viewer.view.seg_move, np.int32), viewer.path.move_of)


def test_raster_picture_agrees_with_matplotlib(cube, monkeypatch):
    sys.path.insert(0, str(ROOT / "tests"))
    from picture_compare import agreement

    from gcodekit.widgets import picture

    viewer = LayerViewer(cube)
    pictures = []
    for layers in ((0, 99), (50, 50)):
        viewer.layers.value = layers
        drawn = viewer.screenshot()  # 4 731 segments at most: matplotlib
        with monkeypatch.context() as m:
            m.setattr(picture, "RASTER_FROM", 0)
            m.setattr(picture, "RASTER_CHUNK", 1000)  # several chunks share the depth buffer
            pictures.append(agreement(viewer.screenshot(), drawn))
        print(f"layers {layers}: NumPy raster against matplotlib: {pictures[-1]}")
    whole, one = pictures
    # the whole cube: the same ink (which of the lines packed into a pixel shows differs: a depth
    # buffer keeps the nearest sample, matplotlib blends antialiased lines in painter's order)
    assert whole.iou > 0.9, whole
    assert one.iou > 0.8 and one.median_angle < 8 and one.within_10 > 0.85, one


@pytest.mark.parametrize("program, chunk", [(None, 1000), (CORPUS / "cylinder_marlin2.gcode", 400_000)])
def test_raster_engines_draw_the_same_picture(cube, monkeypatch, program, chunk):
    """The compiled pixel loop and the NumPy raster give the same image to the bit (ties: the last sample)."""
    from gcodekit.view import Camera
    from gcodekit.widgets import picture, raster_kernel

    kernel = raster_kernel.compiled()
    if kernel is None:
        pytest.skip("Numba is not installed: the NumPy raster alone")
    if program is not None and not program.is_file():
        pytest.skip(f"{program.name} is not in the shared corpus")
    op = cube if program is None else gcodekit.gcode_to_operation(program)
    path = Toolpath.of(op)
    color = coloring(path, "speed")
    monkeypatch.setattr(picture, "RASTER_CHUNK", chunk)  # several chunks share the depth buffer (the cube)
    images = []
    for chosen in (None, kernel):
        monkeypatch.setattr(raster_kernel, "engine", lambda n, chosen=chosen: chosen)
        fig = picture.new_figure((640, 480))
        ax = fig.add_axes((0.0, 0.0, 0.78, 1.0))
        picture.raster_toolpath(ax, path, color, Camera(), np.arange(path.n_segments))
        images.append(np.asarray(ax.images[0].get_array()))
    assert (images[0] != 1.0).any(axis=2).sum() > 1000  # something drawn
    assert images[0].tobytes() == images[1].tobytes()


def test_plot_names_the_toolpaths_moves_and_shares_the_viewers_path(cube):
    viewer = LayerViewer(cube)
    plot = VelocityPlot(cube)
    assert plot._path is None  # no toolpath cut for a plot on its own
    plot.link(viewer)
    assert plot.path is viewer.path
    # each corner's move, found as before the plot shared the viewer's toolpath (the first at or after its waypoint)
    corners = np.arange(0, len(plot.profile) * plot.corners, 7)
    waypoint = cube.plan[0].waypoint[corners // 4]
    expected = np.clip(np.searchsorted(Toolpath.of(cube).move_rows, waypoint), 0, len(viewer.path.move_rows) - 1)
    assert np.array_equal(plot.moves_of(corners), expected)
