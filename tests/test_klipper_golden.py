"""Klipper's planner: totals and per-move velocities against klippy's own output."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import gcodekit
from shared_corpus import CORPUS as SHARED_CORPUS

HERE = Path(__file__).parent / "golden" / "klipper"
CASES = HERE / "cases"
CONFIG = HERE / "klipper_printer.cfg"
SHARED_FFF = SHARED_CORPUS / "fff"
TOTALS = {r["case"]: float(r["klipper_total_s"]) for r in csv.DictReader(open(CASES / "totals.csv"))}
CORPUS = {r["file"]: float(r["klipper_total_s"]) for r in csv.DictReader(open(HERE / "corpus_totals.csv"))}


def planned(path: Path, **options) -> gcodekit.Operation:
    return gcodekit.gcode_to_operation(path, "klipper", machine_config=CONFIG, **options)


@pytest.mark.parametrize("case", sorted(TOTALS))
def test_case_totals_within_a_millisecond(case):
    program, _, variant = case.partition(".")
    options = {"temperature_waits_flush": True} if variant == "temp_wait_flush" else {}
    op = gcodekit.gcode_to_operation(CASES / f"{program}.gcode", "klipper", machine_config=CONFIG, plan=False)
    from gcodekit.plan import planner_settings, run_planner

    settings = planner_settings("klipper", {}, CONFIG)
    if options:
        import dataclasses

        settings = dataclasses.replace(settings, **options)
    op.attach_plan(run_planner(op, "klipper", settings))
    assert op.get_statistics()["time_s"] == pytest.approx(TOTALS[case], abs=1e-3)


MOVE_FILES = sorted(CASES.glob("*.moves.csv")) + [CASES / "cube20_marlin2.klipper_moves.csv"]


@pytest.mark.parametrize("moves_csv", MOVE_FILES, ids=lambda p: p.name)
def test_every_move_velocity(moves_csv):
    name = moves_csv.name.split(".")[0].replace("_moves", "")
    op = planned(CASES / f"{name}.gcode")
    moves, result = op.plan
    ref = pd.read_csv(moves_csv)
    assert len(moves) == len(ref), "number of planned moves (arcs cut into 1 mm chords)"
    assert (op.table.line[moves.row] == ref["line"].to_numpy()).all()
    for column in ("start_v", "cruise_v", "end_v"):
        ours, theirs = getattr(result, column), ref[column].to_numpy()
        rel = np.abs(ours - theirs) / np.maximum(np.abs(theirs), 1e-300)
        rel[(ours == 0) & (theirs == 0)] = 0.0
        worst = int(np.argmax(rel))
        assert rel[worst] <= 1e-6, (
            f"{column} of move {worst} (line {ref['line'][worst]}: {ref['text'][worst]!r}): "
            f"ours {ours[worst]!r}, Klipper {theirs[worst]!r}")
    np.testing.assert_allclose(result.duration_t, ref["dur"].to_numpy(), rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("name", sorted(CORPUS))
def test_corpus_totals_within_0_1_percent(name):
    path = CASES / name if (CASES / name).exists() else SHARED_FFF / name
    if not path.exists():
        pytest.skip(f"{name} is only in the shared corpus")
    total = planned(path).get_statistics()["time_s"]
    assert total == pytest.approx(CORPUS[name], rel=1e-3)


def test_m204_needs_s_or_p_and_t():
    op = gcodekit.gcode_to_operation("M204 P500\nG1 X100 F6000\nM204 P500 T400\nG4 P0\nG1 X0\n", "klipper",
                                     machine_config=CONFIG)
    moves, result = op.plan
    assert result.accel.tolist() == [3000.0, 400.0]
    assert any("M204" in d.message for d in op.diagnostics)


def test_printer_cfg_errors_name_the_file(tmp_path):
    bad = tmp_path / "printer.cfg"
    bad.write_text("[printer]\nmax_velocity: fast\nmax_accel: 3000\n")
    with pytest.raises(gcodekit.ConfigError, match=r"printer\.cfg.*max_velocity"):
        gcodekit.gcode_to_operation(CASES / "a_only.gcode", "klipper", machine_config=bad)


def test_radius_arcs_are_rejected_like_klipper():
    op = gcodekit.gcode_to_operation("G1 X10 F6000\nG2 X20 Y0 R5\nG1 X30\n", "klipper", machine_config=CONFIG)
    assert op.motions()["x"].tolist() == [10.0, 30.0]
    assert [d.line for d in op.diagnostics if "R-form" in d.message] == [2]


def test_a_move_refused_for_its_speed_leaves_the_next_to_start_where_the_tool_is():
    """Klipper refuses ``G1 X20 F0`` ("Invalid speed") and takes its gcode position back from the toolhead
    (gcode_move.py ``reset_last_position`` on ``gcode:command_error``): X13 goes 3 mm on from X10, in one
    line with it, not 7 mm back from X20.  Rest to rest at 800 mm/min and 3000 mm/s^2 (the preset's)."""
    op = gcodekit.gcode_to_operation("G1 X10 F800\nG1 X20 F0\nG1 X13\n", "klipper")
    v, accel = 800 / 60, 3000.0
    assert op.motions()["x"].tolist() == [10.0, 13.0]
    assert op.waypoints["time"].sum() == pytest.approx(13 / v + v / accel, rel=1e-12)
