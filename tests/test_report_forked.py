"""A report's pictures drawn in a forked child: the same page as drawn in one process, errors carried back."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import threading

import pytest
from test_report import MILL, tiny_print

from gcodekit.report import forked
from gcodekit.report.forked import Forked

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks on Linux only")

#: Writes a program's page drawn with a fork (which it checks happens) and in one process.
PAGES = """
import sys
from pathlib import Path
from gcodekit.report import ReportOptions, forked, report_program

program, out = Path(sys.argv[1]), Path(sys.argv[2])
assert forked.can_fork()
for name in ("forked", "one"):
    (out / name).mkdir()
    row = report_program(program, out / name, options=ReportOptions(pdf=False))
    assert row["error"] is None, row
    forked.can_fork = lambda: False
"""


@pytest.fixture
def fork_here(monkeypatch):
    """Fork even where this test process runs another thread (a Dask test's leaves one): the children of
    these tests touch no lock another thread could hold."""
    monkeypatch.setattr(forked, "can_fork", lambda: True)


@pytest.mark.parametrize("program", ["print", "mill"])
def test_forked_page_is_the_page_drawn_in_one_process(tmp_path, program):
    path = MILL if program == "mill" else tmp_path / "tiny.gcode"
    if program == "print":
        path.write_text(tiny_print(layers=4))
    # a fresh interpreter: one thread, as the command line has
    subprocess.run([sys.executable, "-c", PAGES, str(path), str(tmp_path)], check=True)
    pages = [re.sub(r"\d{4}-\d\d-\d\d \d\d:\d\d", "DATE", page.read_text())
             for page in sorted(tmp_path.glob("*/*.html"))]
    assert len(pages) == 2 and pages[0] == pages[1]
    assert pages[0].count("data:image/png;base64,") >= 3


def test_result_comes_from_another_process(fork_here):
    assert Forked(os.getpid).result() != os.getpid()


def test_without_fork_the_work_runs_here(monkeypatch):
    monkeypatch.setattr(forked, "can_fork", lambda: False)
    assert Forked(os.getpid).result() == os.getpid()


def test_no_fork_while_another_thread_runs():
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert not forked.can_fork()
        assert Forked(os.getpid).result() == os.getpid()
    finally:
        stop.set()
        other.join()


def test_an_error_in_the_child_is_raised_by_result(fork_here):
    def fails():
        raise ValueError("bad picture")

    with pytest.raises(ValueError, match="bad picture"):
        Forked(fails).result()


def test_an_error_that_does_not_pickle_comes_back_as_its_text(fork_here):
    class Local(Exception):  # a local class does not pickle
        pass

    def fails():
        raise Local("unpicklable")

    with pytest.raises(RuntimeError, match="unpicklable"):
        Forked(fails).result()


def test_a_child_that_dies_is_an_error(fork_here):
    with pytest.raises(RuntimeError, match="died"):
        Forked(lambda: os._exit(3)).result()


def test_a_child_still_drawing_is_ended_with_the_process(fork_here, monkeypatch):
    """The exit handlers (which a SIGTERM to the command runs) kill a child still at work, so that a stopped
    report leaves nothing running that holds its output open; a child waited for is not touched."""
    import signal
    import time

    done = Forked(lambda: 6 * 7)
    assert done.result() == 42 and not forked._running
    busy = Forked(lambda: time.sleep(60))
    assert forked._running == {busy._pid}
    reaped, waitpid = [], os.waitpid
    monkeypatch.setattr(os, "waitpid", lambda pid, flags: reaped.append(waitpid(pid, flags)) or reaped[-1])
    forked._end_children()
    ((pid, status),) = reaped
    assert pid == busy._pid and os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL
    assert not forked._running
