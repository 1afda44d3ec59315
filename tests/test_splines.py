"""G5, G5.1 and G5.2/G5.3 splines: curve geometry against closed forms, chords, rs274's errors.

The end points and source lines of splines in LinuxCNC's example programs
are checked against rs274 by the golden tests; here the curve between them.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.emulate.splines import clamped_knots, cubic_bezier, nurbs, polyline
from gcodekit.transpile import Transpiler


def run(text: str):
    return gcodekit.gcode_to_operation("G21 G17 G90 G0 X0 Y0\nF600\n" + text + "M2\n", "linuxcnc", plan=False)


def errors(op) -> list[tuple[int, str]]:
    return [(d.line, d.message) for d in op.diagnostics if d.severity == "error"]


def test_rational_quadratic_is_an_exact_quarter_circle():
    # the classic conic: weights 1, cos(45 deg), 1 put every point on the unit circle
    points = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    weights = np.array([1.0, np.sqrt(0.5), 1.0])
    t = np.linspace(0, 1, 101)
    np.testing.assert_allclose(np.hypot(*nurbs(points, weights, 3, t).T), 1.0, atol=1e-12)


def test_nurbs_with_unit_weights_and_four_points_of_order_four_is_the_cubic_bezier():
    points = np.array([[0.0, 0.0], [1.0, 3.0], [4.0, -1.0], [6.0, 2.0]])
    t = np.linspace(0, 1, 33)
    s = (1 - t)[:, None]
    expected = s**3 * points[0] + 3 * s**2 * t[:, None] * points[1] + 3 * s * t[:, None] ** 2 * points[2] \
        + t[:, None] ** 3 * points[3]
    np.testing.assert_allclose(nurbs(points, np.ones(4), 4, t), expected, atol=1e-12)
    np.testing.assert_allclose(cubic_bezier(points, t), expected, atol=1e-12)


def test_knots_are_clamped_and_uniform():
    np.testing.assert_allclose(clamped_knots(5, 3) * 3, [0, 0, 0, 1, 2, 3, 3, 3])


def test_g5_1_follows_the_parabola():
    # from (0,0) with control point (5,5) to (10,0): y = x - x^2/10, length 5 (sqrt 2 + asinh 1)
    op = run("G5.1 X10 Y0 I5 J5\n")
    m = op.motions()
    assert m["motion"].iloc[1:].eq("feed").all() and (m["line"].iloc[1:] == 3).all()
    x, y = m["x"].to_numpy()[1:], m["y"].to_numpy()[1:]
    np.testing.assert_allclose(y, x - x * x / 10, atol=1e-9)
    length = float(np.sum(op.waypoints["distance"]))
    assert length == pytest.approx(5 * (np.sqrt(2) + np.arcsinh(1)), abs=1e-3)
    assert (x[-1], y[-1]) == (10.0, 0.0)


def test_g5_without_i_j_continues_the_previous_cubic_smoothly():
    op = run("G5 X10 Y0 I0 J5 P0 Q5\nG5 X20 Y0 P0 Q-5\n")
    m = op.motions()
    first, second = m[m["line"] == 3], m[m["line"] == 4]
    # the end tangent of the first (straight down) is the start tangent of the second
    before = np.array([first["x"].iloc[-1] - first["x"].iloc[-2], first["y"].iloc[-1] - first["y"].iloc[-2]])
    after = np.array([second["x"].iloc[0] - 10.0, second["y"].iloc[0]])
    cos = before @ after / np.linalg.norm(before) / np.linalg.norm(after)
    assert cos > 0.999
    assert (second["x"].iloc[-1], second["y"].iloc[-1]) == (20.0, 0.0)


def test_incremental_g5_1_and_offsets():
    op = gcodekit.gcode_to_operation("G21 G17 G0 X1 Y1\nG55 G91 F600\nG5.1 X10 Y0 I5 J5\nM2\n", "linuxcnc",
                                     plan=False, work_offsets={"G55": (100.0, 0.0, 0.0)})
    end = op.motions().iloc[-1]
    # the tool is at program X-99 in G55 (offset X100); G91 X10 ends at program X-89, machine X11
    assert (end["x"], end["y"]) == pytest.approx((11.0, 1.0))


def test_nurbs_control_points_start_at_the_tool_and_end_at_the_last():
    op = run("G5.2 P1 L3\nX0 Y10 P1\nX10 Y10 P1\nX10 Y0 P1\nG5.3\n")
    m = op.motions().iloc[1:]
    assert (m["line"] == 7).all()  # the curve is cut at G5.3, as rs274 prints it
    assert (m["x"].iloc[-1], m["y"].iloc[-1]) == (10.0, 0.0)
    assert m["x"].between(0, 10).all() and m["y"].between(0, 10).all()  # inside the control polygon's hull


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=4, max_size=4),
       st.sampled_from([0.1, 0.01, 0.001]))
def test_chords_stay_within_the_tolerance(points, tolerance):
    points = np.array(points)
    chords = polyline(lambda t: cubic_bezier(points, t), tolerance)
    np.testing.assert_allclose(chords[[0, -1]], points[[0, -1]], atol=1e-9)
    dense = cubic_bezier(points, np.linspace(0, 1, 4001))
    # every curve point lies near the polyline: within the tolerance where the curve is smooth; a curve
    # that turns back on itself (a cusp, common among random control points) can poke out up to about
    # twice the tolerance between the three points per chord that the refinement checks
    a, b = chords[:-1], chords[1:]
    d = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    u = np.clip(np.einsum("kij,ij->ki", dense[:, None, :] - a[None], d) / length2, 0, 1)
    nearest = a[None] + u[..., None] * d[None]
    gap = np.min(np.linalg.norm(dense[:, None, :] - nearest, axis=2), axis=1)
    assert gap.max() <= tolerance * 2.5


@pytest.mark.parametrize("text, line, message", [
    ("G5.1 X10 Y0\n", 3, "Must specify both I and J with G5.1"),
    ("G5 X10 Y0 I1 J1\n", 3, "Must specify both P and Q with G5"),
    ("G18\nG5.1 X10 Y0 I1 J1\n", 4, "Splines must be in the XY plane"),
    ("G5.1 X10 Y0 Z2 I5 J5\n", 3, "Splines may not have motion in Z, A, B, or C"),
    ("G5.3\n", 3, "Cannot use G5.3 without G5.2 first"),
    ("G5.2 P1 L3\nX2 Y1\nX3 Y0 P1\nG5.3\n", 4, "Must specify positive weight P for every Control Point"),
    ("G5.2 P1 L3\nX2 P1\nX3 Y0 P1\nG5.3\n", 4, "You must specify both X and Y coordinates for Control Points"),
    ("G5.2 P1 L3\nX2 Y0 P1\nG5.3\n", 5, "You must specify a number of control points at least equal to the order L = 3"),
    ("G5.2 P1 L3\nX2 Y0 P1\nG1 X3\nG5.3\n", 6, "Cannot use G5.3 without G5.2 first"),
    ("G5.1 X10 I1 J1\nI1 J1 X12\n", 4, "Cannot use axis values without a g code that uses them"),
])
def test_errors_as_rs274_words_them(text, line, message):
    # each message and line checked by running the same block in LinuxCNC's rs274
    assert errors(run(text))[:1] == [(line, message)]


def test_last_transpiler_stage_follows_the_curve_with_g1():
    original = run("G5.1 X10 Y0 I5 J5\nG5.2 P1 L3\nX10 Y10 P1\nX0 Y10 P2\nG5.3\n")
    stage6 = Transpiler(original).stage(6)
    body = [line.split() for line in stage6.splitlines() if not line.startswith("(")]
    assert {words[1] for words in body[1:]} == {"G0", "G1", "F600", "M2"}  # no G5.x left
    again = gcodekit.gcode_to_operation(stage6, "linuxcnc", plan=False).motions()
    np.testing.assert_allclose(again[["x", "y"]].to_numpy(), original.motions()[["x", "y"]].to_numpy(), atol=1e-4)
