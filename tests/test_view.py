"""The one toolpath and colouring every picture draws (gcodekit.view), the source lines beside the viewer,
and program text reaching HTML only escaped.

Expected values are worked out by hand from the programs written here.
"""

from __future__ import annotations

import bz2
import codecs
import gzip
import html
import lzma

import numpy as np
import pytest

import gcodekit
from gcodekit.read.source import ProgramLines, program_lines
from gcodekit.view import (CHORD_ANGLE_DEG, PALETTE, TRAVEL, WORK, Camera, Toolpath, ToolpathError, coloring,
                           move_masks, source_lines)

#: A square, then a half circle; line k of the text is PROGRAM_LINES[k - 1].
PROGRAM_LINES = ["G21 G90 G17", "G0 X0 Y0 Z1", "G1 Z0 F300", "G1 X10 F600 (side one)", "G1 Y10 (side two)",
                 "G2 X0 Y10 I-5 J0 F1200 (half circle)", "G0 Z5", "M2"]
PROGRAM = "\n".join(PROGRAM_LINES) + "\n"


def test_segments_groups_and_lines_by_hand():
    op = gcodekit.gcode_to_operation(PROGRAM, "linuxcnc", plan=False)
    path = Toolpath.of(op)
    assert op.process != "additive" and path.group_by == "z"
    # moves: the rapid to Z1, the plunge (feed: work), two sides, the half circle, the retract (rapid)
    assert [path.line_of(k) for k in range(len(path.move_rows))] == [2, 3, 4, 5, 6, 7]
    chords = int(np.ceil(180 / CHORD_ANGLE_DEG))
    assert path.n_segments == 5 + chords
    arc = slice(path.move_seg[4], path.move_seg[5])
    assert np.allclose(np.hypot(path.end[arc, 0] - 5, path.end[arc, 1] - 10), 5)
    assert (path.end[arc, 1] <= 10 + 1e-9).all()  # clockwise from east of the centre to west: through the south
    assert path.kind.tolist() == [TRAVEL] + [WORK] * (3 + chords) + [TRAVEL]
    assert path.group_labels == ["Z 0"]  # one level of work; the retract goes with it
    work, travel = move_masks(op)
    assert work.sum() == 4 and travel.sum() == 2


def test_colourings_are_per_segment_and_share_one_palette():
    op = gcodekit.gcode_to_operation(PROGRAM, "linuxcnc", plan=False)
    path = Toolpath.of(op)
    feed = coloring(path, "feed")
    assert feed.categories is None and feed.title == "commanded feed (mm/min)"
    assert feed.values[path.move_seg[4]:path.move_seg[5]].tolist() == [1200.0] * int(np.ceil(180 / CHORD_ANGLE_DEG))
    assert feed.value_range(np.flatnonzero(path.kind == WORK)) == (300.0, 1200.0)
    rgb, vmin, vmax = feed.segment_rgb(path, np.arange(path.n_segments))
    assert (vmin, vmax) == (300.0, 1200.0)
    assert np.allclose(rgb[-1], 0x9a / 255)  # the retract: travel grey
    assert np.allclose(rgb[0], 0x9a / 255)  # the first rapid too
    assert np.allclose(rgb[1] * 255, feed.table()[0], atol=0.5)  # the plunge, slowest: viridis' first colour
    tool = coloring(path, "tool")
    assert tool.categories == ["T0"] and np.allclose(tool.rgb(np.array([0]), 0, 1)[0] * 255,
                                                     [int(PALETTE[0][i:i + 2], 16) for i in (1, 3, 5)])
    with pytest.raises(ValueError, match="did you mean 'feed'"):
        coloring(path, "fed")


def test_a_program_that_does_not_move_is_nothing_to_draw():
    op = gcodekit.gcode_to_operation("G21 G90\nM2\n", "linuxcnc", plan=False)
    with pytest.raises(ToolpathError, match="nothing to draw"):
        Toolpath.of(op)


def test_named_cameras_look_along_the_axes():
    right, up, eye = Camera.named("top").axes()
    assert np.allclose(right, [1, 0, 0]) and np.allclose(up, [0, 1, 0], atol=2e-3) and eye[2] > 0.999
    right, up, eye = Camera.named("front").axes()
    assert np.allclose(right, [1, 0, 0]) and np.allclose(up, [0, 0, 1]) and np.allclose(eye, [0, -1, 0])
    _, _, eye = Camera.named("iso").axes()
    assert np.allclose(eye, np.array([1, -1, 1]) / np.sqrt(3), atol=1e-4)


def test_a_fitted_camera_frames_the_work():
    op = gcodekit.gcode_to_operation("G0 X0 Y0 Z0\nG1 X40 F600\nG1 Y10\n", "linuxcnc", plan=False)
    path = Toolpath.of(op)
    cam = Camera.named("top").fitted(path, aspect=2.0, margin=0.0)
    centre, half = cam.view(*path.frame())
    # from above, a 40 x 10 mm rectangle in a 2:1 view: 40 mm wide fills it, 20 mm high, centred at (20, 5)
    assert half == pytest.approx(10.0, rel=1e-3) and np.allclose(centre[:2], [20, 5], atol=0.05)


# -- the source lines beside the viewer: read as the pipeline reads them -------------------------------


@pytest.mark.parametrize("suffix, encode", [
    (".ngc", lambda t: t.encode()),
    (".ngc.gz", lambda t: gzip.compress(t.encode())),
    (".ngc.bz2", lambda t: bz2.compress(t.encode())),
    (".ngc.xz", lambda t: lzma.compress(t.encode())),
    (".ngc", lambda t: codecs.BOM_UTF16_LE + t.encode("utf-16-le")),
    (".ngc", lambda t: codecs.BOM_UTF8 + t.replace("\n", "\r").encode()),  # old Mac line ends
])
def test_source_lines_read_every_container(tmp_path, suffix, encode):
    program = tmp_path / f"part{suffix}"
    program.write_bytes(encode(PROGRAM))
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False)
    assert source_lines(op) == PROGRAM_LINES
    lazy = ProgramLines(program)  # the viewer's panel: decoded a line at a time
    assert len(lazy) == len(PROGRAM_LINES) and list(lazy) == PROGRAM_LINES
    assert lazy[-1] == PROGRAM_LINES[-1] and lazy[2:5] == PROGRAM_LINES[2:5]


def test_program_lines_one_at_a_time_keep_what_cannot_be_decoded(tmp_path):
    program = tmp_path / "odd.ngc"
    program.write_bytes(b"G0 X0\nG1 X1 (caf\xe9 \xff)\n\nG1 X2 (\xc3\xa9t\xc3\xa9)\n")
    assert list(ProgramLines(program)) == program_lines(program) == ["G0 X0", "G1 X1 (caf\ufffd \ufffd)", "",
                                                                    "G1 X2 (\u00e9t\u00e9)"]
    with pytest.raises(IndexError):
        ProgramLines(program)[4]


@pytest.mark.parametrize("suffix, compress", [(".bz2", bz2.compress), (".xz", lzma.compress)])
def test_the_viewers_source_panel_shows_compressed_programs(tmp_path, suffix, compress):
    """The panel re-read .gz files only: a .bz2 or .xz program showed its compressed bytes."""
    pytest.importorskip("anywidget")
    from gcodekit.widgets import LayerViewer

    program = tmp_path / f"part.ngc{suffix}"
    program.write_bytes(compress(PROGRAM.encode()))
    viewer = LayerViewer(program, group_by="line")
    viewer.show_move(3)  # G1 Y10, line 5
    assert viewer.current_line() == 5
    panel = viewer.code.value
    assert f"{html.escape(PROGRAM_LINES[4])}</div>" in panel and "side one" in panel and "half circle" in panel
    assert "\ufffd" not in panel and "BZh" not in panel


def test_a_form_feed_does_not_shift_the_lines(tmp_path):
    """str.splitlines() cuts at form feeds and other separators the reader keeps inside a line."""
    lines = ["G0 X0 Y0", "G1 X1 F600 (page\x0cbreak)", "G1 X2", "M2"]
    program = tmp_path / "ff.ngc"
    program.write_text("\n".join(lines) + "\n")
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False)
    assert source_lines(op) == lines
    path = Toolpath.of(op)
    assert source_lines(op)[path.line_of(1) - 1] == "G1 X2"


# -- program text reaches HTML only escaped -------------------------------------------------------------


MARKUP = "<img src=x onerror=alert(1)>"


def test_viewer_sends_names_as_text_and_escapes_the_panel(tmp_path):
    pytest.importorskip("anywidget")
    from gcodekit.widgets import LayerViewer

    program = tmp_path / "planted.gcode"
    program.write_text(f"M83\nG1 Z0.2 F600\n;TYPE:{MARKUP}\nG1 X10 E1 F1200\nG1 Y10 E1 ; {MARKUP}\n")
    viewer = LayerViewer(program, color_by="feature")
    assert viewer.view.categories == ["(none)", MARKUP]  # strings the browser sets as text (viewer.js: textContent)
    assert "<img" not in viewer.code.value and html.escape(MARKUP, quote=False) in viewer.code.value


def test_exploration_notebook_title_is_literal_markdown():
    pytest.importorskip("nbformat")
    from gcodekit.widgets.notebook import exploration_notebook, markdown_text

    name = f"{MARKUP}*bold*_[link](x).gcode"
    nb = exploration_notebook(name)
    title = nb.cells[0].source.splitlines()[0]
    assert "<" not in title and "*bold*" not in title and "](x)" not in title
    assert title == "# " + markdown_text(name)
    import re

    import mistune  # nbconvert's Markdown renderer: what the notebook's HTML export shows

    rendered = mistune.html(title)
    assert "<img" not in rendered and "<em>" not in rendered and "<a " not in rendered
    assert html.unescape(re.sub(r"<[^>]+>", "", rendered)).strip() == name
