"""Reading ahead on a second thread gives the serial reader's result, diagnostics in the same order.

``read.ahead.read_ahead`` runs a producer on another thread and replays its
reports where the serial reader would have made them; the pipeline uses it
for program files from ``pipeline.source.READ_AHEAD_BYTES`` on.
"""

from __future__ import annotations

import gzip
import threading

import numpy as np
import pytest
from shared_corpus import CORPUS

import gcodekit
import gcodekit.pipeline.source
from gcodekit.errors import Diagnostics, GcodeError
from gcodekit.read.ahead import read_ahead


def counting(n: int, fail_at: int | None = None, closed: list | None = None):
    """A producer of ``n`` items that reports one warning before each (an error before ``fail_at``)."""
    def produce(diagnostics):
        try:
            for k in range(n):
                severity = "error" if k == fail_at else "warning"
                diagnostics.report(k + 1, 1, f"before item {k}", severity=severity)
                yield k, threading.current_thread().name
            diagnostics.warn(n + 1, 1, "after the last item")
        finally:
            if closed is not None:
                closed.append(True)
    return produce


def consume(items, diagnostics: Diagnostics) -> list[str]:
    """The consumer's view: the messages it finds as it takes each item, and its own report per item."""
    seen = []
    for k, _ in items:
        seen.append(diagnostics.items[-1].message)
        diagnostics.warn(1000 + k, 1, f"consumer took item {k}")
    return seen + [diagnostics.items[-1].message]


def test_items_and_reports_arrive_in_the_serial_order():
    serial, ahead = Diagnostics("p.gcode"), Diagnostics("p.gcode")
    assert consume(counting(5)(serial), serial) == consume(read_ahead(counting(5), ahead, depth=2), ahead)
    assert [(d.line, d.message, d.severity) for d in serial] == [(d.line, d.message, d.severity) for d in ahead]
    assert [d.message for d in ahead][:3] == ["before item 0", "consumer took item 0", "before item 1"]
    assert ahead.items[-1].message == "after the last item" and len(ahead) == 11


def test_the_producer_runs_on_another_thread():
    names = {name for _, name in read_ahead(counting(3), Diagnostics())}
    assert names == {"gcodekit-read-ahead"}


def test_strict_mode_raises_at_the_item_the_serial_reader_raised():
    taken = []
    strict = Diagnostics("p.gcode", "strict")
    with pytest.raises(GcodeError, match="p.gcode:3:1: error: before item 2"):
        for k, _ in read_ahead(counting(10, fail_at=2), strict):
            taken.append(k)
    assert taken == [0, 1]


def test_an_error_of_the_producer_is_raised_on_the_consumer_after_the_items_before_it():
    def produce(diagnostics):
        yield 1
        yield 2
        raise ValueError("broken source")
    taken = []
    with pytest.raises(ValueError, match="broken source"):
        for item in read_ahead(produce, Diagnostics()):
            taken.append(item)
    assert taken == [1, 2]


def test_a_producer_that_fails_before_its_first_item_fails_the_consumer_instead_of_hanging_it():
    def produce(diagnostics):
        raise OSError("cannot open the program")

    with pytest.raises(OSError, match="cannot open the program"):
        next(read_ahead(produce, Diagnostics()))


def test_a_consumer_that_stops_early_stops_the_producer_and_closes_its_source():
    closed: list = []
    before = {t.ident for t in threading.enumerate()}
    items = read_ahead(counting(1000, closed=closed), Diagnostics())
    assert next(items)[0] == 0
    items.close()
    assert closed == [True]
    assert not [t for t in threading.enumerate() if t.ident not in before and t.name == "gcodekit-read-ahead"]


def _read(path, ahead: bool, monkeypatch, **options):
    monkeypatch.setattr(gcodekit.pipeline.source, "READ_AHEAD_BYTES", 0 if ahead else 1 << 62)
    return gcodekit.gcode_to_operation(path, **options)


def _same(a, b) -> None:
    assert len(a.table) == len(b.table)
    for name in ("line", "kind", "letter", "number", "name", "motion"):
        np.testing.assert_array_equal(getattr(a.table, name), getattr(b.table, name))
    assert sorted(a.table.params) == sorted(b.table.params)
    for key in a.waypoints:
        np.testing.assert_array_equal(np.asarray(a.waypoints[key]), np.asarray(b.waypoints[key]), err_msg=key)
    assert [(d.file, d.line, d.column, d.severity, d.message) for d in a.diagnostics] == \
        [(d.file, d.line, d.column, d.severity, d.message) for d in b.diagnostics]


REALWORLD = sorted((CORPUS / "realworld").glob("*.*[!d]")) if CORPUS.is_dir() else []


@pytest.mark.skipif(not REALWORLD, reason="the shared corpus is not here")
@pytest.mark.parametrize("path", REALWORLD, ids=lambda p: p.name)
def test_a_program_read_ahead_is_the_program_read_serially(path, monkeypatch):
    """The programs of other slicers, CAM posts and laser tools (several with diagnostics), read both ways."""
    _same(_read(path, False, monkeypatch, plan=False), _read(path, True, monkeypatch, plan=False))


def test_a_large_program_with_problems_throughout_reads_the_same_ahead(tmp_path, monkeypatch):
    """Several compiled chunks (over 2 MB each), bad words and a truncated end, diagnostics in order."""
    lines = []
    for k in range(400_000):
        lines.append(f"G1 X{k % 200}.5 Y{k % 170}.25 E0.0{k % 9} F1800\n")
        if k % 50_000 == 7:
            lines.append(f"G1 X{k} $\n")  # the reader's error at this line
        if k % 70_000 == 3:
            lines.append(f"G1 X1 *{k % 100}\n")  # a wrong checksum: a warning
    data = gzip.compress("".join(lines).encode())
    path = tmp_path / "big.gcode.gz"
    path.write_bytes(data[: len(data) - 5000])
    serial = _read(path, False, monkeypatch, machine="marlin", plan=False)
    ahead = _read(path, True, monkeypatch, machine="marlin", plan=False)
    assert len(serial.diagnostics.errors) == 9 and "truncated" in serial.diagnostics.items[-1].message
    _same(serial, ahead)
