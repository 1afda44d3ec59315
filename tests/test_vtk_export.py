"""VTKExporter: one poly-line cell per deposition segment, read back by PyVista as ParaView would."""

import math
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit import AdditivePart, Bead, VTKExporter

pv = pytest.importorskip("pyvista")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def cube():
    return AdditivePart(gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode"))


def _cell_lengths(mesh):
    """Length of each poly-line cell, from its points."""
    out, cells, k = [], mesh.lines, 0
    while k < cells.size:
        n = cells[k]
        pts = mesh.points[cells[k + 1:k + 1 + n]]
        out.append(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
        k += n + 1
    return np.array(out)


@pytest.mark.parametrize("suffix", [".vtk", ".vtp"])
def test_round_trip(cube, tmp_path, suffix):
    n = len(cube.depositions)
    temperature = np.linspace(200, 220, n)
    path = VTKExporter.additive_part_to_vtk(cube, tmp_path / f"cube{suffix}", custom_scalars={"temperature": temperature})
    mesh = pv.read(path)
    assert mesh.n_cells == n
    for key in ("feed", "speed", "time", "start_time", "layer", "layer_time", "volume", "bead_width", "bead_height",
                "bead_area", "temperature"):
        assert key in mesh.cell_data, key
    assert mesh.cell_data["temperature"] == pytest.approx(temperature)
    assert mesh.cell_data["layer"].tolist() == cube.depositions["layer"].tolist()
    assert mesh.cell_data["volume"].sum() == pytest.approx(cube.volume)
    # the cube has no arcs: each cell's polyline is as long as its segment
    assert _cell_lengths(mesh) == pytest.approx(cube.depositions["length"].to_numpy(), rel=1e-6)
    assert {"elapsed_time", "feed", "speed"} <= set(mesh.point_data.keys())


def test_cell_scalars_by_hand():
    # 20 mm at F600 then 10 mm at F1200, one segment: length-weighted feed 800 mm/min
    op = gcodekit.gcode_to_operation("M83\nG1 X20 E1 F600\nG1 X30 E0.5 F1200\nG4 S5\n", machine="marlin", plan=False)
    mesh = VTKExporter.additive_part_to_polydata(AdditivePart(op, Bead(0.5, 0.25, "rectangle")))
    assert mesh.n_cells == 1 and mesh.n_points == 3
    assert mesh.cell_data["feed"][0] == pytest.approx(800.0)
    assert mesh.cell_data["time"][0] == pytest.approx(2.0 + 0.5)
    assert mesh.cell_data["speed"][0] == pytest.approx(30.0 / 2.5)
    assert mesh.cell_data["layer_time"][0] == pytest.approx(7.5)  # the dwell belongs to the layer
    assert mesh.cell_data["bead_area"][0] == pytest.approx(0.125)
    assert mesh.point_data["elapsed_time"].tolist() == pytest.approx([0.0, 2.0, 2.5])


def test_tool_vectors_of_a_five_axis_part():
    mesh = VTKExporter.additive_part_to_polydata(AdditivePart(gcodekit.gcode_to_operation(EXAMPLES / "dome_ded_beckhoff.nc")))
    uvw = mesh.point_data["tool_vector"]
    assert np.linalg.norm(uvw, axis=1) == pytest.approx(np.ones(len(uvw)))
    # "G01 X49.69 Y5.22 Z2.50 A0.12 B-1.14": (sin B, -sin A cos B, cos A cos B)
    k = np.flatnonzero(np.all(np.isclose(mesh.points, [49.69, 5.22, 2.5]), axis=1))[0]
    a, b = math.radians(0.12), math.radians(-1.14)
    assert uvw[k] == pytest.approx([math.sin(b), -math.sin(a) * math.cos(b), math.cos(a) * math.cos(b)])
    # the head tilts further from vertical as the dome closes in
    z = mesh.points[:, 2]
    tilt = np.linalg.norm(uvw[:, :2], axis=1)
    heights = np.unique(z)
    mean_tilt = np.array([tilt[z == h].mean() for h in heights])
    assert np.all(np.diff(mean_tilt) > 0)


def test_custom_scalars_must_fit(cube):
    with pytest.raises(ValueError, match="segments"):
        VTKExporter.additive_part_to_polydata(cube, custom_scalars={"t": np.zeros(3)})
    with pytest.raises(ValueError, match=".vtp"):
        VTKExporter.additive_part_to_vtk(cube, "cube.stl")


def test_arcs_become_polylines_as_long_as_the_arcs(shared_dir, tmp_path):
    # ArcWelder turned the cylinder's perimeters into G2/G3; each cell must follow the arcs, not their chords
    op = gcodekit.gcode_to_operation(shared_dir / "corpus" / "fff" / "cylinder_marlin2_arcwelder.gcode", plan=False)
    assert np.count_nonzero(op.waypoints["motion"] >= 3) > 10_000
    part = AdditivePart(op)
    mesh = pv.read(VTKExporter.additive_part_to_vtk(part, tmp_path / "cylinder.vtp"))
    lengths = _cell_lengths(mesh)
    assert lengths.sum() == pytest.approx(part.deposition_length, rel=1e-3)
    assert lengths == pytest.approx(part.depositions["length"].to_numpy(), rel=2e-3, abs=1e-6)


# -- the toolpath of a program that lays no material --------------------------------------------------

MILL_PROGRAM = """G21 G90 G17
T2 M6
G0 X10 Y0 Z5
G1 Z-1 F300
G3 X0 Y10 I-10 J0 F600
G1 X-5
G0 Z5
"""


def _cells(mesh):
    cells, k, out = mesh.lines, 0, []
    while k < cells.size:
        out.append(cells[k + 1:k + 1 + cells[k]])
        k += cells[k] + 1
    return out


def test_a_mill_toolpath_is_cells_of_rapids_and_feeds_with_arcs_drawn():
    op = gcodekit.gcode_to_operation(MILL_PROGRAM, machine="linuxcnc", plan=False)
    mesh = op.to_vtk()
    # G0 (rapid), then Z-1 + arc + X-5 (one feed run), then the rapid up
    assert mesh.cell_data["rapid"].tolist() == [1, 0, 1]
    arc = 10 * math.pi / 2  # a quarter turn of radius 10, counter-clockwise
    assert mesh.cell_data["length"] == pytest.approx([math.hypot(10, 5), 6 + arc + 5, 6])
    assert _cell_lengths(mesh)[1] == pytest.approx(6 + arc + 5, rel=2e-3)  # chords 5 degrees apart
    feed_cell = mesh.points[_cells(mesh)[1]]
    on_arc = feed_cell[1:-1]
    assert np.hypot(on_arc[:, 0], on_arc[:, 1]) == pytest.approx(10.0)
    assert mesh.cell_data["tool"].tolist() == [2, 2, 2]
    assert mesh.cell_data["start_line"].tolist() == [3, 4, 7]
    feeds = mesh.point_data["feed"][_cells(mesh)[1]]
    assert feeds[1] == 300 and feeds[-1] == 600  # the plunge's feed, then the arc's
    assert "tool_vector" not in mesh.point_data


def test_a_mill_toolpath_carries_the_tool_direction_when_rotary_axes_turn():
    op = gcodekit.gcode_to_operation("G21 G90\nG1 X10 A0 F600\nG1 X20 A90\n", machine="linuxcnc", plan=False)
    mesh = op.to_vtk()
    assert mesh.point_data["tool_vector"][-1] == pytest.approx([0.0, -1.0, 0.0], abs=1e-12)
    assert mesh.point_data["tool_vector"][0] == pytest.approx([0.0, 0.0, 1.0])


def test_a_mill_toolpath_writes_vtp_and_refuses_options(tmp_path):
    op = gcodekit.gcode_to_operation(EXAMPLES / "bracket_mill.ngc")
    op.to_vtk(tmp_path / "bracket.vtp")
    back = pv.read(tmp_path / "bracket.vtp")
    assert back.n_cells == op.to_vtk().n_cells > 0
    assert back.cell_data["length"].sum() == pytest.approx(np.asarray(op.waypoints["distance"])[op.moving].sum())
    with pytest.raises(TypeError, match="takes no options"):
        op.to_vtk(bead="rectangle")


def test_a_program_that_never_moves_has_nothing_to_export():
    from gcodekit.errors import NothingToShowError

    op = gcodekit.gcode_to_operation("G21\nM5\n", machine="linuxcnc", plan=False)
    with pytest.raises(NothingToShowError, match="no move"):
        op.to_vtk()
