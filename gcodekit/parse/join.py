"""Parse stage: the command tables of consecutive chunks joined into the program's one table.

:class:`TableJoiner` takes each chunk's table as it is parsed, so a large
program's columns are held once, in :class:`~gcodekit.growing.GrowingColumn`
maps, rather than per chunk and then joined.  A parameter letter stays
sparse while every chunk has it sparse (or not at all) and turns dense from
the first chunk that has it dense.  Dense words are kept as decimal units
(:class:`~.table.DecimalColumn`, half the memory) while every word so far
comes back from them bit for bit: a chunk with more decimals scales the
units kept so far, and a word no int32 unit can hold (a computed value, a
-0.0) turns the letter to floats for good.  The joined table is compacted
as any table is (see :meth:`.CommandTable.compact`).
"""

from __future__ import annotations

import numpy as np

from ..growing import GrowingColumn
from .table import CommandTable, DecimalColumn, SparseColumn, fewest_units, scale_units

__all__ = ["TableJoiner", "GrowingDecimals"]

_COLUMNS = ("line", "kind", "letter", "number", "name", "motion")


class GrowingDecimals:
    """Float values appended in order, kept as decimal units (:class:`~.table.DecimalColumn`) while each
    comes back from them bit for bit, and as floats from the first that does not.

    A chunk needing more decimals scales the units kept so far in place; a
    value no int32 unit holds (a computed value, a -0.0, past int32) turns
    the column to floats for good.  NaN is kept (as ``NO_WORD`` in units).
    """

    def __init__(self) -> None:
        self.column = GrowingColumn(np.int32)
        self.places: int | None = 0  # None once the column holds floats

    def __len__(self) -> int:
        return len(self.column)

    def append(self, values: np.ndarray) -> None:
        if self.places is not None:
            found = fewest_units(values, self.places)
            if found is not None and (found[0] == self.places
                                      or scale_units(self.column.values(), self.places, found[0])):
                self.places = found[0]
                self.column.append(found[1])
                return
            self._to_floats()
        self.column.append(values)

    def fill_missing(self, count: int) -> None:
        """Add ``count`` NaN."""
        self.column.fill(np.nan if self.places is None else DecimalColumn.NO_WORD, count)

    def _to_floats(self) -> None:
        assert self.places is not None
        kept = DecimalColumn(self.column.finish(), self.places)
        self.column, self.places = GrowingColumn(np.float64), None
        self.column.append(kept.dense())

    def finish(self) -> np.ndarray | DecimalColumn:
        """The values: decimal units when every one holds, else floats (the column is empty afterwards)."""
        values = self.column.finish()
        return values if self.places is None else DecimalColumn(values, self.places)


class _Param:
    """One parameter letter across the chunks: sparse pieces until a chunk has it dense, then
    :class:`GrowingDecimals`."""

    def __init__(self) -> None:
        self.pieces: list[tuple[int, int, SparseColumn | None]] = []  # (first row, rows, column) while sparse
        self.dense: GrowingDecimals | None = None

    def add(self, col: np.ndarray | SparseColumn | None, first_row: int, rows: int) -> None:
        if self.dense is None and not isinstance(col, np.ndarray):
            self.pieces.append((first_row, rows, col))
            return
        if self.dense is None:  # the first dense chunk: the earlier ones written out densely
            self.dense = GrowingDecimals()
            for _, size, piece in self.pieces:
                self._add_dense(piece, size)
            self.pieces = []
        self._add_dense(col, rows)

    def _add_dense(self, col: np.ndarray | SparseColumn | None, rows: int) -> None:
        assert self.dense is not None
        if col is None:
            self.dense.fill_missing(rows)
        else:
            self.dense.append(col.dense() if isinstance(col, SparseColumn) else col)

    def finish(self, n: int) -> np.ndarray | SparseColumn | DecimalColumn:
        if self.dense is not None:
            return self.dense.finish()
        given = [(first, c) for first, _, c in self.pieces if c is not None]
        return SparseColumn(np.concatenate([c.rows + np.int64(first) for first, c in given]),
                            np.concatenate([c.values for _, c in given]), n)


class TableJoiner:
    """Chunks' tables, in program order, joined as they come; :meth:`finish` gives the program's table.

    A lone chunk's table is returned as it is (compacted).
    """

    def __init__(self) -> None:
        self._first: CommandTable | None = None
        self._joined = False
        self._n = 0
        self._columns = {name: None for name in _COLUMNS}  # type: dict[str, GrowingColumn | None]
        self._params: dict[str, _Param] = {}
        self._comment_rows: list[np.ndarray] = []
        self._comment_offsets: list[np.ndarray] = []
        self._comment_data: list[bytes] = []
        self._deleted: list[np.ndarray] = []
        self._named: dict = {}
        self._texts: dict = {}
        self._profiles: dict = {}

    def add(self, table: CommandTable) -> None:
        """The next chunk's table (its rows counted from 0)."""
        if not self._joined and self._first is None:
            self._first = table
            return
        if not self._joined:
            self._joined, first, self._first = True, self._first, None
            self._take(first)  # type: ignore[arg-type]
        self._take(table)

    def _take(self, table: CommandTable) -> None:
        n, shift = len(table), np.int64(self._n)
        for name in _COLUMNS:
            values = getattr(table, name)
            column = self._columns[name]
            if column is None:
                column = self._columns[name] = GrowingColumn(values.dtype)
            column.append(values)
        for letter in table.params.keys() - self._params.keys():  # a letter new in this chunk: none before
            self._params[letter] = param = _Param()
            if self._n:
                param.add(None, 0, self._n)
        for letter, param in self._params.items():
            param.add(table.params.get(letter), self._n, n)
        self._comment_rows.append(table.comment_rows + shift)
        self._comment_offsets.append(table.comment_offsets)
        self._comment_data.append(table.comment_data)
        self._deleted.append(table.deleted + shift)
        for joined, own in ((self._named, table.named), (self._texts, table.texts), (self._profiles, table.profiles)):
            joined.update({k + self._n: v for k, v in own.items()})
        self._n += n

    def finish(self) -> CommandTable | None:
        """The program's table (None when no chunk came); the joiner is spent."""
        if not self._joined:
            return None if self._first is None else self._first.compact().store_decimals()
        n = self._n
        table = CommandTable(
            **{name: column.finish() for name, column in self._columns.items()},  # type: ignore[union-attr]
            params={letter: self._params[letter].finish(n) for letter in sorted(self._params)},
            comment_rows=np.concatenate(self._comment_rows),
            comment_offsets=_joined_offsets(self._comment_offsets),
            comment_data=b"".join(self._comment_data),
            named=self._named, texts=self._texts,
            deleted=np.concatenate(self._deleted),
            profiles=self._profiles,
        )
        assert len(table) == n
        return table.compact()


def _joined_offsets(offsets: list[np.ndarray]) -> np.ndarray:
    out = [offsets[0]]
    base = offsets[0][-1]
    for o in offsets[1:]:
        out.append(o[1:] + base)
        base += o[-1]
    return np.concatenate(out)
