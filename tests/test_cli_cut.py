"""Command line: ``gcodekit cut`` on the bundled mill example and the LinuxCNC corpus, and its bad input."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from cli_helpers import run
from shared_corpus import CORPUS

EXAMPLES = Path(__file__).parents[1] / "examples"
MILL = EXAMPLES / "bracket_mill.ngc"
TOOLS = EXAMPLES / "tools" / "bracket_mill.toml"
STOCK = "0,0,-10,60,40,0"


def test_bracket_json_matches_mesh_booleans(tmp_path, capsys):
    import test_cut_volumes as volumes

    import gcodekit
    from gcodekit.tool_shapes import ToolShape

    part = tmp_path / "part.stl"
    status, out, err = run(["cut", MILL, "--tools", TOOLS, "--stock", STOCK, "--json", "-o", part], capsys)
    assert status == 0, err
    record = json.loads(out)
    for key in ("stock_mm3", "removed_mm3", "remaining_mm3", "air_cut_s", "rapid_collisions"):
        assert key in record
    assert record["stock_mm3"] == pytest.approx(60 * 40 * 10)
    assert record["remaining_mm3"] == pytest.approx(record["stock_mm3"] - record["removed_mm3"])
    assert record["rapid_collisions"] == []
    assert record["tools"]["1"] == {"shape": "endmill", "diameter": 6.0, "length": 20.0}
    # the same moves through exact mesh booleans, intersected with the 60 x 40 x 10 plate
    op = gcodekit.gcode_to_operation(MILL)
    exact = volumes._manifold_removed(op, ToolShape("endmill", 6.0), stock=(0, 0, -10, 60, 40, 0))
    assert record["removed_mm3"] == pytest.approx(exact, rel=0.01)
    assert part.stat().st_size > 10_000


def test_text_output_and_no_overwrite(tmp_path, capsys):
    part = tmp_path / "part.vtp"
    status, out, _ = run(["cut", MILL, "--tools", TOOLS, "--stock", STOCK, "--resolution", "0.25", "-o", part],
                         capsys)
    assert status == 0
    assert "removed" in out and "air cuts" in out and str(part) in out
    status, _, err = run(["cut", MILL, "--tools", TOOLS, "--stock", STOCK, "-o", part], capsys)
    assert status == 2 and "use --force" in err


def test_without_tools_the_tool_is_named_and_cut_as_a_stated_end_mill(capsys):
    status, out, err = run(["cut", MILL, "--resolution", "0.5", "--json"], capsys)
    assert status == 0
    # named where it first cuts (line 10's move from the machine's start is not cut)
    assert "bracket_mill.ngc:12:1: warning: tool 1 has no shape in any tool file" in err
    assert "rapid move" not in err
    record = json.loads(out)
    assert record["tools"]["1"]["diameter"] == 6.0 and record["removed_mm3"] > 0


@pytest.mark.parametrize("args, words", [
    (["--stock", "1,2,3"], "give six numbers"),
    (["--stock", "0,0,0,-1,1,1"], "X0 < X1"),
    (["--resolution", "0"], "positive cell size"),
    (["--resolution", "-1"], "positive cell size"),
    (["--stock", STOCK, "--resolution", "0.00001"], "give a coarser resolution"),
    (["--tools", "no-such.toml"], "no such file: no-such.toml"),
    (["--tool-table", "no-such.tbl"], "no such file: no-such.tbl"),
    (["-o", "part.txt"], "a .vtp, .stl"),
    (["--stock", STOCK, "--stock-file", "x.stl"], "not both"),
])
def test_bad_arguments_are_one_clear_line(args, words, capsys):
    status, _, err = run(["cut", MILL, *args], capsys)
    assert status == 2
    assert words in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_bad_tools_file_names_file_table_and_key(tmp_path, capsys):
    tools = tmp_path / "TOOLS.toml"
    tools.write_text('[T1]\nshape = "endmill"\ndiameter = 0\n')
    status, _, err = run(["cut", MILL, "--tools", tools], capsys)
    assert status == 2 and f"{tools}: [T1]: a endmill's diameter must be a positive number" in err
    tools.write_text('[T1]\nshape = "endmill"\ndiameter = 6\nflute_length = 20\n')
    status, _, err = run(["cut", MILL, "--tools", tools], capsys)
    assert status == 2 and "[T1]: unknown key 'flute_length'" in err


def test_a_stock_the_program_never_touches_is_a_warning(capsys):
    status, out, err = run(["cut", MILL, "--tools", TOOLS, "--stock", "200,200,-10,260,240,0", "--json"], capsys)
    assert status == 0
    assert "never reaches the stock" in err
    assert json.loads(out)["removed_mm3"] == 0


def _corpus_programs():
    root = CORPUS / "linuxcnc"
    if not (root / "RESULTS.tsv").exists():
        return []
    overrides = {}
    for line in (root / "TOOLTABLE_OVERRIDES.tsv").read_text().splitlines():
        if line and not line.startswith("#"):
            name, table = line.split("\t")
            overrides[name] = table
    with open(root / "RESULTS.tsv", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f, delimiter="\t") if r["status"] == "ok"]
    return [(root / r["file"], root / overrides.get(r["file"], "tooltables/tool.tbl")) for r in rows
            if "lathe" not in r["file"]]


def test_corpus_3_axis_programs_cut_without_error(capsys):
    """Every LinuxCNC sample rs274 runs cleanly (lathe programs aside) cuts, with its tool table (inches)."""
    import gcodekit

    programs = _corpus_programs()
    if not programs:
        pytest.skip("the LinuxCNC corpus is not beside the repository")
    failures, cut = [], 0
    for program, table in programs:
        op = gcodekit.gcode_to_operation(program, machine="linuxcnc", tool_table=str(table),
                                         tool_table_units="inch")
        if any(abs(op.waypoints[a]).max() > 0 for a in "abc"):
            continue  # 4/5-axis programs: the height field only approximates them
        status, out, err = run(["cut", program, "--machine", "linuxcnc", "--tool-table", table,
                                "--tool-table-units", "inch", "--resolution", "0.25", "--json"], capsys)
        if status != 0 or "internal error" in err:
            failures.append(f"{program.name}: {status} {err.strip()[:300]}")
            continue
        record = json.loads(out)
        assert record["remaining_mm3"] <= record["stock_mm3"] + 1e-6
        cut += 1
    assert not failures, "\n".join(failures)
    assert cut > 80
