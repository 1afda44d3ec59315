"""Read stage, fast path: bytes of many lines to words with NumPy, no Python per line.

A line is *regular* when, outside its line comment, it holds only letters
each followed by a plain decimal number (``G1 X10.5 Y-3 E.02``).  Those
lines are cut and their numbers converted here in bulk; every other line
(paren comments, parameters, checksums, named commands, anything odd) is
returned as *irregular* for :class:`~.tokenize.LineTokenizer`, which knows
every rule.

Numbers are converted exactly: the digits of a word form an integer below
2**53, summed exactly in float64, and the value is that integer divided by
``10**n_fraction_digits`` -- one correctly rounded IEEE division, so the
result equals Python's ``float(text)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..syntax import Flavor

_MAX_DIGITS = 15  # keeps the integer below 2**53, exact in float64
_POW10 = 10.0 ** np.arange(23)

# Byte classes.
_OTHER, _UPPER, _LOWER, _DIGIT, _DOT, _SIGN, _BLANK, _NEWLINE, _COMMENT = range(9)


def _byte_classes(flavor: Flavor) -> np.ndarray:
    table = np.full(256, _OTHER, np.uint8)
    table[ord("A") : ord("Z") + 1] = _UPPER
    table[ord("a") : ord("z") + 1] = _LOWER
    table[ord("0") : ord("9") + 1] = _DIGIT
    table[ord(".")] = _DOT
    table[[ord("+"), ord("-")]] = _SIGN
    table[[ord(" "), ord("\t"), ord("\r")]] = _BLANK
    table[ord("\n")] = _NEWLINE
    for c in flavor.line_comments:
        if len(c) == 1 and ord(c) < 128:
            table[ord(c)] = _COMMENT
    return table


def _string_code_keys(flavor: Flavor) -> np.ndarray:
    """The flavor's string codes keyed as :func:`scan` keys words: letter * 10**6 + tenths."""
    keys = []
    for code in flavor.string_codes:
        whole, _, tenth = code[1:].partition(".")
        keys.append(ord(code[0].upper()) * 1_000_000 + int(whole) * 10 + int(tenth or 0))
    return np.array(keys, np.int64)


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


def scan(data: bytes, flavor: Flavor, max_line_length: int | None = None) -> ScanResult:
    """Cut ``data`` (whole lines, ending with ``\\n``) into words and comments.

    Lines longer than ``max_line_length`` are left irregular, for the
    tokenizer to report.
    """
    b = np.frombuffer(data, dtype=np.uint8)
    cls = _byte_classes(flavor)[b]
    nl = np.flatnonzero(cls == _NEWLINE)
    n_lines = nl.size
    line_start = np.r_[0, nl[:-1] + 1] if n_lines else np.zeros(0, np.int64)

    # Line comments run from the first comment character to the end of the line.
    marks = np.flatnonzero(cls == _COMMENT)
    mark_line = np.searchsorted(nl, marks)
    first = np.r_[True, mark_line[1:] != mark_line[:-1]] if marks.size else np.zeros(0, bool)
    c_start, c_line = marks[first], mark_line[first]
    c_end = nl[c_line]
    keep = cls != _BLANK
    keep[_ranges(c_start, c_end)] = False

    pos = np.flatnonzero(keep)
    del keep
    c = cls[pos]
    ob = b[pos]
    is_nl = c == _NEWLINE
    is_letter = (c == _UPPER) if flavor.case_sensitive else ((c == _UPPER) | (c == _LOWER))
    is_num = (c >= _DIGIT) & (c <= _SIGN)
    cline = np.cumsum(is_nl, dtype=np.int32)
    cline -= is_nl  # a newline belongs to the line it ends

    prev_letter = np.r_[False, is_letter[:-1]]
    prev_num = np.r_[False, is_num[:-1]]
    bad = ~(is_letter | is_num | is_nl)  # other bytes, or lower case where that is not a word
    bad |= is_num & ~(prev_letter | prev_num)  # a number with no letter before it
    bad |= is_letter & ~np.r_[is_num[1:], False]  # a letter without a number (flag, name)
    bad |= (c == _SIGN) & ~prev_letter  # a sign inside a number
    line_ok = np.ones(n_lines, dtype=bool)
    line_ok[cline[bad]] = False
    if max_line_length is not None and n_lines:
        line_ok &= np.diff(np.r_[line_start, nl[-1] + 1]) - 1 <= max_line_length
    del bad, prev_letter, prev_num

    # Segments start at each letter and each newline, so no word runs into
    # the next line; the segments that start with a letter are the words.
    head = is_letter | is_nl
    heads = np.flatnonzero(head)
    segment = np.cumsum(head, dtype=np.int32)
    segment -= 1
    n_seg = heads.size
    seg_end = np.r_[heads[1:], c.size] - 1
    is_digit = c == _DIGIT
    digits_upto = np.cumsum(is_digit, dtype=np.int32)
    nums_upto = np.cumsum(is_num, dtype=np.int32)
    digit_end = digits_upto[seg_end]  # digits up to the end of each segment
    words = np.flatnonzero(is_letter[heads])
    starts = heads[words]
    token_line = cline[starts]
    n_digits = digit_end[words] - digits_upto[starts]
    n_chars = nums_upto[seg_end[words]] - nums_upto[starts]
    dots = np.flatnonzero(c == _DOT)
    dot_seg = segment[dots]
    dots, dot_seg = dots[dot_seg >= 0], dot_seg[dot_seg >= 0]
    n_dots = np.bincount(dot_seg, minlength=n_seg)[words]
    token_bad = (n_digits == 0) | (n_digits > _MAX_DIGITS) | (n_dots > 1)
    if not flavor.spaces_in_numbers:
        # Blanks are allowed between the letter and its number, not inside it.
        last = np.minimum(starts + n_chars, c.size - 1)
        after_letter = pos[np.minimum(starts + 1, c.size - 1)] - pos[starts] - 1
        token_bad |= (pos[last] - pos[starts] - n_chars) != after_letter
    line_ok[token_line[token_bad]] = False

    # Value of each word: sum of digit * 10**(digits after it in the word).
    digit_at = np.flatnonzero(is_digit)
    after = digit_end[segment[digit_at]] - np.arange(1, digit_at.size + 1, dtype=np.int32)
    np.clip(after, 0, 22, out=after)
    contrib = (ob[digit_at] - 48) * _POW10[after]
    if heads.size:
        # One trailing zero keeps every segment's first-digit index in range.
        contrib = np.append(contrib, 0.0)
        mantissa = np.add.reduceat(contrib, digits_upto[heads])[words]
        mantissa[n_digits == 0] = 0.0
    else:
        mantissa = np.zeros(0)
    frac_seg = np.zeros(n_seg, dtype=np.int32)
    frac_seg[dot_seg] = digit_end[dot_seg] - digits_upto[dots]
    value = mantissa / _POW10[np.clip(frac_seg[words], 0, 22)]
    value[ob[np.minimum(starts + 1, ob.size - 1)] == ord("-")] *= -1.0

    code_letter = ob[starts] & 0xDF
    odd_code = ((code_letter == ord("G")) | (code_letter == ord("M"))) & ~((value >= 0) & (value < 10000))
    line_ok[token_line[odd_code]] = False  # the reference tokenizer reports it
    if flavor.string_codes:  # the rest of an M23/M117 line is its argument, not words
        # only G/M numbers in range make a code key (a long digit run elsewhere is no integer)
        tenths = np.round(np.where(odd_code | ~np.isfinite(value) | (np.abs(value) >= 1e12), -1.0, value) * 10)
        codes = code_letter.astype(np.int64) * 1_000_000 + tenths.astype(np.int64)
        line_ok[token_line[np.isin(codes, _string_code_keys(flavor))]] = False

    keep_tok = line_ok[token_line]
    word_line = token_line[keep_tok]
    word_pos = pos[starts[keep_tok]]
    letters = ob[starts[keep_tok]]
    if not flavor.case_sensitive:
        letters = letters & 0xDF

    comment_keep = line_ok[c_line]
    c_start, c_line, c_end = c_start[comment_keep], c_line[comment_keep], c_end[comment_keep]
    lengths = c_end - c_start - 1
    offsets = np.zeros(lengths.size + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    return ScanResult(
        word_line=word_line,
        word_letter=letters,
        word_value=value[keep_tok],
        word_col=(word_pos - line_start[word_line] + 1).astype(np.int32),
        comment_line=c_line.astype(np.int32),
        comment_col=(c_start - line_start[c_line] + 1).astype(np.int32),
        comment_offsets=offsets,
        comment_data=b[_ranges(c_start + 1, c_end)].tobytes(),
        irregular=np.flatnonzero(~line_ok).astype(np.int32),
        line_start=line_start,
        n_lines=n_lines,
    )


def _ranges(starts: np.ndarray, stops: np.ndarray) -> np.ndarray:
    """Concatenated ``arange(start, stop)`` for each pair, without a Python loop."""
    nonempty = stops > starts
    starts, lengths = starts[nonempty], (stops - starts)[nonempty]
    if not starts.size:
        return np.zeros(0, np.int64)
    out = np.ones(int(lengths.sum()), dtype=np.int64)
    out[0] = starts[0]
    # At each range's head, jump from the previous range's last value to its start.
    out[np.cumsum(lengths)[:-1]] = starts[1:] - (starts[:-1] + lengths[:-1] - 1)
    return np.cumsum(out)
