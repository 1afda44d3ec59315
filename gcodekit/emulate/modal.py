"""Emulate stage: the commands that change the machine's modal state, dispatched to their handlers.

These are rare (a few per layer or per tool), so each such block runs
alone, in plain Python, in the handler registered for it (the
:mod:`.handlers` package, one module per family: units and planes, work
systems, tools, spindle and coolant, homing, printer commands, cycles,
splines and polar moves).  The dispatcher does what every block shares:
block delete, the F word, G16's rule on the program zero; it routes the
block to its handler (:func:`route`) and writes the block's waypoint from
what the handler did (:class:`~.handlers.registry.Outcome`).
"""

from __future__ import annotations

import numpy as np

from ..parse.table import (MOTION_CCW, MOTION_CW, MOTION_CYCLE, MOTION_LINEAR, MOTION_NONE, MOTION_RAPID,
                           MOTION_THREAD, NAME_ID, SPLINE_MOTIONS, CommandTable)
from .arcs import PLANES, single_turn_lengths
from .handlers import HANDLERS
from .handlers.modes import FEED_AT_OR_BELOW_ZERO, UNITS
from .handlers.registry import (AFTER_LATHE_CYCLE, CANNED_CYCLE, LATHE_CYCLE, POLAR_MODE, POLAR_WORDS, SPLINE_MODE,
                                SYNCHRONIZED, T_WORD, Block, Context, Outcome, Waypoint)
from .lathe import LATHE_CYCLES
from .splines import SPLINE_NAMES
from .state import AXES

__all__ = ["ModalHandler", "Waypoint", "route"]

_PROGRAM_ZERO = frozenset({"local_offset", "set_position", "clear_position_offset"})  # G52, G92, G92.1


def route(block: Block, ctx: Context) -> str:
    """The key in :data:`~.handlers.registry.HANDLERS` of the handler that runs ``block``.

    A block that moves in a mode of its own goes by that mode, checked in
    this order: a lathe cycle or axis words alone after one, G76, a canned
    cycle, G33/G33.1, a spline, polar words, G16.  A T word alone goes to
    :data:`~.handlers.registry.T_WORD`; every other block by its name.
    """
    name, motion, moves = block.name, block.motion, block.moves
    repeat = moves and motion == MOTION_CYCLE and not name  # axis words alone repeat the cycle in force
    cycle = ctx.cycle_mode.name
    if name in LATHE_CYCLES:
        return LATHE_CYCLE
    if repeat and cycle in LATHE_CYCLES:
        return AFTER_LATHE_CYCLE
    if name == "cycle_thread" or (repeat and cycle == "cycle_thread"):
        return "cycle_thread"
    if moves and motion == MOTION_CYCLE and name not in ("retract_initial", "retract_r"):
        return CANNED_CYCLE
    if moves and motion == MOTION_THREAD:
        return SYNCHRONIZED
    if name in SPLINE_NAMES:
        return name
    if moves and motion in SPLINE_MOTIONS:
        return SPLINE_MODE
    if moves and ("@" in block.params or "^" in block.params):
        return POLAR_WORDS
    if ctx.state.polar and (moves or motion in (MOTION_CW, MOTION_CCW)):
        return POLAR_MODE
    return T_WORD if block.letter == "T" else name


class ModalHandler:
    """Runs state-changing commands one at a time on the machine parts of ``context``.

    Parameters
    ----------
    context : Context
        The state, configuration, diagnostics, tool table and motion budget
        the handlers work on.
    """

    def __init__(self, context: Context):
        self.context = context
        #: Name ids of the commands with a handler: the machine runs their blocks one at a time.
        self.special_ids = np.array(sorted(NAME_ID[key] for key in HANDLERS if key in NAME_ID), np.uint8)

    def apply(self, t: CommandTable, row: int, out: dict) -> list[Waypoint]:
        """Run command ``row`` and write its waypoint; return points passed on the way."""
        ctx = self.context
        s = ctx.state
        block = Block(t, row, t.command(row))
        before = s.position.copy()
        if ctx.config.block_delete and row in set(t.deleted.tolist()):
            self._write(out, row, before, Outcome())
            return []
        self._read_feed(block)
        if s.polar and ctx.polar_incremental_only and (block.name in _PROGRAM_ZERO or
                                                       block.name.startswith("work_offset_")):
            ctx.error(block.line, "the program zero may not change while polar coordinates (G16) are on")
        handler = HANDLERS.get(route(block, ctx))
        outcome = handler(ctx, block) if handler is not None else None
        if outcome is None:  # the tool stays where it is
            outcome = Outcome()
        if outcome.motion != MOTION_NONE and outcome.axes_move:
            s.program_shift[:] = 0.0  # the machine has reached the offsets in force
            s.note_move()
        if outcome.believed is not None:
            s.keep_program_position(outcome.believed)
        passed = _dwells_apart(outcome.passed)
        for w in passed:
            self._fill_passing(w, before)
            before = np.array([w.values[k] for k in AXES.lower()])
        self._write(out, row, before, outcome)
        return passed

    def _read_feed(self, block: Block) -> None:
        """An F word sets the feed (in RS274NGC whatever else the block does; on firmware not beside an M code,
        and on Marlin and Klipper only above 0)."""
        ctx, params = self.context, block.params
        if "F" in params and (block.letter != "M" or ctx.rs274_blocks):
            if ctx.zero_feed in ("kept", "stops") and not params["F"] > 0:  # Klipper's G28, G92 read no F
                ctx.warn_once("feed at or below 0", block.line, FEED_AT_OR_BELOW_ZERO)
                return
            # an F beside G20/G21 is in the block's new units ("G20 F60" is 60 in/min); where
            # the units change keeps the F number, the units handler converts the feed instead
            keep = ctx.config.units_keep_feed
            units = UNITS[block.name] if block.name in UNITS and not keep else ctx.state.units
            ctx.state.feed = params["F"] * units
            ctx.state.feed_given = True

    # -- output -------------------------------------------------------------------

    def _fill_passing(self, w: Waypoint, before: np.ndarray) -> None:
        point = np.array([w.values[k] for k in AXES.lower()])
        motion = int(w.values.get("motion", MOTION_RAPID))
        distance = self._length(before, point, motion, [w.values.get(k, np.nan) for k in ("cx", "cy", "cz")])
        rate = w.values["feed"] if "feed" in w.values and motion != MOTION_RAPID else self._rate(motion)
        dwell = w.values.pop("dwell", 0.0)
        w.values.update(distance=distance, time=_duration(distance, rate) + dwell, de=0.0)
        for k in ("cx", "cy", "cz"):
            w.values.setdefault(k, np.nan)

    def _rate(self, motion: int) -> float:
        """Feed of a move made by a special command, mm/min."""
        ctx = self.context
        feeding = motion in (MOTION_LINEAR, MOTION_CW, MOTION_CCW) or ctx.rapid_is_feed
        return max(ctx.state.feed, ctx.state.minimum_feed) if feeding else ctx.config.rapid_feed

    def _length(self, before: np.ndarray, point: np.ndarray, motion: int, centre) -> float:
        """Path length of a move made by a special command: the chord, or the arc round ``centre``."""
        (f, g, h), _ = PLANES[self.context.state.plane]
        centre = np.asarray(centre, float)
        if motion not in (MOTION_CW, MOTION_CCW) or np.isnan(centre[[f, g]]).any():
            return float(np.linalg.norm((point - before)[:3]))
        return float(single_turn_lengths(before[[f, g]][None], point[[f, g]][None], centre[[f, g]][None],
                                         np.array([motion == MOTION_CW]), np.array([point[h] - before[h]]))[0])

    def _write(self, out: dict, row: int, before: np.ndarray, outcome: Outcome) -> None:
        """The block's own waypoint: where the tool ends, reached from ``before``."""
        s = self.context.state
        for k, v in zip(AXES.lower(), s.position):
            out[k][row] = v
        distance = self._length(before, s.position, outcome.motion, outcome.centre)
        rate = self._rate(outcome.motion) if outcome.feed is None else outcome.feed
        path = distance or abs(outcome.de)
        out["distance"][row] = distance
        out["time"][row] = _duration(path, rate) + outcome.dwell
        out["de"][row] = outcome.de
        out["feed"][row] = rate if outcome.feed is not None else s.feed
        out["motion"][row] = outcome.motion
        out["cx"][row], out["cy"][row], out["cz"][row] = outcome.centre
        out["spindle"][row] = s.speed * s.spindle
        s.fill_columns(row, out)


def _duration(path: float, rate: float) -> float:
    """Seconds to travel ``path`` mm at ``rate`` mm/min; NaN (unknown, never invented) with no rate: the
    handler gave the move a rate of zero (a synchronized move at zero pitch or spindle speed, which never
    ends), or no feed rate is in force (a controller refuses the move)."""
    if path and rate > 0:
        return path / (rate / 60.0)
    return float("nan") if path else 0.0


def _dwells_apart(passed: list[Waypoint]) -> list[Waypoint]:
    """A cycle's dwell at a point it passes (G82, G86, G89 at the bottom) as a waypoint of its own that does
    not move, so planners time the move before it at its feed and the machine at rest for the dwell."""
    if not any(w.values.get("dwell") for w in passed):
        return passed
    out = []
    for w in passed:
        dwell = w.values.pop("dwell", 0.0)
        out.append(w)
        if dwell:
            out.append(Waypoint({**{k: w.values[k] for k in AXES.lower()}, "motion": MOTION_NONE, "dwell": dwell}))
    return out
