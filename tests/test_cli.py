"""Command line: info (text and JSON), export, errors, progress bar."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from cli_helpers import run

from gcodekit import cli

EXAMPLES = Path(__file__).parents[1] / "examples"
MILL = EXAMPLES / "bracket_mill.ngc"
PRINT = EXAMPLES / "cube20_prusaslicer_marlin.gcode"


def test_info_json_has_the_documented_keys(capsys):
    status, out, _ = run(["info", PRINT, "--json"], capsys)
    record = json.loads(out)
    assert status == 0
    for key in ("file", "flavor", "machine", "lines", "moves", "bounds", "distance_mm", "time_s", "layers",
                "filament_mm", "diagnostics"):
        assert key in record
    assert record["flavor"] == "prusa" and record["layers"] == 100  # the file checks for an MK3S (M862.3)
    assert set(record["bounds"]) == {"min", "max"} and len(record["bounds"]["min"]) == 3
    assert set(record["distance_mm"]) == {"feed", "rapid", "extrude"}
    assert all({"line", "column", "severity", "message"} <= set(d) for d in record["diagnostics"])


def test_info_text_for_several_files(capsys):
    status, out, _ = run(["info", MILL, PRINT], capsys)
    assert status == 0
    assert "bracket_mill.ngc" in out and "cube20_prusaslicer_marlin.gcode" in out
    assert "rs274ngc" in out and "layers     100" in out


def test_export_csv_columns_and_no_overwrite(tmp_path, capsys):
    target = tmp_path / "moves.csv"
    status, _, _ = run(["export", MILL, "--to", "csv", "-o", target], capsys)
    assert status == 0
    header = target.read_text().splitlines()[0].split(",")
    assert header[:13] == ["line", "motion", "x", "y", "z", "a", "b", "c", "feed", "cx", "cy", "cz", "plane"]
    status, _, err = run(["export", MILL, "--to", "csv", "-o", target], capsys)
    assert status == 2 and "--force" in err


def test_errors_are_one_clear_line(capsys):
    status, _, err = run(["info", "no/such/file.gcode"], capsys)
    assert status == 2 and err.startswith("gcodekit: error: no such file")
    status, _, err = run(["info", MILL, "--machine", "linuxcnk"], capsys)
    assert status == 2 and "did you mean 'linuxcnc'" in err


def test_strict_mode_reports_the_location(tmp_path, capsys):
    bad = tmp_path / "bad.ngc"
    bad.write_text("G21\nG1 X1 X2 F100\n")
    status, _, err = run(["info", bad, "--strict"], capsys)
    assert status == 1 and f"{bad}:2:7" in err


def test_progress_bar_on_a_terminal(tmp_path, monkeypatch):
    big = tmp_path / "big.gcode"
    big.write_text(PRINT.read_text() * 14)  # > 2 MB, so the bar shows
    stderr = io.StringIO()
    stderr.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr("sys.stderr", stderr)
    monkeypatch.setattr("sys.stdout", io.StringIO())
    assert cli.main(["info", str(big)]) == 0
    assert "B/s" in stderr.getvalue() or "%|" in stderr.getvalue()


def test_translate_writes_plain_gcode(tmp_path, capsys):
    target = tmp_path / "plain.ngc"
    status, _, _ = run(["translate", MILL, "--stage", "6", "-o", target], capsys)
    assert status == 0
    body = [line for line in target.read_text().splitlines() if not line.startswith("(")]
    assert body[0] == "G21"  # the output names its units
    assert body[1:] and all(line.split()[1] in ("G0", "G1", "G2", "G3", "G4", "M2", "M3", "M5", "M6", "M8", "M9",
                                                "M30") for line in body[1:])


def test_a_bug_is_told_apart_from_bad_input(capsys, monkeypatch):
    """An exception gcodekit does not expect is an internal error (status 3), never 'bad input'."""
    import gcodekit.pipeline

    def broken(*args, **kwargs):
        raise ValueError("an invariant did not hold")

    monkeypatch.setattr(gcodekit.pipeline, "gcode_to_operation", broken)
    status, _, err = run(["info", MILL], capsys)
    assert status == cli.EXIT_INTERNAL == 3
    assert err.startswith("gcodekit: internal error: ValueError: an invariant did not hold")
    assert f"gcodekit {gcodekit.__version__}" in err and "--debug" in err and "Traceback" not in err
    status, _, err = run(["info", MILL, "--debug"], capsys)
    assert status == 3 and "Traceback (most recent call last)" in err and 'raise ValueError("an invariant' in err


def test_bad_input_and_bad_arguments_have_their_own_statuses(tmp_path, capsys):
    status, _, err = run(["render", MILL, "-o", tmp_path / "x.png", "--size", "3"], capsys)
    assert status == cli.EXIT_USAGE and "--size '3'" in err and "internal" not in err
    bad = tmp_path / "bad.ngc"
    bad.write_text("G21\nG2 X10 Y0 R1 F100\nM2\n")
    status, _, err = run(["export", bad, "--to", "csv", "--strict"], capsys)
    assert status == cli.EXIT_PROGRAM_ERROR and f"{bad}:2:" in err


def test_version_prints_the_package_version(capsys):
    import pytest

    import gcodekit

    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"gcodekit {gcodekit.__version__}"


def _command(*args, **options) -> subprocess.CompletedProcess:
    """``gcodekit ARGS`` in a fresh interpreter, through the console script's entry point (:func:`cli.run`)."""
    return subprocess.run([sys.executable, "-m", "gcodekit.cli", *map(str, args)], capture_output=True, text=True,
                          **options)


def test_the_command_flushes_its_output_and_exits_with_its_status(tmp_path):
    done = _command("info", PRINT, "--json")
    assert done.returncode == 0 and json.loads(done.stdout)["file"] == str(PRINT)  # the whole record, flushed
    bad = tmp_path / "bad.ngc"
    bad.write_text("G21\nG2 X10 Y0 R1 F100\nM2\n")
    done = _command("info", bad, "--strict")
    assert done.returncode == cli.EXIT_PROGRAM_ERROR and f"{bad}:2:" in done.stderr
    assert _command("--version").stdout.strip().startswith("gcodekit ")  # argparse's own exit


def test_a_reader_that_has_gone_gets_no_traceback():
    with subprocess.Popen([sys.executable, "-m", "gcodekit.cli", "info", MILL, "--json"],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE) as proc:
        proc.stdout.close()  # gone before the command writes a byte, as ``| true`` is
        err = proc.stderr.read().decode()
    assert proc.returncode == 0 and err == ""


def test_the_report_command_ends_its_chromium_and_leaves_no_profile(tmp_path):
    import pytest

    if not shutil.which("chromium"):
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    temp = Path(tempfile.mkdtemp(prefix="t", dir="/tmp"))  # short: the browser's profile is made in it
    try:
        done = _command("report", PRINT, "-o", tmp_path / "out", "--no-progress",
                        env={**os.environ, "TMPDIR": str(temp)})
        assert done.returncode == 0, done.stderr
        assert (tmp_path / "out" / f"{PRINT.name}.pdf").stat().st_size > 10_000
        assert list(temp.iterdir()) == []  # the exit handlers ran: the profile and Chromium's own files are gone
    finally:
        shutil.rmtree(temp)


def test_a_terminated_report_ends_its_chromium_and_leaves_no_profile(tmp_path):
    import signal
    import time

    import pytest

    if not shutil.which("chromium"):
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    big = tmp_path / "big.gcode"  # long enough to read that the signal comes while the report is made
    big.write_text("G21\nG90\nM83\n" + "G1 X10 Y0 E0.1 F1800\nG1 X10 Y10 E0.1\nG1 X0 Y10 E0.1\nG1 X0 Y0 E0.1\n"
                   * 250_000)
    temp = Path(tempfile.mkdtemp(prefix="t", dir="/tmp"))  # short: the browser's profile is made in it
    try:
        with subprocess.Popen([sys.executable, "-m", "gcodekit.cli", "report", str(big), "-o", str(tmp_path / "out"),
                               "--no-progress"], env={**os.environ, "TMPDIR": str(temp)},
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE) as proc:
            for _ in range(600):  # Chromium is started as the command begins
                if list(temp.glob("gcodekit-chromium-*")) or proc.poll() is not None:
                    break
                time.sleep(0.05)
            assert proc.poll() is None, "the report ended before it could be stopped"
            proc.send_signal(signal.SIGTERM)
            proc.communicate(timeout=60)
        assert proc.returncode == 128 + signal.SIGTERM
        assert list(temp.iterdir()) == []  # the exit handlers ran: Chromium's profile is gone
    finally:
        shutil.rmtree(temp)


def test_a_report_terminated_while_its_forked_child_draws_leaves_nothing_running(tmp_path):
    """The SIGTERM comes once the report has forked the child that draws its pictures: the command ends it
    too, so nothing holds the command's output open (before, the child drew on for a minute, orphaned)."""
    import signal
    import time

    import pytest

    if not sys.platform.startswith("linux"):
        pytest.skip("reports fork on Linux only")
    big = tmp_path / "big.gcode"
    big.write_text("G21\nG90\nM83\n" + "G1 X10 Y0 E0.1 F1800\nG1 X10 Y10 E0.1\nG1 X0 Y10 E0.1\nG1 X0 Y0 E0.1\n"
                   * 250_000)
    with subprocess.Popen([sys.executable, "-m", "gcodekit.cli", "report", str(big), "-o", str(tmp_path / "out"),
                           "--no-progress", "--no-pdf"], stdout=subprocess.PIPE, stderr=subprocess.PIPE) as proc:
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children")
        child = None
        while proc.poll() is None and child is None:  # the forked child: a python process of the command's
            child = next((k for k in children.read_text().split()
                          if b"python" in Path(f"/proc/{k}/cmdline").read_bytes()), None)
            time.sleep(0.02)
        assert child is not None, "the report ended before it forked"
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=60)  # returns once no process holds the output: the child is gone too
    assert proc.returncode == 128 + signal.SIGTERM
    assert not Path(f"/proc/{child}").exists()


@pytest.mark.parametrize("environment, advice", [({}, False), ({"NUMPY_MADVISE_HUGEPAGE": "1"}, True)])
def test_the_command_turns_numpy_s_huge_page_advice_off_unless_the_environment_chose(environment, advice):
    """The command (``cli.run``) sets NUMPY_MADVISE_HUGEPAGE=0 before NumPy is imported, so NumPy in the
    command and its children gives the kernel no huge-page advice; a value the user set is kept."""
    probe = ("import gcodekit.cli as cli, sys; assert 'numpy' not in sys.modules; cli._without_huge_page_advice(); "
             "import numpy; print(numpy._core.multiarray._set_madvise_hugepage(True))")
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"} | environment
    done = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == str(advice)
