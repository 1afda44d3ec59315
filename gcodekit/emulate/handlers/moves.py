"""Emulate stage: moves the machine works out block by block: splines (G5, G5.1, G5.2/G5.3) and
polar coordinates (LinuxCNC's ``@``/``^`` words, Fanuc's and GER's G16)."""

from __future__ import annotations

import numpy as np

from ...parse.table import MOTION_LINEAR, MOTION_NURBS, MOTION_RAPID
from ..cycles import polar_target
from ..splines import SPLINE_NAMES
from ..state import AXES
from .registry import POLAR_MODE, POLAR_WORDS, SPLINE_MODE, Block, Context, Outcome, Waypoint, handles
from .words import move_to


@handles(*SPLINE_NAMES, SPLINE_MODE)
def spline(ctx: Context, block: Block) -> Outcome | None:
    """G5, G5.1, G5.2/G5.3 and the control points between: the curve's chords become waypoints
    (see :mod:`gcodekit.emulate.splines`)."""
    s, name, params = ctx.state, block.name, block.params
    # the mode the block before left in force (a chunk's first row: trust it)
    mode_before = int(block.table.motion[block.row - 1]) if block.row else MOTION_NURBS
    problem = ""
    if not name and block.motion != MOTION_NURBS:
        problem = "Cannot use axis values without a g code that uses them"  # rs274: G5/G5.1 are not modal
    elif name == "nurbs_end" and mode_before != MOTION_NURBS:
        problem = "Cannot use G5.3 without G5.2 first"
        ctx.splines.discard()
    elif name in ("spline_cubic", "spline_quadratic") and s.plane != 17:  # rs274 draws a NURBS in XY anyway
        problem = "Splines must be in the XY plane"
    elif name in ("spline_cubic", "spline_quadratic") and any(letter in params for letter in "ZABC"):
        problem = "Splines may not have motion in Z, A, B, or C"
    if name == "nurbs_start" and not ("X" in params or "Y" in params) and not params.get("P", 1.0) > 0:
        ctx.diagnostics.report(block.line, 1, f"G5.2's weight P{params['P']:g} is not positive: rs274 takes it, but a "
                               "NURBS with such a weight has no well-defined path; gcodekit moves in a straight line "
                               "to the curve's end", severity="warning", kind="machine")
    try:
        if problem:
            raise ValueError(problem)
        chords = ctx.splines.block(name or "nurbs_point", params, s.program_position()[:2], float(s.scale()[0]),
                                   s.incremental)
    except ValueError as exc:
        ctx.error(block.line, str(exc))
        return None
    if chords is None:
        return None
    points = np.repeat(s.program_position()[None, :], len(chords) - 1, axis=0)
    points[:, :2] = chords[1:]
    points = s.to_machine(points)
    passed = [Waypoint({**dict(zip(AXES.lower(), p)), "motion": MOTION_LINEAR}) for p in points[:-1]]
    s.position = points[-1].copy()
    return Outcome(MOTION_LINEAR, passed)


@handles(POLAR_WORDS)
def polar_words(ctx: Context, block: Block) -> Outcome | None:
    """G0/G1 with ``@``/``^``: the X/Y end point in polar form (LinuxCNC, XY plane only)."""
    s = ctx.state
    if block.motion not in (MOTION_RAPID, MOTION_LINEAR) or s.plane != 17:
        ctx.error(block.line, "polar words need G0 or G1 in the XY plane")
        return None
    program = s.program_position()
    program[[0, 1]] = polar_target(block.params, program[[0, 1]], s.scale()[0], s.incremental)
    move_to(s, program, block.params)
    return Outcome(block.motion)


@handles(POLAR_MODE)
def radius_angle_move(ctx: Context, block: Block) -> Outcome | None:
    """G0/G1 under G16 (Fanuc, GER): X the radius, Y the angle in degrees.

    In G90 the pole is the program origin and a missing word keeps the
    last polar value; in G91 the pole is the current point (the move is
    X long at angle Y), as GER requires.  Arcs are refused, as GER does.
    """
    s, params = ctx.state, block.params
    if block.motion not in (MOTION_RAPID, MOTION_LINEAR) or s.plane != 17:
        ctx.error(block.line, "G16 polar coordinates allow only G0 and G1 in the XY plane")
        return None
    if ctx.polar_incremental_only and not s.incremental:
        ctx.error(block.line, "polar coordinates (G16) may only be used in incremental mode (G91)")
        return None
    program = s.program_position()
    scale = s.scale()
    if s.incremental:
        radius, angle = params.get("X", 0.0) * scale[0], np.radians(params.get("Y", 0.0))
        program[[0, 1]] += radius * np.array([np.cos(angle), np.sin(angle)])
    else:
        radius = params["X"] * scale[0] if "X" in params else float(np.hypot(*program[[0, 1]]))
        angle = np.radians(params["Y"]) if "Y" in params else float(np.arctan2(program[1], program[0]))
        program[[0, 1]] = radius * np.array([np.cos(angle), np.sin(angle)])
    move_to(s, program, params)
    return Outcome(block.motion)
