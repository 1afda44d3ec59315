"""G76 threading cycle (gcodekit.emulate.threading) against values worked out by hand.

rs274's own output for a cycle with every option is the golden case
golden/linuxcnc/own/g76_threading.ngc.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gcodekit
from gcodekit.emulate.threading import threading_moves


def test_depth_of_each_pass_follows_the_degression():
    # |I| = 0.5, J = 0.2, K = 1.0, R = 2: depths 0.5 + 0.2 * sqrt(n) for n = 1.. while below 1.5
    moves = threading_moves((10.0, 0.0), -10.0, p=1.0, i=-0.5, j=0.2, k=1.0, r=2.0)
    cut_x = [x for kind, x, _, _ in moves if kind == "feed"]
    depths = [0.5 + 0.2 * math.sqrt(n) for n in range(1, 26) if 0.5 + 0.2 * math.sqrt(n) < 1.5] + [1.5]
    np.testing.assert_allclose(cut_x, [10.0 - d for d in depths])


def test_compound_angle_moves_each_start_along_z():
    q = 30.0
    moves = threading_moves((10.0, 0.0), -10.0, p=1.0, i=-0.5, j=0.25, k=1.0, q=q)
    starts = [z for kind, _, z, _ in moves[1::4]]  # the rapid in of each pass
    depths = [0.75, 1.0, 1.25, 1.5]
    np.testing.assert_allclose(starts, [-(d - 0.5) * math.tan(math.radians(q)) for d in depths])


def test_threading_feeds_take_pitch_times_spindle_speed():
    program = "G18 G21 G90\nS200 M3\nG0 X10 Z2\nG76 P1.5 Z-18 I-1 J0.5 K1.5 R1\nM2\n"
    op = gcodekit.gcode_to_operation(program, "linuxcnc", plan=False)
    w = op.waypoints
    feeds = w["motion"] == 2
    # three passes (depths 1.5, 2, full depth 2.5), each 20 mm along Z at 1.5 mm x 200 rpm = 300 mm/min
    assert feeds.sum() == 3
    np.testing.assert_allclose(w["feed"][feeds], 300.0)
    np.testing.assert_allclose(w["time"][feeds], 20.0 / 300.0 * 60.0)


@pytest.mark.parametrize("words, message", [
    ("P1.5 Z-20 I-1 K1.2", "I J or K words missing with G76"),
    ("Z-20 I-1 J0.2 K1.2", "P word missing with G76"),
    ("P1.5 I-1 J0.2 K1.2", "All axes missing with motion code"),
    ("P1.5 Z-20 I0 J0.2 K1.2", "In G76, I must not be 0"),
    ("P1.5 Z-20 I-1 J0.2 K0.2", "In G76, K must be greater than J"),
])
def test_refusals_as_rs274(words: str, message: str):
    op = gcodekit.gcode_to_operation(f"G18 G21 G90\nS300 M3\nG0 X10 Z5\nG76 {words}\nM2\n", "linuxcnc", plan=False)
    errors = [(d.line, d.message) for d in op.diagnostics if d.severity == "error"]
    assert errors == [(4, message)]


def test_axis_words_alone_repeat_the_cycle():
    """G76 stays the motion mode: rs274 refuses "X14 Z4" after it for want of P."""
    op = gcodekit.gcode_to_operation("G18 G21\nS300 M3\nG0 X10 Z5\nG76 P1 Z-5 I-0.5 J0.2 K0.6\nX14 Z4\nM2\n",
                                     "linuxcnc", plan=False)
    assert [(d.line, d.message) for d in op.diagnostics if d.severity == "error"] == [(5, "P word missing with G76")]


def test_rigid_tap_goes_in_and_back_out_at_the_pitch():
    # K1.25 at 500 rpm: 625 mm/min, 12 mm down and 12 mm back up
    op = gcodekit.gcode_to_operation("G21 G90\nS500 M3\nG0 X5 Y5 Z2\nG33.1 Z-10 K1.25\nM2\n", "linuxcnc", plan=False)
    w = op.waypoints
    feeds = w["motion"] == 2
    np.testing.assert_allclose(w["z"][feeds], [-10.0, 2.0])
    np.testing.assert_allclose(w["time"][feeds], 12.0 / 625.0 * 60.0)
    refused = gcodekit.gcode_to_operation("G21\nG0 Z2\nG33.1 Z-10 K1\nM2\n", "linuxcnc", plan=False)
    assert [(d.line, d.message) for d in refused.diagnostics] == [(3, "Spindle not turning in G33.1")]
