"""gcodekit.memory: freed heap pages go back to the system (glibc)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from gcodekit.memory import release_freed_memory

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc malloc_trim")


def _resident_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20


def test_holes_left_by_freed_chunk_temporaries_are_returned():
    # the reader's pattern: per chunk, small temporaries freed between results that stay
    kept, freed = [], []
    for _ in range(2000):
        freed.append(np.ones(4096))  # 32 kB: below the mmap threshold, on the heap
        kept.append(np.ones(16))
    release_freed_memory()
    before = _resident_mb()
    del freed
    if not release_freed_memory():
        pytest.skip("this C library cannot trim its heap")
    # 2000 x 32 kB = 62.5 MB freed; most of it is no longer resident
    assert before - _resident_mb() > 40
    assert sum(k.sum() for k in kept) == 2000 * 16
