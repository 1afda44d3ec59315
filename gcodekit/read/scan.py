"""Read stage, fast path: bytes of many lines to words with NumPy, no Python per line.

A line is *regular* when, outside its ``;`` comment, it holds only letters
each followed by a plain decimal number (``G1 X10.5 Y-3 E.02``).  Those lines
are cut and their numbers converted here in bulk; every other line (paren
comments, parameters, checksums, named commands, anything odd) is returned as
*irregular* for :class:`~.tokenize.LineTokenizer`, which knows every rule.

Numbers are converted exactly: the digits form an integer mantissa below
2**53 and the value is ``mantissa / 10**n_fraction_digits``, one correctly
rounded IEEE division, so the result equals Python's ``float(text)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..syntax import Flavor

_MAX_DIGITS = 15  # below 2**53, so the mantissa is exact in float64
_POW10_INT = 10 ** np.arange(19, dtype=np.int64)
_POW10_FLOAT = 10.0 ** np.arange(23)


@dataclass
class ScanResult:
    """Words and comments of the regular lines of one chunk.

    Line indices are 0-based within the chunk; columns are 1-based.
    """

    word_line: np.ndarray
    word_letter: np.ndarray
    word_value: np.ndarray
    word_col: np.ndarray
    comment_line: np.ndarray
    comment_col: np.ndarray
    comment_offsets: np.ndarray
    comment_data: bytes
    irregular: np.ndarray
    line_start: np.ndarray
    n_lines: int


def fast_path_possible(flavor: Flavor) -> bool:
    """Flavors whose lines never depend on the line before (no GER separators)."""
    return not (flavor.statement_separators or flavor.multiline_comments)


def scan(data: bytes, flavor: Flavor) -> ScanResult:
    """Cut ``data`` (whole lines, ending with ``\\n``) into words and comments."""
    b = np.frombuffer(data, dtype=np.uint8)
    nl = np.flatnonzero(b == 10)
    n_lines = nl.size
    line_start = np.empty(n_lines, dtype=np.int64)
    if n_lines:
        line_start[0] = 0
        line_start[1:] = nl[:-1] + 1
    line_id = np.zeros(b.size, dtype=np.int32)
    line_id[line_start[1:]] = 1
    np.cumsum(line_id, out=line_id)

    comment_first, comment_line = _first_comment_chars(b, line_id, flavor)
    in_comment = np.zeros(b.size + 1, dtype=np.int8)
    np.add.at(in_comment, comment_first, 1)
    np.add.at(in_comment, nl[comment_line], -1)
    in_comment = np.cumsum(in_comment[:-1], dtype=np.int8).view(bool)

    blank = (b == 32) | (b == 9) | (b == 13)
    keep = ~(in_comment | blank)
    pos = np.flatnonzero(keep)
    cb = b[pos]
    cline = line_id[pos]
    del keep, in_comment

    if not flavor.case_sensitive:
        lower = (cb >= 97) & (cb <= 122)
        cb = cb - (lower.view(np.uint8) << 5)
    is_letter = (cb >= 65) & (cb <= 90)
    is_digit = (cb >= 48) & (cb <= 57)
    is_dot = cb == 46
    is_sign = (cb == 43) | (cb == 45)
    is_nl = cb == 10
    is_num = is_digit | is_dot | is_sign

    bad = ~(is_letter | is_num | is_nl)
    prev_letter = np.r_[False, is_letter[:-1]]
    prev_num = np.r_[False, is_num[:-1]]
    next_num = np.r_[is_num[1:], False]
    bad |= is_num & ~(prev_letter | prev_num)  # a number with no letter before it
    bad |= is_letter & ~next_num  # a letter with no number (flag, named command)
    bad |= is_sign & ~prev_letter  # a sign inside a number
    if not flavor.spaces_in_numbers:
        gap = np.r_[False, np.diff(pos) > 1]
        bad |= is_num & prev_num & gap  # "X1 0": blank inside a number
    line_ok = np.ones(n_lines, dtype=bool)
    line_ok[cline[bad]] = False
    del bad, prev_letter, prev_num, next_num

    take = line_ok[cline] & ~is_nl
    ob = cb[take]
    opos = pos[take]
    oline = cline[take]
    o_letter = is_letter[take]
    o_digit = is_digit[take]
    o_dot = is_dot[take]
    del take, cb, pos, cline, is_letter, is_digit, is_dot, is_sign, is_nl, is_num

    starts = np.flatnonzero(o_letter)
    ends = np.r_[starts[1:], ob.size] - 1
    digits_upto = np.cumsum(o_digit, dtype=np.int32)
    n_digits = digits_upto[ends] - digits_upto[starts]
    n_dots = np.add.reduceat(o_dot.view(np.uint8), starts, dtype=np.int32) if starts.size else starts
    token_bad = (n_digits == 0) | (n_digits > _MAX_DIGITS) | (n_dots > 1)
    if token_bad.any():
        line_ok[oline[starts[token_bad]]] = False

    token = np.cumsum(o_letter, dtype=np.int32) - 1
    after = digits_upto[ends][token] - digits_upto
    np.clip(after, 0, 18, out=after)
    contrib = np.where(o_digit, (ob - 48).astype(np.int64) * _POW10_INT[after], 0)
    mantissa = np.add.reduceat(contrib, starts) if starts.size else np.zeros(0, np.int64)
    del contrib, after
    n_frac = np.zeros(starts.size, dtype=np.int32)
    dots = np.flatnonzero(o_dot)
    n_frac[token[dots]] = digits_upto[ends][token[dots]] - digits_upto[dots]
    value = mantissa / _POW10_FLOAT[np.minimum(n_frac, 22)]
    negative = ob[np.minimum(starts + 1, ob.size - 1)] == 45
    value[negative] = -value[negative]

    keep_tok = line_ok[oline[starts]]
    word_line = oline[starts][keep_tok]
    word_col = (opos[starts][keep_tok] - line_start[word_line] + 1).astype(np.int32)
    comment_keep = line_ok[comment_line]
    first = comment_first[comment_keep]
    cline_kept = comment_line[comment_keep]
    data_mask = np.zeros(b.size + 1, dtype=np.int8)
    np.add.at(data_mask, first + 1, 1)
    np.add.at(data_mask, nl[cline_kept], -1)
    data_mask = np.cumsum(data_mask[:-1], dtype=np.int8).view(bool)
    lengths = nl[cline_kept] - first - 1
    offsets = np.zeros(lengths.size + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    return ScanResult(
        word_line=word_line,
        word_letter=ob[starts][keep_tok],
        word_value=value[keep_tok],
        word_col=word_col,
        comment_line=cline_kept.astype(np.int32),
        comment_col=(first - line_start[cline_kept] + 1).astype(np.int32),
        comment_offsets=offsets,
        comment_data=b[data_mask].tobytes(),
        irregular=np.flatnonzero(~line_ok).astype(np.int32),
        line_start=line_start,
        n_lines=n_lines,
    )


def _first_comment_chars(b: np.ndarray, line_id: np.ndarray, flavor: Flavor):
    """Position of the first line-comment character of each commented line.

    A ``(`` left before it is not a word character, so a line with a paren
    comment becomes irregular and the reference tokenizer, which knows how
    ``(`` and ``;`` interact, reads it.
    """
    marks = [np.flatnonzero(b == ord(c)) for c in flavor.line_comments if len(c) == 1 and ord(c) < 128]
    if not marks:
        return np.zeros(0, np.int64), np.zeros(0, np.int32)
    found = np.sort(np.concatenate(marks)) if len(marks) > 1 else marks[0]
    lines = line_id[found]
    firsts = np.r_[True, lines[1:] != lines[:-1]] if found.size else np.zeros(0, bool)
    return found[firsts], lines[firsts]
