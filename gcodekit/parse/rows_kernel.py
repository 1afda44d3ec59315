"""Parse stage, fast path compiled: the block summaries and the rows of one-code blocks as loops over the words, with Numba.

:class:`~gcodekit.parse.parser.GcodeParser` first sums up each block (its
codes, whether it has parameter and axis words), then builds the rows of
the blocks holding at most one code (nearly every line of a slicer's
output), with a dozen NumPy passes over the words, each a masked gather or
scatter as long as the chunk; these are the loops those passes vectorize,
compiled when Numba is installed (``pip install 'gcodekit[fast]'``).  The
NumPy passes stay the reference: the tests run both on the same blocks and
require identical summaries and rows, bit for bit.

The rule, word by word (words are ordered by block): a G or M word is the
row's code; a T word in a row without one is the command (printer tool
change, RS274 tool select), the last such word winning; every other word
but the line number is a parameter, the first of a repeated letter kept.
The code number in tenths is rounded by NumPy afterwards, as the reference
does it.
"""

from __future__ import annotations

import functools

import numpy as np

from ..jit import compile_loops, numba_loaded

__all__ = ["compiled", "use_compiled", "block_words_compiled", "simple_rows_compiled", "COMPILED_FROM_BLOCKS"]

#: Chunks of fewer blocks stay with NumPy: the loop pays off only when Numba is loaded anyway
COMPILED_FROM_BLOCKS = 10_000

_G, _M, _T = ord("G"), ord("M"), ord("T")


@functools.lru_cache(maxsize=1)
def compiled():
    """The compiled loops (block words, rows), or None when Numba is not installed (compiled on first use,
    cached on disk)."""
    return compile_loops(_block_words, _rows)


def use_compiled(engine: str, n_blocks: int) -> bool:
    """Whether the parser's ``engine`` takes the compiled loop for a chunk of ``n_blocks`` blocks.

    ``"auto"`` takes it for chunks of :data:`COMPILED_FROM_BLOCKS` blocks
    or more, once Numba is loaded (the reader loads it for large programs):
    importing it for the parser alone would cost more than it saves.
    """
    if engine == "numpy":
        return False
    if engine == "numba":
        return True
    return n_blocks >= COMPILED_FROM_BLOCKS and numba_loaded() and compiled() is not None


def simple_rows_compiled(word_block: np.ndarray, word_letter: np.ndarray, word_value: np.ndarray,
                         rows_blocks: np.ndarray, n_blocks: int, n_letter: int, letter_row: np.ndarray):
    """The rows of the blocks ``rows_blocks`` (Numba must be installed: see :func:`compiled`).

    Returns each row's code letter and number in tenths (-1 without a
    code), the parameter letters present (rows of ``letter_row``), the
    parameter table (one row per letter present, NaN where a row has no
    such word) and the repeated letters as (row, table row, second word)
    in the order of ``row * len(present) + table row``.
    """
    letter, code_value, present, table, repeats = compiled()[1](
        word_block, word_letter, word_value, rows_blocks, n_blocks, n_letter, letter_row)
    number = np.full(letter.size, -1, np.int32)
    coded = letter != 0
    number[coded] = np.round(code_value[coded] * 10).astype(np.int32)
    if repeats.shape[0] > 1:
        repeats = repeats[np.argsort(repeats[:, 0] * present.size + repeats[:, 1], kind="stable")]
    return letter, number, present, table, repeats


def block_words_compiled(word_block: np.ndarray, word_letter: np.ndarray, n_blocks: int, n_letter: int,
                         axis: np.ndarray):
    """Per block: its number of G and M codes, whether it has parameter words and axis words (``axis``:
    a table by byte), and its last code word, -1 for none (as ``parser._block_words``)."""
    return compiled()[0](word_block, word_letter, n_blocks, n_letter, axis)


def _block_words(wb, wl, n_blocks, n_letter, axis):
    """The loop of :func:`block_words_compiled`."""
    n_codes = np.zeros(n_blocks, np.int64)
    has_param = np.zeros(n_blocks, np.bool_)
    has_axis = np.zeros(n_blocks, np.bool_)
    code_word = np.full(n_blocks, -1, np.int64)
    for k in range(wb.size):
        b = wb[k]
        c = wl[k]
        if c == _G or c == _M:
            n_codes[b] += 1
            code_word[b] = k
        elif c != n_letter:
            has_param[b] = True
            if axis[c]:
                has_axis[b] = True
    return n_codes, has_param, has_axis, code_word


def _rows(wb, wl, wv, rows_blocks, n_blocks, n_letter, letter_row):
    """The loop; see the module's docstring for the rule."""
    n = rows_blocks.size
    row_of_block = np.full(n_blocks, -1, np.int64)
    for r in range(n):
        row_of_block[rows_blocks[r]] = r
    letter = np.zeros(n, np.uint8)
    code_value = np.zeros(n, np.float64)
    n_words = wb.size
    # codes first: a T word is the command only in a row without a G or M code, wherever it stands
    for k in range(n_words):
        r = row_of_block[wb[k]]
        c = wl[k]
        if r >= 0 and (c == _G or c == _M):
            letter[r] = c
            code_value[r] = wv[k]
    tool_row = np.zeros(n, np.bool_)
    for k in range(n_words):
        r = row_of_block[wb[k]]
        if r >= 0 and wl[k] == _T and letter[r] == 0:
            tool_row[r] = True
            code_value[r] = wv[k]
    width = letter_row.size
    counts = np.zeros(width, np.int64)
    for k in range(n_words):
        r = row_of_block[wb[k]]
        c = wl[k]
        if r < 0 or c == _G or c == _M or c == n_letter or (c == _T and tool_row[r]):
            continue
        counts[letter_row[c]] += 1
    for r in range(n):
        if tool_row[r]:
            letter[r] = _T
    slot = np.zeros(width, np.int64)
    n_present = 0
    for j in range(width):
        if counts[j] > 0:
            slot[j] = n_present
            n_present += 1
    present = np.empty(n_present, np.int64)
    for j in range(width):
        if counts[j] > 0:
            present[slot[j]] = j
    table = np.full((n_present, n), np.nan)
    seen = np.zeros((n_present, n), np.uint8)
    repeats = np.empty((0, 3), np.int64)
    found = []
    for k in range(n_words):
        r = row_of_block[wb[k]]
        c = wl[k]
        if r < 0 or c == _G or c == _M or c == n_letter or (c == _T and tool_row[r]):
            continue
        j = slot[letter_row[c]]
        if seen[j, r] == 0:
            table[j, r] = wv[k]
            seen[j, r] = 1
        elif seen[j, r] == 1:  # the second word of the letter: the one the diagnostic points at
            seen[j, r] = 2
            found.append((r, j, k))
    if len(found):
        repeats = np.empty((len(found), 3), np.int64)
        for i in range(len(found)):
            repeats[i, 0], repeats[i, 1], repeats[i, 2] = found[i]
    return letter, code_value, present, table, repeats
