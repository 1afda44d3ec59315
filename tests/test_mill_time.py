"""Planned time of mill programs against closed forms, move by move, for every planner that plans them.

The planners of mill machines are: none (``fanuc``, ``freecad``, ``ger``:
each move's length over its feed), ``motion_profile`` (``linuxcnc``,
``generic``; with and without acceleration) and ``grbl``.  Each case is a
motion kind with its time worked out here by hand:

* without acceleration a move takes its length over its rate: F for feeds,
  K*S for G33 and G33.1 (down and back), F*S for G95, 60/F seconds for G93,
  the rapid rate for G0; a dwell its P seconds;
* with acceleration ``a`` and the machine at rest around the move (G61), a
  move of length L at speed v takes L/v + v/a when L >= v^2/a (the
  trapezoid), else 2*sqrt(L/a) (the triangle);
* GRBL cuts arcs into mc_arc's chords (``floor(angle r / 2 / sqrt(tol (2r - tol)))``),
  each 2 r sin(angle / 2N) long, which it runs at the feed.

Multi-turn arcs and helices are given by P turns in every plane, in the
I/J/K and the R forms.  The property tests scale a program's turns, pitch
or feed and check that the time scales as the geometry says.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.emulate.presets import load_machine

TAU = 2.0 * math.pi
RAPID = 3000.0  # mm/min, the linuxcnc preset's rapid rate
ACCEL = 500.0  # mm/s^2, the linuxcnc preset's acceleration


def machine(planner: str) -> gcodekit.emulate.presets.MachineConfig:
    """The linuxcnc preset planned by ``planner``: "none", "motion_profile" (no acceleration),
    "motion_profile_accel" (the preset's 500 mm/s^2) or "grbl" (accelerations too high to matter)."""
    base = load_machine("linuxcnc")
    if planner == "none":
        return dataclasses.replace(base, planner="", planner_settings={})
    if planner == "motion_profile":
        return dataclasses.replace(base, planner_settings={"max_velocity": 50.0})
    if planner == "motion_profile_accel":
        return base
    huge = 1e12  # mm/s^2: every speed change instant, so the time is the chords' length over the feed
    return dataclasses.replace(base, planner="grbl", planner_settings={
        "max_rate_x": 1e6, "max_rate_y": 1e6, "max_rate_z": 1e6,
        "acceleration_x": huge, "acceleration_y": huge, "acceleration_z": huge})


def run(text: str, planner: str):
    """The program's operation and its per-waypoint times; no error may be reported."""
    op = gcodekit.gcode_to_operation("G21 G90 G17 G94\n" + text, machine(planner), flavor="rs274ngc")
    assert not op.diagnostics.errors, op.diagnostics.errors
    return op, np.asarray(op.waypoints["time"], float)


def row_time(op, times, line: int) -> float:
    """Time of the moves of source line ``line`` (1-based, counting the header line)."""
    rows = np.asarray(op.waypoints["command"])
    return float(np.nansum(times[op.table.line[rows] == line]))


def trapezoid(length: float, v: float, a: float) -> float:
    """From rest to rest: L/v + v/a, or the triangle 2 sqrt(L/a) when v is never reached."""
    return length / v + v / a if length >= v * v / a else 2.0 * math.sqrt(length / a)


def grbl_chords(radius: float, angle: float, rise: float = 0.0, tol: float = 0.002) -> float:
    """Length of the chords grbl's mc_arc cuts an arc into."""
    n = max(math.floor(0.5 * angle * radius / math.sqrt(tol * (2 * radius - tol))), 1)
    return n * math.hypot(2 * radius * math.sin(angle / (2 * n)), rise / n)


# -- arcs of many turns, every plane, both forms ------------------------------------------

#: (plane, move to the start, arc block, radius, swept turns, rise along the helix axis)
ARCS = [
    ("G17", "G1 X5 F120", "G2 X5 Y0 I-5 J0 P3", 5.0, 3.0, 0.0),
    ("G17", "G1 X5 F120", "G3 X5 Y0 Z-4 I-5 J0 P4", 5.0, 4.0, -4.0),
    ("G18", "G1 Z5 F120", "G2 Z5 X0 K-5 I0 P2", 5.0, 2.0, 0.0),
    ("G18", "G1 Z5 F120", "G3 Z5 X0 Y3 K-5 I0 P5", 5.0, 5.0, 3.0),
    ("G19", "G1 Y5 F120", "G2 Y5 Z0 J-5 K0 P3", 5.0, 3.0, 0.0),
    ("G19", "G1 Y5 F120", "G3 Y5 Z0 X-2 J-5 K0 P2", 5.0, 2.0, -2.0),
    # R form: a half turn (X5 Y0 to X-5 Y0) plus P-1 more turns
    ("G17", "G1 X5 F120", "G2 X-5 Y0 R5 P3", 5.0, 2.5, 0.0),
    ("G17", "G1 X5 F120", "G3 X-5 Y0 Z2 R5 P2", 5.0, 1.5, 2.0),
]
PLANNERS = ["none", "motion_profile", "motion_profile_accel", "grbl"]


@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("plane, lead_in, arc, radius, turns, rise", ARCS)
def test_multi_turn_arcs_and_helices(planner, plane, lead_in, arc, radius, turns, rise):
    text = f"{plane} G61\n{lead_in}\n{arc}\n"  # G61: at rest after each move, so each has its own closed form
    op, times = run(text, planner)
    length = math.hypot(TAU * radius * turns, rise)
    assert op.waypoints["distance"][-1] == pytest.approx(length, rel=1e-9)
    v = 120.0 / 60.0
    expected = {
        "none": length / v,
        "motion_profile": length / v,
        "motion_profile_accel": trapezoid(length, v, ACCEL),
        "grbl": grbl_chords(radius, TAU * turns, rise) / v,
    }[planner]
    assert row_time(op, times, 4) == pytest.approx(expected, rel=1e-6)


def test_the_issue_arcs_and_helix():
    # gcodekit info of the issue: G1 X1 F100 then a full circle of radius 1 turned P times
    for p in (1, 3, 1000):
        op, times = run(f"G1 X1 F100\nG2 X1 Y0 I-1 J0 P{p}\n", "none")
        assert row_time(op, times, 3) == pytest.approx(TAU * p / (100 / 60), rel=1e-12)
    # the helix: two turns of radius 1 falling 2 mm, 12.72 mm at 100 mm/min: 7.63 s
    op, times = run("G1 X1 F100\nG2 X1 Y0 Z-2 I-1 J0 P2\n", "motion_profile_accel")
    length = math.hypot(2 * TAU, 2.0)
    assert length == pytest.approx(12.724, abs=1e-3)
    assert row_time(op, times, 3) == pytest.approx(length * 0.6, rel=1e-3)


def test_grbl_arc_of_many_turns_follows_its_chords():
    # mc_arc cuts the whole sweep, not one turn of it
    op, times = run("G1 X10 F600\nG3 X10 Y0 I-10 J0 P50\n", "grbl")
    assert row_time(op, times, 3) == pytest.approx(grbl_chords(10.0, 50 * TAU) / 10.0, rel=1e-9)
    moves, _ = op.plan
    chords = math.floor(0.5 * 50 * TAU * 10 / math.sqrt(0.002 * (20 - 0.002)))
    assert int(np.sum(moves.waypoint == op.waypoints["x"].size - 1)) == chords


# -- lines, rapids, feed modes, synchronized moves, dwells and cycles ---------------------

@pytest.mark.parametrize("planner", PLANNERS)
def test_straight_feed_and_rapid(planner):
    op, times = run("G61\nG1 X30 Y40 F600\nG0 X0 Y0 Z10\n", planner)
    feed_len, rapid_len = 50.0, math.sqrt(30**2 + 40**2 + 10**2)
    if planner == "motion_profile_accel":
        expected = (trapezoid(feed_len, 10.0, ACCEL), trapezoid(rapid_len, 50.0, ACCEL))
    elif planner == "grbl":
        # grbl's rapids run at the axes' max rate ($110-$112) along the move: the longest axis sets the time
        expected = (feed_len / 10.0, 40.0 / (1e6 / 60))
    else:
        expected = (feed_len / 10.0, rapid_len / 50.0)
    assert (row_time(op, times, 3), row_time(op, times, 4)) == pytest.approx(expected, rel=1e-6, abs=1e-6)


@pytest.mark.parametrize("planner", PLANNERS)
def test_inverse_time(planner):
    # G93: each move takes 1/F minutes, whatever its length
    op, times = run("G61 G93\nG1 X10 F2\nG1 X40 F4\nG2 X40 Y0 I-10 J0 P3 F0.5\n", planner)
    got = [row_time(op, times, line) for line in (3, 4, 5)]
    if planner == "motion_profile_accel":
        expected = [trapezoid(10, 10 / 30, ACCEL), trapezoid(30, 30 / 15, ACCEL),
                    trapezoid(60 * math.pi, 60 * math.pi / 120, ACCEL)]
    elif planner == "grbl":
        expected = [30.0, 15.0, grbl_chords(10.0, 3 * TAU) / (60 * math.pi / 120)]
    else:
        expected = [30.0, 15.0, 120.0]
    assert got == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("planner", PLANNERS)
def test_feed_per_revolution(planner):
    # G95 F0.1 at S1000: 100 mm/min, 10 mm in 6 s; S2000 halves it
    op, times = run("G61 M3 S1000 G95\nG1 X10 F0.1\nS2000\nG1 X0\n", planner)
    v1, v2 = 100 / 60, 200 / 60
    expected = ([trapezoid(10, v1, ACCEL), trapezoid(10, v2, ACCEL)] if planner == "motion_profile_accel"
                else [6.0, 3.0])
    assert [row_time(op, times, 3), row_time(op, times, 5)] == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("planner", PLANNERS)
def test_spindle_synchronized_moves(planner):
    # G33 K1 at S100: 100 mm/min, 10 mm in 6 s; G33.1 K0.5 at S300 goes 8 mm down and back at 150 mm/min
    op, times = run("G61 M3 S100\nG33 Z-10 K1\nS300\nG0 Z0\nG33.1 Z-8 K0.5\n", planner)
    if planner == "motion_profile_accel":
        expected = [trapezoid(10, 100 / 60, ACCEL), 2 * trapezoid(8, 2.5, ACCEL)]
    else:
        expected = [6.0, 16 / 2.5]
    assert row_time(op, times, 3) == pytest.approx(expected[0], rel=1e-6)
    if planner == "motion_profile_accel":  # the rigid tap's two halves are one step: reverses at rest
        assert row_time(op, times, 6) == pytest.approx(expected[1], rel=1e-6)
    else:
        assert row_time(op, times, 6) == pytest.approx(expected[1], rel=1e-6)


@pytest.mark.parametrize("planner", ["none", "motion_profile", "grbl"])
def test_g76_threading_at_pitch_and_spindle_speed(planner):
    # G76 P1 at S200: the threading passes feed at 200 mm/min along Z; all else is rapid.  Passes (rs274's,
    # the same with P0 above): depth J*n until K, no spring pass: 0.2, 0.4 from a drive line X4.5
    op, times = run("G18 M3 S200 G0 X5 Z0\nG76 P1 Z-10 I-0.5 J0.2 K0.4 H0\n", planner)
    w = op.waypoints
    rows = np.flatnonzero(op.table.line[np.asarray(w["command"])] == 3)
    feeds = rows[w["motion"][rows] == 2]  # the synchronized feeds
    assert len(feeds) == 2 and np.allclose(w["distance"][feeds], 10.0)
    assert np.allclose(w["feed"][feeds], 200.0)
    rapid_len = float(np.sum(w["distance"][rows]) - 20.0)
    if planner == "grbl":  # rapids at 1e6 mm/min or more (faster along a diagonal): a bound, not a value
        assert 6.0 < row_time(op, times, 3) <= 6.0 + rapid_len / (1e6 / 60) + 1e-9
    else:
        assert row_time(op, times, 3) == pytest.approx(20.0 / (200 / 60) + rapid_len / 50.0, rel=1e-6)


@pytest.mark.parametrize("planner", PLANNERS)
def test_dwell_and_drilling_cycle(planner):
    # G82 from Z5: rapid down 4 mm to R1, feed 2 mm at 60 mm/min (2 s), dwell P2, rapid 6 mm back to Z5 (G98)
    op, times = run("G61 G0 Z5\nG4 P2.5\nG98 G82 X0 Y0 Z-1 R1 P2 F60\n", planner)
    assert row_time(op, times, 3) == pytest.approx(2.5)
    rapid = 1e6 / 60 if planner == "grbl" else 50.0
    if planner == "motion_profile_accel":
        expected = trapezoid(4, 50, ACCEL) + trapezoid(2, 1, ACCEL) + 2.0 + trapezoid(6, 50, ACCEL)
    else:
        expected = 4 / rapid + 2 / 1.0 + 2.0 + 6 / rapid
    assert row_time(op, times, 4) == pytest.approx(expected, rel=1e-6, abs=1e-6)


def test_tool_change_time_of_the_machine_model():
    # the linuxcnc preset gives a tool change no time of its own (M6 waits for the motion, then swaps)
    op, times = run("G1 X10 F600\nT2 M6\nG1 X20\n", "none")
    assert row_time(op, times, 3) == 0.0
    assert float(np.nansum(times)) == pytest.approx(2.0)


# -- moves that cannot end, and programs no machine runs ----------------------------------

@pytest.mark.parametrize("text, message", [
    ("M3 S100\nG33 Z-10 K0\n", "G33 with a pitch of K0"),
    ("M3 S100\nG33.1 Z-10 K0\n", "G33.1 with a pitch of K0"),
    ("G93\nG1 X10 F0\n", "inverse time move (G93) with F0"),
])
def test_moves_that_never_end_are_named(text, message):
    op = gcodekit.gcode_to_operation("G21 G90\n" + text, "linuxcnc")
    (warning,) = [d for d in op.diagnostics if message in d.message]
    assert warning.severity == "warning" and warning.line == 3 and "never ends" in warning.message
    assert np.isnan(op.waypoints["time"][-1]) or op.waypoints["time"][-1] == 0.0


@pytest.mark.parametrize("text, message", [
    ("G95\nG1 X10 F0.1\n", "Cannot feed with zero spindle speed in feed per rev mode"),
    ("M3 S0 G95\nG1 X10 F0.1\n", "Cannot feed with zero spindle speed in feed per rev mode"),
    ("G18 G0 X5 Z0\nG76 P1 Z-10 I-0.5 J0.2 K1\n", "Chosen spindle (0) not turning in G76"),
    ("M5\nG33 Z-10 K1\n", "Spindle not turning in G33"),
    ("G93\nG1 X10\n", "F word missing with inverse time g1 move"),
    ("G93\nG2 X10 I5 J0\n", "F word missing with inverse time arc move"),
])
def test_rs274_refuses_moves_without_a_rate(text, message):
    # rs274 2.9's messages for these programs (checked with /usr/bin/rs274)
    op = gcodekit.gcode_to_operation("G21 G90\n" + text, "linuxcnc")
    (error,) = op.diagnostics.errors
    assert error.message == message and error.line == 3


def test_a_billion_turn_arc_is_timed_and_warned_about():
    op = gcodekit.gcode_to_operation("G21 G17 G90 G1 X1 F100\nG2 X1 Y0 I-1 J0 P1000000000\n", "linuxcnc")
    seconds = 1e9 * TAU / (100 / 60)
    assert seconds / (365.25 * 86400) == pytest.approx(119.46, abs=0.01)
    assert float(np.nansum(op.waypoints["time"])) == pytest.approx(seconds + 0.6, rel=1e-6)
    (warning,) = [d for d in op.diagnostics if d.severity == "warning"]
    assert warning.line == 2 and "119.5 years" in warning.message
    (limit,) = op.diagnostics.errors  # too many chords to plan: timed at length over feed, said so
    assert "timed at its length over its feed" in limit.message


def test_log_comments_are_said_to_write_no_file():
    op = gcodekit.gcode_to_operation("(LOGOPEN,out.txt)\n(LOG,x)\n(LOGCLOSE)\nG1 X1 F60\n", "linuxcnc")
    (warning,) = list(op.diagnostics)
    assert warning.line == 1 and "writes no log file" in warning.message
    plain = gcodekit.gcode_to_operation("(logo of the shop)\nG1 X1 F60\n", "linuxcnc")
    assert not list(plain.diagnostics)


# -- properties: the time scales as the geometry says --------------------------------------

@settings(deadline=None, max_examples=30)
@given(turns=st.integers(1, 40), more=st.integers(1, 40), radius=st.floats(5.0, 50.0),
       feed=st.floats(10.0, 2000.0), planner=st.sampled_from(["none", "motion_profile", "motion_profile_accel"]))
def test_each_extra_turn_adds_one_turn_of_time(turns, more, radius, feed, planner):
    # full circles at the feed (below the centripetal limit sqrt(a r), and on radii of 5 mm or more, where the
    # 1 mm chords' corners do not slow the feed): the time grows by 2 pi r / v per turn, with or without
    # acceleration (the trapezoid's ramps do not depend on the length)
    v = min(feed / 60.0, math.sqrt(ACCEL * radius) * 0.9)
    text = lambda p: f"G61\nG1 X{radius:.6f} F{v * 60:.6f}\nG2 X{radius:.6f} Y0 I{-radius:.6f} J0 P{p}\n"  # noqa: E731
    op_a, t_a = run(text(turns), planner)
    op_b, t_b = run(text(turns + more), planner)
    v = op_a.waypoints["feed"][-1] / 60.0
    difference = row_time(op_b, t_b, 4) - row_time(op_a, t_a, 4)
    assert difference == pytest.approx(more * TAU * radius / v, rel=1e-6)


@settings(deadline=None, max_examples=30)
@given(pitch=st.floats(0.05, 5.0), scale=st.floats(0.1, 10.0), speed=st.floats(50.0, 3000.0))
def test_synchronized_time_scales_inversely_with_pitch_and_speed(pitch, scale, speed):
    def time(k, s):
        op, times = run(f"M3 S{s:.6f}\nG33 Z-20 K{k:.6f}\n", "none")
        return row_time(op, times, 3)

    base = time(pitch, speed)
    assert base == pytest.approx(20.0 / (float(f"{pitch:.6f}") * float(f"{speed:.6f}") / 60.0), rel=1e-9)
    assert time(pitch * scale, speed) * float(f"{pitch * scale:.6f}") == pytest.approx(
        base * float(f"{pitch:.6f}"), rel=1e-9)


@settings(deadline=None, max_examples=30)
@given(feed=st.floats(5.0, 600.0), factor=st.floats(0.2, 5.0), turns=st.integers(1, 6))
def test_grbl_time_scales_inversely_with_feed(feed, factor, turns):
    # with instant speed changes, GRBL's time of a program at any feed is its chords' length over the feed
    def time(f):
        op, times = run(f"G1 X4 F{f:.6f}\nG2 X4 Y0 Z-1 I-4 J0 P{turns}\n", "grbl")
        return float(np.nansum(times)), float(f"{f:.6f}")

    (t1, f1), (t2, f2) = time(feed), time(feed * factor)
    assert t1 * f1 == pytest.approx(t2 * f2, rel=1e-6)
    assert t1 == pytest.approx((4.0 + grbl_chords(4.0, TAU * turns, -1.0)) / (f1 / 60.0), rel=1e-6)
