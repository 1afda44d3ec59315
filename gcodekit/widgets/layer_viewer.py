"""Widgets stage: LayerViewer, the toolpath in 3D with layer and move sliders.

The browser draws the segments with WebGL (``static/viewer.js``, an
anywidget front end): they are sent once, and the sliders are linked to the
view in the browser, so a slider step redraws a range without a round trip
to the kernel.  The kernel follows the same sliders for what it owns: the
move slider's length, the source lines beside the view, ``screenshot()``.

A program of more than ``max_segments`` segments is sent as an overview of
at most that many chords (:func:`gcodekit.view.overview`), and the top
layer of the range shown, the one the move slider steps through, at full
detail when the view asks for it (a message per layer, kept in the browser):
the browser gets at most ``max_segments`` chords of 33 bytes at the start
and one layer's segments (33 bytes each, 4 per move) per layer visited.
"""

from __future__ import annotations

import dataclasses
import html
import threading
from pathlib import Path

import anywidget
import ipywidgets as widgets
import numpy as np
import traitlets

from ..read.source import ProgramLines
from ..view import Camera, Coloring, Toolpath, ToolpathError, choices, coloring, overview
from .cell import after_cell
from .display import PictureDisplay, friendly, message_html
from .picture import import_in_background, message_figure, toolpath_figure
from .toolpath import load_toolpath

#: Source lines shown around the current one.
CONTEXT_LINES = 6
#: Most segments sent to the browser at once (the overview's budget): 33 bytes each, 8.3 MB.
MAX_SEGMENTS = 250_000
#: Program files up to this size are read for their source lines at once; larger ones on a thread.
SOURCE_BYTES_NOW = 4_000_000
#: Bytes per segment sent: 2 x 3 float32 positions, its kind (uint8), value (float32) and move (int32).
SEGMENT_BYTES = 33


class ToolpathView(anywidget.AnyWidget):
    """The WebGL view: segment buffers, what range to draw, colours and camera.

    ``positions``, ``kinds``, ``values`` and ``seg_move`` (the first move of
    each) are the overview's chords, every segment when ``stride`` is 1;
    ``group_seg`` and ``group_move`` are each group's first chord and move.
    A layer's own segments go out in a ``{"detail": group}`` message when
    the view asks for them.
    """

    _esm = Path(__file__).parent / "static" / "viewer.js"
    positions = traitlets.Bytes(b"").tag(sync=True)
    kinds = traitlets.Bytes(b"").tag(sync=True)
    seg_move = traitlets.Bytes(b"").tag(sync=True)
    group_seg = traitlets.Bytes(b"").tag(sync=True)
    group_move = traitlets.Bytes(b"").tag(sync=True)
    stride = traitlets.Int(1).tag(sync=True)
    #: counts the colourings sent: a layer's detail answers one of them
    color_version = traitlets.Int(0).tag(sync=True)
    group_labels = traitlets.List(traitlets.Unicode()).tag(sync=True)
    values = traitlets.Bytes(b"").tag(sync=True)
    palette = traitlets.Bytes(b"").tag(sync=True)
    categories = traitlets.List(traitlets.Unicode()).tag(sync=True)
    title = traitlets.Unicode("").tag(sync=True)
    radius = traitlets.Float(1.0).tag(sync=True)
    layers = traitlets.List(traitlets.Int(), default_value=[0, 0]).tag(sync=True)
    #: [top group, its last move shown], set by the kernel (and by keys pressed in the view)
    top_move = traitlets.List(traitlets.Int(), default_value=[0, 0]).tag(sync=True)
    show_travel = traitlets.Bool(False).tag(sync=True)
    camera = traitlets.Dict().tag(sync=True)
    height = traitlets.Int(480).tag(sync=True)


class LayerViewer(PictureDisplay):
    """The toolpath of a program in 3D, stepped through by layer and move.

    Parameters
    ----------
    source : Operation, AdditivePart or path
        The program; a path is read with :func:`gcodekit.gcode_to_operation`.
    color_by : str, default: "feature"
        ``feature``, ``speed`` (planned), ``feed`` (commanded), ``layer``,
        ``time``, ``tool``, ``flow`` or a waypoint column; a program without
        slicer features falls back to ``speed``.
    group_by : {"layer", "z", "line"}, default: None
        What the range slider steps through: layers for additive programs,
        Z levels (or source lines) for mill programs.
    show_travel : bool, default: False
    height : int, default: 480
        Height of the view in pixels.
    max_segments : int, default: MAX_SEGMENTS
        Most segments the browser gets at once: a larger program is sent as
        an overview of that many chords and the top layer in full detail.

    Attributes
    ----------
    layers : ipywidgets.IntRangeSlider
        The groups shown, both ends included.
    moves : ipywidgets.IntSlider
        The last move shown of the top group (its moves counted from 0).
    color_by : ipywidgets.Dropdown
    travel : ipywidgets.Checkbox
    play : ipywidgets.Play
        Steps ``moves`` forward.
    error : str or None
        Why nothing can be drawn (the widget then shows this message).

    Examples
    --------
    ::

        viewer = LayerViewer("part.gcode", color_by="speed")
        viewer.layers.value = (10, 10)
        image = viewer.screenshot()
    """

    def __init__(self, source, color_by: str = "feature", *, group_by: str | None = None,
                 show_travel: bool = False, height: int = 480, max_segments: int = MAX_SEGMENTS):
        self.error: str | None = None
        self.max_segments = max(int(max_segments), 1)
        import_in_background()  # the display's PNG needs matplotlib: loaded while this widget is built
        self.details_sent = 0
        self.path: Toolpath | None = None
        self.camera = Camera()
        self._lines: ProgramLines | list[str] | None = None
        self._reading: threading.Thread | None = None
        try:
            self.path = load_toolpath(source, group_by)
        except ToolpathError as exc:
            self.error = str(exc)
        except Exception as exc:  # anything the reader raised: a message in the widget, not a traceback
            self.error = friendly(exc)
        self._build(color_by, show_travel, height)

    # -- building ----------------------------------------------------------------

    def _build(self, color_by: str, show_travel: bool, height: int) -> None:
        path = self.path
        n_groups = path.n_groups if path else 1
        noun = {"layer": "layers", "z": "Z levels", "line": "lines"}[path.group_by] if path else "layers"
        self.layers = widgets.IntRangeSlider(value=(0, n_groups - 1), min=0, max=max(n_groups - 1, 0), step=1,
                                             description=noun, continuous_update=True,
                                             layout=widgets.Layout(width="98%"))
        top = path.moves_in(n_groups - 1) if path else 1
        self.moves = widgets.IntSlider(value=max(top - 1, 0), min=0, max=max(top - 1, 0), description="move",
                                       continuous_update=True, layout=widgets.Layout(width="98%"))
        self.play = widgets.Play(value=self.moves.value, min=0, max=self.moves.max, interval=150, step=1,
                                 description="play")
        options = choices(path) if path else [color_by]
        if color_by not in options:
            color_by = "speed" if "speed" in options else options[0]
        self.color_by = widgets.Dropdown(options=options, value=color_by, description="colour by")
        self.travel = widgets.Checkbox(value=show_travel, description="travel moves", indent=False)
        self.code = widgets.HTML(layout=widgets.Layout(width="32%", overflow="auto"))
        # the canvas is laid over its box: the view takes its width from the page
        self.view = ToolpathView(height=height, layout=widgets.Layout(width="100%"))
        self._coloring: Coloring | None = None
        if self.error is not None:
            self.message = widgets.HTML(message_html(self.error))
            for control in (self.layers, self.moves, self.play, self.color_by, self.travel):
                control.disabled = True
            self.widget = widgets.VBox([self.message], layout=widgets.Layout(width="100%"))
            return
        self._send_geometry()
        self._recolor()
        widgets.jslink((self.layers, "value"), (self.view, "layers"))
        widgets.jslink((self.play, "value"), (self.moves, "value"))
        widgets.jslink((self.travel, "value"), (self.view, "show_travel"))
        self.view.layers, self.view.show_travel = list(self.layers.value), show_travel
        self.view.top_move = [self.layers.value[1], self.moves.value]
        self.layers.observe(self._on_layers, "value")
        self.moves.observe(self._on_move, "value")
        self.color_by.observe(lambda change: self._recolor(), "value")
        self.travel.observe(lambda change: setattr(self.view, "show_travel", change["new"]), "value")
        self.view.observe(self._on_camera, "camera")
        self.view.observe(self._on_view_move, "top_move")
        self.view.on_msg(self._on_message)
        self._show_code()
        controls = widgets.HBox([self.color_by, self.travel, self.play])
        self.widget = widgets.VBox([controls, self.layers, self.moves,
                                    widgets.HBox([widgets.Box([self.view], layout=widgets.Layout(width="68%")),
                                                  self.code])],
                                   layout=widgets.Layout(width="100%"))

    def _send_geometry(self) -> None:
        path = self.path
        self._middle, radius = path.frame()
        with self.view.hold_sync():
            self.view.group_move = path.group_move.astype(np.int32).tobytes()
            self.view.group_labels = path.group_labels
            self.view.radius = radius
            self.view.camera = self.camera.as_dict()

    def _recolor(self) -> None:
        """Colour by the dropdown's choice: the overview's chords (their runs keep one colour) and their values."""
        path = self.path
        self._coloring = color = coloring(path, self.color_by.value, list(self.color_by.options))
        key = (path.segment_group, path.kind, color.values)
        first, last, stride = overview(path.start, path.end, key, self.max_segments)
        self._chords = first, last
        chord_group = path.segment_group[first]
        with self.view.hold_sync():
            self.view.positions = self._positions(path.start[first], path.end[last])
            self.view.kinds = path.kind[first].astype(np.uint8).tobytes()
            self.view.values = color.values[first].astype(np.float32).tobytes()
            self.view.seg_move = path.move_of[first].astype(np.int32).tobytes()
            self.view.group_seg = np.searchsorted(chord_group, np.arange(path.n_groups + 1)).astype(np.int32).tobytes()
            self.view.stride = stride
            self.view.palette = color.table().tobytes()
            self.view.categories = color.categories or []
            self.view.title = color.title
            self.view.color_version += 1

    def _positions(self, start: np.ndarray, end: np.ndarray) -> bytes:
        return np.stack([start - self._middle, end - self._middle], axis=1).astype(np.float32).tobytes()

    def _on_message(self, view, content, buffers) -> None:
        """The view asks for a layer's own segments: send them, with the colouring they answer."""
        group = content.get("detail") if isinstance(content, dict) else None
        if not isinstance(group, int) or not 0 <= group < self.path.n_groups:
            return
        self.view.send({"detail": group, "version": self.view.color_version}, self.detail(group))
        self.details_sent += 1

    def detail(self, group: int) -> list[bytes]:
        """Group ``group``'s segments as sent to the view: positions, kinds, values and each move's first segment."""
        path = self.path
        moves = path.group_move[group], path.group_move[group + 1]
        a, b = int(path.move_seg[moves[0]]), int(path.move_seg[moves[1]])
        return [self._positions(path.start[a:b], path.end[a:b]), path.kind[a:b].astype(np.uint8).tobytes(),
                self._coloring.values[a:b].astype(np.float32).tobytes(),
                (path.move_seg[moves[0]:moves[1] + 1] - a).astype(np.int32).tobytes()]

    # -- following the controls -----------------------------------------------------

    def _on_layers(self, change) -> None:
        lo, hi = change["new"]
        count = self.path.moves_in(hi)
        with self.moves.hold_sync(), self.play.hold_sync():
            self.moves.max = self.play.max = max(count - 1, 0)
            self.moves.value = self.play.value = max(count - 1, 0)
        # not view.layers: the browser links it to the slider, and an answer to an older step would undo a newer one
        self.view.top_move = [hi, self.moves.value]
        self._show_code()

    def _on_move(self, change) -> None:
        self.view.top_move = [self.layers.value[1], change["new"]]
        self._show_code()

    def _on_view_move(self, change) -> None:  # keys pressed in the view
        group, move = change["new"]
        if group == self.layers.value[1] and move != self.moves.value:
            self.moves.value = min(max(move, 0), self.moves.max)

    def _on_camera(self, change) -> None:
        c = change["new"] or {}
        self.camera = Camera(float(c.get("azimuth", -60)), float(c.get("elevation", 30)), float(c.get("zoom", 1)),
                             list(c.get("target", [0, 0, 0])))

    # -- what is shown ----------------------------------------------------------------

    @property
    def current_move(self) -> int:
        """Index (into ``path.move_rows``) of the move the sliders point at; -1 when none."""
        if self.path is None:
            return -1
        return self.path.current_move(self.layers.value[1], self.moves.value)

    @property
    def span(self) -> tuple[int, int]:
        """Segments drawn, ``[a, b)``."""
        lo, hi = self.layers.value
        return self.path.group_slice(lo, hi, self.moves.value)

    def show_move(self, move: int) -> None:
        """Move the sliders to move ``move`` (an index of ``path.move_rows``), keeping the range's lower end."""
        if self.path is None or not 0 <= move < len(self.path.move_rows):
            return
        group = int(np.searchsorted(self.path.group_move, move, side="right") - 1)
        lo = min(self.layers.value[0], group)
        self.layers.value = (lo, group)
        self.moves.value = move - int(self.path.group_move[group])

    def current_line(self) -> int | None:
        """Source line of the current move."""
        move = self.current_move
        return None if move < 0 else self.path.line_of(move)

    def _show_code(self) -> None:
        line = self.current_line()
        if line is None:
            self.code.value = "<i>no move in this range</i>"
            return
        if self._lines is None and not self._read_lines():
            self.code.value = (f'<div class="gcodekit-code" data-line="{line}" style="font:12px monospace">'
                               f'line {line}, move {self.current_move}<br><i>reading the program ...</i></div>')
            return
        rows = []
        if self._lines:
            first = max(line - CONTEXT_LINES, 1)
            for k in range(first, min(line + CONTEXT_LINES, len(self._lines)) + 1):
                text = html.escape(self._lines[k - 1])
                style = "background:#ffe08a;font-weight:600" if k == line else "color:#555"
                rows.append(f'<div style="{style}"><span style="color:#999">{k:>6} </span>{text}</div>')
        else:
            row = int(self.path.op.waypoints["command"][self.path.move_rows[self.current_move]])
            rows.append(f"<div>{html.escape(str(self.path.op.table.command(row)))}</div>")
        self.code.value = (f'<div class="gcodekit-code" data-line="{line}" style="font:12px monospace;'
                           f'white-space:pre">line {line}, move {self.current_move}<br>{"".join(rows)}</div>')

    def _read_lines(self) -> bool:
        """Whether the source lines are read; a large file is read on a thread once the cell has finished
        (the first picture does not wait for it), which shows them when done."""
        path = Path(self.path.op.file)
        if not path.is_file():
            self._lines = []
            return True
        if path.stat().st_size <= SOURCE_BYTES_NOW:
            self._lines = ProgramLines(path)
            return True
        if self._reading is None:
            def read():
                self._lines = ProgramLines(path)
                self._show_code()

            self._reading = threading.Thread(target=read, name="gcodekit-source-lines", daemon=True)
            after_cell(self._reading.start)
        return False

    def figure(self, size: tuple[int, int] = (800, 600)):
        """The current picture as a matplotlib Figure (what :meth:`screenshot` returns).

        A program sent as an overview is drawn from the overview's chords (as
        the browser draws it before a layer's own segments arrive).
        """
        if self.error is not None:
            return message_figure(self.error)
        lo, hi = self.layers.value
        labels = self.path.group_labels
        name = Path(self.path.op.file).name
        what = labels[lo] if lo == hi else f"{labels[lo]} to {labels[hi]}"
        path, color = self._drawn()
        return toolpath_figure(path, path.group_slice(lo, hi, self.moves.value), color, self.camera,
                               show_travel=self.travel.value, current_move=self.current_move, size=size,
                               title=f"{name}: {what}, move {self.moves.value + 1} of {self.moves.max + 1}")

    def _drawn(self) -> tuple[Toolpath, Coloring]:
        """The toolpath and colouring pictures draw: the program's, or its overview's chords as a Toolpath."""
        if self.view.stride == 1:
            return self.path, self._coloring
        first, last = self._chords
        p = self.path
        move_of = p.move_of[first]
        move_seg = np.zeros(p.move_rows.size + 1, np.int64)  # each move's first chord: the chords before it counted
        np.cumsum(np.bincount(move_of, minlength=p.move_rows.size), out=move_seg[1:])
        chords = dataclasses.replace(p, start=p.start[first], end=p.end[last], move_of=move_of, kind=p.kind[first],
                                     move_seg=move_seg)
        return chords, dataclasses.replace(self._coloring, values=self._coloring.values[first])

    def __repr__(self) -> str:
        if self.error is not None:
            return f"<LayerViewer: {self.error}>"
        return (f"<LayerViewer {Path(self.path.op.file).name!r}: {self.path.n_groups} {self.layers.description}, "
                f"showing {self.layers.value}, colour by {self.color_by.value}>")
