"""Read stage, fast path compiled: the scanner of :mod:`.scan` as one loop over the bytes, with Numba.

:func:`gcodekit.read.scan.scan` does its work in about forty passes of
NumPy over a chunk (byte classes, masks, running sums, ``reduceat``), each
pass an array as long as the chunk; this is the same rule written as the
loop those passes vectorize, one line at a time, and compiled when Numba is
installed (``pip install 'gcodekit[fast]'``).  It reads a chunk in one pass
and makes no temporaries, so it is several times faster and needs no small
chunks.  The NumPy scanner stays the reference: the tests run both on the
same bytes and require identical arrays.

A line is cut into words only when it is *regular* (see :mod:`.scan`); the
loop writes a line's words as it goes and takes them back when the line
turns out irregular.  Numbers are converted as in :mod:`.scan`: the digits
as an integer below 2**53, divided once by a power of ten, so the value is
Python's ``float(text)`` to the last bit.
"""

from __future__ import annotations

import functools

import numpy as np

from ..jit import compile_loops
from ..syntax import Flavor
from .scan import (_BLANK, _COMMENT, _DIGIT, _DOT, _LOWER, _MAX_DIGITS, _NEWLINE, _POW10, _SIGN, _UPPER, ScanResult,
                   _byte_classes, _string_code_keys)

__all__ = ["compiled", "scan_compiled"]

_POW10_INT = 10 ** np.arange(_MAX_DIGITS + 1, dtype=np.int64)


@functools.lru_cache(maxsize=1)
def compiled():
    """The compiled scanner loop, or None when Numba is not installed (compiled on first use, cached on disk)."""
    loops = compile_loops(_scan_lines)
    return loops and loops[0]


@functools.lru_cache(maxsize=32)
def _flavor_tables(flavor: Flavor) -> tuple[np.ndarray, np.ndarray]:
    return _byte_classes(flavor), np.unique(_string_code_keys(flavor))


def scan_compiled(data: bytes, flavor: Flavor, max_line_length: int | None = None) -> ScanResult:
    """:func:`gcodekit.read.scan.scan` by the compiled loop (Numba must be installed: see :func:`compiled`)."""
    classes, keys = _flavor_tables(flavor)
    (word_line, word_letter, mantissa, frac, word_col, comment_line, comment_col, comment_len, comment_data, irregular,
     line_start, n_lines) = compiled()(np.frombuffer(data, np.uint8), classes, flavor.case_sensitive,
                                       flavor.spaces_in_numbers, -1 if max_line_length is None else max_line_length,
                                       keys, _POW10, _POW10_INT)
    # one correctly rounded division per word, as scan.py (the sign commutes with it)
    word_value = np.divide(mantissa, _POW10[frac], out=mantissa)
    offsets = np.zeros(comment_len.size + 1, np.int64)
    np.cumsum(comment_len, out=offsets[1:])
    return ScanResult(word_line=word_line, word_letter=word_letter, word_value=word_value, word_col=word_col,
                      comment_line=comment_line, comment_col=comment_col, comment_offsets=offsets,
                      comment_data=comment_data.tobytes(), irregular=irregular, line_start=line_start,
                      n_lines=int(n_lines))


def _scan_lines(b, classes, case_sensitive, spaces_in_numbers, max_line_length, string_keys, pow10, pow10_int):
    """The scanner's rule, line by line; see :func:`gcodekit.read.scan.scan` for what each test means.

    Returns the word columns, the comment columns (lengths, not offsets)
    with their bytes, the irregular lines, every line's start and the line
    count, all trimmed to their lengths.
    """
    size = b.size
    cap = size // 2 + 1  # a word is at least a letter and a digit
    word_line = np.empty(cap, np.int32)
    word_letter = np.empty(cap, np.uint8)
    word_mantissa = np.empty(cap, np.float64)  # the digits as an integer, signed
    word_frac = np.empty(cap, np.uint8)  # digits after the point
    word_col = np.empty(cap, np.int32)
    n_newlines = 0
    for i in range(size):
        if b[i] == 10:
            n_newlines += 1
    line_start = np.empty(n_newlines, np.int64)
    comment_line = np.empty(n_newlines, np.int32)
    comment_col = np.empty(n_newlines, np.int32)
    comment_len = np.empty(n_newlines, np.int64)
    comment_data = np.empty(size, np.uint8)
    irregular = np.empty(n_newlines, np.int32)
    nw = nc = nd = ni = 0
    start = 0
    for line in range(n_newlines):
        line_start[line] = start
        first_word = nw
        ok = True
        prev_letter = False
        prev_num = False
        in_word = False
        mantissa = 0
        n_digits = n_dots = n_chars = frac = 0
        negative = False
        last_num = -1
        contiguous = True
        letter = 0
        col = 0
        code_end = -1  # where the code ends: the line comment's first character, or the newline
        i = start
        while True:
            c = classes[b[i]]
            if c == _BLANK:
                i += 1
                continue
            if c == _COMMENT or c == _NEWLINE:
                code_end = i
                c = _NEWLINE  # the line comment runs from its first character to the end of the line
            is_letter = c == _UPPER or (c == _LOWER and not case_sensitive)
            is_num = c == _DIGIT or c == _DOT or c == _SIGN
            if is_letter or c == _NEWLINE:
                if in_word:  # close the word before this byte
                    if n_chars == 0 or n_digits == 0 or n_digits > _MAX_DIGITS or n_dots > 1:
                        ok = False
                        break
                    if not spaces_in_numbers and not contiguous:
                        ok = False
                        break
                    code_letter = letter & 0xDF
                    is_code = code_letter == 71 or code_letter == 77
                    # the value is needed here only for a G or M code's checks, or where it could pass
                    # for a string code's key; the others are divided below, all at once
                    if is_code or (string_keys.size and mantissa >= 10000 * pow10_int[frac]):
                        value = mantissa / pow10[frac] if frac else float(mantissa)
                        if negative:
                            value = -value
                        if is_code and not (value >= 0 and value < 10000):
                            ok = False  # the reference tokenizer reports it
                            break
                        if string_keys.size:
                            # as scan.py: a huge number makes no key (-1 times ten)
                            tenths = np.rint((value if abs(value) < 1e12 else -1.0) * 10.0)
                            key = np.int64(code_letter) * 1_000_000 + np.int64(tenths)
                            for k in string_keys:
                                if k == key:
                                    ok = False
                            if not ok:
                                break
                    word_line[nw] = line
                    word_letter[nw] = letter if case_sensitive else letter & 0xDF
                    word_mantissa[nw] = -float(mantissa) if negative else float(mantissa)
                    word_frac[nw] = frac
                    word_col[nw] = col
                    nw += 1
                    in_word = False
                if c == _NEWLINE:
                    break
                # a letter: a word starts; the next byte must be part of a number
                in_word = True
                letter = b[i]
                col = i - start + 1
                mantissa = 0
                n_digits = n_dots = n_chars = frac = 0
                negative = False
                contiguous = True
                last_num = -1
                prev_letter, prev_num = True, False
            elif is_num:
                if not (prev_letter or prev_num):
                    ok = False  # a number with no letter before it
                    break
                if c == _SIGN:
                    if not prev_letter:
                        ok = False  # a sign inside a number
                        break
                    negative = b[i] == 45
                elif c == _DIGIT:
                    mantissa = mantissa * 10 + (b[i] - 48) if n_digits < _MAX_DIGITS else mantissa
                    n_digits += 1
                    if n_dots:
                        frac += 1
                else:
                    n_dots += 1
                if last_num >= 0 and i != last_num + 1:
                    contiguous = False  # a blank inside the number
                last_num = i
                n_chars += 1
                prev_letter, prev_num = False, True
            else:
                ok = False  # another byte, or a lower-case letter where that is no word
                break
            i += 1
        end = i
        while b[end] != 10:
            end += 1
        if ok and in_word:
            ok = False  # a letter without a number at the end of the line
        if max_line_length >= 0 and end - start > max_line_length:
            ok = False
        if not ok:
            nw = first_word
            irregular[ni] = line
            ni += 1
        elif code_end < end:
            comment_line[nc] = line
            comment_col[nc] = code_end - start + 1
            length = end - code_end - 1
            comment_len[nc] = length
            comment_data[nd:nd + length] = b[code_end + 1:end]
            nd += length
            nc += 1
        start = end + 1
    return (word_line[:nw].copy(), word_letter[:nw].copy(), word_mantissa[:nw].copy(), word_frac[:nw].copy(), word_col[:nw].copy(),
            comment_line[:nc].copy(), comment_col[:nc].copy(), comment_len[:nc].copy(), comment_data[:nd].copy(),
            irregular[:ni].copy(), line_start, n_newlines)

