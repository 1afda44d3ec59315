"""The front door: what users reach from ``import gcodekit`` and an Operation, in their own words."""

from __future__ import annotations

import math

from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.schema import COLUMNS
from gcodekit.testing import assert_operations_equal

EXAMPLES = Path(__file__).parents[1] / "examples"
PRINT = EXAMPLES / "cube20_prusaslicer_marlin.gcode"


@pytest.fixture(scope="module")
def cube():
    return gcodekit.gcode_to_operation(PRINT)


def test_derived_columns_are_computed_once_and_kept(cube):
    assert cube.layers is cube.layers and cube.features is cube.features and cube.depositing is cube.depositing
    # PrusaSlicer wrote 100 ;LAYER_CHANGE comments for this 20 mm cube at 0.2 mm
    assert cube.n_layers == 100 == cube.get_statistics()["layers"] == cube.summary()["layers"]
    frame = cube.to_dataframe()
    assert np.array_equal(frame["layer"], cube.layers) and np.array_equal(frame["depositing"], cube.depositing)
    # every depositing move inside the part is in a layer; the purge line before the first is not
    assert (cube.layers[cube.depositing] >= -1).all() and (cube.layers[cube.depositing] >= 0).mean() > 0.99
    assert set(cube.features[cube.depositing]) >= {"Perimeter", "External perimeter", "Solid infill"}


def test_new_waypoints_forget_the_old_derived_columns():
    op = gcodekit.gcode_to_operation("M83\nG1 Z0.2 F600\nG1 X10 E1\n", "marlin", plan=False)
    assert op.n_layers == 1
    other = gcodekit.gcode_to_operation("M83\nG1 Z0.2 F600\nG1 X10 E1\nG1 Z0.4\nG1 X0 E1\n", "marlin", plan=False)
    op.table, op.waypoints = other.table, other.waypoints
    assert op.n_layers == 2


def test_columns_document_every_dataframe_column(cube):
    frame = cube.to_dataframe()
    schema = cube.columns
    assert set(frame.columns) <= set(COLUMNS), set(frame.columns) - set(COLUMNS)  # every column is in the schema
    assert set(schema.index) >= set(frame.columns) >= set(schema.index) - {"accel"}
    assert schema.loc["x", "unit"] == "mm" and schema.loc["elapsed_time", "unit"] == "s"
    for name in frame.columns:
        if name == "motion":
            continue  # the waypoints' uint8 code, a categorical of its names in the frame
        assert str(frame[name].dtype) == schema.loc[name, "dtype"], name


@pytest.mark.parametrize("program, machine", [("bracket_mill.ngc", None), ("dome_ded_beckhoff.nc", None),
                                              ("cead_wall.mpf", None), ("baam_wall.nc", None)])
def test_every_column_a_stage_makes_is_in_the_schema(program, machine):
    op = gcodekit.gcode_to_operation(EXAMPLES / program, machine)
    for name, values in op.waypoints.items():
        assert name in COLUMNS, name
        assert values.dtype == np.dtype(COLUMNS[name].dtype), name
    frame = op.to_dataframe()
    assert set(frame.columns) <= set(COLUMNS), set(frame.columns) - set(COLUMNS)


def test_the_one_summary_record_is_what_info_prints(cube, capsys):
    import json

    from cli_helpers import run

    _, out, _ = run(["info", PRINT, "--json"], capsys)
    printed = json.loads(out)
    record = cube.summary()
    for key in ("layers", "time_s", "moves", "distance_mm", "filament_mm", "mass_g"):
        assert printed[key] == pytest.approx(record[key]), key


def test_outputs_one_call_away(cube, tmp_path):
    picture = cube.plot(window_size=(160, 120))
    assert picture.shape == (120, 160, 3) and len(np.unique(picture.reshape(-1, 3), axis=0)) > 4
    mesh = cube.to_vtk(tmp_path / "cube.vtp")
    assert (tmp_path / "cube.vtp").stat().st_size > 1000 and mesh.n_cells > 100
    text = cube.to_gcode("marlin")
    again = gcodekit.gcode_to_operation(text, "marlin")
    assert_operations_equal(again, cube, rtol=1e-6, atol=1e-4, check_lines=False)  # written back: lines move


def test_assert_operations_equal_names_the_first_difference():
    a = gcodekit.gcode_to_operation("G1 X10 F600\nG1 Y5\nG1 Z1\n", "linuxcnc", plan=False)
    b = gcodekit.gcode_to_operation("G1 X10 F600\nG1 Y5\nG1 Z1.5\n", "linuxcnc", plan=False)
    with pytest.raises(AssertionError, match=r"waypoint 2, column 'z' \(line 3\): 1.0 != 1.5"):
        assert_operations_equal(a, b)
    with pytest.raises(AssertionError, match="3 commands != 2 commands"):
        assert_operations_equal(a, gcodekit.gcode_to_operation("G1 X1\nG1 X2\n", "linuxcnc", plan=False))


def test_seed_names_are_kept():
    for name in ("gcode_to_operation", "gcode_file_to_dataframe", "AdditivePart", "Bead", "VTKExporter",
                 "GcodeExporter", "MotionProfile", "BAAMMotionProfile", "gcode_dataframe_to_event_series",
                 "export_event_series_from_gcode", "transpile_program"):
        assert hasattr(gcodekit, name), name
    from gcodekit.analysis import depositing, features, layers  # where users looked for them

    assert layers is gcodekit.model.derived.layers and callable(depositing) and callable(features)


# -- process behaviour lives on the process classes -------------------------------------------------------


def test_each_process_answers_what_it_deposits_works_and_moves():
    from gcodekit.model import AdditiveOperation, SubtractiveOperation

    printed = gcodekit.gcode_to_operation("M83\nG1 Z0.2 F600\nG1 X10 E1\nG1 X20 E-0.5\nG0 X30\n", "marlin", plan=False)
    assert isinstance(printed, AdditiveOperation) and printed.process == "additive"
    assert printed.moving.tolist() == [False, True, True, True, True]  # M83 moves nothing
    assert printed.depositing.tolist() == [False, False, True, False, False]
    assert printed.work.tolist() == [False, False, True, False, False]
    area = math.pi * 1.75**2 / 4
    assert printed.volumes() == pytest.approx([0.0, 0.0, area, -0.5 * area, 0.0])  # a retraction draws back
    assert printed.get_bounds("extrude") == {"min": [0.0, 0.0, 0.2], "max": [10.0, 0.0, 0.2]}

    milled = gcodekit.gcode_to_operation("G21 G90\nG0 X5\nG1 X10 F300\nG1 X10\n", "linuxcnc", plan=False)
    assert isinstance(milled, SubtractiveOperation) and milled.process == "subtractive"
    assert milled.moving.tolist() == [False, False, True, True, False]  # the last move goes nowhere
    assert milled.work.tolist() == [False, False, False, True, False]
    assert not milled.depositing.any()
    assert np.isnan(milled.volumes()).all()  # until a cutting simulation says what each move removes
    assert milled.get_bounds("extrude") is None
    assert milled.get_bounds("feed") == {"min": [5.0, 0.0, 0.0], "max": [10.0, 0.0, 0.0]}
