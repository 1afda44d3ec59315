"""Read stage: a program opened by a ``%`` line ends at the next ``%`` line.

RS274NGC (LinuxCNC's ``read_text``) and Fanuc controllers stop loading there:
whatever follows, notes or a subroutine written after the end, is never
read, so it can neither run nor be wrong.

Examples
--------
>>> b"".join(until_closing_percent([b"%\\nG0 X1\\n", b"%\\n(notes (nested))\\n"]))
b'%\\nG0 X1\\n%\\n'
>>> b"".join(until_closing_percent([b"(no opening mark)\\n%\\nG0 X1\\n"]))
b'(no opening mark)\\n%\\nG0 X1\\n'
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator

_PERCENT_LINE = re.compile(rb"^[ \t]*%[ \t]*\r?$", re.MULTILINE)
_BLANK_LINES = re.compile(rb"(?:[ \t]*\r?\n)*")


def until_closing_percent(chunks: Iterable[bytes]) -> Iterator[bytes]:
    """Byte chunks of whole lines, cut after the ``%`` line that closes a program whose first
    non-blank line is ``%``."""
    opened = None  # unknown until the first non-blank line
    rest = iter(chunks)
    for chunk in rest:
        start = 0
        if opened is None:
            start = _BLANK_LINES.match(chunk).end()
            if start == len(chunk):
                yield chunk
                continue
            first = _PERCENT_LINE.match(chunk, start)
            opened = first is not None
            if not opened:
                yield chunk
                yield from rest
                return
            start = first.end()
        closing = _PERCENT_LINE.search(chunk, start)
        if closing is None:
            yield chunk
            continue
        end = chunk.find(b"\n", closing.end())
        yield chunk[: len(chunk) if end < 0 else end + 1]
        return
