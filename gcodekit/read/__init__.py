"""Read stage: program text to :class:`Blocks` of words and comments.

Files may be plain or gzip-compressed; strings and preprocessed line lists
are read the same way.  Large inputs are read in chunks of whole lines so
later stages can run chunk by chunk with bounded memory.

Examples
--------
>>> from gcodekit.read import read_text
>>> blocks = read_text("G1 X10 Y2.5 ; go\\nM104 S200\\n", flavor="marlin")
>>> blocks[0].words[1], blocks[0].comments
(Word(letter='X', value=10.0, column=4), ('go',))
"""

from __future__ import annotations

import gzip
import io
import os
from pathlib import Path
from typing import IO, Iterable, Iterator, Union

import numpy as np

from ..errors import Diagnostics
from ..syntax import Flavor, load_flavor
from .blocks import Block, Blocks, Word
from .scan import fast_path_possible, scan
from .tokenize import LineTokenizer, RawBlock

__all__ = ["Block", "Blocks", "Word", "read_text", "read_file", "iter_blocks", "iter_lines",
           "open_program", "read_source_lines", "MAX_LINE_LENGTH"]

Source = Union[str, os.PathLike, bytes]
CHUNK_BYTES = 256 << 10  # small chunks keep the per-chunk arrays (about 60 bytes per input byte) small
#: Longer lines are reported and skipped: no real controller accepts them,
#: and a binary file without newlines must not be read as one huge block.
MAX_LINE_LENGTH = 65536


def open_program(path: str | os.PathLike) -> IO[bytes]:
    """Open a program for reading bytes, decompressing gzip by its magic number."""
    f = open(path, "rb")
    if f.peek(2)[:2] == b"\x1f\x8b":
        return gzip.GzipFile(fileobj=f)  # type: ignore[return-value]
    return f


def _byte_chunks(stream: IO[bytes], size: int) -> Iterator[bytes]:
    """Chunks of whole lines, each ending with a newline."""
    rest = b""
    while True:
        data = stream.read(size)
        if not data:
            break
        data = rest + data
        cut = data.rfind(b"\n") + 1
        if cut == 0:
            rest = data
            if len(rest) > MAX_LINE_LENGTH * 4:
                yield rest + b"\n"
                rest = b""
            continue
        rest = data[cut:]
        yield data[:cut]
    if rest:
        yield rest + b"\n"


def iter_lines(source: Source) -> Iterator[bytes]:
    """Byte chunks of whole lines from a path, text or bytes."""
    if isinstance(source, (str, bytes)) and not _is_path(source):
        data = source.encode("utf-8", "surrogateescape") if isinstance(source, str) else source
        yield from _byte_chunks(io.BytesIO(data), CHUNK_BYTES)
        return
    with open_program(source) as f:  # type: ignore[arg-type]
        yield from _byte_chunks(f, CHUNK_BYTES)


def _is_path(source: object) -> bool:
    return isinstance(source, os.PathLike)


def iter_blocks(
    chunks: Iterable[bytes],
    flavor: Flavor,
    diagnostics: Diagnostics,
) -> Iterator[Blocks]:
    """Read chunks of whole lines into :class:`Blocks`, one per chunk.

    Line numbers continue from chunk to chunk; block indices restart at 0 in
    each chunk (see :meth:`Blocks.concat`).
    """
    tokenizer = LineTokenizer(flavor, diagnostics)
    first_line = 0
    fast = fast_path_possible(flavor)
    for data in chunks:
        if fast:
            part = _read_fast(data, first_line, flavor, tokenizer, diagnostics)
        else:
            part = _read_slow(data, first_line, tokenizer, diagnostics)
        first_line += data.count(b"\n")
        yield part


def _line_text(data: bytes, start: int, end: int) -> str:
    return data[start:end].rstrip(b"\r\n").decode("utf-8", "replace")


def _read_slow(data: bytes, first_line: int, tokenizer: LineTokenizer, diagnostics: Diagnostics) -> Blocks:
    raw: list[RawBlock] = []
    for k, line in enumerate(data.split(b"\n")[:-1]):
        raw.extend(_tokenize(tokenizer, line, first_line + k + 1, diagnostics))
    return Blocks.from_raw(diagnostics.file, raw)


def _tokenize(tokenizer: LineTokenizer, line: bytes, number: int, diagnostics: Diagnostics) -> list[RawBlock]:
    if len(line) > MAX_LINE_LENGTH:
        diagnostics.report(number, 1, f"line is longer than {MAX_LINE_LENGTH} characters; skipped",
                           line[:40].decode("utf-8", "replace"))
        return []
    return tokenizer.tokenize(line.rstrip(b"\r").decode("utf-8", "replace"), number)


def _read_fast(
    data: bytes, first_line: int, flavor: Flavor, tokenizer: LineTokenizer, diagnostics: Diagnostics
) -> Blocks:
    s = scan(data, flavor)
    n = s.n_lines
    ends = np.r_[s.line_start[1:] - 1, len(data) - 1]
    raw_lines: list[int] = []
    raw_blocks: list[RawBlock] = []
    for k in s.irregular.tolist():
        found = _tokenize(tokenizer, data[s.line_start[k] : ends[k]], first_line + k + 1, diagnostics)
        if found:
            raw_lines.append(k)
            raw_blocks.append(found[0])
    block_line = np.arange(first_line + 1, first_line + n + 1, dtype=np.int32)
    fast = Blocks(
        diagnostics.file, block_line, s.word_line.astype(np.int32), s.word_letter, s.word_value,
        s.word_col, s.comment_line, s.comment_col, s.comment_offsets, s.comment_data,
    )
    if not raw_blocks:
        return fast
    slow = Blocks.from_raw(diagnostics.file, raw_blocks)
    lines = np.array(raw_lines, np.int32)
    return _merge(fast, slow, lines)


def _merge(fast: Blocks, slow: Blocks, slow_lines: np.ndarray) -> Blocks:
    """Insert the reference tokenizer's blocks into the fast path's, by line."""
    wb = slow_lines[slow.word_block]
    at = np.searchsorted(fast.word_block, wb)
    cb = slow_lines[slow.comment_block]
    cat = np.searchsorted(fast.comment_block, cb)
    lengths = np.diff(slow.comment_offsets)
    fast_lengths = np.diff(fast.comment_offsets)
    all_lengths = np.insert(fast_lengths, cat, lengths)
    offsets = np.zeros(all_lengths.size + 1, np.int64)
    np.cumsum(all_lengths, out=offsets[1:])
    data = _insert_bytes(fast.comment_data, fast.comment_offsets, cat, slow.comment_data, slow.comment_offsets)
    return Blocks(
        file=fast.file,
        block_line=fast.block_line,
        word_block=np.insert(fast.word_block, at, wb),
        word_letter=np.insert(fast.word_letter, at, slow.word_letter),
        word_value=np.insert(fast.word_value, at, slow.word_value),
        word_col=np.insert(fast.word_col, at, slow.word_col),
        comment_block=np.insert(fast.comment_block, cat, cb),
        comment_col=np.insert(fast.comment_col, cat, slow.comment_col),
        comment_offsets=offsets,
        comment_data=data,
        extras={int(slow_lines[k]): v for k, v in slow.extras.items()},
    )


def _insert_bytes(a: bytes, a_off: np.ndarray, at: np.ndarray, b: bytes, b_off: np.ndarray) -> bytes:
    """Comment bytes of ``b`` inserted before comment ``at[k]`` of ``a``."""
    if not len(at):
        return a
    pieces = []
    prev = 0
    for k, i in enumerate(at.tolist()):
        pieces.append(a[prev : a_off[i]])
        pieces.append(b[b_off[k] : b_off[k + 1]])
        prev = a_off[i]
    pieces.append(a[prev:])
    return b"".join(pieces)


def _resolve(flavor: Flavor | str) -> Flavor:
    return load_flavor(flavor) if isinstance(flavor, str) else flavor


def read_text(text: str, flavor: Flavor | str = "rs274ngc", *, file: str = "<string>",
              mode: str = "lenient") -> Blocks:
    """Read program text into :class:`Blocks` (diagnostics in ``blocks.diagnostics``)."""
    diagnostics = Diagnostics(file, mode)
    blocks = Blocks.concat(list(iter_blocks(iter_lines(text), _resolve(flavor), diagnostics)))
    blocks.file = file
    blocks.diagnostics = diagnostics  # type: ignore[attr-defined]
    return blocks


def read_file(path: str | os.PathLike, flavor: Flavor | str = "rs274ngc", *, mode: str = "lenient") -> Blocks:
    """Read a plain or gzip program file into :class:`Blocks`."""
    diagnostics = Diagnostics(str(path), mode)
    blocks = Blocks.concat(list(iter_blocks(iter_lines(Path(path)), _resolve(flavor), diagnostics)))
    blocks.file = str(path)
    blocks.diagnostics = diagnostics  # type: ignore[attr-defined]
    return blocks


def read_source_lines(lines: Iterable, flavor: Flavor, diagnostics: Diagnostics) -> Blocks:
    """Read preprocessed lines (objects with ``text`` and ``line``) one by one."""
    tokenizer = LineTokenizer(flavor, diagnostics)
    raw: list[RawBlock] = []
    for sl in lines:
        if len(sl.text) > MAX_LINE_LENGTH:
            diagnostics.report(sl.line, 1, f"line is longer than {MAX_LINE_LENGTH} characters; skipped")
            continue
        raw.extend(tokenizer.tokenize(sl.text, sl.line))
    return Blocks.from_raw(diagnostics.file, raw)
