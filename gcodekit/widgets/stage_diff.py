"""Widgets stage: StageDiff, two stages of the transpiler (or two programs) side by side.

Every output line of a stage starts with the N-number of the source line it
came from, so two stages line up by source line: the table pairs them, marks
what changed and shows the source line each pair came from.  By default the
picture draws both stages' toolpaths as their words say, in the frame each
stage is written in: a stage that still carries work offsets or cutter
compensation is drawn without them (program coordinates, the programmed
path), a later stage in machine coordinates with the compensated path.
``frame="machine"`` or ``frame="program"`` draws both in one frame instead,
so the programmed and the compensated path can be compared: a stage written
in program coordinates is drawn with its offsets applied, or a stage in
machine coordinates moved back by the offsets in force at each source line.
"""

from __future__ import annotations

import difflib
import html
import re
from dataclasses import dataclass
from pathlib import Path

import ipywidgets as widgets
import numpy as np

from .display import PictureDisplay, friendly, message_html
from .picture import message_figure, new_figure, to_png

#: Rows of the table beyond which the rest is summarised (a browser chokes on 100 k rows).
MAX_ROWS = 3000
_N_WORD = re.compile(r"^N(\d+)\s")
_N_IN_COMMENT = re.compile(r"^\((?:dropped: )?N(\d+)\s")
#: Codes whose effect a stage still carries in words: left out when drawing the stage "as written".
_FRAME_CODES = re.compile(r"^N\d+\s+(G5[4-9](\.\d)?|G92(\.\d)?|G10|G43(\.\d)?|G49|G52|G4[0-2](\.\d)?)\b")
#: Cutter compensation codes: left out when drawing a stage's programmed path in machine coordinates.
_COMP_CODES = re.compile(r"^N\d+\s+G4[0-2](\.\d)?\b")
#: The frames both stages can be drawn in (None: each in its own).
FRAMES = (None, "machine", "program")
#: (feed, rapid) line colour and style of the left and the right side
STYLES = ((("#1f77b4", "-"), ("#1f77b4", "--")), (("#ff7f0e", "-"), ("#ff7f0e", "--")))


@dataclass
class Side:
    """One side of a diff: its name, text lines (None when it failed) and why it failed."""

    name: str
    lines: list[str] | None
    error: str | None = None
    frame: str = ""


def source_key(line: str) -> tuple[str, object]:
    """What a stage's line lines up by: its source line number, else its own text (comments)."""
    m = _N_WORD.match(line) or _N_IN_COMMENT.match(line)
    return ("N", int(m.group(1))) if m else ("text", line.strip())


def body(line: str) -> str:
    """The line without its N-word (what the stages are compared on)."""
    return _N_WORD.sub("", line, count=1).strip()


def align(a: list[str], b: list[str], by_source: bool) -> list[tuple[str, int | None, int | None]]:
    """Pairs of line indices of ``a`` and ``b`` with a status: ``same``, ``changed``, ``removed`` or ``added``.

    By source line, lines pair only with lines of the same source line (in
    order); two programs pair line by line where difflib finds a replacement.
    """
    keys_a = [source_key(x) for x in a] if by_source else [x.strip() for x in a]
    keys_b = [source_key(x) for x in b] if by_source else [x.strip() for x in b]
    rows = []
    for tag, i0, i1, j0, j1 in difflib.SequenceMatcher(None, keys_a, keys_b, autojunk=False).get_opcodes():
        paired = tag == "equal" or (tag == "replace" and not by_source)
        n = min(i1 - i0, j1 - j0) if paired else 0
        for k in range(n):
            i, j = i0 + k, j0 + k
            same = body(a[i]) == body(b[j]) if by_source else tag == "equal"
            rows.append(("same" if same else "changed", i, j))
        rows += [("removed", i, None) for i in range(i0 + n, i1)]
        rows += [("added", None, j) for j in range(j0 + n, j1)]
    return rows


class StageDiff(PictureDisplay):
    """Two stages of the staged transpiler side by side, or two programs.

    Parameters
    ----------
    program : path, program text or Operation
    a, b : int, default: 0 and 6
        The stages compared (see :data:`gcodekit.transpile.STAGE_NAMES`).
    frame : {None, "machine", "program"}, default: None
        Draw both stages in machine or in program coordinates; None draws
        each in the frame it is written in.
    machine : str, default: None
    **options
        As for :func:`gcodekit.gcode_to_operation` (``tool_table="tools.tbl"`` for cutter compensation).

    Attributes
    ----------
    stage_a, stage_b : ipywidgets.Dropdown
        The stages shown (disabled when comparing two programs).
    error : str or None
        Why nothing can be compared.

    Examples
    --------
    ::

        diff = StageDiff("part.ngc", a=4, b=5)   # cutter compensation
        html = diff.diff_html()
        StageDiff.programs("part_v1.ngc", "part_v2.ngc")
    """

    def __init__(self, program, a: int = 0, b: int = 6, *, frame: str | None = None, machine: str | None = None,
                 **options):
        from ..transpile import STAGE_NAMES

        if frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, not {frame!r}")
        self.frame = frame
        self.error: str | None = None
        self.transpiler = None
        self._stages: dict[int, Side] = {}
        self._programs: tuple[Side, Side] | None = None
        self._ops: dict = {}
        self._options = options
        self.name = Path(program).name if isinstance(program, (str, Path)) and "\n" not in str(program) else "program"
        try:
            from ..model.operation import Operation
            from ..pipeline import transpile_program
            from ..transpile import Transpiler

            self.transpiler = Transpiler(program) if isinstance(program, Operation) else transpile_program(
                program, machine, **options)
            if not np.any(np.asarray(self.transpiler.op.waypoints["motion"]) > 0):
                self.error = f"{self.transpiler.op.file}: the program has no motions to translate"
        except Exception as exc:  # unreadable input: a message in the widget, not a traceback
            self.error = friendly(exc)
        options = [(f"{k}: {name}", k) for k, name in enumerate(STAGE_NAMES)]
        self.stage_a = widgets.Dropdown(options=options, value=a, description="left")
        self.stage_b = widgets.Dropdown(options=options, value=b, description="right")
        self._build()

    @classmethod
    def programs(cls, a_path, b_path, *, machine: str | None = None, **options) -> "StageDiff":
        """Compare two programs line by line (a part before and after an edit), their toolpaths overlaid."""
        self = cls.__new__(cls)
        self.frame = None
        self.error, self.transpiler, self._stages, self._ops, self._options = None, None, {}, {}, options
        self.name = f"{Path(a_path).name} / {Path(b_path).name}"
        sides = []
        for path in (a_path, b_path):
            try:
                text = Path(path).read_text(encoding="utf-8", errors="replace")
                sides.append(Side(Path(path).name, text.splitlines(), frame="machine coordinates"))
                self._ops[Path(path).name] = _emulate(Path(path), machine, options)
            except Exception as exc:
                sides.append(Side(Path(path).name, None, friendly(exc)))
        self._programs = (sides[0], sides[1])
        self.stage_a = widgets.Dropdown(options=[(sides[0].name, 0)], value=0, description="left", disabled=True)
        self.stage_b = widgets.Dropdown(options=[(sides[1].name, 1)], value=1, description="right", disabled=True)
        self._build()
        return self

    # -- building -------------------------------------------------------------------

    def _build(self) -> None:
        self.table = widgets.HTML(layout=widgets.Layout(max_height="420px", overflow="auto", width="100%"))
        self.image = widgets.Image(format="png", layout=widgets.Layout(width="640px"))
        if self.error is not None:
            for control in (self.stage_a, self.stage_b):
                control.disabled = True
            self.widget = widgets.VBox([widgets.HTML(message_html(self.error))])
            return
        self.stage_a.observe(self._refresh, "value")
        self.stage_b.observe(self._refresh, "value")
        self.widget = widgets.VBox([widgets.HBox([self.stage_a, self.stage_b]), self.image, self.table],
                                   layout=widgets.Layout(width="100%"))
        self._refresh()

    def _refresh(self, change=None) -> None:
        # the picture first: the browser gets updates in order, so a table that shows the new pair
        # means the picture of that pair has arrived too
        self.image.value = to_png(self.figure())
        self.table.value = self.diff_html()

    def sides(self) -> tuple[Side, Side]:
        """The two texts compared."""
        if self._programs is not None:
            return self._programs
        return self._stage(self.stage_a.value), self._stage(self.stage_b.value)

    def _stage(self, k: int) -> Side:
        from ..transpile import STAGE_NAMES

        if k not in self._stages:
            name = f"stage {k}: {STAGE_NAMES[k]}"
            try:
                lines = self.transpiler.stage(k).splitlines()
                frame = re.search(r"stage \d+: (.*)\)", lines[0])
                self._stages[k] = Side(name, lines, frame=_frame(lines[0]) if frame else "")
            except Exception as exc:  # a stage that cannot be written is shown as such
                self._stages[k] = Side(name, None, f"stage {k} could not be translated: {friendly(exc)}")
        return self._stages[k]

    # -- the table ---------------------------------------------------------------------

    def rows(self) -> list[tuple[str, int | None, int | None]]:
        """Aligned line pairs (see :func:`align`)."""
        a, b = self.sides()
        if a.lines is None or b.lines is None:
            return []
        return align(a.lines, b.lines, by_source=self._programs is None)

    def diff_html(self) -> str:
        """The side-by-side table as HTML: changed lines marked, each row with its source line."""
        if self.error is not None:
            return message_html(self.error)
        a, b = self.sides()
        failed = [s.error for s in (a, b) if s.error]
        if failed:
            return "".join(message_html(m) for m in failed)
        source = None if self._programs is not None else self._source_lines()
        headers = (["line", "source"] if source is not None else ["#", "#"]) + [a.name, b.name]
        # fixed columns: both stages stay in view however long a source line or comment is
        widths = ["5%", "24%", "35.5%", "35.5%"] if source is not None else ["4%", "4%", "46%", "46%"]
        out = ['<table class="gcodekit-diff" style="border-collapse:collapse;font:12px monospace;width:100%;'
               'table-layout:fixed">', "<colgroup>" + "".join(f'<col style="width:{w}">' for w in widths) + "</colgroup>",
               "<thead><tr>" + "".join(f'<th style="text-align:left;padding:2px 6px;border-bottom:1px solid #999">'
                                        f'{html.escape(h)}</th>' for h in headers) + "</tr></thead><tbody>"]
        colors = {"same": "", "changed": "background:#fff3c4", "removed": "background:#fde0dc",
                  "added": "background:#dff3e4"}
        rows = self.rows()
        counts = {k: sum(1 for r in rows if r[0] == k) for k in colors}
        for status, i, j in rows[:MAX_ROWS]:
            left = html.escape(a.lines[i]) if i is not None else ""
            right = html.escape(b.lines[j]) if j is not None else ""
            cells = []
            if source is not None:
                key = source_key((a.lines[i] if i is not None else b.lines[j]))
                number = key[1] if key[0] == "N" else None
                text = html.escape(source[number - 1]) if number and 0 < number <= len(source) else ""
                cells += [str(number or ""), f'<span style="color:#666">{text}</span>']
            else:
                cells += ["" if i is None else str(i + 1), "" if j is None else str(j + 1)]
            cells += [left, right]
            out.append(f'<tr class="{status}" style="{colors[status]}">'
                       + "".join(f'<td style="padding:1px 6px;vertical-align:top;white-space:pre;overflow:hidden;'
                                 f'text-overflow:ellipsis">{c}</td>' for c in cells)
                       + "</tr>")
        out.append("</tbody></table>")
        note = f"{counts['changed']} changed, {counts['removed']} only left, {counts['added']} only right, " \
               f"{counts['same']} the same"
        if len(rows) > MAX_ROWS:
            note += f"; the first {MAX_ROWS} of {len(rows)} rows shown"
        return f'<div class="gcodekit-diff-summary" style="font:12px sans-serif;margin:4px 0">{note}</div>' + "".join(out)

    def _source_lines(self) -> list[str]:
        from ..view import source_lines

        return source_lines(self.transpiler.op) or []

    # -- the picture ----------------------------------------------------------------------

    def _operation(self, side: Side, index: int):
        """The toolpath of one side and the frame it is drawn in: a stage's text (see the module), or a program.

        Returns the operation, the (n, 3) shift to take off each waypoint (None for none) and the frame's name.
        """
        if self._programs is not None:
            return self._ops.get(side.name), None, side.frame
        key = (self.stage_a.value if index == 0 else self.stage_b.value, self.frame)
        if key not in self._ops:
            in_machine = side.frame.startswith("machine")
            if self.frame == "machine" and not in_machine:  # offsets applied, the programmed path
                op, _ = self._emulate_lines(side.lines, _COMP_CODES)
                self._ops[key] = op, None, "machine coordinates, programmed path"
            elif self.frame == "program" and in_machine:  # moved back by the offsets of each source line
                op, kept = self._emulate_lines(side.lines, _FRAME_CODES)
                self._ops[key] = op, self._shift(op, kept), side.frame.replace("machine", "program")
            else:
                self._ops[key] = self._emulate_lines(side.lines, _FRAME_CODES)[0], None, side.frame
        return self._ops[key]

    def _emulate_lines(self, lines: list[str], leave_out: re.Pattern):
        """The operation of ``lines`` without those ``leave_out`` matches, and the lines kept."""
        kept = [line for line in lines if not leave_out.match(line)]
        machine = self.transpiler.op.machine
        return _emulate("\n".join(kept) + "\n", machine.name if machine is not None else None, self._options), kept

    def _offsets(self) -> dict[int, np.ndarray]:
        """Machine minus program position after each source line of stage 0 (its offsets in force)."""
        if "offsets" not in self._ops:
            lines = self._stage(0).lines or []
            ends = []
            for leave_out in (_COMP_CODES, _FRAME_CODES):
                ends.append(_ends_by_source(*self._emulate_lines(lines, leave_out)))
            machine, program = ends
            self._ops["offsets"] = {n: machine[n] - program[n] for n in machine if n in program}
        return self._ops["offsets"]

    def _shift(self, op, lines: list[str]) -> np.ndarray:
        """Per waypoint of ``op`` (emulated from ``lines``), the offsets in force at its source line."""
        offsets = self._offsets()
        numbers = _source_numbers(op, lines)
        shift = np.zeros((numbers.size, 3))
        known = sorted(offsets)
        for row, n in enumerate(numbers):
            earlier = [k for k in known if k <= n] if n >= 0 else []
            if earlier:
                shift[row] = offsets[earlier[-1]]
        return shift

    def figure(self, size: tuple[int, int] = (800, 560)):
        """Both toolpaths from above: feed moves solid, rapids dashed, each named with its frame."""
        if self.error is not None:
            return message_figure(self.error)
        sides = self.sides()
        failed = [s.error for s in sides if s.error]
        if failed:
            return message_figure("\n".join(failed))
        from matplotlib.collections import LineCollection

        fig = new_figure(size)
        ax = fig.add_axes([0.08, 0.08, 0.9, 0.76])
        handles = []
        for index, side in enumerate(sides):
            try:
                op, shift, frame = self._operation(side, index)
            except Exception as exc:
                return message_figure(f"{side.name}: cannot draw its toolpath: {friendly(exc)}")
            w = op.waypoints
            motion = np.asarray(w["motion"])
            from ..view import move_segments

            rows = np.flatnonzero(op.moving)
            rows = rows[rows > 0]  # a move runs from the waypoint before it
            start, end, move_of = move_segments(w, rows)
            if shift is not None:
                start, end = start - shift[rows][move_of], end - shift[rows][move_of]
            rapid = motion[rows][move_of] == 1
            # the left stage wide and pale under the right one: where both agree, both stay visible
            width = 3.5 if index == 0 else 1.3
            for (color, style), mask, what in ((STYLES[index][0], ~rapid, "feed"), (STYLES[index][1], rapid, "rapid")):
                segs = np.stack([start[mask][:, :2], end[mask][:, :2]], axis=1)
                ax.add_collection(LineCollection(segs, colors=color, linestyles=style, alpha=0.45 if index == 0 else 0.9,
                                                 linewidths=width if what == "feed" else width / 2))
                label = f"{side.name} ({frame})" if what == "feed" else f"{side.name}: rapids"
                handles.append(ax.plot([], [], color=color, linestyle=style, linewidth=width, label=label)[0])
        ax.autoscale()
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
        ax.set_xlabel("X (mm)")
        ax.set_ylabel("Y (mm)")
        ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=1, fontsize=8, frameon=False)
        return fig

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict:
        """The live view, a PNG of the picture, and HTML with the picture and the table (read offline)."""
        import base64

        bundle = super()._repr_mimebundle_(include, exclude)
        picture = base64.b64encode(bundle["image/png"]).decode("ascii")
        bundle["text/html"] = f'<img src="data:image/png;base64,{picture}" alt="{html.escape(repr(self))}">' \
                              + self.diff_html()
        return bundle

    def __repr__(self) -> str:
        if self.error is not None:
            return f"<StageDiff: {self.error}>"
        a, b = self.sides()
        return f"<StageDiff {self.name!r}: {a.name} against {b.name}>"


def _frame(header: str) -> str:
    """The frame a stage is written in, from its header line."""
    if "absolute machine" in header:
        return "machine coordinates, compensated"
    if "machine coordinates" in header:
        return "machine coordinates, programmed path"
    return "program coordinates, programmed path"


def _source_numbers(op, lines: list[str]) -> np.ndarray:
    """The source line (N-number) of each waypoint of ``op``, emulated from ``lines``; -1 where none."""
    numbers = np.array([key[1] if key[0] == "N" else -1 for key in map(source_key, lines)] + [-1])
    text_line = np.asarray(op.table.line, np.int64)[op.waypoints["command"]] - 1
    return numbers[np.clip(text_line, 0, len(lines))]


def _ends_by_source(op, lines: list[str]) -> dict[int, np.ndarray]:
    """Where the tool is after each source line (the last waypoint carrying its N-number)."""
    xyz = np.column_stack([np.asarray(op.waypoints[k], float) for k in "xyz"])
    return {int(n): xyz[row] for row, n in enumerate(_source_numbers(op, lines)) if n >= 0}


def _emulate(source, machine: str | None, options: dict):
    from ..pipeline import gcode_to_operation

    return gcode_to_operation(source, machine, plan=False, **options)
