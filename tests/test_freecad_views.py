"""A FreeCAD-style path or job in gcodekit's notebook widgets and reports, like any program."""

from __future__ import annotations

import pytest

import gcodekit.path as Path

pytest.importorskip("anywidget")
pytest.importorskip("jinja2")


def _job():
    table = Path.Tooltable()
    table.addTools(Path.Tool("3 mm end mill", tooltype="EndMill", diameter=3))
    job = Path.Job(tooltable=table)
    job.add(Path.Path("G0 Z5 G0 X0 Y0 G1 Z-1 F300 G1 X20 G2 X20 Y10 I0 J5 G1 X0 G1 Y0 G0 Z5"), tool=1, name="pocket")
    return job


def test_layer_viewer_and_velocity_plot_show_a_job():
    from gcodekit.widgets import LayerViewer, VelocityPlot

    op = Path.to_operation(_job())
    viewer = LayerViewer(op, color_by="speed")
    assert viewer.error is None
    assert viewer.path.group_labels == ["Z -1"]  # the one cutting level
    plot = VelocityPlot(op)
    assert getattr(plot, "error", None) is None
    # the planned time covers every move: at least length / feed for the cuts
    cut = 20 + 5 * 3.141592653589793 + 20 + 10
    assert op.waypoints["time"].sum() > cut / 300 * 60


def test_a_job_gets_a_report(tmp_path):
    row = Path.write_report(_job(), tmp_path, name="pocket")
    assert row.get("error") is None, row["error"]
    assert row["distance_mm"] == pytest.approx(_job().Path.Length, rel=1e-9)  # 5 + 6 + 20 + 5 pi + 20 + 10 + 6
    page = (tmp_path / row["html"]).read_text()
    assert "pocket" in page and (tmp_path / "pocket.ngc").read_text().startswith("(pocket: post-processed by gcodekit for linuxcnc)")


def test_a_report_name_cannot_leave_the_folder(tmp_path):
    from gcodekit.errors import ConfigError

    with pytest.raises(ConfigError, match="plain file name"):
        Path.write_report(_job(), tmp_path, name="../escape")
