"""Cincinnati BAAM programs (ORNL Slicer 2's Cincinnati syntax): screw extruder, W table, layers, planning.

Expected values are worked out by hand from examples/baam_wall.nc: a 20 x 10 in
rectangle, two layers of 0.2 in, at 600 in/min, the screw at 110 then 120 rpm.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit import analysis

WALL = Path(__file__).parents[1] / "examples" / "baam_wall.nc"
INCH = 25.4


def test_detected_from_the_slicer_header():
    op = gcodekit.gcode_to_operation(WALL)
    assert (op.flavor.name, op.machine.name) == ("baam", "baam")


def test_the_w_table_drop_is_a_layer_change_in_the_part_frame():
    op = gcodekit.gcode_to_operation(WALL)
    w = op.waypoints
    printing = analysis.depositing(w, screw=True)
    # Z30.2 with the table at W30 is 0.2 in above the table; W29.8 lowers the table 0.2 in more
    assert np.unique(np.round(w["z"][printing], 6)).tolist() == [pytest.approx(0.2 * INCH), pytest.approx(0.4 * INCH)]
    assert op.get_statistics()["layers"] == 2  # "M1 (OPTIONAL STOP - LAYER CHANGE)" before each layer
    assert set(analysis.features(op)[printing]) == {"PERIMETER"}


def test_the_screw_deposits_on_feed_moves_while_it_turns():
    op = gcodekit.gcode_to_operation(WALL, screw_displacement=2.0)
    stats = op.get_statistics()
    assert stats["moves"]["extruding"] == 8
    assert stats["distance_mm"]["extrude"] == pytest.approx(2 * 60 * INCH)  # two 60 in perimeters
    volumes = [p.deposited_volume for p in op.process_data if p.motion == "feed"]
    # 20 in at 600 in/min is 2 s; 110 rpm for 2 s is 3.667 rev of 2 cm^3
    assert volumes[0] == pytest.approx(110 * 2 / 60 * 2.0 * 1000)
    assert volumes[4] == pytest.approx(120 * 2 / 60 * 2.0 * 1000)  # S120 on the second layer
    unknown = gcodekit.gcode_to_operation(WALL)  # no displacement in the preset: unknown, not zero
    assert np.isnan(unknown.process_data[18].deposited_volume)


def test_planner_stops_before_and_after_the_layer_change():
    # the screw keeps turning through the table drop, so only BAAM's rule makes the machine stop there
    text = ("(Cincinnati)\nG0 W30\nG0 X0 Y0 Z30.2\nM3 S100\nG1 F600 X20\nY10\nG1 W29.8\nG1 X0\nY0\nM5\nM30\n")
    rules = {"max_acceleration": 500.0, "max_velocity": 1000.0}
    op = gcodekit.gcode_to_operation(text, "baam", planner_settings={"machine_rules": "baam", **rules})
    moves, result = op.plan
    z = np.round(op.waypoints["z"][moves.waypoint], 6)
    change = int(np.flatnonzero(np.diff(z) > 0)[-1]) + 1  # the move up to the second layer
    assert result.end_v[change - 1] == 0.0 and result.start_v[change] == 0.0 and result.end_v[change] == 0.0
    free = gcodekit.gcode_to_operation(text, "baam", planner_settings=rules)
    _, free_result = free.plan
    assert free_result.end_v[change - 1] > 0.0  # a plain corner otherwise
    assert free.get_statistics()["time_s"] < op.get_statistics()["time_s"]  # the stops cost time


def test_additive_part_counts_the_screws_volume_per_layer():
    op = gcodekit.gcode_to_operation(WALL, screw_displacement=2.0)
    part = gcodekit.AdditivePart(op)
    assert part.n_layers == 2
    assert part.deposition_length == pytest.approx(2 * 60 * INCH)
    # each perimeter: 4 sides of 2 s (20 in) and 1 s (10 in) -> 6 s; 110 then 120 rpm, 2 cm^3 per rev
    assert part.volume == pytest.approx((110 + 120) * 6 / 60 * 2.0 * 1000)


def test_report_draws_the_screw_deposits():
    from gcodekit.report.figures import toolpath_drawing

    drawing = toolpath_drawing(gcodekit.gcode_to_operation(WALL))
    assert len(drawing.segments) == 8  # the two perimeters' eight sides, no travel


def test_material_event_series_follows_the_screw():
    events = analysis.gcode_dataframe_to_event_series(gcodekit.gcode_to_operation(WALL).to_dataframe())
    on = events[events["value"] == 1.0]
    assert len(on) == 8  # the eight perimeter sides, each an event with the screw turning
    assert events["value"].iloc[-1] == 0.0


def test_iterating_process_data_derives_the_volumes_once(monkeypatch):
    # a whole-program column per item made iteration quadratic in the program's length
    op = gcodekit.gcode_to_operation(WALL, "baam", screw_displacement=2.0)
    calls = []
    whole = type(op).deposited_volumes
    monkeypatch.setattr(type(op), "deposited_volumes", lambda self: calls.append(1) or whole(self))
    items = list(op.process_data)
    assert len(calls) == 1
    expected = whole(op) if op._waypoint_of_command() is None else whole(op)[op._waypoint_of_command()]
    np.testing.assert_allclose([p.deposited_volume for p in items], expected)
    assert np.nansum(expected) > 0
