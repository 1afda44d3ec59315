"""Columns kept compactly (as runs of equal values, or as another column's values) and the mapping that gives
them as arrays.

A large print's feed rate, layer height and flow change a few thousand
times over millions of waypoints.  Stored as their runs (where each run
starts, and its value: :class:`RunColumn`), such a column takes a few
hundred kilobytes instead of 25 MB; a plan's move lengths are mostly their
waypoints' distances (:class:`GatheredColumn` keeps the exceptions).
Both, and the decimal units and planned times stored elsewhere, are read
as arrays through :class:`ColumnReader`.
:class:`Waypoints` is the mapping an operation keeps its columns in:
reading a column gives it as an array, decoded on the first read and kept
so from then on; :meth:`Waypoints.stored` gives what is stored, which a
planner reads a block of moves at a time without decoding the whole
column.  Values come back bit for bit (runs are compared by their bits:
``-0.0`` and each NaN are their own values).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, MutableMapping
from typing import Union

import numpy as np

from .growing import GrowingColumn

__all__ = ["ColumnReader", "RunColumn", "GatheredColumn", "GrowingRuns", "Waypoints", "Column", "stored", "same_bits", "run_starts"]


class ColumnReader:
    """What a column stored another way shares: indexed like the 1-D array of ``size`` values of ``dtype`` it
    stands for, and given whole by ``np.asarray``.

    A subclass gives :meth:`window` (the values ``lo`` to ``hi - 1``) and,
    where it can gather indices without the whole column, :meth:`_take`.
    """

    size: int
    dtype: np.dtype

    @property
    def shape(self) -> tuple[int]:
        return (self.size,)

    @property
    def ndim(self) -> int:
        return 1

    def __len__(self) -> int:
        return self.size

    def window(self, lo: int, hi: int) -> np.ndarray:
        raise NotImplementedError

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        out = self.window(0, self.size)
        return out if dtype is None else out.astype(dtype, copy=False)

    def __getitem__(self, index) -> np.ndarray | np.generic:
        if isinstance(index, slice):
            lo, hi, step = index.indices(self.size)
            return self.window(lo, hi) if step == 1 else np.asarray(self)[index]
        if isinstance(index, (int, np.integer)):
            k = int(index) + (self.size if index < 0 else 0)
            if not 0 <= k < self.size:
                raise IndexError(f"index {int(index)} is out of bounds for a column of {self.size}")
            return self.window(k, k + 1)[0]
        return self._take(np.asarray(index))

    def _take(self, index: np.ndarray) -> np.ndarray:
        """The values at ``index`` (indices or a mask), as the array would give them."""
        return np.asarray(self)[index]

    def _indices(self, index: np.ndarray) -> np.ndarray:
        """``index`` as indices from 0 (a mask's places, negative ones counted from the end), checked."""
        if index.dtype == bool:
            if index.shape != self.shape:
                raise IndexError(f"a mask of {index.shape} for a column of {self.size}")
            index = np.flatnonzero(index)
        index = np.where(index < 0, index + self.size, index)
        if index.size and (int(index.min()) < 0 or int(index.max()) >= self.size):
            raise IndexError(f"indices out of bounds for a column of {self.size}")
        return index


class RunColumn(ColumnReader):
    """A column of ``size`` values stored as runs: run ``k`` holds ``values[k]`` from ``starts[k]`` on.

    Indexed like a 1-D array (an int, a slice of step 1, indices or a
    mask), it gives float or int values as an array would;
    ``np.asarray`` gives the whole column.

    Examples
    --------
    >>> col = RunColumn(np.array([0, 3]), np.array([1.5, 2.0]), 5)
    >>> np.asarray(col).tolist(), col[2:4].tolist(), col[[4, 0]].tolist()
    ([1.5, 1.5, 1.5, 2.0, 2.0], [1.5, 2.0], [2.0, 1.5])
    """

    def __init__(self, starts: np.ndarray, values: np.ndarray, size: int):
        if starts.size != values.size or (size and (starts.size == 0 or starts[0] != 0)):
            raise ValueError("runs need one value each, the first starting at 0")
        self.starts, self.values, self.size = starts, values, int(size)

    @classmethod
    def of_runs(cls, starts: np.ndarray, values: np.ndarray, size: int) -> "Column":
        """The column of these runs: a zero-stride view of a lone value (no view of ``values``), else a
        RunColumn (its starts as int32 when they fit)."""
        if values.size == 1:
            return np.broadcast_to(values[0], (size,))
        return cls(starts.astype(np.int32) if size < 2**31 else starts, values, size)

    @classmethod
    def encode(cls, values: np.ndarray, min_values_per_run: int = 8) -> "Column":
        """``values`` as runs when each run holds ``min_values_per_run`` values on average (a zero-stride view
        for a lone value), else the array itself."""
        starts = run_starts(values)
        if values.size == 0 or (starts.size > 1 and starts.size * min_values_per_run > values.size):
            return values
        return cls.of_runs(starts, values[starts], values.size)

    @property
    def dtype(self) -> np.dtype:
        return self.values.dtype

    @property
    def nbytes(self) -> int:
        """The memory the runs take (an array of the values would take ``size * itemsize``)."""
        return int(self.starts.nbytes + self.values.nbytes)

    def __repr__(self) -> str:
        return f"RunColumn({self.size} values in {self.values.size} runs, {self.dtype})"

    def _lengths(self, lo: int, hi: int) -> tuple[int, np.ndarray]:
        """The first run reaching into ``[lo, hi)`` and how many of its values each run from it gives."""
        first, last = np.searchsorted(self.starts, np.array((lo, hi), self.starts.dtype), side="right") - 1
        bounds = np.clip(np.r_[self.starts[first + 1:last + 1], hi], lo, hi)
        return int(first), np.diff(np.r_[lo, bounds])

    def window(self, lo: int, hi: int) -> np.ndarray:
        """The values ``lo`` to ``hi - 1`` as an array."""
        hi = max(hi, lo)
        if hi == lo:
            return np.empty(0, self.dtype)
        first, lengths = self._lengths(lo, hi)
        return np.repeat(self.values[first:first + lengths.size], lengths)

    def _take(self, index: np.ndarray) -> np.ndarray:
        index = self._indices(index)
        if index.size == 0:
            return np.empty(index.shape, self.dtype)
        lo, hi = int(index.min()), int(index.max()) + 1
        if hi - lo <= 4 * index.size:  # a block of nearby indices: the window, then gathered
            return self.window(lo, hi)[index - lo]
        return self.values[np.searchsorted(self.starts, index, side="right") - 1]


class GatheredColumn(ColumnReader):
    """A column that repeats another at given places but for a few: ``source[index]``, with ``values`` at
    ``rows`` (sorted) instead.

    A plan's move lengths are their waypoints' distances but where a move is
    a chord of an arc or moves the extruder alone: kept so, they cost the
    exceptions alone.  Indexed like a 1-D array; ``np.asarray`` gives it whole.
    """

    def __init__(self, source: np.ndarray, index: np.ndarray, rows: np.ndarray, values: np.ndarray):
        self.source, self.index, self.rows, self.values = source, index, rows, values

    @classmethod
    def encode(cls, column: np.ndarray, source: np.ndarray, index: np.ndarray, most: float = 1 / 8,
               block: int = 1 << 16) -> "Column | GatheredColumn":
        """``column`` as ``source`` at ``index`` (compared bit for bit, a block at a time), or ``column`` itself
        where more than a fraction ``most`` of it differs."""
        if not (isinstance(source, np.ndarray) and source.dtype == column.dtype and index.size == column.size):
            return column
        rows, own = [], 0
        for lo in range(0, column.size, block):
            differ = np.flatnonzero(bits(column[lo:lo + block]) != bits(source[index[lo:lo + block]]))
            rows.append(differ + lo)
            own += differ.size
            if own > most * column.size:
                return column
        rows = np.concatenate(rows) if rows else np.zeros(0, np.int64)
        return cls(source, index, rows, column[rows])

    @property
    def size(self) -> int:
        return int(self.index.size)

    @property
    def dtype(self) -> np.dtype:
        return self.source.dtype

    @property
    def nbytes(self) -> int:
        """What it holds of its own (the index and the source are the plan's and the waypoints')."""
        return int(self.rows.nbytes + self.values.nbytes)

    def __repr__(self) -> str:
        return f"GatheredColumn({self.size} values, {self.rows.size} of their own)"

    def window(self, lo: int, hi: int) -> np.ndarray:
        """The values ``lo`` to ``hi - 1`` as an array."""
        hi = max(hi, lo)
        out = self.source[self.index[lo:hi]]
        first, last = np.searchsorted(self.rows, (lo, hi))
        out[self.rows[first:last] - lo] = self.values[first:last]
        return out

    def _take(self, index: np.ndarray) -> np.ndarray:
        index = self._indices(index)
        out = self.source[self.index[index]]
        at = np.minimum(np.searchsorted(self.rows, index), max(self.rows.size - 1, 0))
        own = (self.rows[at] == index) if self.rows.size else np.zeros(index.shape, bool)
        out[own] = self.values[at[own]]
        return out


#: What a column may be stored as (besides decimal units, :class:`gcodekit.parse.table.DecimalColumn`, and a
#: plan's times, :class:`gcodekit.plan.times.PlannedTimes`, which read as these do).
Column = Union[np.ndarray, RunColumn, GatheredColumn]


def bits(values: np.ndarray) -> np.ndarray:
    """The values' bit patterns as unsigned integers (a float's ``-0.0`` and NaN payloads kept apart)."""
    values = np.ascontiguousarray(values)
    return values.view(f"u{values.dtype.itemsize}") if values.dtype.kind in "fiub" else values


def same_bits(a: np.generic, b: np.generic) -> bool:
    """Whether two values of one dtype are the same bit for bit."""
    return bool(bits(np.array([a]))[0] == bits(np.array([b], dtype=np.asarray(a).dtype))[0])


def run_starts(values: np.ndarray) -> np.ndarray:
    """Where each run of bitwise equal values begins (0 first), for a 1-D array with values."""
    if values.strides == (0,) or values.size < 2:
        return np.zeros(min(values.size, 1), np.int64)
    b = bits(values)
    return np.r_[0, np.flatnonzero(b[1:] != b[:-1]) + 1]


class GrowingRuns:
    """A column's runs of bitwise equal values, appended chunk by chunk while there are few of them.

    :meth:`add` refuses a chunk (and takes nothing) once the runs would be
    too many to be worth keeping: the caller then keeps an array instead.
    """

    #: Kept as runs while there are at most this many values per run on average (or a few runs in all)
    MIN_VALUES_PER_RUN = 8
    FEW_RUNS = 1024

    def __init__(self, dtype: np.dtype):
        self.dtype = np.dtype(dtype)
        self.starts = GrowingColumn(np.int64)
        self.values = GrowingColumn(self.dtype)
        self.size = 0

    def add(self, col: np.ndarray) -> bool:
        """Take the chunk's values as runs; False (nothing taken) when the column has too many runs for that,
        or the chunk's dtype is not the column's."""
        if col.dtype != self.dtype:
            return False
        starts = run_starts(col)
        n_runs = len(self.values) + starts.size
        if n_runs > self.FEW_RUNS and n_runs * self.MIN_VALUES_PER_RUN > self.size + col.size:
            return False
        if starts.size and len(self.values) and same_bits(self.values.values()[-1], col[0]):
            starts = starts[1:]  # the chunk goes on with the last run's value
        self.starts.append(starts + self.size)
        self.values.append(col[starts])
        self.size += col.size
        return True

    def finish(self) -> Column:
        """The column: a zero-stride view of a lone value, else its runs (start indices as int32 when they fit)."""
        return RunColumn.of_runs(self.starts.finish(), self.values.finish(), self.size)


class Waypoints(MutableMapping):
    """An operation's waypoint columns by name: each read gives an array.

    A column stored as runs (:class:`RunColumn`) is decoded on its first
    read and kept as an array from then on, so a reader may write into it
    as into any other; :meth:`stored` gives it undecoded.  ``columns`` is
    kept, not copied: what is added to it shows here.
    """

    def __init__(self, columns: MutableMapping[str, Column] | None = None):
        self._columns: MutableMapping[str, Column] = {} if columns is None else columns

    def __getitem__(self, key: str) -> np.ndarray:
        column = self._columns[key]
        if not isinstance(column, np.ndarray):
            column = self._columns[key] = np.asarray(column)
        return column

    def __setitem__(self, key: str, column: Column) -> None:
        self._columns[key] = column

    def __delitem__(self, key: str) -> None:
        del self._columns[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._columns)

    def __len__(self) -> int:
        return len(self._columns)

    def __contains__(self, key: object) -> bool:
        return key in self._columns

    def __repr__(self) -> str:
        return f"Waypoints({', '.join(self._columns)})"

    def stored(self, key: str) -> Column:
        """Column ``key`` as stored: an array, or a :class:`RunColumn` read by slices and indices."""
        return self._columns[key]

    def copy(self) -> "Waypoints":
        """A new mapping of the same columns (the arrays are shared, as ``dict.copy`` shares its values)."""
        return Waypoints(dict(self._columns))


def stored(columns: Mapping[str, Column], key: str) -> Column:
    """Column ``key`` of ``columns`` without decoding it (a plain mapping's value as it is)."""
    return columns.stored(key) if isinstance(columns, Waypoints) else columns[key]
