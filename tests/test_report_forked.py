"""A report's pictures drawn in a forked child: the same page as drawn in one process, errors carried back."""

from __future__ import annotations

import os
import re
import threading
from pathlib import Path

import pytest
from test_report import MILL, tiny_print

from gcodekit.report import ReportOptions, forked, report_program
from gcodekit.report.forked import Forked

pytestmark = pytest.mark.skipif(not forked.can_fork(), reason="forks on Linux only, from a single thread")


def _page(path: Path, out: Path) -> str:
    out.mkdir()
    row = report_program(path, out, options=ReportOptions(pdf=False))
    assert row["error"] is None
    return re.sub(r"\d{4}-\d\d-\d\d \d\d:\d\d", "DATE", (out / row["html"]).read_text())


def _in_one_process(monkeypatch) -> None:
    monkeypatch.setattr(forked, "can_fork", lambda: False)


@pytest.mark.parametrize("program", ["print", "mill"])
def test_forked_page_is_the_page_drawn_in_one_process(tmp_path, monkeypatch, program):
    path = MILL if program == "mill" else tmp_path / "tiny.gcode"
    if program == "print":
        path.write_text(tiny_print(layers=4))
    forked_page = _page(path, tmp_path / "forked")
    _in_one_process(monkeypatch)
    assert _page(path, tmp_path / "one") == forked_page
    assert forked_page.count("data:image/png;base64,") >= 3


def test_result_comes_from_another_process():
    assert Forked(os.getpid).result() != os.getpid()


def test_without_fork_the_work_runs_here(monkeypatch):
    _in_one_process(monkeypatch)
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


def test_an_error_in_the_child_is_raised_by_result():
    def fails():
        raise ValueError("bad picture")

    with pytest.raises(ValueError, match="bad picture"):
        Forked(fails).result()


def test_an_error_that_does_not_pickle_comes_back_as_its_text():
    class Local(Exception):  # a local class does not pickle
        pass

    def fails():
        raise Local("unpicklable")

    with pytest.raises(RuntimeError, match="unpicklable"):
        Forked(fails).result()


def test_a_child_that_dies_is_an_error():
    with pytest.raises(RuntimeError, match="died"):
        Forked(lambda: os._exit(3)).result()
