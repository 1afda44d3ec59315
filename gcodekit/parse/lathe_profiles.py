"""Parse stage: the lathe cycles' profiles, by row (see :mod:`gcodekit.lathe_profile`).

A lathe cycle row (G70-G72) takes the profile the preprocess stage attached
to its block, read from the cycle's ``Q`` subroutine.  A cycle whose
profile was not captured that way (the program has no such subroutine, or
ran without the control-flow stage) takes the written form its block's
comment may hold, ``(g7x profile: ...)``, as gcodekit's writers put it;
that text then leaves the comment, which keeps only what the program wrote
before it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..lathe_profile import TAG, LatheProfile, read_written
from ..read import Blocks


class Comments(NamedTuple):
    """The comment columns of a chunk of blocks (as :class:`~gcodekit.read.Blocks` holds them)."""

    block: np.ndarray
    offsets: np.ndarray
    data: bytes


def lathe_profiles(blocks: Blocks, block_of_row: np.ndarray, lathe_rows: np.ndarray
                   ) -> tuple[dict[int, LatheProfile], Comments]:
    """Profiles of the rows ``lathe_rows``, and the comments without the written profiles read."""
    comments = Comments(blocks.comment_block, blocks.comment_offsets, blocks.comment_data)
    profiles: dict[int, LatheProfile] = {}
    pending: list[tuple[int, int]] = []
    for row in lathe_rows.tolist():
        block = int(block_of_row[row])
        extra = blocks.extras.get(block)
        if extra is not None and extra.profile is not None:
            profiles[row] = extra.profile
        else:
            pending.append((row, block))
    if not pending or TAG.encode() not in blocks.comment_data:
        return profiles, comments
    written: dict[int, tuple[int, int, str | None]] = {}  # first comment -> (last + 1, block, own comment)
    for row, block in pending:
        lo, hi = np.searchsorted(blocks.comment_block, [block, block + 1]).tolist()
        found = read_written(" ".join(blocks.comment(k) for k in range(lo, hi))) if hi > lo else None
        if found is not None:
            own, profiles[row] = found
            written[lo] = (hi, block, own)
    return profiles, _replace(comments, written) if written else comments


def _replace(comments: Comments, written: dict[int, tuple[int, int, str | None]]) -> Comments:
    """``comments`` with each run of a block's comments that held a written profile replaced by the
    program's own comment (or nothing)."""
    owners: list[int] = []
    pieces: list[bytes] = []
    k, n = 0, comments.block.size
    while k < n:
        if k in written:
            end, block, own = written[k]
            if own is not None:
                owners.append(block)
                pieces.append(own.encode("utf-8", "surrogatepass"))
            k = end
            continue
        owners.append(int(comments.block[k]))
        pieces.append(comments.data[comments.offsets[k]:comments.offsets[k + 1]])
        k += 1
    offsets = np.zeros(len(pieces) + 1, np.int64)
    np.cumsum([len(p) for p in pieces], out=offsets[1:])
    return Comments(np.array(owners, comments.block.dtype), offsets, b"".join(pieces))
