"""The report: its numbers against the Operation, escaping, batches, PDF and HTML in Chromium.

Tests that need Chromium or pdftoppm skip with the package to install when
they are absent (``scripts/setup.sh`` installs both).
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

import gcodekit
from gcodekit import cli
from gcodekit.report import ReportOptions, report_program, write_reports
from gcodekit.report.build import report_data
from gcodekit.report.figures import toolpath_drawing
from gcodekit.view import CHORD_ANGLE_DEG

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
MILL = EXAMPLES / "bracket_mill.ngc"


def tiny_print(layers: int = 3, comment: str = "") -> str:
    """A 10 mm square printed ``layers`` times, perimeter then a diagonal infill, with a travel between."""
    lines = ["; tiny print" + comment, "M83", "G21 G90", "G1 Z0.2 F600"]
    for k in range(layers):
        z = 0.2 * (k + 1)
        lines += [";LAYER_CHANGE", f";Z:{z:.1f}", f"G1 Z{z:.1f} F600", "G0 X0 Y0 F6000", ";TYPE:Perimeter",
                  "G1 X10 Y0 E0.5 F1800", "G1 X10 Y10 E0.5", "G1 X0 Y10 E0.5", "G1 X0 Y0 E0.5",
                  ";TYPE:Internal infill", "G1 X10 Y10 E0.7 F3000"]
    return "\n".join(lines) + "\n"


@pytest.fixture
def print_file(tmp_path: Path) -> Path:
    path = tmp_path / "tiny.gcode"
    path.write_text(tiny_print())
    return path


def test_summary_is_the_operations_own_numbers(print_file):
    op = gcodekit.gcode_to_operation(print_file)
    stats = op.get_statistics()
    s = report_data(op)["summary"]
    assert s["time_s"] == stats["time_s"] > 0
    assert s["layers"] == 3 and s["flavor"] == "marlin" and s["process"] == "additive"
    # 3 layers x (4 x 0.5 + 0.7) mm of 1.75 mm filament, PLA at 1.24 g/cm^3
    filament = 3 * (4 * 0.5 + 0.7)
    assert s["filament_mm"] == pytest.approx(filament)
    assert s["volume_mm3"] == pytest.approx(filament * np.pi * 1.75**2 / 4)
    assert s["mass_g"] == pytest.approx(filament * np.pi * 1.75**2 / 4 / 1000 * 1.24)


def test_breakdown_by_feature_adds_up(print_file):
    op = gcodekit.gcode_to_operation(print_file)
    data = report_data(op)
    rows = {r["label"]: r for r in data["breakdown"]["rows"]}
    assert data["breakdown"]["by"] == "feature"
    assert rows["Perimeter"]["extrude_mm"] == pytest.approx(3 * 40.0)
    assert rows["Internal infill"]["extrude_mm"] == pytest.approx(3 * np.hypot(10, 10))
    assert sum(r["time_s"] for r in rows.values()) == pytest.approx(data["summary"]["time_s"])
    assert [r["layer"] for r in data["layers"]] == [0, 1, 2]


def test_mill_program_has_stages_and_toolpath_breakdown_by_tool():
    op = gcodekit.gcode_to_operation(MILL)
    data = report_data(op)
    from gcodekit.transpile import Transpiler

    assert data["stages"] == Transpiler(op).summary()
    assert data["toolpath"]["text"] == Transpiler(op).stage(6).rstrip("\n")
    assert data["breakdown"]["by"] == "tool"
    assert [r["label"] for r in data["breakdown"]["rows"]] == ["T1"]  # T0 never moved: left out
    assert data["summary"]["volume_mm3"] is None and data["layers"] is None


def test_arcs_are_drawn_as_chords_on_their_circle():
    # the first move starts where the machine was before the program, which no waypoint holds: not drawn
    op = gcodekit.gcode_to_operation("G0 X0 Y0\nG0 X10 Y0\nG3 X10 Y0 I-10 J0 F600\n", machine="linuxcnc")
    seg = toolpath_drawing(op)
    chords = int(np.ceil(360 / CHORD_ANGLE_DEG))  # 72: the full circle in chords of at most 5 degrees
    arc = seg.start.shape[0] - chords
    assert arc == 1  # the rapid, then the full circle
    points = np.vstack([seg.start[arc:], seg.end[-1:]])
    assert np.allclose(np.hypot(points[:, 0], points[:, 1]), 10.0)
    angles = np.unwrap(np.arctan2(points[:, 1], points[:, 0]))
    assert angles[-1] - angles[0] == pytest.approx(2 * np.pi)  # counter-clockwise, once round
    assert np.diff(angles).max() <= np.radians(CHORD_ANGLE_DEG) + 1e-12


def test_only_depositing_arcs_are_drawn_in_a_print():
    program = "M83\nG1 Z0.2 F600\nG2 X10 Y0 I5 J0 E1 F1200\nG2 X0 Y0 I-5 J0\nG3 X10 Y0 I5 J0 E1\n"
    op = gcodekit.gcode_to_operation(program, machine="marlin")
    seg = toolpath_drawing(op)
    half = int(np.ceil(180 / CHORD_ANGLE_DEG))  # each half circle in 36 chords
    assert seg.start.shape[0] == 2 * half  # the travel arc between them is left out
    assert np.allclose(np.hypot(seg.end[:, 0] - 5, seg.end[:, 1]), 5.0)
    # left to right, clockwise passes above the centre and counter-clockwise below
    assert (seg.end[:half, 1] >= -1e-9).all() and (seg.end[half:, 1] <= 1e-9).all()


def test_comments_and_file_names_are_escaped(tmp_path):
    bad = "<script>alert(1)</script>"
    program = tmp_path / "<script>alert(1).gcode"
    text = tiny_print(1, comment=" " + bad).replace(";TYPE:Perimeter", f";TYPE:{bad}")
    program.write_text(text + f"M999 ; {bad}\n")  # an unknown code: a diagnostic quoting the line
    rows = write_reports([program], tmp_path / "out", options=ReportOptions(pdf=False))
    page = (tmp_path / "out" / rows[0]["html"]).read_text()
    index = (tmp_path / "out" / "index.html").read_text()
    for html in (page, index):
        assert "<script" not in html.lower()
        assert "&lt;script&gt;alert(1)" in html
    assert page.count("&lt;script&gt;alert(1)&lt;/script&gt;") >= 2  # the feature name and the diagnostic
    assert rows[0]["html"] == "_script_alert_1_.gcode.html"


def test_markup_in_feature_names_is_text_on_the_page(tmp_path):
    """Jinja's autoescape: a slicer feature name holding an element with a handler reaches the page as text."""
    planted = "<img src=x onerror=alert(1)>"
    program = tmp_path / "planted.gcode"
    program.write_text(tiny_print(2).replace(";TYPE:Internal infill", f";TYPE:{planted}"))
    rows = write_reports([program], tmp_path / "out", options=ReportOptions(pdf=False))
    page = (tmp_path / "out" / rows[0]["html"]).read_text()
    assert "&lt;img src=x onerror=alert(1)&gt;" in page  # the breakdown's row label
    images = re.findall(r"<img\b[^>]*>", page, flags=re.IGNORECASE)
    assert images and all('src="data:image/png;base64,' in tag for tag in images)  # only the figures
    assert "onerror" not in "".join(images)


def test_empty_program_gets_a_page_without_pictures(tmp_path):
    program = tmp_path / "empty.ngc"
    program.write_text("(nothing to do)\n")
    row = report_program(program, tmp_path, options=ReportOptions(pdf=False))
    assert row["error"] is None and row["time_s"] == 0
    assert "The program does not move" in (tmp_path / row["html"]).read_text()


def test_batch_on_two_processes_survives_a_failing_program(tmp_path, print_file):
    bad = tmp_path / "bad.ngc"
    bad.write_text("G0 X1\nG2 X5 R0.1\n")
    missing = tmp_path / "missing.gcode"
    out = tmp_path / "out"
    rows = write_reports([print_file, bad, missing], out, options=ReportOptions(pdf=False, strict=True), workers=2)
    assert [r["name"] for r in rows] == ["tiny.gcode", "bad.ngc", "missing.gcode"]
    assert rows[0]["error"] is None
    assert rows[0]["time_s"] == gcodekit.gcode_to_operation(print_file).get_statistics()["time_s"]
    assert "bad.ngc:2:1" in rows[1]["error"] and "arc radius" in rows[1]["error"]
    assert "no such program file" in rows[2]["error"]
    error_page = (out / "bad.ngc.html").read_text()
    assert "GcodeMachineError" in error_page and "<th>Line</th><td>2, column 1</td>" in error_page
    index = (out / "index.html").read_text()
    assert all(f'href="{r["html"]}"' in index for r in rows)
    assert index.count('class="error"') >= 2


def test_workers_are_forked_only_from_a_process_without_other_threads(tmp_path, print_file):
    import threading

    from gcodekit.report.batch import _start_method

    done = threading.Event()
    waiter = threading.Thread(target=done.wait)
    waiter.start()
    try:
        assert _start_method().get_start_method() == "spawn"
        rows = write_reports([print_file, print_file], tmp_path / "out", options=ReportOptions(pdf=False),
                             workers=2, progress=True)
    finally:
        done.set()
        waiter.join()
    assert [r["error"] for r in rows] == [None, None] and rows[1]["html"] == "tiny.gcode-2.html"


def test_batch_on_a_dask_cluster(tmp_path, print_file):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        rows = write_reports([print_file, MILL, tmp_path / "missing.ngc"], tmp_path / "out",
                             options=ReportOptions(pdf=False), dask=cluster.scheduler_address)
    assert [r["error"] is None for r in rows] == [True, True, False]
    assert rows[1]["time_s"] == gcodekit.gcode_to_operation(MILL).get_statistics()["time_s"]
    assert (tmp_path / "out" / "bracket_mill.ngc.html").exists()


def test_cli_never_overwrites_without_force(tmp_path, print_file, capsys):
    out = tmp_path / "out"
    out.mkdir()
    mine = out / "tiny.gcode.html"
    mine.write_text("mine")
    assert cli.main(["report", str(print_file), "-o", str(out), "--no-pdf"]) == 2
    assert "tiny.gcode.html" in capsys.readouterr().err and mine.read_text() == "mine"
    assert cli.main(["report", str(print_file), "-o", str(out), "--no-pdf", "--force"]) == 0
    assert "<h1>tiny.gcode</h1>" in mine.read_text()


def test_cli_rejects_a_wrong_machine_before_writing_anything(tmp_path, print_file, capsys):
    assert cli.main(["report", str(print_file), "-o", str(tmp_path / "out"), "--no-pdf", "--machine", "marlinn"]) == 2
    assert "did you mean 'marlin'" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_report_package_imports_nothing_heavy():
    code = ("import sys, gcodekit.report, gcodekit.report.build, gcodekit.report.figures\n"
            "print([m for m in ('matplotlib', 'jinja2', 'nbclient', 'distributed') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_notebook_runs_and_shows_the_pictures(tmp_path, print_file):
    pytest.importorskip("nbclient")
    from gcodekit.report.notebook import write_notebook

    out = write_notebook(print_file, tmp_path / "tiny.ipynb", html=True)
    nb = json.loads(out.read_text())
    outputs = [o for c in nb["cells"] if c["cell_type"] == "code" for o in c["outputs"]]
    assert not [o for o in outputs if o["output_type"] == "error"]
    assert sum("image/png" in o.get("data", {}) for o in outputs) >= 5  # iso, top, layers x2, speed, breakdown
    assert "tiny.gcode" in json.dumps(nb["cells"][1]["source"])
    assert (tmp_path / "tiny.notebook.html").stat().st_size > 10_000


# -- with Chromium and poppler ---------------------------------------------------------


def _need(tool: str, package: str) -> str:
    found = shutil.which(tool)
    if not found:
        pytest.skip(f"{tool} not found: apt-get install {package} (scripts/setup.sh does as root)")
    return found


def test_pdf_pages_are_not_blank_and_hold_the_plots(tmp_path):
    _need("chromium", "chromium")
    _need("pdftoppm", "poppler-utils")
    from PIL import Image

    row = report_program(EXAMPLES / "cube20_prusaslicer_marlin.gcode", tmp_path)
    assert row["error"] is None and row["pdf"]
    subprocess.run(["pdftoppm", "-r", "30", "-png", str(tmp_path / row["pdf"]), str(tmp_path / "page")], check=True)
    pages = sorted(tmp_path.glob("page-*.png"))
    assert len(pages) >= 3  # summary and views, layers and speed, breakdown and diagnostics
    inked, colourful = [], []
    for page in pages:
        rgb = np.asarray(Image.open(page).convert("RGB"), dtype=int)
        inked.append(np.mean(rgb.min(axis=2) < 230))  # anything not white
        colourful.append(np.mean(rgb.max(axis=2) - rgb.min(axis=2) > 60))  # plotted colour, not grey text
    assert min(inked) > 0.01, inked
    assert max(colourful) > 0.03, colourful  # the toolpath views and bar charts
    assert sum(c > 0.005 for c in colourful) >= 2


def test_pages_printed_one_after_another_each_show_their_own_text(tmp_path):
    _need("chromium", "chromium")
    pdftotext = _need("pdftotext", "poppler-utils")
    from gcodekit.report.pdf import html_to_pdf

    for k in (1, 2):
        (tmp_path / f"p{k}.html").write_text(f"<html><body><h1>page {k}</h1></body></html>")
    with pytest.raises(RuntimeError, match="could not open"):
        html_to_pdf(tmp_path / "missing.html", tmp_path / "missing.pdf")
    for k in (1, 2, 1):  # the browser's one tab, after an error and back to a page it printed
        html_to_pdf(tmp_path / f"p{k}.html", tmp_path / "out.pdf")
        text = subprocess.run([pdftotext, str(tmp_path / "out.pdf"), "-"], capture_output=True, text=True).stdout
        assert text.strip() == f"page {k}"


def _process_table() -> dict[int, tuple[int, str]]:
    """Every process: its parent and its state (``Z``: dead, not yet reaped)."""
    table = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()  # after the command's name
            except OSError:  # ended meanwhile
                continue
            table[int(entry.name)] = int(fields[1]), fields[0]
    return table


def _running(pids: list[int]) -> list[int]:
    table = _process_table()
    return [p for p in pids if p in table and table[p][1] not in "ZX"]


def _descendants(pid: int) -> list[int]:
    table, found, frontier = _process_table(), [], {pid}
    while frontier:
        frontier = {p for p, (parent, _) in table.items() if parent in frontier}
        found += frontier
    return found


def test_closing_the_browser_ends_every_chromium_process_and_removes_its_profile(tmp_path):
    _need("chromium", "chromium")
    from gcodekit.report.pdf import Browser

    (tmp_path / "p.html").write_text("<html><body><h1>page</h1></body></html>")
    browser = Browser()
    assert browser.print_pdf((tmp_path / "p.html").as_uri()).startswith(b"%PDF")
    helpers = _running(_descendants(browser._proc.pid))
    assert helpers  # its zygote and renderer
    profile = Path(browser._profile)
    browser.close()
    assert browser._proc.returncode is not None and not profile.exists()
    for _ in range(100):  # the helpers end by themselves once the browser is gone
        if not _running(helpers):
            break
        time.sleep(0.05)
    assert _running(helpers) == []


def test_chromium_prints_under_a_deep_temporary_folder(tmp_path, monkeypatch):
    _need("chromium", "chromium")
    from gcodekit.report.pdf import Browser

    deep = tmp_path / ("d" * 60)  # Chromium's socket path would be longer than a socket address takes
    deep.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(deep))
    (tmp_path / "p.html").write_text("<html><body><h1>page</h1></body></html>")
    browser = Browser()
    try:
        assert browser.print_pdf((tmp_path / "p.html").as_uri()).startswith(b"%PDF")
    finally:
        browser.close()
    assert list(deep.iterdir()) == []


def chromium_console(page: Path) -> tuple[list[str], str]:
    """Console messages Chromium logs while loading ``page``, and the DOM it ends with."""
    from gcodekit.report.pdf import chromium_command

    with tempfile.TemporaryDirectory() as profile:
        done = subprocess.run(chromium_command("--enable-logging=stderr", "--v=0", "--dump-dom", page.as_uri(),
                                               profile=profile), capture_output=True, text=True, timeout=120)
    return [line for line in done.stderr.splitlines() if ":CONSOLE" in line], done.stdout


def test_html_loads_in_chromium_without_console_errors(tmp_path, print_file):
    _need("chromium", "chromium")
    broken = tmp_path / "broken.html"
    broken.write_text("<html><body><script>console.error('boom'); nosuch();</script></body></html>")
    messages, _ = chromium_console(broken)
    assert any("boom" in m for m in messages) and any("nosuch" in m for m in messages)  # the probe hears errors

    rows = write_reports([print_file], tmp_path / "out", options=ReportOptions(pdf=False))
    for page in [tmp_path / "out" / "index.html"] + [tmp_path / "out" / r["html"] for r in rows]:
        messages, dom = chromium_console(page)
        assert messages == [], page.name
        assert re.search(r"<h1>[^<]+</h1>", dom)
        assert not re.search(r"""(src|href)=["']https?:""", dom)  # offline: nothing fetched from the network
