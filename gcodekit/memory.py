"""Give the memory a finished stage freed back to the operating system.

The reader works chunk by chunk: each chunk's temporaries (about 60 bytes
per input byte) are freed while the chunk's results stay, interleaved with
them on the C heap.  glibc keeps such holes resident, so without a trim a
program's peak memory counts the reader's garbage on top of the planner's
arrays.  ``malloc_trim(0)`` returns every free page; elsewhere this is a
no-op.
"""

from __future__ import annotations

import functools
import sys


@functools.lru_cache(maxsize=1)
def _malloc_trim():
    if not sys.platform.startswith("linux"):
        return None
    import ctypes  # imported here, and glibc tried by name: ctypes.util.find_library starts ldconfig

    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:
        import ctypes.util

        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c"))
        except OSError:
            return None
    return getattr(libc, "malloc_trim", None)  # not glibc (musl has no malloc_trim)


def release_freed_memory() -> bool:
    """Return freed heap pages to the system; True when the C library could."""
    trim = _malloc_trim()
    return bool(trim(0)) if trim is not None else False
