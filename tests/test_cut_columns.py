"""Material removal per move as columns of the operation: removed volume and removal rate, in the schema."""

import math
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.cut import CutSimulation, Stock, ToolLibrary, cut
from gcodekit.schema import COLUMNS
from gcodekit.tool_shapes import ToolShape

EXAMPLES = Path(__file__).parents[1] / "examples"
FLAT4 = ToolLibrary({0: ToolShape("endmill", 4.0)})

# a plunge, a slot, a rapid up and a feed move in the air; planned as programmed (no planner), so each
# move's time is its length over its feed and the rates can be worked out by hand
SLOT = "G21 G90\nG0 X0 Y0 Z1\nG1 Z-1 F100\nG1 X10\nG0 Z5\nG1 X20 F200\n"


def _rows_by_line(op):
    lines = np.asarray(op.table.line)[op.waypoints["command"]]
    return {int(line): int(np.flatnonzero(lines == line)[-1]) for line in np.unique(lines)}


def test_a_slot_gets_its_hand_computed_volume_and_rate_per_move():
    op = gcodekit.gcode_to_operation(SLOT, machine="linuxcnc", plan=False)
    result = cut(op, stock=Stock.box(-5, -5, -5, 25, 5, 0, resolution=0.05), tools=FLAT4)
    rows = _rows_by_line(op)
    w = op.waypoints
    # line 3: a 4 mm end mill plunges from Z1 to Z-1, 1 mm into the stock: pi r^2 h = 4 pi mm^3, in
    # 2 mm / 100 mm/min = 0.02 min
    assert w["removed_volume"][rows[3]] == pytest.approx(4 * math.pi, rel=2e-3)
    assert w["removal_rate"][rows[3]] == pytest.approx(4 * math.pi / 0.02, rel=2e-3)
    # line 4: the slot on to X10 adds a 10 x 4 x 1 box (the half disc ahead replaces the one left behind)
    # in 10 mm / 100 mm/min = 0.1 min
    assert w["removed_volume"][rows[4]] == pytest.approx(40.0, rel=2e-3)
    assert w["removal_rate"][rows[4]] == pytest.approx(400.0, rel=2e-3)
    # the rate is the volume over the move's own time, exactly
    for line in (3, 4):
        k = rows[line]
        assert w["removal_rate"][k] == pytest.approx(w["removed_volume"][k] / (w["time"][k] / 60), rel=1e-12)
    # line 5 rapids up and line 6 feeds 10 mm at Z5, over the stock: nothing removed, rate 0
    for line in (5, 6):
        assert w["removed_volume"][rows[line]] == 0.0 and w["removal_rate"][rows[line]] == 0.0
    assert [int(result.lines[k]) for k in result.air_cuts] == [6]
    # moves that do not move (line 1's modes) take no time: rate 0, not NaN
    assert w["removal_rate"][rows[1]] == 0.0
    # the sum over the moves is the volume the stock lost
    assert w["removed_volume"].sum() == pytest.approx(result.removed_mm3, rel=1e-12)
    assert result.removed_mm3 == pytest.approx(40 + 4 * math.pi, rel=2e-3)


@pytest.mark.parametrize("engine", ["numpy", "auto"])
def test_the_bracket_per_move_volumes_add_up_to_the_removed_volume(engine):
    op = gcodekit.gcode_to_operation(EXAMPLES / "bracket_mill.ngc")
    result = cut(op, stock=Stock.box(0, 0, -10, 60, 40, 0, resolution=0.2),
                 tools=ToolLibrary.read(EXAMPLES / "tools" / "bracket_mill.toml"), engine=engine)
    removed = op.waypoints["removed_volume"]
    assert result.removed_mm3 > 100
    # what each move took from the cells, summed, against the stock's volume less the part's
    assert removed.sum() == pytest.approx(result.removed_mm3, rel=1e-9)
    np.testing.assert_array_equal(op.volumes(), removed)
    assert op.volumes().sum() == pytest.approx(result.removed_mm3, rel=1e-9)
    # every move that removes something is a move; air and rapids above the stock remove nothing
    motion = np.asarray(op.waypoints["motion"])
    assert (removed[motion == 0] == 0).all()
    assert (removed[result.air_cuts] == 0).all()
    assert (removed >= 0).all()


def test_the_columns_are_in_the_schema_the_frame_and_the_process_data():
    op = gcodekit.gcode_to_operation(SLOT, machine="linuxcnc", plan=False)
    before = op.to_dataframe()
    assert "removed_volume" not in before and "removed_volume" not in op.columns.index
    assert np.isnan(op.volumes()).all()  # not known before a cut
    assert op.process_data[3].removed_volume is None
    cut(op, stock=Stock.box(-5, -5, -5, 25, 5, 0, resolution=0.1), tools=FLAT4)
    for name, values in op.waypoints.items():
        assert name in COLUMNS, name
        assert values.dtype == np.dtype(COLUMNS[name].dtype), name
    frame = op.to_dataframe()
    schema = op.columns
    assert schema.loc["removed_volume", "unit"] == "mm^3" and schema.loc["removal_rate", "unit"] == "mm^3/min"
    for name in ("removed_volume", "removal_rate"):
        assert str(frame[name].dtype) == schema.loc[name, "dtype"] == "float64"
        np.testing.assert_array_equal(frame[name].to_numpy(), op.waypoints[name])
    assert set(frame.columns) <= set(COLUMNS)
    # the process data of line 4's command carries its volume
    command = int(op.waypoints["command"][_rows_by_line(op)[4]])
    assert op.process_data[command].removed_volume == pytest.approx(40.0, rel=5e-3)


def test_a_partial_cut_leaves_the_operation_alone_the_whole_run_sets_it():
    op = gcodekit.gcode_to_operation(SLOT, machine="linuxcnc", plan=False)
    sim = CutSimulation(op, stock=Stock.box(-5, -5, -5, 25, 5, 0, resolution=0.1), tools=FLAT4)
    sim.cut_to(_rows_by_line(op)[3])
    assert "removed_volume" not in op.waypoints  # the slider's partial states are not the program's figures
    sim.run()
    assert op.waypoints["removed_volume"].sum() == pytest.approx(sim.result().removed_mm3, rel=1e-12)


def test_attach_removal_checks_its_columns():
    op = gcodekit.gcode_to_operation(SLOT, machine="linuxcnc", plan=False)
    with pytest.raises(ValueError, match="removed_volume has"):
        op.attach_removal(np.zeros(2), np.zeros(2))
