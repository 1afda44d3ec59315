"""The built-in wizards: pockets, drilling patterns and facing (see :mod:`gcodekit.preprocess.wizards`).

Each is a generator of G-code lines in the program's units, using only
G0/G1/G3 with X Y Z I J F; they switch to G90 for their moves (and back to
G91 if the program was incremental), plunge straight down and end at
``safe_z``, in G0 mode.
"""

from __future__ import annotations

import math
from typing import Iterator

from .context import MAX_LINES, WizardArgumentError, WizardContext, WizardFunction

# Most passes, rows or rings one built-in plans; beyond that the arguments
# are nonsense (a 1e-9 stepdown), not a program.
_MAX_STEPS = MAX_LINES


def _n(value: float) -> str:
    """A coordinate to 4 decimals, trailing zeros dropped ('-0' is '0')."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _positive(value: float, what: str, index: int) -> float:
    if not value > 0:
        raise WizardArgumentError(f"{what} must be positive, not {value:g}", index)
    return value


def _steps(span: float, step: float, index: int | None) -> int:
    """How many steps of at most ``step`` cover ``span`` (at least 1)."""
    count = span / step
    if count > _MAX_STEPS:
        raise WizardArgumentError(f"needs {count:.3g} steps (more than {_MAX_STEPS})", index)
    return max(1, math.ceil(count - 1e-9))


class _Tool:
    """The tool and feeds a built-in uses, in the program's units."""

    def __init__(self, ctx: WizardContext, stepdown: float | None, stepover: float | None,
                 stepdown_index: int, stepover_index: int):
        self.diameter = ctx.tool_diameter if ctx.tool_diameter is not None else ctx.setting("tool_diameter")
        if not self.diameter > 0:
            raise WizardArgumentError(f"tool diameter must be positive, not {self.diameter:g}")
        self.radius = self.diameter / 2
        self.stepdown = self.radius if stepdown is None else _positive(stepdown, "stepdown", stepdown_index)
        if stepover is None:
            stepover = ctx.setting("stepover") * self.diameter
        elif not 0 < stepover <= self.diameter * (1 + 1e-9):
            raise WizardArgumentError(f"stepover must be above 0 and at most the tool diameter "
                                      f"{_n(self.diameter)}, not {stepover:g}", stepover_index)
        self.stepover = stepover
        self.feed = _n(ctx.setting("feed"))
        self.plunge = _n(ctx.setting("plunge_feed"))
        self.safe = _n(ctx.setting("safe_z"))
        self.incremental = ctx.distance == "incremental"

    def depths(self, depth: float, index: int) -> Iterator[float]:
        """Pass depths: stepdown, 2 stepdown, ..., the last one at ``depth``."""
        for k in range(1, _steps(depth, self.stepdown, index) + 1):
            yield -min(k * self.stepdown, depth)

    def start(self) -> Iterator[str]:
        if self.incremental:
            yield "G90"
        yield f"G0 Z{self.safe}"

    def end(self) -> Iterator[str]:
        yield f"G0 Z{self.safe}"
        if self.incremental:
            yield "G91"


def _evenly(low: float, high: float, step: float, index: int) -> Iterator[float]:
    """``low`` .. ``high`` inclusive, evenly spaced at most ``step`` apart."""
    count = _steps(high - low, step, index) if high > low else 0
    return (low + (high - low) * k / count if k < count else high for k in range(count + 1))


def pocket(ctx: WizardContext, width: float, height: float, depth: float,
           stepdown: float | None = None, stepover: float | None = None) -> Iterator[str]:
    """``Pocket width height depth [stepdown] [stepover]``: rectangular pocket on X0 Y0.

    The pocket spans X -width/2..width/2, Y -height/2..height/2 and Z0 down
    to Z-depth.  At each depth (``stepdown`` apart, default half the tool
    diameter) the tool zigzags along X, rows ``stepover`` apart (default 0.4
    tool diameters), then follows the walls once; it plunges at the
    lower-left corner.  The tool centre stays within the outline shrunk by
    the tool radius.
    """
    tool = _Tool(ctx, stepdown, stepover, 3, 4)
    _positive(width, "width", 0), _positive(height, "height", 1), _positive(depth, "depth", 2)
    for value, what, index in ((width, "width", 0), (height, "height", 1)):
        if value < tool.diameter * (1 - 1e-9):
            raise WizardArgumentError(f"pocket {what} {value:g} is less than the tool diameter "
                                      f"{_n(tool.diameter)}", index)
    x0, x1 = -width / 2 + tool.radius, width / 2 - tool.radius
    y0, y1 = -height / 2 + tool.radius, height / 2 - tool.radius
    x0, x1 = min(x0, x1), max(x0, x1)
    y0, y1 = min(y0, y1), max(y0, y1)
    yield from tool.start()
    yield f"G0 X{_n(x0)} Y{_n(y0)}"
    for z in tool.depths(depth, 2):
        yield f"G1 Z{_n(z)} F{tool.plunge}"
        for k, y in enumerate(_evenly(y0, y1, tool.stepover, 4)):
            if k:
                yield f"G1 Y{_n(y)}"
            yield f"G1 X{_n(x1 if k % 2 == 0 else x0)}" + ("" if k else f" F{tool.feed}")
        yield f"G1 X{_n(x0)} Y{_n(y0)}"
        yield f"G1 X{_n(x1)}"
        yield f"G1 Y{_n(y1)}"
        yield f"G1 X{_n(x0)}"
        yield f"G1 Y{_n(y0)}"
    yield from tool.end()


def circle_pocket(ctx: WizardContext, diameter: float, depth: float,
                  stepdown: float | None = None, stepover: float | None = None) -> Iterator[str]:
    """``CirclePocket diameter depth [stepdown] [stepover]``: round pocket on X0 Y0.

    At each depth the tool plunges at the centre and cuts concentric full
    circles (G3, I/J) at most ``stepover`` apart, out to the wall.
    """
    tool = _Tool(ctx, stepdown, stepover, 2, 3)
    _positive(diameter, "diameter", 0), _positive(depth, "depth", 1)
    outer = diameter / 2 - tool.radius
    if outer < -1e-9 * diameter:
        raise WizardArgumentError(f"pocket diameter {diameter:g} is less than the tool diameter "
                                  f"{_n(tool.diameter)}", 0)
    radii = list(_evenly(0.0, max(outer, 0.0), tool.stepover, 3))[1:]
    yield from tool.start()
    yield "G0 X0 Y0"
    for k, z in enumerate(tool.depths(depth, 1)):
        if k and radii:
            yield "G1 X0 Y0"
        yield f"G1 Z{_n(z)} F{tool.plunge}"
        for j, r in enumerate(radii):
            yield f"G1 X{_n(r)} Y0" + ("" if j else f" F{tool.feed}")
            yield f"G3 X{_n(r)} Y0 I{_n(-r)} J0"
    yield from tool.end()


def _drill(tool: _Tool, x: float, y: float, depth: float, peck: float | None, ctx: WizardContext) -> Iterator[str]:
    yield f"G0 X{_n(x)} Y{_n(y)}"
    if peck is None:
        yield f"G1 Z{_n(-depth)} F{tool.plunge}"
    else:
        clearance = ctx.length(0.5)  # stop short of the last peck's bottom: chips
        previous = 0.0
        for k in range(1, _steps(depth, peck, 5) + 1):
            z = -min(k * peck, depth)
            if k > 1:
                yield f"G0 Z{_n(min(previous + clearance, 0.0))}"
            yield f"G1 Z{_n(z)} F{tool.plunge}"
            if z > -depth:
                yield f"G0 Z{tool.safe}"
            previous = z
    yield f"G0 Z{tool.safe}"


def drill_grid(ctx: WizardContext, nx: int, ny: int, dx: float, dy: float, depth: float,
               peck: float | None = None) -> Iterator[str]:
    """``DrillGrid nx ny dx dy depth [peck]``: a grid of holes, the first at X0 Y0.

    Columns are ``dx`` apart along X, rows ``dy`` apart along Y (either may
    be negative); holes are drilled row by row, alternating direction.
    With ``peck`` the tool backs out to ``safe_z`` after each ``peck`` of
    depth.
    """
    tool = _Tool(ctx, None, None, -1, -1)
    for value, what, index in ((nx, "nx", 0), (ny, "ny", 1)):
        if value < 1:
            raise WizardArgumentError(f"{what} must be at least 1, not {value}", index)
    if nx * ny > _MAX_STEPS:
        raise WizardArgumentError(f"{nx} x {ny} holes is more than {_MAX_STEPS}", 0)
    _positive(depth, "depth", 4)
    if peck is not None:
        _positive(peck, "peck", 5)
    yield from tool.start()
    for j in range(ny):
        for i in range(nx) if j % 2 == 0 else range(nx - 1, -1, -1):
            yield from _drill(tool, i * dx, j * dy, depth, peck, ctx)
    if tool.incremental:
        yield "G91"


def bolt_circle(ctx: WizardContext, count: int, diameter: float, depth: float,
                start_angle: float = 0.0) -> Iterator[str]:
    """``BoltCircle count diameter depth [start_angle]``: holes on a circle on X0 Y0.

    The first hole is at ``start_angle`` degrees counter-clockwise from +X;
    the others follow counter-clockwise, evenly spaced.
    """
    tool = _Tool(ctx, None, None, -1, -1)
    if count < 1:
        raise WizardArgumentError(f"count must be at least 1, not {count}", 0)
    if count > _MAX_STEPS:
        raise WizardArgumentError(f"{count} holes is more than {_MAX_STEPS}", 0)
    _positive(diameter, "diameter", 1), _positive(depth, "depth", 2)
    yield from tool.start()
    for k in range(count):
        angle = math.radians(start_angle + 360.0 * k / count)
        yield from _drill(tool, diameter / 2 * math.cos(angle), diameter / 2 * math.sin(angle), depth, None, ctx)
    if tool.incremental:
        yield "G91"


def face(ctx: WizardContext, width: float, height: float, depth: float,
         stepdown: float | None = None, stepover: float | None = None) -> Iterator[str]:
    """``Face width height depth [stepdown] [stepover]``: face X0..width, Y0..height.

    The top is cut down to Z-depth in passes ``stepdown`` apart; each pass
    zigzags along X, from one tool radius outside the left edge to one
    outside the right, with rows from Y0 to Y``height`` at most
    ``stepover`` apart, so the cutter covers the whole rectangle.
    """
    tool = _Tool(ctx, stepdown, stepover, 3, 4)
    _positive(width, "width", 0), _positive(height, "height", 1), _positive(depth, "depth", 2)
    x0, x1 = -tool.radius, width + tool.radius
    yield from tool.start()
    for z in tool.depths(depth, 2):
        yield f"G0 X{_n(x0)} Y0"
        yield f"G1 Z{_n(z)} F{tool.plunge}"
        for k, y in enumerate(_evenly(0.0, height, tool.stepover, 4)):
            if k:
                yield f"G1 Y{_n(y)}"
            yield f"G1 X{_n(x1 if k % 2 == 0 else x0)}" + ("" if k else f" F{tool.feed}")
        yield f"G0 Z{tool.safe}"
    if tool.incremental:
        yield "G91"


#: The built-in wizards by name
BUILTINS: dict[str, WizardFunction] = {
    "Pocket": pocket,
    "CirclePocket": circle_pocket,
    "DrillGrid": drill_grid,
    "BoltCircle": bolt_circle,
    "Face": face,
}
