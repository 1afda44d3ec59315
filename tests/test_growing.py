"""Columns joined as the chunks come: ``growing.GrowingColumn``, ``parse.join.TableJoiner`` and ``WaypointJoiner``.

The reference is what joining every chunk at the end gives: ``np.concatenate``
of the chunks, and a zero-stride view of the first chunk's value when every
chunk is a zero-stride view of one value (equal, or NaN).
"""

from __future__ import annotations

import mmap
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gcodekit import growing
from gcodekit.errors import Diagnostics
from gcodekit.growing import GrowingColumn
from gcodekit.parse import GcodeParser
from gcodekit.parse.join import TableJoiner
from gcodekit.parse.table import CommandTable, DecimalColumn, SparseColumn
from gcodekit.columns import RunColumn, Waypoints
from gcodekit.pipeline.assemble import WaypointJoiner
from gcodekit.read import read_text
from gcodekit.syntax import load_flavor


def test_a_column_grows_past_its_first_capacity_without_losing_a_value():
    column = GrowingColumn(np.float64)
    pieces = [np.arange(k * 1000, (k + 1) * 1000, dtype=np.float64) for k in range(1500)]  # 12 MB > 4 MB first map
    for piece in pieces:
        column.append(piece)
    column.fill(-0.0, 3)
    out = column.finish()
    np.testing.assert_array_equal(out[:-3], np.arange(1_500_000, dtype=np.float64))
    assert np.signbit(out[-3:]).all() and out.dtype == np.float64 and out.flags.writeable
    assert len(column) == 0 and column.finish().size == 0


def test_a_wider_dtype_promotes_the_column_as_concatenate_would():
    column = GrowingColumn(np.int32)
    column.append(np.array([1, 2], np.int32))
    column.append(np.array([0.5]))
    out = column.finish()
    assert out.dtype == np.float64 and out.tolist() == [1.0, 2.0, 0.5]


def test_where_a_map_cannot_grow_the_column_copies(monkeypatch):
    class Fixed(mmap.mmap):
        def resize(self, size):
            raise SystemError("mmap: resizing not available--no mremap()")

    monkeypatch.setattr(growing.mmap, "mmap", Fixed)
    column = GrowingColumn(np.uint8)
    for k in range(10):
        column.append(np.full(1 << 20, k, np.uint8))
    out = column.finish()
    assert out.size == 10 << 20 and np.array_equal(np.unique(out), np.arange(10))


def _joined_at_the_end(parts: list[dict], sizes: list[int]) -> dict:
    """The reference: every chunk kept, then each column joined (the pipeline's way before WaypointJoiner)."""
    if len(parts) == 1:
        return parts[0]
    shift = np.cumsum([0] + sizes[:-1])
    return {key: np.concatenate([p[key] + np.int32(s) for p, s in zip(parts, shift)] if key == "command"
                                else [p[key] for p in parts]) for key in parts[0]}


def _bits(values) -> np.ndarray:
    return np.ascontiguousarray(values).view(np.uint8)  # -0.0 is not 0.0, NaN payloads count


values = st.sampled_from([0.0, -0.0, 1.5, np.nan, 2.0])
chunk = st.tuples(st.integers(0, 5), st.booleans(), values, values)  # size, constant?, its value, another


def _part(size: int, constant: bool, value: float, other: float) -> dict:
    z = np.broadcast_to(np.float64(value), (size,)) if constant and size else np.r_[np.full(size, value)[1:], other][:size]
    tool = np.broadcast_to(np.int32(3), (size,)) if size else np.empty(0, np.int32)
    return {"x": np.arange(size, dtype=np.float64) * other, "z": z, "tool": tool,
            "command": np.arange(size, dtype=np.int32)}


def _check_joined(got, expected: dict) -> None:
    """``got`` holds ``expected``'s columns bit for bit; a column of one value is a zero-stride view, one
    of few runs is stored as its runs."""
    assert list(got) == list(expected)
    for key in expected:
        kept = got.stored(key) if isinstance(got, Waypoints) else got[key]
        assert kept.dtype == expected[key].dtype and got[key].dtype == expected[key].dtype, key
        one_value = key != "command" and expected[key].size and np.unique(_bits(expected[key]).reshape(
            expected[key].size, -1), axis=0).shape[0] == 1
        if isinstance(got, Waypoints) and one_value:
            assert isinstance(kept, np.ndarray) and kept.strides == (0,), key
        assert isinstance(got[key], np.ndarray)
        np.testing.assert_array_equal(_bits(got[key]), _bits(expected[key]))


@settings(max_examples=300, deadline=None)
@given(st.lists(chunk, min_size=1, max_size=6), st.lists(st.integers(0, 4), min_size=6, max_size=6))
def test_waypoints_joined_as_they_come_are_the_ones_joined_at_the_end(chunks, extra_rows):
    parts = [_part(*c) for c in chunks]
    sizes = [p["command"].size + r for p, r in zip(parts, extra_rows)]  # rows: a chunk has comments too
    joiner = WaypointJoiner()
    for p, rows in zip(parts, sizes):
        joiner.add({k: v.copy() if v.strides != (0,) and v.size else v for k, v in p.items()}, rows)
    _check_joined(joiner.finish(), _joined_at_the_end(parts, sizes))


def test_waypoints_of_few_runs_are_kept_as_runs_and_of_many_as_arrays():
    """A print's feed (a few values, long runs) is kept as runs; positions (a new value each) as an array,
    also when the first chunks looked like runs; a column whose dtype changes becomes one array."""
    rng = np.random.default_rng(7)
    sizes, parts = [3000, 50_000, 50_000, 40_000], []
    for k, n in enumerate(sizes):
        parts.append({
            "x": np.zeros(n) if k == 0 else rng.normal(size=n),  # one value, then a new one each
            "feed": np.repeat(rng.choice([1800.0, 600.0, -0.0, 0.0, np.nan], size=n // 100 + 1), 100)[:n],
            "flow": np.broadcast_to(np.float32(0.5 if k < 3 else 0.25), (n,)),
            "tool": np.full(n, 1, np.int32) if k < 2 else np.full(n, 2, np.int64),
            "command": np.arange(n, dtype=np.int32)})
    joiner = WaypointJoiner()
    for p, n in zip(parts, sizes):
        joiner.add(p, n + 5)
    got, expected = joiner.finish(), _joined_at_the_end(parts, [n + 5 for n in sizes])
    assert isinstance(got, Waypoints)
    assert isinstance(got.stored("feed"), RunColumn) and isinstance(got.stored("flow"), RunColumn)
    assert got.stored("feed").nbytes < expected["feed"].nbytes / 50
    assert type(got.stored("x")) is np.ndarray and type(got.stored("tool")) is np.ndarray
    _check_joined(got, expected)


@pytest.mark.parametrize("n", [0, 1])
def test_no_chunk_or_one_chunk(n):
    joiner = WaypointJoiner()
    parts = [_part(3, True, 1.0, 2.0) for _ in range(n)]
    for p in parts:
        joiner.add(p, 3)
    out = joiner.finish()
    assert out == {} if n == 0 else out is parts[0]


def _tables_joined_at_the_end(parts: list[CommandTable]) -> CommandTable:
    """The reference: every chunk's table kept, then each column joined (the pipeline's way before TableJoiner),
    its dense words then stored as decimals where they can be."""
    if len(parts) == 1:
        return parts[0].compact().store_decimals()
    sizes = [len(p) for p in parts]
    shift = np.cumsum([0] + sizes[:-1])
    n = sum(sizes)
    params = {}
    for letter in sorted({k for p in parts for k in p.params}):
        cols = [p.params.get(letter) for p in parts]
        if all(c is None or isinstance(c, SparseColumn) for c in cols):
            params[letter] = SparseColumn(np.concatenate([c.rows + s for c, s in zip(cols, shift) if c is not None]),
                                          np.concatenate([c.values for c in cols if c is not None]), n)
        else:
            params[letter] = np.concatenate([np.full(size, np.nan) if c is None else (
                c.dense() if isinstance(c, SparseColumn) else c) for c, size in zip(cols, sizes)])
    offsets, base = [parts[0].comment_offsets], parts[0].comment_offsets[-1]
    for p in parts[1:]:
        offsets.append(p.comment_offsets[1:] + base)
        base += p.comment_offsets[-1]
    return CommandTable(
        **{name: np.concatenate([getattr(p, name) for p in parts])
           for name in ("line", "kind", "letter", "number", "name", "motion")},
        params=params,
        comment_rows=np.concatenate([p.comment_rows + s for p, s in zip(parts, shift)]),
        comment_offsets=np.concatenate(offsets), comment_data=b"".join(p.comment_data for p in parts),
        named={k + int(s): v for p, s in zip(parts, shift) for k, v in p.named.items()},
        texts={k + int(s): v for p, s in zip(parts, shift) for k, v in p.texts.items()},
        deleted=np.concatenate([p.deleted + s for p, s in zip(parts, shift)]),
        profiles={k + int(s): v for p, s in zip(parts, shift) for k, v in p.profiles.items()},
    ).compact().store_decimals()


# decimal words: X takes one place or none (its units scaled as chunks come), X300000000 passes int32 units at
# one place (the letter then floats), Y-0 cannot be a unit (-0.0), E0.125 needs three places
LINES = ["G1 X1.5 Y2 E0.1 F1200", "G1 X3 Y-0", "G0 Z0.3", "M104 S200", "; a comment", "M117 hello there",
         "/G1 X9 Y9", "T1", "G1 E-0.8 F2400", "G92 E0", "M106 S255 P1", "", "G4 P100 ; dwell",
         "G1 X300000000 E0.125", "G1 Y7.25 E2"]


class DecimalFields(NamedTuple):
    places: int
    units: np.ndarray


def _chunk_tables(chunks: list[list[int]], sparse: list[bool]) -> list[CommandTable]:
    parser = GcodeParser(load_flavor("marlin"), Diagnostics())
    tables = []
    for lines, compact in zip(chunks, sparse):
        table = parser.parse(read_text("".join(LINES[k] + "\n" for k in lines), "marlin"))
        tables.append(table.compact() if compact else table)  # a chunk's own sparse columns
    return tables


def _table_fields(t: CommandTable) -> dict:
    out = {name: np.asarray(getattr(t, name)) for name in
           ("line", "kind", "letter", "number", "name", "motion", "comment_rows", "comment_offsets", "deleted")}
    for letter, c in t.params.items():
        if isinstance(c, DecimalColumn):
            out[letter] = DecimalFields(c.places, c.units)
        else:
            out[letter] = (c.rows, c.values, c.size) if isinstance(c, SparseColumn) else c
    out.update(letters=list(t.params), data=t.comment_data, named=t.named, texts=t.texts, profiles=t.profiles)
    return out


@settings(max_examples=200, deadline=None)
@given(st.lists(st.lists(st.integers(0, len(LINES) - 1), max_size=8), min_size=1, max_size=5),
       st.lists(st.booleans(), min_size=5, max_size=5))
def test_tables_joined_as_they_come_are_the_ones_joined_at_the_end(chunks, sparse):
    joiner = TableJoiner()
    for table in _chunk_tables(chunks, sparse):
        joiner.add(table)
    got = _table_fields(joiner.finish())
    expected = _table_fields(_tables_joined_at_the_end(_chunk_tables(chunks, sparse)))
    assert got.keys() == expected.keys() and got["letters"] == expected["letters"]
    for key, value in expected.items():
        if isinstance(value, np.ndarray):
            assert got[key].dtype == value.dtype, key
            np.testing.assert_array_equal(got[key].view(np.uint8), value.view(np.uint8), err_msg=key)
        elif isinstance(value, DecimalFields):  # decimal units: the joiner's places grow as the chunks need
            assert isinstance(got[key], DecimalFields) and got[key].places == value.places, key
            assert np.array_equal(got[key].units, value.units), key
        elif isinstance(value, tuple):  # a sparse column
            assert isinstance(got[key], tuple) and got[key][2] == value[2], key
            for a, b in zip(got[key][:2], value[:2]):
                assert a.dtype == b.dtype and np.array_equal(a.view(np.uint8), b.view(np.uint8)), key
        else:
            assert got[key] == value, key
