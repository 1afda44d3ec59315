"""Abaqus AM event series for material deposition and for the heat source."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import gcodekit
from gcodekit import export_event_series_from_gcode, gcode_dataframe_to_event_series

EXAMPLES = Path(__file__).parents[1] / "examples"


def test_material_events_follow_the_extrusion():
    text = "M83\nG1 X10 F600\nG1 X20 E1\nG1 X30 E1\nG1 X40\nG1 X50\nG1 Y10 E1\n"
    events = gcode_dataframe_to_event_series(gcodekit.gcode_file_to_dataframe(text, "marlin", plan=False))
    # travel 0-1 s, print 1-3 s, travel 3-5 s (one off event), print 5-6 s, off at the end
    assert events["time"].tolist() == [0.0, 1.0, 2.0, 3.0, 5.0, 6.0]
    assert events["value"].tolist() == [0.0, 1.0, 1.0, 0.0, 1.0, 0.0]
    assert events[["x", "y"]].values.tolist() == [[0, 0], [10, 0], [20, 0], [30, 0], [50, 0], [50, 10]]


def test_heat_events_of_a_ded_program_switch_at_m61_and_m62(tmp_path):
    out = tmp_path / "events.csv"
    events = export_event_series_from_gcode(EXAMPLES / "dome_ded_beckhoff.nc", out, source="heat", plan=False)
    lines = out.read_text().splitlines()
    assert len(lines) == len(events) and len(lines[0].split(",")) == 5
    on = events["value"].to_numpy()
    switches = np.flatnonzero(np.diff(on) != 0)
    # every weld path starts (off -> on) and ends (on -> off): an even number of switches, one path per fraction
    assert switches.size % 2 == 0 and switches.size // 2 == 40
    assert np.all(np.diff(events["time"].to_numpy()) >= 0)
