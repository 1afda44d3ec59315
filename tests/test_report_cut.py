"""Reports of mill programs: the material-removal section (numbers, tools beside the program, the picture)."""

import base64
import io
import shutil
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit.cut import CutSimulation, ToolLibrary
from gcodekit.report.build import report_data

EXAMPLES = Path(__file__).parents[1] / "examples"
MILL = EXAMPLES / "bracket_mill.ngc"


def test_mill_report_cuts_with_the_tools_beside_the_program():
    op = gcodekit.gcode_to_operation(MILL)
    cut = report_data(op)["cut"]
    # the same cut made directly: stock from the program, tools/bracket_mill.toml
    direct = CutSimulation(op, tools=ToolLibrary.read(EXAMPLES / "tools" / "bracket_mill.toml")).run()
    assert cut["removed_mm3"] == pytest.approx(direct.removed_mm3)
    assert cut["remaining_mm3"] == pytest.approx(cut["stock_mm3"] - cut["removed_mm3"])
    assert cut["tools"] == {"1": {"shape": "endmill", "diameter": 6.0, "length": 20.0}}
    assert cut["notes"] == []  # every tool has a shape; no rapid goes into the stock


def test_without_a_tools_file_the_page_says_how_the_tool_was_taken(tmp_path):
    program = tmp_path / "bracket.ngc"
    shutil.copy(MILL, program)
    cut = report_data(gcodekit.gcode_to_operation(program))["cut"]
    assert any(n["line"] == 12 and "tool 1 has no shape" in n["message"] for n in cut["notes"])


def test_print_reports_have_no_cut():
    op = gcodekit.gcode_to_operation(EXAMPLES / "cube20_prusaslicer_marlin.gcode")
    assert report_data(op, transpile=False)["cut"] is None


def test_mill_page_shows_the_part_and_volumes(tmp_path):
    from PIL import Image

    from gcodekit.report.batch import write_reports
    from gcodekit.report.batch import ReportOptions

    write_reports([MILL], tmp_path, options=ReportOptions(pdf=False))
    page = (tmp_path / "bracket_mill.ngc.html").read_text()
    section = page[page.index("<h2>Material removal</h2>"):]
    assert "Removed" in section and "mm³" in section and "Air cuts" in section
    uri = section.split('src="', 1)[1].split('"', 1)[0]
    image = np.asarray(Image.open(io.BytesIO(base64.b64decode(uri.split(",", 1)[1]))).convert("RGB"))
    assert image.shape[:2] == (700, 1000)
    # the part covers a good share of the picture in shaded colours, on white
    part = np.any(image < 240, axis=2)
    assert 0.15 < part.mean() < 0.9
    assert len(np.unique(image[part], axis=0)) > 50


def test_the_page_lists_the_moves_that_remove_fastest(tmp_path):
    op = gcodekit.gcode_to_operation(MILL)
    cut = report_data(op, transpile=False)["cut"]
    # the report's cut gave the operation its columns; the page's figures are read from them
    rate, removed = op.waypoints["removal_rate"], op.waypoints["removed_volume"]
    lines = np.asarray(op.table.line)[op.waypoints["command"]]
    top = cut["top_moves"]
    assert len(top) == 5 and top[0]["rate"] == pytest.approx(rate.max())
    assert [m["rate"] for m in top] == sorted((m["rate"] for m in top), reverse=True)
    for move in top:
        k = int(np.flatnonzero((lines == move["line"]) & np.isclose(rate, move["rate"]))[0])
        assert move["removed_mm3"] == pytest.approx(removed[k])
    cutting = removed > 0
    assert cut["mean_rate"] == pytest.approx(removed.sum() / (op.waypoints["time"][cutting].sum() / 60), rel=1e-9)

    from gcodekit.report.batch import ReportOptions, write_reports

    write_reports([MILL], tmp_path, options=ReportOptions(pdf=False))
    section = (tmp_path / "bracket_mill.ngc.html").read_text().split("<h2>Material removal</h2>", 1)[1]
    assert "Removal rate" in section and "mm³/min" in section
    assert f"<td>{top[0]['line']}</td>" in section.split('class="top-moves"', 1)[1]
