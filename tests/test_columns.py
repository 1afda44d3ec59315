"""Waypoint columns kept as runs (``gcodekit.columns``): read back as the arrays they stand for."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.columns import GatheredColumn, RunColumn, Waypoints, run_starts, stored

run_values = st.sampled_from([0.0, -0.0, 1.5, np.nan, 2.0, -7.25])
runs = st.lists(st.tuples(run_values, st.integers(1, 6)), min_size=1, max_size=12)


def _column(pairs) -> tuple[RunColumn, np.ndarray]:
    """The runs as a RunColumn and, the reference, as the array they stand for."""
    values = np.array([v for v, _ in pairs])
    lengths = np.array([n for _, n in pairs])
    starts = np.r_[0, np.cumsum(lengths)[:-1]].astype(np.int32)
    return RunColumn(starts, values, int(lengths.sum())), np.repeat(values, lengths)


def _same(a, b) -> None:
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype and a.shape == b.shape
    np.testing.assert_array_equal(np.ascontiguousarray(a).view(np.uint8), np.ascontiguousarray(b).view(np.uint8))


@settings(max_examples=200, deadline=None)
@given(runs, st.data())
def test_a_run_column_reads_as_its_array(pairs, data):
    col, dense = _column(pairs)
    n = dense.size
    assert len(col) == n and col.shape == (n,) and col.dtype == dense.dtype
    _same(np.asarray(col), dense)
    lo = data.draw(st.integers(-n - 2, n + 2))
    hi = data.draw(st.integers(-n - 2, n + 2))
    step = data.draw(st.sampled_from([None, 1, 2, -1]))
    _same(col[lo:hi:step], dense[lo:hi:step])
    k = data.draw(st.integers(-n, n - 1))
    _same(col[k], dense[k])
    near = data.draw(st.lists(st.integers(-n, n - 1), max_size=8))  # a few indices: the window path
    _same(col[np.array(near, np.int64)], dense[np.array(near, np.int64)])
    spread = np.array([0, n - 1] * 3 + [n // 2], np.int64)  # few indices far apart: the search path
    _same(col[spread], dense[spread])
    mask = np.array(data.draw(st.lists(st.booleans(), min_size=n, max_size=n)))
    _same(col[mask], dense[mask])


def test_bad_indices_are_refused_as_an_array_refuses_them():
    col, _ = _column([(1.0, 3), (2.0, 2)])
    for index in (5, -6):
        with pytest.raises(IndexError):
            col[index]
    with pytest.raises(IndexError):
        col[np.array([0, 5])]
    with pytest.raises(IndexError):
        col[np.ones(4, bool)]
    with pytest.raises(ValueError):
        RunColumn(np.array([1]), np.array([1.0]), 3)  # the first run must start at 0


def test_runs_begin_where_the_bits_change():
    values = np.array([0.0, 0.0, -0.0, np.nan, np.nan, 1.0, 1.0])
    assert run_starts(values).tolist() == [0, 2, 3, 5]
    assert run_starts(np.broadcast_to(3.0, (9,))).tolist() == [0]
    assert run_starts(np.empty(0)).tolist() == []


def test_waypoints_decode_a_column_once_and_keep_it():
    col, dense = _column([(600.0, 4), (1800.0, 3)])
    columns = {"feed": col, "x": np.arange(7.0)}
    w = Waypoints(columns)
    assert stored(w, "feed") is col and stored(columns, "feed") is col
    feed = w["feed"]
    _same(feed, dense)
    feed[0] = 1.0  # written into as any column: the write stays
    assert w["feed"] is feed and w["feed"][0] == 1.0 and stored(w, "feed") is feed
    w["power"] = np.zeros(7)
    assert list(w) == ["feed", "x", "power"] and "power" in columns  # the dict given is the one kept
    copy = w.copy()
    del copy["x"]
    assert "x" in w and "x" not in copy
    assert dict(w).keys() == {"feed", "x", "power"}


def test_an_operation_keeps_its_columns_in_waypoints():
    op = gcodekit.gcode_to_operation("G21\nG1 X10 F600\n", "linuxcnc", plan=False)
    assert isinstance(op.waypoints, Waypoints)
    op.waypoints = {"x": np.zeros(2)}
    assert isinstance(op.waypoints, Waypoints) and op.waypoints["x"].tolist() == [0.0, 0.0]


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(run_values, st.booleans()), min_size=1, max_size=30), st.data())
def test_a_gathered_column_reads_as_the_values_it_was_made_from(pairs, data):
    """``source[index]`` but at its own rows: the column it encodes, bit for bit, however read."""
    source = np.array([v for v, _ in pairs] + [3.0, -0.0])
    index = np.array(data.draw(st.lists(st.integers(0, source.size - 1), min_size=1, max_size=40)))
    column = source[index].copy()
    own = np.resize(np.array([flag for _, flag in pairs]), index.size)
    column[own] = 9.5  # moves that are not their waypoints' distance
    got = GatheredColumn.encode(column, source, index, most=1.0)
    assert isinstance(got, GatheredColumn) and got.rows.size == int(np.count_nonzero(
        np.ascontiguousarray(column).view(np.uint64) != np.ascontiguousarray(source[index]).view(np.uint64)))
    n = column.size
    _same(np.asarray(got), column)
    lo, hi = data.draw(st.integers(-n - 1, n + 1)), data.draw(st.integers(-n - 1, n + 1))
    _same(got[lo:hi], column[lo:hi])
    _same(got[::3], column[::3])
    k = data.draw(st.integers(-n, n - 1))
    _same(got[k], column[k])
    picks = np.array(data.draw(st.lists(st.integers(-n, n - 1), max_size=10)), np.int64)
    _same(got[picks], column[picks])
    mask = np.arange(n) % 2 == 0
    _same(got[mask], column[mask])


def test_a_column_mostly_its_own_is_kept_as_it_is():
    source, index = np.arange(10.0), np.arange(10)
    column = source + 1.0
    assert GatheredColumn.encode(column, source, index) is column  # every value its own: no gain
    assert GatheredColumn.encode(column, source.astype(np.float32), index) is column  # another dtype
    with pytest.raises(IndexError):
        GatheredColumn.encode(source.copy(), source, index)[10]
