"""An array appended to chunk by chunk, grown where it lies instead of copied.

A large program is read, parsed and emulated a chunk at a time; its
columns used to be kept per chunk and joined at the end, which holds every
value twice for a moment and touches every page twice.  A
:class:`GrowingColumn` takes each chunk's values as they come into one
anonymous memory map: growing it moves its pages (``mremap``) rather than
copying them, the capacity not yet written costs no memory, and the
finished array is the map itself, cut to its length.  Where a map cannot be
resized (no ``mremap``), growing copies.
"""

from __future__ import annotations

import mmap

import numpy as np

__all__ = ["GrowingColumn"]

_FIRST_CAPACITY = 1 << 22  # bytes: untouched capacity is address space only
_PRIVATE = {"flags": mmap.MAP_PRIVATE} if hasattr(mmap, "MAP_PRIVATE") else {}  # (Windows maps have no flags)


class GrowingColumn:
    """Values appended in order; :meth:`finish` gives them as one array.

    Examples
    --------
    >>> c = GrowingColumn(np.float64)
    >>> c.append(np.array([1.0, 2.0])); c.fill(np.nan, 1); c.append(np.array([4.0]))
    >>> c.finish()
    array([ 1.,  2., nan,  4.])
    """

    def __init__(self, dtype: np.dtype | type | str):
        self.dtype = np.dtype(dtype)
        self.size = 0
        self._map: mmap.mmap | None = None

    def __len__(self) -> int:
        return self.size

    def append(self, values: np.ndarray) -> None:
        """Add ``values`` at the end (a dtype the column cannot hold promotes it, as ``np.concatenate``)."""
        values = np.asarray(values)
        if values.dtype != self.dtype:
            self._promote(np.promote_types(self.dtype, values.dtype))
        self._room_view(values.size)[:] = values.reshape(-1)
        self.size += values.size

    def fill(self, value, count: int) -> None:
        """Add ``count`` copies of ``value``."""
        if count:
            self._room_view(count)[:] = value
            self.size += count

    def values(self) -> np.ndarray:
        """A writable view of the values so far (valid until the next append)."""
        if self._map is None:
            return np.empty(0, self.dtype)
        return np.frombuffer(self._map, self.dtype, count=self.size)

    def finish(self) -> np.ndarray:
        """The values as one array, backed by the column's memory (the column is empty afterwards)."""
        mapping, size = self._map, self.size
        self._map, self.size = None, 0
        if mapping is None or size == 0:
            return np.empty(0, self.dtype)
        return np.frombuffer(_resize(mapping, size * self.dtype.itemsize), self.dtype, count=size)

    def _room_view(self, count: int) -> np.ndarray:
        """A writable view of the ``count`` places after the last value (the map grown to hold them)."""
        need = (self.size + count) * self.dtype.itemsize
        if self._map is None:
            self._map = mmap.mmap(-1, max(need, _FIRST_CAPACITY), **_PRIVATE)
        elif need > len(self._map):
            self._map = _resize(self._map, max(need, 2 * len(self._map)))
        return np.frombuffer(self._map, self.dtype, count=count, offset=self.size * self.dtype.itemsize)

    def _promote(self, dtype: np.dtype) -> None:
        old = self.finish()
        self.dtype = np.dtype(dtype)
        if old.size:
            self.append(old.astype(self.dtype))


def _resize(mapping: mmap.mmap, size: int) -> mmap.mmap:
    """``mapping`` holding ``size`` bytes, its pages moved when it must move; a copy where maps cannot grow."""
    try:
        mapping.resize(size)
        return mapping
    except (OSError, SystemError, ValueError):  # no mremap on this system
        grown = mmap.mmap(-1, size, **_PRIVATE)
        kept = min(size, len(mapping))
        grown[:kept] = mapping[:kept]
        mapping.close()
        return grown
