"""Read stage output: blocks of words and comments as columns.

A block is what the controller executes as one unit, normally one line.  The
words of all blocks live in flat arrays (``word_block`` says whose they are),
comments in one byte string with offsets; :class:`Block` objects are made
only when a caller indexes ``blocks[i]``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..lathe_profile import LatheProfile
from .tokenize import RawBlock


@dataclass(frozen=True, slots=True)
class Word:
    """A letter and its number, with its 1-based column."""

    letter: str
    value: float
    column: int

    def __str__(self) -> str:
        return f"{self.letter}{self.value:g}"


@dataclass(frozen=True, slots=True)
class Block:
    """One block as read: its source line, words, comments and extras."""

    line: int
    words: tuple[Word, ...]
    comments: tuple[str, ...] = ()
    flags: tuple[str, ...] = ()
    named: tuple[str, str] | None = None
    text: str | None = None
    deleted: bool = False
    profile: LatheProfile | None = None


@dataclass
class Blocks:
    """Columns of every block read from one program (or one chunk of it).

    Attributes
    ----------
    file : str
    block_line : ndarray of int32
        1-based source line of each block.
    word_block, word_letter, word_value, word_col : ndarray
        One entry per word: owning block (0-based), ASCII letter code,
        value, 1-based column.  Words are ordered by block, then column.
    comment_block, comment_col : ndarray of int32
    comment_offsets : ndarray of int64
        Comment ``k`` is ``comment_data[offsets[k]:offsets[k+1]]`` (UTF-8,
        without its delimiters, not yet stripped).
    comment_data : bytes
    extras : dict of int to RawBlock
        The few blocks with flags (``G28 W``), named commands
        (``SET_VELOCITY_LIMIT``, ``M117 text``), code values (``M60=1``),
        the block-delete mark or a lathe cycle's profile, keyed by block index.
    """

    file: str
    block_line: np.ndarray
    word_block: np.ndarray
    word_letter: np.ndarray
    word_value: np.ndarray
    word_col: np.ndarray
    comment_block: np.ndarray
    comment_col: np.ndarray
    comment_offsets: np.ndarray
    comment_data: bytes
    extras: dict[int, RawBlock] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.block_line.size)

    def comment(self, k: int) -> str:
        """Text of comment ``k``, stripped."""
        a, b = self.comment_offsets[k], self.comment_offsets[k + 1]
        return self.comment_data[a:b].decode("utf-8", "replace").strip()

    def __getitem__(self, i: int) -> Block:
        n = len(self)
        if not -n <= i < n:
            raise IndexError(f"block {i} out of range for {n} blocks")
        i %= n
        lo, hi = np.searchsorted(self.word_block, [i, i + 1])
        words = tuple(
            Word(chr(self.word_letter[k]), float(self.word_value[k]), int(self.word_col[k]))
            for k in range(lo, hi)
        )
        clo, chi = np.searchsorted(self.comment_block, [i, i + 1])
        comments = tuple(self.comment(k) for k in range(clo, chi))
        extra = self.extras.get(i)
        return Block(
            line=int(self.block_line[i]),
            words=words,
            comments=comments,
            flags=tuple(f for f, _ in extra.flags) if extra else (),
            named=extra.named[:2] if extra and extra.named else None,
            text=extra.text if extra else None,
            deleted=bool(extra and extra.deleted),
            profile=extra.profile if extra else None,
        )

    @classmethod
    def empty(cls, file: str) -> "Blocks":
        i32 = np.zeros(0, np.int32)
        return cls(file, i32, i32, np.zeros(0, np.uint8), np.zeros(0), i32, i32, i32,
                   np.zeros(1, np.int64), b"")

    @classmethod
    def concat(cls, parts: list["Blocks"]) -> "Blocks":
        """Join chunks read one after another into one :class:`Blocks`."""
        if not parts:
            return cls.empty("<string>")
        if len(parts) == 1:
            return parts[0]
        shift = np.cumsum([0] + [len(p) for p in parts[:-1]])
        cshift = np.cumsum([0] + [len(p.comment_data) for p in parts[:-1]])
        offsets = [parts[0].comment_offsets[:1]] + [
            p.comment_offsets[1:] + s for p, s in zip(parts, cshift)
        ]
        extras = {k + s: v for p, s in zip(parts, shift) for k, v in p.extras.items()}
        return cls(
            file=parts[0].file,
            block_line=np.concatenate([p.block_line for p in parts]),
            word_block=np.concatenate([p.word_block + s for p, s in zip(parts, shift)]).astype(np.int32),
            word_letter=np.concatenate([p.word_letter for p in parts]),
            word_value=np.concatenate([p.word_value for p in parts]),
            word_col=np.concatenate([p.word_col for p in parts]),
            comment_block=np.concatenate([p.comment_block + s for p, s in zip(parts, shift)]).astype(np.int32),
            comment_col=np.concatenate([p.comment_col for p in parts]),
            comment_offsets=np.concatenate(offsets),
            comment_data=b"".join(p.comment_data for p in parts),
            extras=extras,
        )

    @classmethod
    def from_raw(cls, file: str, raw: list[RawBlock]) -> "Blocks":
        """Columns from blocks made by the reference tokenizer."""
        words = [(i, w) for i, b in enumerate(raw) for w in b.words]
        comments = [(i, c) for i, b in enumerate(raw) for c in b.comments]
        encoded = [text.encode("utf-8", "surrogatepass") for _, (text, _) in comments]
        offsets = np.zeros(len(encoded) + 1, np.int64)
        np.cumsum([len(e) for e in encoded], out=offsets[1:])
        return cls(
            file=file,
            block_line=np.array([b.line for b in raw], np.int32),
            word_block=np.array([i for i, _ in words], np.int32),
            word_letter=np.array([ord(w[0]) for _, w in words], np.uint8),
            word_value=np.array([w[1] for _, w in words], np.float64),
            word_col=np.array([w[2] for _, w in words], np.int32),
            comment_block=np.array([i for i, _ in comments], np.int32),
            comment_col=np.array([c[1] for _, c in comments], np.int32),
            comment_offsets=offsets,
            comment_data=b"".join(encoded),
            extras={i: b for i, b in enumerate(raw)
                    if b.flags or b.named or b.text or b.code_value is not None or b.deleted or b.assignments
                    or b.profile is not None},
        )
