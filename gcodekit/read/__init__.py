"""Read stage: program text to :class:`Blocks` of words and comments.

Files may be plain or compressed (see :mod:`.source` for the containers
and encodings); strings and preprocessed line lists are read the same way.  Large inputs are read in chunks of whole lines so
later stages can run chunk by chunk with bounded memory.

Examples
--------
>>> from gcodekit.read import read_text
>>> blocks = read_text("G1 X10 Y2.5 ; go\\nM104 S200\\n", flavor="marlin")
>>> blocks[0].words[1], blocks[0].comments
(Word(letter='X', value=10.0, column=4), ('go',))
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np

from ..errors import Diagnostics, MissingDependencyError, check_choice
from ..jit import numba_installed
from ..syntax import Flavor, load_flavor
from .blocks import Block, Blocks, Word
from . import scan_kernel
from .scan import fast_path_possible, scan
from .source import MAX_LINE_LENGTH, iter_lines, open_program, program_lines
from .tokenize import LineTokenizer, RawBlock

__all__ = ["Block", "Blocks", "Word", "read_text", "read_file", "iter_blocks", "iter_counted_blocks", "iter_lines",
           "open_program", "program_lines", "read_source_lines", "iter_source_blocks", "scans_without_gil",
           "MAX_LINE_LENGTH", "COMPILED_AFTER_BYTES"]

#: Preprocessed lines read into one chunk of blocks (see :func:`iter_source_blocks`)
CHUNK_LINES = 50_000


#: Bytes read with the NumPy scanner before a large program switches to the compiled one (importing
#: Numba takes about half a second, which pays off from about this size on)
COMPILED_AFTER_BYTES = 8 << 20
#: The compiled scanner reads chunks of about this size (several of the source's)
COMPILED_CHUNK_BYTES = 2 << 20
ENGINES = ("auto", "numba", "numpy")


def iter_blocks(
    chunks: Iterable[bytes],
    flavor: Flavor,
    diagnostics: Diagnostics,
    *,
    engine: str = "auto",
    size_hint: int = 0,
) -> Iterator[Blocks]:
    """Read chunks of whole lines into :class:`Blocks`, one per chunk.

    Line numbers continue from chunk to chunk; block indices restart at 0 in
    each chunk (see :meth:`Blocks.concat`).  ``engine`` chooses the fast
    path's scanner: ``"numpy"`` (:func:`.scan.scan`), ``"numba"`` (the
    compiled loop of :mod:`.scan_kernel`; Numba must be installed) or
    ``"auto"``: NumPy, and the compiled loop from
    :data:`COMPILED_AFTER_BYTES` on when Numba is installed.  Both give the
    same blocks.  ``size_hint`` (the file's size on disk, when known)
    lets "auto" start with the compiled loop when it is that large already.
    Chunks read by the compiled loop are joined to about
    :data:`COMPILED_CHUNK_BYTES`: a yielded chunk holds every chunk taken
    from ``chunks`` so far, none read ahead.
    """
    for blocks, _ in iter_counted_blocks(chunks, flavor, diagnostics, engine=engine, size_hint=size_hint):
        yield blocks


def scans_without_gil(flavor: Flavor) -> bool:
    """Whether the compiled scanner can read ``flavor`` and Numba is installed (looked up, not imported):
    then scanning a chunk releases the GIL, and reading ahead on a second thread pays."""
    return fast_path_possible(flavor) and numba_installed()


def iter_counted_blocks(chunks: Iterable[bytes], flavor: Flavor, diagnostics: Diagnostics, *, engine: str = "auto",
                        size_hint: int = 0) -> Iterator[tuple[Blocks, int]]:
    """:func:`iter_blocks`, each chunk's blocks with its number of lines (the scanner counts them anyway)."""
    check_choice("engine", engine, ENGINES)
    if engine == "numba" and scan_kernel.compiled() is None:
        raise MissingDependencyError("the compiled scanner needs Numba: pip install 'gcodekit[fast]'")
    tokenizer = LineTokenizer(flavor, diagnostics)
    first_line = 0
    fast = fast_path_possible(flavor)
    read = size_hint if size_hint >= COMPILED_AFTER_BYTES else 0
    pending: list[bytes] = []
    waiting = 0
    for data in chunks:
        compiled = fast and (engine == "numba" or (engine == "auto" and read >= COMPILED_AFTER_BYTES
                                                  and scan_kernel.compiled() is not None))
        read += len(data)
        if compiled:  # the compiled loop makes no big temporaries: fewer, larger chunks for the later stages
            pending.append(data)
            waiting += len(data)
            if waiting < COMPILED_CHUNK_BYTES:
                continue
            data, pending, waiting = b"".join(pending), [], 0
        part, lines = _read(data, first_line, flavor, tokenizer, diagnostics, fast, compiled)
        first_line += lines
        yield part, lines
    if pending:
        yield _read(b"".join(pending), first_line, flavor, tokenizer, diagnostics, fast, True)


def _read(data: bytes, first_line: int, flavor: Flavor, tokenizer: LineTokenizer, diagnostics: Diagnostics,
          fast: bool, compiled: bool) -> tuple[Blocks, int]:
    """The blocks of a chunk and its number of lines."""
    if fast:
        return _read_fast(data, first_line, flavor, tokenizer, diagnostics, compiled)
    return _read_slow(data, first_line, tokenizer, diagnostics), data.count(b"\n")


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
    data: bytes, first_line: int, flavor: Flavor, tokenizer: LineTokenizer, diagnostics: Diagnostics,
    compiled: bool = False,
) -> tuple[Blocks, int]:
    s = (scan_kernel.scan_compiled if compiled else scan)(data, flavor, MAX_LINE_LENGTH)
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
        return fast, n
    slow = Blocks.from_raw(diagnostics.file, raw_blocks)
    lines = np.array(raw_lines, np.int32)
    return _merge(fast, slow, lines), n


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
    blocks = Blocks.concat(list(iter_blocks(iter_lines(text, diagnostics), _resolve(flavor), diagnostics)))
    blocks.file = file
    blocks.diagnostics = diagnostics  # type: ignore[attr-defined]
    return blocks


def read_file(path: str | os.PathLike, flavor: Flavor | str = "rs274ngc", *, mode: str = "lenient") -> Blocks:
    """Read a plain or gzip program file into :class:`Blocks`."""
    diagnostics = Diagnostics(str(path), mode)
    blocks = Blocks.concat(list(iter_blocks(iter_lines(Path(path), diagnostics), _resolve(flavor), diagnostics)))
    blocks.file = str(path)
    blocks.diagnostics = diagnostics  # type: ignore[attr-defined]
    return blocks


def read_source_lines(lines: Iterable, flavor: Flavor, diagnostics: Diagnostics) -> Blocks:
    """Read preprocessed lines (objects with ``text`` and ``line``) one by one."""
    return Blocks.concat(list(iter_source_blocks(lines, flavor, diagnostics, chunk_lines=None)))


def iter_source_blocks(lines: Iterable, flavor: Flavor, diagnostics: Diagnostics, *,
                       chunk_lines: int | None = CHUNK_LINES) -> Iterator[Blocks]:
    """Read preprocessed lines into :class:`Blocks` of at most ``chunk_lines`` lines each.

    A loop can emit millions of lines: reading them a chunk at a time lets
    the later stages run on each chunk and drop it, so memory holds the
    columns, not the lines.  At least one (possibly empty) chunk is yielded.
    A line's lathe profile (``profile``, see :mod:`gcodekit.lathe_profile`)
    goes with each block read from it.
    """
    tokenizer = LineTokenizer(flavor, diagnostics)
    raw: list[RawBlock] = []
    count = 0
    for sl in lines:
        if len(sl.text) > MAX_LINE_LENGTH:
            diagnostics.report(sl.line, 1, f"line is longer than {MAX_LINE_LENGTH} characters; skipped")
        else:
            found = tokenizer.tokenize(sl.text, sl.line)
            profile = getattr(sl, "profile", None)  # lines may be any objects with text and line
            if profile is not None:
                for block in found:
                    block.profile = profile
            raw.extend(found)
        count += 1
        if chunk_lines is not None and count >= chunk_lines:
            yield Blocks.from_raw(diagnostics.file, raw)
            raw, count = [], 0
    yield Blocks.from_raw(diagnostics.file, raw)
