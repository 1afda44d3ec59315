"""Material removal: removed volumes against closed forms worked out by hand and an exact mesh boolean library.

Each program has a volume written as a formula below, and the same moves
are swept through manifold3d (exact booleans on meshes): a straight move of
a convex tool sweeps the convex hull of the tool at its two ends, their
union intersected with the stock box is the removed material.  gcodekit's
height field at its default resolution (0.1 mm) must come within 1 % of
both; both engines (the NumPy reference and the compiled loop) must agree.
"""

import math

import numpy as np
import pytest

import gcodekit
from gcodekit.cut import CutSimulation, Stock, ToolLibrary
from gcodekit.cut.kernel import compiled
from gcodekit.cut.path import tool_tip_pieces
from gcodekit.tool_shapes import ToolShape

manifold3d = pytest.importorskip("manifold3d")

STOCK = (0.0, 0.0, -20.0, 60.0, 40.0, 0.0)


def _segment_area(R, d):
    """Area of a circle of radius R cut off by a chord at depth d (the section of a ball end's slot)."""
    return R * R * math.acos((R - d) / R) - (R - d) * math.sqrt(2 * R * d - d * d)


def _slot(depth):
    return f"G21 G90 G17\nT1 M6\nG0 X10 Y20 Z5\nG1 Z{-depth} F300\nG1 X40 F600\nG0 Z5\nM30\n"


def _drill(depth):
    return f"G21 G90\nT1 M6\nG0 X30 Y20 Z5\nG1 Z{-depth} F100\nG0 Z5\nM30\n"


# a helix down 3 mm in three turns round (30, 20) at radius 2.5, then a full circle at depth
_HELIX = ("G21 G90 G17\nT1 M6\nG0 X32.5 Y20 Z1\nG1 Z0 F200\n"
          "G2 X32.5 Y20 I-2.5 J0 Z-1\nG2 X32.5 Y20 I-2.5 J0 Z-2\nG2 X32.5 Y20 I-2.5 J0 Z-3\n"
          "G2 X32.5 Y20 I-2.5 J0\nG0 Z5\nM30\n")


def _zigzag():
    """Rows 4 mm apart over [15, 45] x [12, 28], then the contour of that rectangle, 2.5 mm deep."""
    lines = ["G21 G90 G17", "T1 M6", "G0 X15 Y12 Z5", "G1 Z-2.5 F200"]
    ys = [12, 16, 20, 24, 28]
    for k, y in enumerate(ys):
        if k:
            lines.append(f"G1 Y{y}")
        lines.append(f"G1 X{45 if k % 2 == 0 else 15}")
    lines += ["G1 X45 Y28", "G1 Y12", "G1 X15", "G1 Y28", "G1 X45", "G0 Z5", "M30"]
    return "\n".join(lines) + "\n"


R = 3.0
DRILL = ToolShape("drill", 6.0)
_CONE_H = R / math.tan(math.radians(59))
CASES = {
    # name: (program, tool, closed-form removed volume mm^3)
    "flat slot": (_slot(2), ToolShape("endmill", 6.0), 2 * (30 * 2 * R + math.pi * R * R)),
    "ball slot": (_slot(2), ToolShape("ballend", 6.0),
                  30 * _segment_area(R, 2) + math.pi * 2**2 * (3 * R - 2) / 3),
    "drilled hole": (_drill(10), DRILL, math.pi * R * R * (10 - _CONE_H) + math.pi * R * R * _CONE_H / 3),
    "helix pocket": (_HELIX, ToolShape("endmill", 6.0), math.pi * (2.5 + R) ** 2 * 3),
    "zig-zag pocket": (_zigzag(), ToolShape("endmill", 6.0),
                       2.5 * (30 * 16 + 2 * R * (30 + 16) + math.pi * R * R)),
}


def _operation(program):
    return gcodekit.gcode_to_operation(program, machine="linuxcnc")


def _manifold_removed(op, tool: ToolShape, stock=STOCK) -> float:
    """Exact removed volume: the union of every move's swept hull, intersected with the stock box."""
    m = manifold3d
    profile = tool.profile(24)
    angles = np.linspace(0, 2 * math.pi, 512, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles)])
    body = np.vstack([np.column_stack([r * ring, np.full(len(ring), h)]) for r, h in profile if r > 0]
                     + [[[0.0, 0.0, 0.0]]])
    pieces = tool_tip_pieces(op.waypoints, {}, tolerance=0.001)
    hulls = [m.Manifold.hull_points(np.vstack([body + a, body + b])) for a, b in zip(pieces.p0, pieces.p1)]
    swept = m.Manifold.batch_boolean(hulls, m.OpType.Add)
    x0, y0, z0, x1, y1, z1 = stock
    box = m.Manifold.cube((x1 - x0, y1 - y0, z1 - z0)).translate((x0, y0, z0))
    return (swept ^ box).volume()


@pytest.fixture(scope="module")
def manifold_volumes():
    return {name: _manifold_removed(_operation(program), tool) for name, (program, tool, _) in CASES.items()}


@pytest.mark.parametrize("name", list(CASES))
def test_removed_volume_matches_closed_form_and_mesh_booleans(name, manifold_volumes):
    program, tool, exact = CASES[name]
    op = _operation(program)
    result = CutSimulation(op, stock=Stock.box(*STOCK), tools=ToolLibrary({1: tool})).run()
    reference = manifold_volumes[name]
    # the reference itself (512-gon tools, 1 micron chords) agrees with the hand formula
    assert reference == pytest.approx(exact, rel=2e-3)
    assert result.removed_mm3 == pytest.approx(exact, rel=0.01)
    assert result.removed_mm3 == pytest.approx(reference, rel=0.01)
    assert result.stock_mm3 == pytest.approx(60 * 40 * 20)
    assert result.remaining_mm3 == pytest.approx(result.stock_mm3 - exact, rel=1e-3)
    # per move: the moves' removals add up to the total
    assert result.removed.sum() == pytest.approx(result.removed_mm3, rel=1e-9)


@pytest.mark.parametrize("name", list(CASES))
def test_numpy_and_compiled_loops_agree(name):
    if compiled() is None:
        pytest.skip("Numba is not installed")
    program, tool, _ = CASES[name]
    op = _operation(program)
    runs = [CutSimulation(op, stock=Stock.box(*STOCK, resolution=0.2), tools=ToolLibrary({1: tool}),
                          engine=engine).run() for engine in ("numpy", "numba")]
    np.testing.assert_allclose(runs[0].top, runs[1].top, atol=1e-9)
    np.testing.assert_allclose(runs[0].removed, runs[1].removed, atol=1e-9)


@pytest.mark.parametrize("tool", [ToolShape("bullnose", 8.0, corner_radius=1.5), ToolShape("vbit", 10.0, angle=60),
                                  ToolShape("chamfer", 8.0, angle=90, tip_diameter=2.0)])
def test_other_shapes_against_mesh_booleans_on_a_ramp(tool):
    """A slot that ramps down (the envelope's minimum is inside the move) and a cross move."""
    program = "G21 G90\nT1 M6\nG0 X10 Y20 Z5\nG1 Z0 F300\nG1 X40 Z-2.5\nG1 X30 Y10 Z-1\nG0 Z5\nM30\n"
    op = _operation(program)
    result = CutSimulation(op, stock=Stock.box(*STOCK), tools=ToolLibrary({1: tool}), engine="numpy").run()
    assert result.removed_mm3 == pytest.approx(_manifold_removed(op, tool), rel=0.01)
