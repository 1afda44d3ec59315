"""Command line: export to parquet, VTK and event series; render to PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run

import gcodekit

EXAMPLES = Path(__file__).parents[1] / "examples"
MILL = EXAMPLES / "bracket_mill.ngc"
PRINT = EXAMPLES / "cube20_prusaslicer_marlin.gcode"
DOME = EXAMPLES / "dome_ded_beckhoff.nc"


def test_parquet_holds_the_csv_table(tmp_path, capsys):
    pytest.importorskip("pyarrow")
    status, _, _ = run(["export", MILL, "--to", "parquet", "-o", tmp_path / "m.parquet"], capsys)
    assert status == 0
    run(["export", MILL, "-o", tmp_path / "m.csv"], capsys)
    parquet, csv = pd.read_parquet(tmp_path / "m.parquet"), pd.read_csv(tmp_path / "m.csv")
    assert list(parquet.columns) == list(csv.columns)
    assert parquet["x"].to_numpy() == pytest.approx(csv["x"].to_numpy(), abs=1e-6)


def test_vtk_export_default_name_and_no_overwrite(tmp_path, capsys, monkeypatch):
    pv = pytest.importorskip("pyvista")
    monkeypatch.chdir(tmp_path)
    status, _, _ = run(["export", PRINT, "--to", "vtk"], capsys)
    assert status == 0
    mesh = pv.read(tmp_path / "cube20_prusaslicer_marlin.vtp")
    assert mesh.n_cells > 100 and "layer_time" in mesh.cell_data
    status, _, err = run(["export", PRINT, "--to", "vtk"], capsys)
    assert status == 2 and "--force" in err
    assert run(["export", PRINT, "--to", "vtk", "--force"], capsys)[0] == 0


def test_vtk_export_of_a_mill_program_writes_its_toolpath_and_refuses_a_bad_name(tmp_path, capsys):
    import pyvista as pv

    status, _, err = run(["export", MILL, "--to", "vtk", "-o", tmp_path / "m.vtp"], capsys)
    assert status == 0, err
    mesh = pv.read(tmp_path / "m.vtp")
    op = gcodekit.gcode_to_operation(MILL)
    moved = np.asarray(op.waypoints["distance"])[op.moving].sum()
    assert mesh.cell_data["length"].sum() == pytest.approx(moved)
    assert set(np.unique(mesh.cell_data["rapid"])) == {0, 1}
    status, _, err = run(["export", PRINT, "--to", "vtk", "-o", tmp_path / "m.stl"], capsys)
    assert status == 2 and ".vtp" in err


def test_events_of_the_heat_source(capsys):
    status, out, _ = run(["export", DOME, "--to", "events", "--source", "heat"], capsys)
    assert status == 0
    events = np.loadtxt(out.splitlines(), delimiter=",")
    assert events.shape[1] == 5 and np.all(np.diff(events[:, 0]) >= 0)
    # the first weld starts at the first M61 move's start point: X49.96 Y0 Z2.5
    on = np.flatnonzero(events[:, 4] == 1)[0]
    assert events[on, 1:4].tolist() == pytest.approx([49.96, 0.0, 2.5])


def test_render_writes_a_png(tmp_path, capsys):
    pytest.importorskip("pyvista")
    target = tmp_path / "dome.png"
    status, _, err = run(["render", DOME, "-o", target, "--color-by", "speed", "--view", "top", "--size", "400x300"],
                         capsys)
    assert status == 0, err
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    status, _, err = run(["render", DOME, "-o", target], capsys)
    assert status == 2 and "--force" in err


def test_render_errors_are_one_line(tmp_path, capsys):
    status, _, err = run(["render", PRINT, "-o", tmp_path / "x.png", "--color-by", "layr"], capsys)
    assert status == 2 and "did you mean 'layer'" in err and "Traceback" not in err
    status, _, err = run(["render", PRINT, "-o", tmp_path / "x.jpg"], capsys)
    assert status == 2 and ".png" in err
    status, _, err = run(["render", "no/such.gcode", "-o", tmp_path / "y.png"], capsys)
    assert status == 2 and "no such file" in err


def test_ded_material_events_follow_the_weld(capsys):
    # DED programs have no E words: material is laid while the heat source is on during a feed move
    _, heat, _ = run(["export", DOME, "--to", "events", "--source", "heat"], capsys)
    _, material, _ = run(["export", DOME, "--to", "events"], capsys)
    assert material == heat
    assert np.loadtxt(material.splitlines(), delimiter=",")[:, 4].sum() > 100


@pytest.mark.parametrize("text", ["", "G28\nG1 X10 Y10 F3000\n"])
def test_programs_that_lay_nothing(tmp_path, capsys, text):
    program = tmp_path / "nothing.gcode"
    program.write_text(text)
    for args in (["render", program, "-o", tmp_path / "n.png"], ["export", program, "--to", "vtk", "-o", tmp_path / "n.vtp"]):
        status, _, err = run(args, capsys)  # the program's problem (1), not the arguments' (2)
        assert status == 1 and "nothing.gcode" in err and "Traceback" not in err
        assert "nothing to draw" in err or "no deposition moves to export" in err


def test_info_json_gives_both_filament_figures(capsys):
    import json

    status, out, _ = run(["info", PRINT, "--json"], capsys)
    record = json.loads(out)
    # PrusaSlicer wrote "; filament used [mm] = 1276.70"; the program runs under M221 S95
    assert record["filament_convention"] == "consumed"
    assert record["filament_mm"] == pytest.approx(1276.70, abs=0.01)
    # pushed: the intro lines (E9 + E12.5) at full flow, the rest of the program's net E (1296.403 mm,
    # summed from its E words separately) at 95 %
    assert record["filament_pushed_mm"] == pytest.approx(21.5 + 0.95 * (1296.403 - 21.5), abs=0.01)
