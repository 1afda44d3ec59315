"""Read stage: a program's bytes to chunks of whole lines, whatever the container.

A program may be plain text, gzip, bzip2 or xz compressed, UTF-8 (with or
without a byte-order mark) or UTF-16, with LF, CR LF or old Mac CR-only line
ends.  :func:`iter_lines` hides all of that and yields chunks of whole lines,
each ending with ``\\n``, so the scanner and the tokenizer see one format.

It also keeps the reader's promises about bad files:

* A line longer than :data:`MAX_LINE_LENGTH` keeps only its first
  ``MAX_LINE_LENGTH + 1`` bytes (the tokenizer reports it as too long and
  skips it); the rest is skipped without being held, so a 200 MB comment
  costs no more memory than a short one, and the lines after it keep their
  numbers.
* A corrupt or truncated archive is reported, naming the file and the line
  where reading stopped; a partial last line is dropped rather than read as
  a shorter number (``X12`` from ``X123.4``).
* A file that is mostly NUL bytes is binary, not a program: reported once
  instead of as thousands of bad characters.

Diagnostics go to the ``diagnostics`` given to :func:`iter_lines`; without
one (a second look at a file already read and reported, such as quoting a
line) problems end the chunks quietly.

Examples
--------
>>> b"".join(iter_lines("G0 X1\\rG1 X2\\r"))
b'G0 X1\\nG1 X2\\n'
"""

from __future__ import annotations

import bz2
import codecs
import gzip
import io
import lzma
import os
import zlib
from typing import IO, Iterator, Sequence, Union

import numpy as np

from ..errors import Diagnostics

__all__ = ["Source", "iter_lines", "open_program", "program_lines", "ProgramLines", "MAX_LINE_LENGTH", "CHUNK_BYTES"]

Source = Union[str, os.PathLike, bytes]
CHUNK_BYTES = 256 << 10  # small chunks keep the per-chunk arrays (about 60 bytes per input byte) small
#: Longer lines are reported and skipped: no real controller accepts them,
#: and a binary file without newlines must not be read as one huge block.
MAX_LINE_LENGTH = 65536
#: A first chunk with at least this share of NUL bytes, and at least BINARY_NULS of them, is binary data, not
#: text (fewer, in a short program, are read as the characters they are: comments keep them, words report them).
BINARY_NUL_SHARE = 0.1
BINARY_NULS = 8


def binary_kind(data: bytes) -> str | None:
    """What a file's first bytes hold when they are not program text, or None for text.

    NUL padding at the end is not counted.  NUL bytes at every other place
    are UTF-16 text; a tenth or more of NUL bytes (and at least
    :data:`BINARY_NULS`) is other binary data.
    """
    body = data.rstrip(b"\x00")
    nuls = body.count(b"\x00")
    if nuls == 0:
        return None
    half = len(body) // 2
    for zeros, chars in ((body[1::2], body[0::2]), (body[0::2], body[1::2])):  # little-endian, big-endian
        if half >= 2 and zeros.count(b"\x00") >= 0.9 * half and _printable_share(chars) >= 0.9:
            return "UTF-16 text without its byte-order mark (save it as UTF-8, or with the mark)"
    if nuls >= BINARY_NULS and nuls >= BINARY_NUL_SHARE * len(body):
        return "binary data (NUL bytes)"
    return None


def _printable_share(data: bytes) -> float:
    """The share of ``data`` that is printable ASCII, tab or a line end."""
    if not data:
        return 0.0
    return 1.0 - len(data.translate(None, _PRINTABLE)) / len(data)  # what is left once the printable are deleted


_PRINTABLE = bytes(range(32, 127)) + b"\t\n\r"


_ARCHIVES = (  # magic number, name, opener
    (b"\x1f\x8b", "gzip", lambda f: gzip.GzipFile(fileobj=f)),
    (b"BZh", "bzip2", lambda f: bz2.BZ2File(f)),
    (b"\xfd7zXZ\x00", "xz", lambda f: lzma.LZMAFile(f)),
)
_UNSUPPORTED = ((b"PK\x03\x04", "a ZIP archive"), (b"7z\xbc\xaf\x27\x1c", "a 7-Zip archive"))
# What a damaged archive raises while it is read.
_ARCHIVE_ERRORS = (EOFError, zlib.error, OSError, lzma.LZMAError)


class _Stream:
    """A program file opened for reading: its bytes as UTF-8, and what it was."""

    def __init__(self, raw: IO[bytes], *, container: bool = True):
        self.file = self.raw = raw
        self.archive = ""
        head = raw.peek(8)[:8] if container else b""  # type: ignore[attr-defined]
        for magic, name, opener in _ARCHIVES:
            if head.startswith(magic):
                self.archive, self.raw = name, opener(raw)
                break
        self.unsupported = next((what for magic, what in _UNSUPPORTED if head.startswith(magic)), "")
        self.decoder = None  # set when the text is UTF-16
        self.started = False
        self.failed: BaseException | None = None  # the archive broke after the data last returned

    def read(self, size: int) -> bytes:
        """About ``size`` bytes (fewer only at the end).

        A damaged archive's error comes on the read after the last good data,
        which is returned first: the container is read a piece at a time.
        """
        if self.failed is not None:
            raise self.failed
        parts, got = [], 0
        while got < size:
            try:
                data = self._read_piece(size - got)
            except _ARCHIVE_ERRORS as exc:
                if not parts:
                    raise
                self.failed = exc
                break
            if not data:
                break
            parts.append(data)
            got += len(data)
        return b"".join(parts)

    def _read_piece(self, size: int) -> bytes:
        """Up to ``size`` bytes from one read of the container, decoded to UTF-8."""
        while True:
            data = self.raw.read1(size)  # type: ignore[attr-defined]
            if not self.started:
                self.started = True
                if data.startswith(codecs.BOM_UTF8):
                    data = data[len(codecs.BOM_UTF8):]
                elif data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
                    self.decoder = codecs.getincrementaldecoder("utf-16")("replace")
            if self.decoder is None:
                return data
            text = self.decoder.decode(data, final=not data)
            if text or not data:  # a read of half a character gives no text yet: read on
                return text.encode("utf-8", "surrogateescape")

    def close(self) -> None:
        self.raw.close()
        self.file.close()  # an archive reader leaves the file it was given open


def open_program(path: str | os.PathLike) -> IO[bytes]:
    """Open a program for reading bytes, decompressing gzip, bzip2 and xz by their magic numbers."""
    return _Stream(open(path, "rb"))  # type: ignore[return-value]


def iter_lines(source: Source, diagnostics: Diagnostics | None = None) -> Iterator[bytes]:
    """Byte chunks of whole lines (each ending with ``\\n``) from a path, text or bytes.

    Problems with the file itself (a damaged archive, binary data, CR-only
    line ends) are reported to ``diagnostics`` when given.
    """
    if isinstance(source, (str, bytes)) and not isinstance(source, os.PathLike):
        data = source.encode("utf-8", "surrogateescape") if isinstance(source, str) else source
        yield from _LineSplitter(_Stream(io.BytesIO(data), container=False), diagnostics).chunks()
        return
    stream = open_program(source)
    try:
        yield from _LineSplitter(stream, diagnostics).chunks()  # type: ignore[arg-type]
    finally:
        stream.close()


def program_lines(source: Source) -> list[str]:
    """The program's lines as text, numbered as the pipeline numbers them (line ``k`` is item ``k - 1``).

    Read by :func:`iter_lines` (every container, encoding and line end it
    knows); bytes that are not UTF-8 show as U+FFFD.  Only ``\\n`` ends a
    line, as in the reader (``str.splitlines`` would also cut at form feeds
    and other separators and shift the numbers).
    """
    text = b"".join(iter_lines(source)).decode("utf-8", "replace")
    return text.split("\n")[:-1] if text else []


class ProgramLines(Sequence[str]):
    """:func:`program_lines` decoded one line at a time, when asked (line ``k`` is item ``k - 1``).

    Keeps the program's bytes and where each line ends, 8 bytes a line: a
    3 M-line print's list of strings took a second and a few hundred MB,
    for a panel that shows a dozen lines at a time.
    """

    def __init__(self, source: Source):
        self._data = b"".join(iter_lines(source))
        self._ends = np.flatnonzero(np.frombuffer(self._data, np.uint8) == ord("\n"))

    def __len__(self) -> int:
        return int(self._ends.size)

    def __getitem__(self, k):  # an int, or a slice (a list)
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        if k < 0:
            k += len(self)
        if not 0 <= k < len(self):
            raise IndexError(f"line {k + 1} of {len(self)}")
        start = int(self._ends[k - 1]) + 1 if k else 0
        return self._data[start:int(self._ends[k])].decode("utf-8", "replace")


class _LineSplitter:
    """Cuts a stream into chunks of whole lines, keeping count of the lines for diagnostics."""

    def __init__(self, stream: _Stream, diagnostics: Diagnostics | None):
        self.stream = stream
        self.diagnostics = diagnostics
        self.lines = 0  # whole lines yielded so far
        self.cr_only = False
        self.skipping = False  # inside an over-long line, dropping bytes until its end
        self.damaged = False  # the archive broke off: a partial last line is not read

    def _report(self, message: str, *, severity: str = "error") -> None:
        if self.diagnostics is not None:
            self.diagnostics.report(self.lines + 1, 1, message, severity=severity, kind="file")  # type: ignore[arg-type]

    def _reads(self) -> Iterator[bytes]:
        """The stream's data, read by :data:`CHUNK_BYTES`; a damaged archive ends it, reported."""
        if self.stream.unsupported:
            self._report(f"the file is {self.stream.unsupported}, not a program; extract the program first")
            return
        first = True
        while True:
            try:
                data = self.stream.read(CHUNK_BYTES)
            except _ARCHIVE_ERRORS as exc:
                self._archive_error(exc)
                return
            if not data:
                return
            if first:
                first = False
                binary = binary_kind(data)
                if binary:
                    self._report(f"the file holds {binary}, not program text; nothing read")
                    return
                if b"\n" not in data and b"\r" in data:
                    self.cr_only = True
                    self._report("line ends are CR alone (classic Mac OS); read as line breaks", severity="info")
            yield data.replace(b"\r", b"\n") if self.cr_only else data

    def _archive_error(self, exc: BaseException) -> None:
        self.damaged = True
        kind = self.stream.archive or "file"
        if isinstance(exc, EOFError):
            problem = f"the {kind} data is truncated (it ends before its end marker)"
        else:
            problem = f"the {kind} data is corrupt ({exc})"
        read = f"only its first {self.lines} lines were read" if self.lines else "no line could be read"
        self._report(f"{problem}: {read}; the rest of the file is lost")

    def chunks(self) -> Iterator[bytes]:
        rest = b""
        for data in self._reads():
            if self.skipping:
                end = data.find(b"\n")
                if end < 0:
                    continue
                self.skipping = False
                data = data[end + 1:]
            data = rest + data
            cut = data.rfind(b"\n") + 1
            if cut == 0:
                rest = data
                if len(rest) > MAX_LINE_LENGTH:  # keep the head for the tokenizer's report, drop the rest
                    self.skipping = True
                    self.lines += 1
                    yield rest[: MAX_LINE_LENGTH + 1] + b"\n"
                    rest = b""
                continue
            rest = data[cut:]
            self.lines += data.count(b"\n", 0, cut)
            yield data[:cut]
        if rest and not self.damaged:
            if not rest.strip(b"\x00"):  # a firmware reads up to the first NUL: such a last line is empty
                self._report(f"the file ends in {len(rest)} NUL bytes after its last line (padding, as an SD card "
                             "or a file transfer can leave); ignored", severity="info")
                return
            self.lines += 1
            yield rest + b"\n"
