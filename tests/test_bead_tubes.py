"""The deposited beads as closed tubes: volumes against closed forms, orientation, program order, limits."""

from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.additive import AdditivePart, Bead, bead_tubes
from gcodekit.additive.bead import bead_area, bead_outline, bead_width
from gcodekit.errors import ConfigError

EXAMPLES = Path(__file__).parents[1] / "examples"
SQUARE = "M83\nG1 Z0.2 F600\nG1 X10 E0.5\nG1 Y10 E0.5\nG1 X0 E0.5\nG1 Y0 E0.5\n"


def _op(text):
    return gcodekit.gcode_to_operation(text, machine="marlin", plan=False)


def signed_volume(tubes) -> float:
    """The divergence theorem over the triangles: positive when they face outwards."""
    p, t = tubes.points, tubes.triangles
    return float(np.einsum("ij,ij->i", p[t[:, 0]], np.cross(p[t[:, 1]], p[t[:, 2]])).sum() / 6)


def outline_area(width, height, shape, sides) -> float:
    lateral, vertical = bead_outline(width, height, shape, sides)
    x, y = lateral[0], vertical[0]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))  # shoelace, counter-clockwise > 0


def test_a_straight_rectangular_bead_is_its_box():
    tubes = bead_tubes(AdditivePart(_op("M83\nG1 Z0.2 F600\nG1 X10 E0.5\n"), Bead(0.4, 0.2, "rectangle")), sides=4)
    mesh = tubes.polydata()
    assert mesh.n_open_edges == 0 and mesh.is_manifold
    assert signed_volume(tubes) == pytest.approx(0.4 * 0.2 * 10, rel=1e-12)
    # the nozzle lays the bead's top: from Z0.2 down to Z0, 0.4 mm wide about Y0
    np.testing.assert_allclose(mesh.bounds, [0, 10, -0.2, 0.2, 0.0, 0.2], atol=1e-12)


@pytest.mark.parametrize("shape", ["rectangle", "stadium", "ellipse"])
def test_a_square_loop_holds_its_outline_times_its_length(shape):
    # mitre joints at the three corners keep a laterally symmetric section's volume: area x centre line
    tubes = bead_tubes(AdditivePart(_op(SQUARE), Bead(0.6, 0.2, shape)), sides=16)
    assert tubes.polydata().n_open_edges == 0
    assert signed_volume(tubes) == pytest.approx(outline_area(0.6, 0.2, shape, 16) * 40, rel=1e-9)
    # the outline's area tends to the bead's
    assert outline_area(0.6, 0.2, shape, 256) == pytest.approx(bead_area(0.6, 0.2, shape), rel=1e-3)
    assert outline_area(0.6, 0.2, "rectangle", 16) == pytest.approx(0.12, rel=1e-12)  # its corners are points


def test_a_path_that_doubles_back_keeps_its_width():
    # infill turning back 180 degrees: two tubes, no mitre spike beyond the bead's width
    op = _op("M83\nG1 Z0.2 F600\nG1 X10 E0.5\nG1 Y0.45 E0.02\nG1 X0 E0.5\n")
    tubes = bead_tubes(AdditivePart(op, Bead(0.45, 0.2, "rectangle")), sides=4)
    lo, hi = tubes.points.min(axis=0), tubes.points.max(axis=0)
    assert hi[0] <= 10 + 0.225 + 1e-9 and lo[0] >= -0.225 - 1e-9
    assert hi[1] <= 0.45 + 0.225 + 1e-9 and lo[1] >= -0.225 - 1e-9
    assert signed_volume(tubes) == pytest.approx(0.45 * 0.2 * (10 + 0.45 + 10), rel=1e-9)


def test_the_fff_example_beads_hold_the_filament_laid():
    part = AdditivePart(gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode"))
    tubes = bead_tubes(part, sides=128)
    assert tubes.notes == []
    # bead area from the filament per mm, height from the layers: the tubes' volume is the filament's
    # (PrusaSlicer's stadium beads, sampled by 128 points)
    assert signed_volume(tubes) == pytest.approx(part.volume, rel=2e-3)
    assert tubes.polydata().n_open_edges == 0


def test_triangles_are_in_program_order_and_count_through_a_move():
    op = _op(SQUARE)
    tubes = bead_tubes(AdditivePart(op, Bead(0.6, 0.2)), sides=8)
    assert (np.diff(tubes.triangle_row) >= 0).all()
    rows = np.unique(tubes.triangle_row)
    lines = np.asarray(op.table.line)[op.waypoints["command"]][rows]
    assert lines.tolist() == [3, 4, 5, 6]
    # after line 3's move: its start cap and its 8 x 2 side triangles, nothing of line 4's
    assert tubes.count_through(int(rows[0])) == (8 - 2) + 16
    assert tubes.count_through(int(rows[-1])) == len(tubes.triangles)
    assert tubes.count_through(int(rows[0]) - 1) == 0
    # the points of a ring are coloured by the move that lays them
    assert set(np.unique(tubes.point_row)) == set(rows.tolist())


def test_bead_width_inverts_bead_area():
    for shape in ("rectangle", "ellipse", "stadium"):
        assert bead_width(bead_area(0.5, 0.2, shape), 0.2, shape) == pytest.approx(0.5)
    assert bead_width(0.01, 0.2, "stadium") == 0.2  # narrower than high: a round bead


def test_unknown_bead_sizes_are_said_and_limits_are_clear_errors():
    ded = AdditivePart(gcodekit.gcode_to_operation(EXAMPLES / "dome_ded_beckhoff.nc"))
    tubes = bead_tubes(ded)
    assert len(tubes.triangles) > 0 and any("does not say how much material" in n for n in tubes.notes)
    part = AdditivePart(_op(SQUARE))
    with pytest.raises(ConfigError, match="at least 3 sides"):
        bead_tubes(part, sides=2)
    from gcodekit.additive import tubes as module

    old = module.MAX_TRIANGLES
    module.MAX_TRIANGLES = 10
    try:
        with pytest.raises(ConfigError, match="layers=\\(first, last\\)"):
            bead_tubes(part)
    finally:
        module.MAX_TRIANGLES = old
    cube = AdditivePart(gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode"))
    top = bead_tubes(cube, layers=(99, 99))
    assert 0 < len(top.triangles) < len(bead_tubes(cube).triangles) / 20
    assert top.points[:, 2].min() > 19.5  # the top layer only (Z 19.8 .. 20.0)
