"""benchmarks/run_all.py: each benchmark's JSON (recorded from real ``--quick`` runs, in tests/bench_records/)
becomes rows of one table, written as markdown and JSON.  The figures are the recorded ones; what is checked
is the table: which rows, the ratios computed from the two sides, the targets and verdicts, the skips."""

import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RECORDS = Path(__file__).resolve().parent / "bench_records"


@pytest.fixture(scope="module")
def run_all():
    spec = importlib.util.spec_from_file_location("run_all", ROOT / "benchmarks" / "run_all.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["run_all"] = module
    spec.loader.exec_module(module)
    return module


def record(name: str):
    return json.loads((RECORDS / f"{name}.json").read_text())


def test_read_rows_put_gcodekit_beside_gcodeparser(run_all):
    r = record("read")
    peer, ours = run_all.read_rows(r)
    assert peer["tool"].startswith("gcodeparser") and peer["ratio"] is None
    gk, gp = r["summary"]["gcodekit"], r["summary"]["gcodeparser"]
    assert ours["seconds"] == gk["seconds"] and peer["seconds"] == gp["seconds"]
    assert ours["ratio"] == pytest.approx(gk["seconds"] / gp["seconds"])
    assert ours["target"] == "<= 0.4x gcodeparser"
    assert ours["pass"] is None and "binds on plate150" in ours["note"]  # a quick run on the cylinder


def test_plan_rows_give_the_time_ratio_and_bind_only_on_the_cylinder(run_all):
    r = record("plan")
    peer, ours = run_all.plan_rows(r)
    assert ours["ratio"] == pytest.approx(r["gcodekit"]["seconds"] / r["pygcodedecode"]["seconds"])
    assert ours["ratio"] == pytest.approx(1 / r["speedup"])
    assert ours["pass"] is None  # cube20: informative
    acceptance = {**r, "acceptance": True, "gcodekit": {**r["gcodekit"], "seconds": r["pygcodedecode"]["seconds"] / 60}}
    assert run_all.plan_rows(acceptance)[1]["pass"] is True  # 60x faster meets 50x
    acceptance["gcodekit"]["seconds"] = r["pygcodedecode"]["seconds"] / 40
    assert run_all.plan_rows(acceptance)[1]["pass"] is False


def test_scale_rows_compare_each_tool_with_the_loop_on_its_file(run_all):
    # the targets bind on plate150; these figures are made up for the test
    plate = "plate150_marlin2.gcode.gz"
    rows = [{"tool": "python_loop", "file": plate, "seconds": 10.0, "peak_mb": 20, "bytes_per_line": 7,
             "lines": 3_000_000},
            {"tool": "gcodekit marlin", "file": plate, "seconds": 4.0, "peak_mb": 400, "bytes_per_line": 140,
             "lines": 3_000_000},
            {"tool": "gcodekit klipper", "file": plate, "seconds": 6.0, "peak_mb": 420, "bytes_per_line": 140,
             "lines": 3_000_000}]
    loop, marlin, klipper = run_all.scale_rows({"rows": rows})
    assert loop["ratio"] is None and loop["pass"] is None
    assert marlin["ratio"] == pytest.approx(0.4) and marlin["pass"] is True
    assert klipper["ratio"] == pytest.approx(0.6) and klipper["pass"] is False
    assert run_all.scale_rows(rows)[1]["ratio"] == pytest.approx(0.4)  # a plain list too


def test_scale_rows_say_how_much_of_the_peak_is_the_runtime(run_all):
    # made-up figures: a 600 MB peak over 2**20 lines, 150 MB of it held with no program
    plate = "plate150_marlin2.gcode.gz"
    rows = [{"tool": "python_loop", "file": plate, "seconds": 10.0, "peak_mb": 20, "bytes_per_line": 20,
             "lines": 2**20, "runtime_mb": 12, "data_bytes_per_line": 8},
            {"tool": "gcodekit marlin", "file": plate, "seconds": 4.0, "peak_mb": 600, "bytes_per_line": 600,
             "lines": 2**20, "runtime_mb": 150, "data_bytes_per_line": 450}]
    loop, marlin = run_all.scale_rows(rows)
    assert marlin["note"] == "600 B/line (450 above the 150 MB runtime)"
    assert marlin["pass"] is False  # the target binds on the whole peak
    assert loop["note"] == "20 B/line"


def test_a_quick_scale_run_shows_its_ratios_without_binding(run_all):
    # bench_scale.py --quick's real record (the cylinder): ratios to the loop, no pass or fail
    loop, *ours = run_all.scale_rows(record("scale"))
    assert loop["tool"] == "python_loop" and loop["ratio"] is None
    for r in ours:
        assert r["ratio"] == pytest.approx(r["seconds"] / loop["seconds"])
        assert r["pass"] is None and r["note"].endswith("target binds on plate150")


def test_cut_and_additive_rows_have_no_peer(run_all):
    cut = run_all.cut_rows(record("cut"))
    assert [r["ratio"] for r in cut] == [None]
    assert cut[0]["pass"] is None and "100 k moves" in cut[0]["note"]  # the quick run's 10 k moves
    additive = run_all.additive_rows(record("additive"))
    assert [r["tool"] for r in additive] == ["read + emulate", "AdditivePart + layers", "VTK export (.vtp)"]
    assert additive[2]["seconds"] == record("additive")["best"]["vtk_s"]


def test_startup_report_and_widget_rows(run_all):
    startup = run_all.startup_rows(record("start-up"))
    by_tool = {r["tool"]: r for r in startup}
    info = by_tool["gcodekit info"]
    assert info["target"] == "<= 0.5 s" and info["pass"] == (info["seconds"] <= 0.5)
    assert by_tool["python -c pass"]["pass"] is None
    report = run_all.report_rows(record("report"))
    assert report[0]["target"] == "<= 10 s" and report[0]["file"] == "cylinder_marlin2.gcode"
    widgets = run_all.widgets_rows(record("widgets"))
    w = record("widgets")[0]
    assert widgets[1]["ratio"] == pytest.approx(w["shown_ms"] / w["peer_png_ms"])
    assert widgets[1]["pass"] == (w["shown_ms"] <= 150 and w["plot_ms"] <= 150)


def test_a_missing_peer_or_script_is_a_row_saying_so(run_all, tmp_path, monkeypatch):
    monkeypatch.setattr(run_all, "missing", lambda bench: ["gcodeparser"] if bench.needs else [])
    rows = run_all.run(run_all.Benchmark("read", "bench_read.py", run_all.read_rows, needs=("gcodeparser",)),
                       True, tmp_path)
    assert rows[0]["note"] == "skipped: gcodeparser missing; pip install -e '.[bench]'"
    rows = run_all.run(run_all.Benchmark("x", "bench_nothing_here.py", run_all.read_rows), True, tmp_path)
    assert "not in this checkout" in rows[0]["note"] and rows[0]["seconds"] is None


def test_the_table_is_written_as_markdown_and_json(run_all, tmp_path):
    rows = run_all.read_rows(record("read")) + run_all.cut_rows(record("cut"))
    rows.append(run_all.row("scale", "", "bench_scale.py", note="skipped: bench_scale.py is not in this checkout"))
    meta = {"date": "2026-12-03 23:00", "quick": True, "cpus": 2, "python": "3.11.7", "load_before": 2.0,
            "load_after": 3.5}
    md, js = run_all.write_table(rows, meta, tmp_path)
    lines = md.read_text().splitlines()
    assert lines[0].startswith("Measured 2026-12-03 23:00 (quick run), 2 CPUs") and "load average 2.0" in lines[0]
    assert lines[2] == "| benchmark | file | tool | seconds | peak MB | ratio to peer | target | result | note |"
    body = lines[4:]
    assert len(body) == len(rows)
    gk = record("read")["summary"]["gcodekit"]
    ratio = gk["seconds"] / record("read")["summary"]["gcodeparser"]["seconds"]
    assert body[1].split(" | ")[:7] == ["| read", "cylinder_marlin2.gcode", "gcodekit read + emulate",
                                         f"{gk['seconds']:.2f}", f"{gk['peak_mb']:.0f}", f"{ratio:.3g}x",
                                         "<= 0.4x gcodeparser"]
    assert body[-1] == "| scale |  | bench_scale.py |  |  |  |  |  | skipped: bench_scale.py is not in this checkout |"
    saved = json.loads(js.read_text())
    assert saved["rows"] == rows and saved["quick"] is True


def test_a_failed_target_shows_and_sets_the_exit_status(run_all, tmp_path, monkeypatch):
    failing = [run_all.row("report", "x.gcode", "gcodekit report", 40.0, None, None, "<= 30 s", False)]
    monkeypatch.setattr(run_all, "run", lambda bench, quick, folder: failing if bench.name == "report" else [])
    assert run_all.main(["--only", "report", "--out", str(tmp_path)]) == 1
    assert "| FAIL |" in (tmp_path / "benchmarks.md").read_text()


def test_the_mill_report_row_is_informative(run_all):
    # made-up figures: bench_report.py --mill's record beside the cylinder's
    rows = run_all.report_rows({"single": {"file": "cylinder_marlin2.gcode", "seconds": 2.0, "target_s": 10.0},
                                "mill": {"file": "surface_200k.ngc", "moves": 200_000, "seconds": 14.5}})
    assert [r["pass"] for r in rows] == [True, None]
    assert rows[1]["file"] == "mill surfacing, 200,000 moves" and rows[1]["seconds"] == 14.5
    assert rows[1]["target"] == "" and rows[1]["ratio"] is None
