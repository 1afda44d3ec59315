"""The notebook widgets as plain Python objects: no browser, the controls set from Python.

Expected values come from the emulator's own columns (``analysis.layers``,
the waypoints) or are worked out by hand in the test.
"""

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("anywidget")

import gcodekit  # noqa: E402
from gcodekit.analysis import layers as waypoint_layers, velocity_corners  # noqa: E402
from gcodekit.widgets import LayerViewer, StageDiff, VelocityPlot  # noqa: E402
from gcodekit.widgets.checks import check  # noqa: E402
from gcodekit.view import Toolpath  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CUBE = ROOT / "examples" / "cube20_prusaslicer_marlin.gcode"
MILL = ROOT / "examples" / "bracket_mill.ngc"
PROGRAMS = ROOT / "notebooks" / "worksheets" / "programs"
# two layers of a square: 4 extruding moves each, a travel move between them
TWO_LAYERS = """M83
G1 Z0.2 F600
G1 X10 E1
G1 Y10 E1
G1 X0 E1
G1 Y0 E1
G0 Z0.4
G1 X10 E1
G1 Y10 E1
G1 X0 E1
G1 Y0 E1
"""


@pytest.fixture(scope="module")
def cube():
    return gcodekit.gcode_to_operation(CUBE)


def ink(image: np.ndarray) -> np.ndarray:
    """Pixels that are not (near) white."""
    return image.min(axis=2) < 235


def ink_height(image: np.ndarray) -> int:
    # the legend is on the right, the title on top
    rows = np.flatnonzero(ink(image[int(image.shape[0] * 0.07):, : int(image.shape[1] * 0.75)]).any(axis=1))
    return int(rows[-1] - rows[0]) if rows.size else 0


# -- the toolpath the viewers draw --------------------------------------------------------


def test_toolpath_groups_follow_the_emulators_layers(cube):
    path = Toolpath.of(cube)
    layer = waypoint_layers(cube)[path.move_rows]
    for k in (0, 7, 55, path.n_groups - 1):
        moves = np.arange(path.group_move[k], path.group_move[k + 1])
        assert np.all(np.maximum(layer[moves], 0) == k)  # start code goes with layer 0
    a, b = path.group_slice(5, 9)
    assert a == path.move_seg[path.group_move[5]] and b == path.move_seg[path.group_move[10]]
    assert path.n_groups == cube.get_statistics()["layers"] == 100


def test_toolpath_segments_by_hand():
    op = gcodekit.gcode_to_operation(TWO_LAYERS, "marlin", plan=False)
    path = Toolpath.of(op)
    assert path.group_labels == ["layer 0", "layer 1"]
    # a layer starts at its first extruding move: the Z lift ends layer 0
    assert path.moves_in(0) == 6 and path.moves_in(1) == 4
    # layer 1's second move is G1 Y10 (line 9) from (10, 0, 0.4)
    move = path.group_move[1] + 1
    s = path.move_seg[move]
    assert path.start[s].tolist() == [10.0, 0.0, 0.4] and path.end[s].tolist() == [10.0, 10.0, 0.4]
    assert path.line_of(move) == 9
    assert path.kind[path.move_seg[path.group_move[1] - 1]] == 1  # the Z lift lays nothing: travel
    assert path.kind[path.move_seg[path.group_move[1]]] == 0


def test_arcs_are_split_into_chords():
    op = gcodekit.gcode_to_operation("G21 G90\nG0 X10 Y0\nG3 X-10 Y0 I-10 J0 F600\nM2\n", "linuxcnc", plan=False)
    path = Toolpath.of(op, "line")
    arc = slice(path.move_seg[1], path.move_seg[2])
    radii = np.hypot(path.end[arc, 0], path.end[arc, 1])
    assert path.move_seg[2] - path.move_seg[1] == 36  # 180 degrees in 5-degree chords
    np.testing.assert_allclose(radii, 10.0)


def test_mill_steps_by_z_level_or_line():
    op = gcodekit.gcode_to_operation(MILL)
    by_z = Toolpath.of(op)
    assert by_z.group_by == "z" and by_z.group_labels[0] == "Z -0.5"  # the facing pass is the first level
    # every level's feed moves at its height (a level changes where the cutting height does)
    for k, label in enumerate(by_z.group_labels):
        moves = np.arange(by_z.group_move[k], by_z.group_move[k + 1])
        cuts = by_z.move_rows[moves][by_z.kind[by_z.move_seg[moves]] == 0]
        assert np.all(np.round(op.waypoints["z"][cuts], 3) == float(label[2:]))
    by_line = Toolpath.of(op, "line")
    lines = [by_line.line_of(m) for m in range(len(by_line.move_rows))]
    assert by_line.n_groups == len(set(lines)) and by_line.group_labels[0] == f"line {lines[0]}"


# -- LayerViewer ----------------------------------------------------------------------------


def test_one_layer_is_not_the_whole_part(cube):
    viewer = LayerViewer(cube)
    whole = viewer.screenshot()
    viewer.layers.value = (50, 50)
    one = viewer.screenshot()
    assert whole.shape == one.shape == (600, 800, 3)
    assert ink(one).sum() < 0.3 * ink(whole).sum()
    assert ink_height(one) < 0.6 * ink_height(whole)  # a 20 mm square seen at 30 degrees, not the 20 mm cube
    path = viewer.path
    assert viewer.moves.max == path.moves_in(50) - 1 == viewer.moves.value
    assert viewer.span == path.group_slice(50, 50)


def test_move_slider_follows_the_source_lines(cube):
    viewer = LayerViewer(cube)
    viewer.layers.value = (3, 3)
    rows = np.flatnonzero(np.maximum(waypoint_layers(cube), 0) == 3)
    moving = rows[(cube.waypoints["motion"][rows] > 0) & (cube.waypoints["distance"][rows] > 0)]
    assert viewer.moves.max == moving.size - 1
    viewer.moves.value = 4
    command = cube.waypoints["command"][moving[4]] if "command" in cube.waypoints else moving[4]
    assert viewer.current_line() == int(cube.table.line[command])
    assert f'data-line="{viewer.current_line()}"' in viewer.code.value
    partial = viewer.screenshot()
    viewer.moves.value = viewer.moves.max
    assert ink(partial).sum() < ink(viewer.screenshot()).sum()


def test_a_new_colouring_changes_the_colours(cube):
    viewer = LayerViewer(cube, color_by="feature")
    viewer.layers.value = (10, 10)
    by_feature = viewer.screenshot()
    viewer.color_by.value = "speed"
    by_speed = viewer.screenshot()
    assert ink(by_feature[:, :560]).sum() == pytest.approx(ink(by_speed[:, :560]).sum(), rel=0.05)  # the same lines

    def colours(image):
        part = image[:, :560][ink(image[:, :560])]
        return {tuple(c) for c in (part // 32).tolist()}

    assert len(colours(by_feature) ^ colours(by_speed)) > 5
    green = np.all(np.abs(by_feature[:, :560].astype(int) - (44, 160, 44)) < 30, axis=2).sum()  # external perimeter
    assert green > 200 and np.all(np.abs(by_speed[:, :560].astype(int) - (44, 160, 44)) < 30, axis=2).sum() < green / 4


def test_every_colouring_is_offered_and_drawn(cube):
    viewer = LayerViewer(cube)
    assert {"feature", "speed", "feed", "layer", "time", "tool", "flow"} <= set(viewer.color_by.options)
    for by in ("flow", "layer", "z"):
        viewer.color_by.value = by
        assert viewer.view.title and len(viewer.view.values) == 4 * viewer.path.n_segments


def test_screenshot_follows_the_browsers_camera(cube):
    """The camera the browser sends back (after a drag) is the one screenshot() draws with."""
    viewer = LayerViewer(cube)
    viewer.layers.value = (30, 30)
    viewer.view.camera = {"azimuth": -90.0, "elevation": 89.9, "zoom": 1.0, "target": [0.0, 0.0, 0.0]}  # from above
    image = viewer.screenshot()[int(600 * 0.07):, :620]  # below the title, left of the legend (at 78 %)
    rows, cols = np.flatnonzero(ink(image).any(axis=1)), np.flatnonzero(ink(image).any(axis=0))
    # layer 30 of the cube from above: a 20 mm square (its perimeters), as wide as it is tall
    assert rows[-1] - rows[0] == pytest.approx(cols[-1] - cols[0], abs=3)
    viewer.view.camera = {"azimuth": -90.0, "elevation": 89.9, "zoom": 2.0, "target": [0.0, 0.0, 0.0]}
    zoomed = viewer.screenshot()[int(600 * 0.07):, :620]
    assert np.ptp(np.flatnonzero(ink(zoomed).any(axis=0))) == pytest.approx(2 * (cols[-1] - cols[0]), rel=0.05)


def test_rich_display_carries_a_png(cube):
    viewer = LayerViewer(cube)
    bundle = viewer._repr_mimebundle_()
    assert bundle["image/png"].startswith(b"\x89PNG")
    assert "application/vnd.jupyter.widget-view+json" in bundle


def test_show_move_moves_the_sliders(cube):
    viewer = LayerViewer(cube)
    path = viewer.path
    target = int(path.group_move[40] + 7)
    viewer.show_move(target)
    assert viewer.layers.value[1] == 40 and viewer.moves.value == 7 and viewer.current_move == target


@pytest.mark.parametrize("source, says", [
    ("", "empty"),
    ("G21 G90\nM2\n", "no motions"),
    ("/no/such/program.gcode", "no such program file"),
])
def test_bad_input_is_a_message_not_a_traceback(source, says):
    for widget in (LayerViewer(source), VelocityPlot(source)):
        assert says in widget.error and says in repr(widget)
        assert says in widget.widget.children[0].value  # the message box is what the widget shows
        assert widget.screenshot().shape[2] == 3
        assert widget._repr_mimebundle_()["image/png"].startswith(b"\x89PNG")


def test_a_large_programs_source_lines_wait_for_the_cell(cube, monkeypatch):
    """Read on a thread started by IPython's post_run_cell event: the first picture does not wait for them."""
    IPython = pytest.importorskip("IPython")
    from IPython.core.events import EventManager, available_events

    from gcodekit.widgets import layer_viewer

    shell = type("Shell", (), {})()
    shell.events = EventManager(shell, available_events)
    monkeypatch.setattr(IPython, "get_ipython", lambda: shell)
    monkeypatch.setattr(layer_viewer, "SOURCE_BYTES_NOW", 0)
    viewer = LayerViewer(cube)
    assert "reading the program" in viewer.code.value and not viewer._reading.is_alive()
    shell.events.trigger("post_run_cell", None)  # the cell has finished
    viewer._reading.join()
    line = viewer.current_line()
    assert f'data-line="{line}"' in viewer.code.value and "reading the program" not in viewer.code.value
    assert not shell.events.callbacks["post_run_cell"]  # once


# -- VelocityPlot ------------------------------------------------------------------------


def test_velocity_envelope_keeps_each_bins_extremes(cube):
    plot = VelocityPlot(cube)
    corners = velocity_corners(cube)
    xs, planned = corners["time"], corners["planned"]
    x0, x1 = xs[0], xs[-1]
    assert plot.range == (x0, x1)
    p = plot.points(x0, x1, bins=300)
    assert p["mode"] == "binned" and p["x"].size <= 300
    # an independent binning of the full profile gives the same highest speed per bin
    edges = np.linspace(x0, x1, 301)
    k = 137
    inside = (xs >= edges[k]) & (xs < edges[k + 1])
    j = np.searchsorted(p["x"], xs[inside][0])
    assert p["hi"][j] == pytest.approx(planned[inside].max())
    assert p["lo"][j] == pytest.approx(planned[inside].min())
    raw = plot.points(x0, x0 + (x1 - x0) / 5000)
    assert raw["mode"] == "raw"  # every corner, from the first move's first corner on
    np.testing.assert_array_equal(raw["x"], xs[:raw["x"].size])


def corner_points(corners: dict, x: str, per_move: int, x0: float, x1: float, bins: int) -> dict:
    """The oracle: VelocityPlot.points as it was, searching and reducing every corner of the program."""
    xs, planned, commanded = corners[x], corners["planned"], corners["commanded"]
    a, b = np.searchsorted(xs, x0, side="left"), np.searchsorted(xs, x1, side="right")
    a = max(a - 1, 0)
    a -= a % per_move
    if b - a <= 3 * bins:
        return {"x": xs[a:b], "lo": planned[a:b], "hi": planned[a:b], "commanded": commanded[a:b],
                "line": corners["line"][a:b], "first": np.arange(a, b), "mode": "raw"}
    starts = np.unique(np.searchsorted(xs[a:b], np.linspace(x0, x1, bins + 1)[:-1]))
    starts = starts[starts < b - a]
    return {"x": xs[a:b][starts], "lo": np.minimum.reduceat(planned[a:b], starts),
            "hi": np.maximum.reduceat(planned[a:b], starts), "commanded": np.maximum.reduceat(commanded[a:b], starts),
            "line": corners["line"][a:b][starts], "first": a + starts, "mode": "binned"}


@pytest.mark.parametrize("plan", [True, False])
@pytest.mark.parametrize("x", ["time", "distance"])
def test_plot_points_are_every_corners_reduced(cube, plan, x):
    """The plot lays out only the corners of the moves it shows, and gives what reducing every corner gives."""
    op = cube if plan else gcodekit.gcode_to_operation(CUBE, plan=False)
    plot = VelocityPlot(op, x=x)
    corners = velocity_corners(op)
    per_move = plot.corners
    assert per_move == (4 if plan else 2)
    middle = plot.profile.corners(100, 140)
    for name, column in corners.items():  # a slice of moves: the same numbers to the bit
        np.testing.assert_array_equal(middle[name], column[100 * per_move:140 * per_move])
    lo, hi = plot.range
    rng = np.random.default_rng(0)
    ranges = [(lo, hi), (lo - 1, hi + 1), (lo, lo + (hi - lo) / 3000)]
    ranges += [tuple(np.sort(rng.uniform(lo, hi, 2))) for _ in range(12)]
    ranges += [(u, u + (hi - lo) * 0.001) for u in rng.uniform(lo, hi, 6)]
    for x0, x1 in ranges:
        for bins in (1200, 40, 3):
            got, want = plot.points(x0, x1, bins), corner_points(corners, x, per_move, x0, x1, bins)
            for key in ("mode", "x", "lo", "hi", "commanded", "line"):
                np.testing.assert_array_equal(got[key], want[key], err_msg=f"{key} of {x0}..{x1}, {bins} bins")
            np.testing.assert_array_equal(got["move"], plot.moves_of(want["first"]))


def test_linked_plot_follows_the_viewers_range(cube):
    viewer = LayerViewer(cube)
    plot = VelocityPlot(cube).link(viewer)
    viewer.layers.value = (12, 12)
    w = cube.waypoints
    rows = np.flatnonzero((waypoint_layers(cube) == 12) & (w["motion"] > 0) & (w["distance"] > 0))
    end = cube.elapsed_time()
    assert plot.range == pytest.approx((end[rows[0]] - w["time"][rows[0]], end[rows[-1]]))
    viewer.moves.value = 3
    assert plot.range[1] == pytest.approx(end[rows[3]])
    plot.view.picked = [int(viewer.path.group_move[30]), 0, 0.0]  # a point clicked in the plot
    assert viewer.layers.value[1] == 30 and viewer.moves.value == 0
    assert "move" in plot.picked.value


def test_velocity_over_distance(cube):
    plot = VelocityPlot(cube, layers=(2, 2), x="distance")
    assert plot.view.x_label == "distance (mm)" and plot.range[1] > plot.range[0]
    assert plot.screenshot().shape == (300, 900, 3)


# -- StageDiff ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def comp_diff():
    return StageDiff(PROGRAMS / "pocket_wall.ngc", a=0, b=6, tool_table=PROGRAMS / "tools.tbl")


def test_stages_line_up_by_source_line(comp_diff):
    rows = comp_diff.rows()
    a, b = comp_diff.sides()
    changed = [(a.lines[i], b.lines[j]) for status, i, j in rows if status == "changed"]
    # G1 X40 (line 10) in G54 moved to machine X50, cut 3 mm inside: the tool centre at X87 (by hand)
    assert ("N10 G1 X40", "N10 G1 X87 Y23 Z-1 F400") in changed
    html = comp_diff.diff_html()
    assert 'class="changed"' in html and "G1 X40" in html and "G10 L2 P1 X50 Y20 Z0" in html


def _feed_box(diff, index):
    """(xmin, ymin, xmax, ymax) of a side's feed moves at cutting depth, as the picture draws them."""
    op, shift, _ = diff._operation(diff.sides()[index], index)
    xyz = np.column_stack([op.waypoints[k] for k in "xyz"]) - (0 if shift is None else shift)
    cut = xyz[(np.asarray(op.waypoints["motion"]) == 2) & (xyz[:, 2] < 0)]
    return (*cut[:, :2].min(axis=0), *cut[:, :2].max(axis=0))


def test_stages_are_drawn_as_written(comp_diff):
    # the 40 x 20 pocket wall: G54 origin at machine X50 Y20, the 6 mm tool's centre 3 mm inside (by hand)
    assert _feed_box(comp_diff, 0) == pytest.approx((0, 0, 40, 20))  # program coordinates, programmed path
    assert _feed_box(comp_diff, 1) == pytest.approx((53, 23, 87, 37))  # machine coordinates, compensated
    comp_diff.stage_a.value = 6
    assert "0 changed, 0 only left, 0 only right" in comp_diff.diff_html()
    assert bytes(comp_diff.image.value).startswith(b"\x89PNG")
    comp_diff.stage_a.value = 0


@pytest.mark.parametrize("frame, programmed, compensated", [
    ("machine", (50, 20, 90, 40), (53, 23, 87, 37)),
    ("program", (0, 0, 40, 20), (3, 3, 37, 17)),
])
def test_both_stages_in_one_frame(frame, programmed, compensated):
    diff = StageDiff(PROGRAMS / "pocket_wall.ngc", a=0, b=6, frame=frame, tool_table=PROGRAMS / "tools.tbl")
    assert _feed_box(diff, 0) == pytest.approx(programmed)
    assert _feed_box(diff, 1) == pytest.approx(compensated)  # 3 mm inside on every side, in the same frame
    legend = " ".join(t.get_text() for t in diff.figure().axes[0].get_legend().get_texts())
    assert legend.count(f"({frame} coordinates") == 2
    with pytest.raises(ValueError, match="frame must be one of"):
        StageDiff(PROGRAMS / "pocket_wall.ngc", frame="work")


def test_two_programs(tmp_path):
    edited = tmp_path / "bracket_edited.ngc"
    lines = MILL.read_text().splitlines()
    k = lines.index("G1 X65 F900")
    lines[k] = "G1 X60 F900"
    edited.write_text("\n".join(lines) + "\n")
    diff = StageDiff.programs(MILL, edited)
    changed = [(status, i, j) for status, i, j in diff.rows() if status != "same"]
    assert changed == [("changed", k, k)]
    assert "G1 X60 F900" in diff.diff_html()


def test_a_stage_that_fails_is_a_message(monkeypatch):
    from gcodekit.transpile import Transpiler

    stage = Transpiler.stage

    def failing(self, k):
        if k == 5:
            raise ValueError("cutter compensation: the tool is larger than the arc")
        return stage(self, k)

    monkeypatch.setattr(Transpiler, "stage", failing)
    diff = StageDiff(MILL, a=0, b=5)
    assert "stage 5 could not be translated: cutter compensation" in diff.diff_html()
    assert diff.screenshot().shape[2] == 3
    diff.stage_b.value = 6  # the other stages still work
    assert "could not" not in diff.diff_html()
    assert "no motions" in StageDiff("G21\nM2\n").error


# -- worksheet checks ------------------------------------------------------------------


def test_checks():
    assert check((110, 50, 24), (110.0, 50.0, 24.0)).ok is True
    assert check((110, 50), (110.0, 50.0, 24.0)).ok is False
    assert check("Planned", "planned").ok is True
    assert check(None, 1.0).ok is None
    assert "Hint: add" in check(3, 4, hint="add").message
    # a wrong answer says which part is off and which way, never the expected value
    wrong = check((110, 50, 25), (110.0, 50.0, 24.0), names=("x", "y", "z"))
    assert wrong.message == "Not quite: z is too large (x and y are right)." and "24" not in wrong.message
    assert "4" not in check(3, 4).message.replace("3", "") and "too small" in check(3, 4).message
    assert "climb" not in check("conventional", "climb").message
