"""G5, G5.1 and G5.2/G5.3 splines: curve geometry against closed forms, chords, rs274's errors.

The end points and source lines of splines in LinuxCNC's example programs
are checked against rs274 by the golden tests; here the curve between them,
against the curves evaluated directly (Bernstein polynomials, Cox-de Boor).
"""

from __future__ import annotations

from math import comb

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.emulate.splines import bezier_chords, clamped_knots, nurbs_chords
from gcodekit.transpile import Transpiler


def run(text: str):
    return gcodekit.gcode_to_operation("G21 G17 G90 G0 X0 Y0\nF600\n" + text + "M2\n", "linuxcnc", plan=False)


def errors(op) -> list[tuple[int, str]]:
    return [(d.line, d.message) for d in op.diagnostics if d.severity == "error"]


def bezier(points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The Bézier curve at ``t``, summed from its Bernstein polynomials."""
    n = len(points) - 1
    basis = np.array([[comb(n, j) * u**j * (1 - u) ** (n - j) for j in range(n + 1)] for u in t])
    return basis @ points


def nurbs(points: np.ndarray, weights: np.ndarray, order: int, t: np.ndarray) -> np.ndarray:
    """The NURBS curve at ``t`` by the Cox-de Boor recursion (the last span also holds t = 1)."""
    knots = clamped_knots(len(points), order)
    span = np.clip(np.searchsorted(knots, t, side="right") - 1, order - 1, len(knots) - order - 1)
    basis = (np.arange(len(knots) - 1)[None, :] == span[:, None]).astype(float)
    for k in range(2, order + 1):
        new = np.zeros((t.size, len(knots) - k))
        for i in range(len(knots) - k):
            left, right = knots[i + k - 1] - knots[i], knots[i + k] - knots[i + 1]
            if left > 0:
                new[:, i] += (t - knots[i]) / left * basis[:, i]
            if right > 0:
                new[:, i] += (knots[i + k] - t) / right * basis[:, i + 1]
        basis = new
    weighted = basis * weights[None, :]
    return weighted @ points / weighted.sum(axis=1, keepdims=True)


def farthest(curve: np.ndarray, chords: np.ndarray) -> float:
    """The largest distance from a point of ``curve`` (m, 2) to the polyline ``chords``."""
    a, d = chords[:-1], np.diff(chords, axis=0)
    length2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    u = np.clip(np.einsum("kij,ij->ki", curve[:, None, :] - a[None], d) / length2, 0, 1)
    nearest = a[None] + u[..., None] * d[None]
    return float(np.min(np.linalg.norm(curve[:, None, :] - nearest, axis=2), axis=1).max())


def test_rational_quadratic_is_an_exact_quarter_circle():
    # the classic conic: weights 1, cos(45 deg), 1 put every point on the unit circle; the chords' corners
    # are points of the curve, and each chord's middle is inside the circle by its sagitta, within the tolerance
    points = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    chords = bezier_chords(points, 1e-3, weights=np.array([1.0, np.sqrt(0.5), 1.0]))
    np.testing.assert_allclose(np.hypot(*chords.T), 1.0, atol=1e-12)
    half_angle = np.arcsin(np.linalg.norm(np.diff(chords, axis=0), axis=1) / 2)
    assert (1 - np.cos(half_angle)).max() <= 1e-3
    assert len(chords) - 1 >= np.pi / 2 / (2 * np.arccos(1 - 1e-3))  # no fewer than the circle needs
    np.testing.assert_array_equal(nurbs_chords(points, np.array([1.0, np.sqrt(0.5), 1.0]), 3, 1e-3), chords)


def test_nurbs_with_unit_weights_and_four_points_of_order_four_is_the_cubic_bezier():
    points = np.array([[0.0, 0.0], [1.0, 3.0], [4.0, -1.0], [6.0, 2.0]])
    t = np.linspace(0, 1, 33)
    np.testing.assert_allclose(nurbs(points, np.ones(4), 4, t), bezier(points, t), atol=1e-12)
    np.testing.assert_array_equal(nurbs_chords(points, np.ones(4), 4, 0.01), bezier_chords(points, 0.01))


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
@example([(0.0, 0.0), (15.0, 0.0), (-25.0, 0.0), (15.0, 0.0)], 0.01)  # turns back twice: found by explore.sh
def test_chords_stay_within_the_tolerance(points, tolerance):
    # every curve point, cusps and turning points included, lies within the tolerance of the chords
    points = np.array(points)
    chords = bezier_chords(points, tolerance)
    np.testing.assert_array_equal(chords[[0, -1]], points[[0, -1]])
    assert farthest(bezier(points, np.linspace(0, 1, 4001)), chords) <= tolerance * (1 + 1e-9)


def test_a_curve_doubling_back_on_a_line_is_followed_to_both_tips():
    # x(t) = 45 t - 165 t^2 + 135 t^3 turns where 3 - 22 t + 27 t^2 = 0, t = (11 -+ 2 sqrt 10) / 27:
    # at x = 3.5457, then at x = -3.3948
    points = np.array([[0.0, 0.0], [15.0, 0.0], [-25.0, 0.0], [15.0, 0.0]])
    chords = bezier_chords(points, 0.01)
    tips = [(11 - 2 * np.sqrt(10)) / 27, (11 + 2 * np.sqrt(10)) / 27]
    far, near = (45 * t - 165 * t**2 + 135 * t**3 for t in tips)
    assert (far, near) == pytest.approx((3.5457, -3.3948), abs=1e-4)
    before_end = chords[:-1, 0]  # the curve ends at x = 15, past both turns
    assert far - 0.01 <= before_end.max() <= far and near <= before_end.min() <= near + 0.01
    assert np.all(chords[:, 1] == 0.0)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_nurbs_chords_stay_within_the_tolerance(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 9))
    order = int(rng.integers(2, n + 1))
    points, weights = rng.uniform(-50, 50, (n, 2)), rng.uniform(0.1, 5.0, n)
    chords = nurbs_chords(points, weights, order, 0.01)
    np.testing.assert_allclose(chords[[0, -1]], points[[0, -1]], atol=1e-9)
    assert farthest(nurbs(points, weights, order, np.linspace(0, 1, 4001)), chords) <= 0.01 * (1 + 1e-9)


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


@pytest.mark.parametrize("weight", ["0", "-1"])
def test_a_first_weight_not_positive_is_a_warning_and_a_straight_move(weight):
    # rs274 runs "G5.2 P0 L3" without an error (checked); the curve has no well-defined path
    op = run(f"G5.2 P{weight} L3\nX10 Y10 P1\nX20 Y0 P1\nG5.3\nG91 G1 X1\n")
    warnings = [(d.line, d.message) for d in op.diagnostics if d.severity == "warning"]
    assert warnings == [(3, f"G5.2's weight P{weight} is not positive: rs274 takes it, but a NURBS with such a weight "
                            "has no well-defined path; gcodekit moves in a straight line to the curve's end")]
    assert not errors(op)
    m = op.motions()
    assert m[["x", "y"]].to_numpy()[-2:].tolist() == [[20.0, 0.0], [21.0, 0.0]]
    assert (m["line"].to_numpy()[-2:] == [6, 7]).all()


def test_last_transpiler_stage_follows_the_curve_with_g1():
    original = run("G5.1 X10 Y0 I5 J5\nG5.2 P1 L3\nX10 Y10 P1\nX0 Y10 P2\nG5.3\n")
    stage6 = Transpiler(original).stage(6)
    body = [line.split() for line in stage6.splitlines() if not line.startswith("(")]
    assert {words[1] for words in body[1:]} == {"G0", "G1", "F600", "M2"}  # no G5.x left
    again = gcodekit.gcode_to_operation(stage6, "linuxcnc", plan=False).motions()
    np.testing.assert_allclose(again[["x", "y"]].to_numpy(), original.motions()[["x", "y"]].to_numpy(), atol=1e-4)
