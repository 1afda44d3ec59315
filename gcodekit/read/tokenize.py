"""Read stage, reference path: one line of text to blocks of words, in Python.

This tokenizer understands every syntax rule a :class:`~gcodekit.syntax.Flavor`
can state.  The vectorized scanner (:mod:`.scan`) handles the common lines of
large files and hands every line it is not sure about to this module, so the
two must agree; ``tests/test_read.py`` checks that they do.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..errors import Diagnostics
from ..lathe_profile import LatheProfile
from ..syntax import Flavor
from ..syntax.flavor import code_label

_DIGITS = "0123456789"
_SPACE = " \t\r\f\v"
_NO_SPACE = str.maketrans("", "", _SPACE)  # removes the blanks a number may hold (spaces_in_numbers)
#: No machine takes coordinates this large; longer numbers are typos or garbage.
_LARGEST = 1e15
#: Sinumerik 840D value assignment: an address or variable, an optional
#: ``[index]``, ``=`` and a number (``EM=1``, ``R1=2.5``, ``H[10]=1``).
_ASSIGNMENT = re.compile(r"([A-Za-z_][A-Za-z0-9_]*(?:\[\s*\d+\s*\])?)\s*=\s*([+-]?(?:\d+\.?\d*|\.\d+))")
#: Sinumerik 840D call of a cycle or subprogram with arguments: ``CYCLE832(2,_finish,1)``.
_CALL = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(")


@dataclass(slots=True)
class RawBlock:
    """One block as read from text: words, comments and rare extras.

    ``profile`` is not read from the text: it is the lathe profile the
    preprocess stage attached to the block's line (see :func:`gcodekit.read.iter_source_blocks`).
    """

    line: int
    words: list[tuple[str, float, int]] = field(default_factory=list)
    comments: list[tuple[str, int]] = field(default_factory=list)
    flags: list[tuple[str, int]] = field(default_factory=list)
    named: tuple[str, str, int] | None = None
    text: str | None = None
    code_value: float | None = None
    assignments: list[tuple[str, float, int]] = field(default_factory=list)
    deleted: bool = False
    profile: LatheProfile | None = None

    def is_empty(self) -> bool:
        return not (self.words or self.comments or self.flags or self.named or self.text or self.assignments)

    def add_text(self, text: str) -> None:
        """Keep a string argument (``M117 Hello``, ``P"MK3S"``) with the block."""
        self.text = text if not self.text else f"{self.text} {text}"


@dataclass(slots=True)
class TokenizerState:
    """What carries from one line to the next (GER's multi-line comments)."""

    open_comment: list[str] | None = None
    open_comment_start: tuple[int, int] = (0, 0)


class LineTokenizer:
    """Cut lines of one flavor into :class:`RawBlock` objects.

    Parameters
    ----------
    flavor : Flavor
    diagnostics : Diagnostics
        Receives a diagnostic for each character that cannot be read; the
        rest of the line is still read where that makes sense.
    """

    def __init__(self, flavor: Flavor, diagnostics: Diagnostics):
        self.flavor = flavor
        self.diagnostics = diagnostics
        self.state = TokenizerState()
        self._named_ok = flavor.extended_commands or flavor.wizards

    def tokenize(self, text: str, line: int) -> list[RawBlock]:
        """Blocks found on ``text`` (source ``line``, 1-based); maybe none."""
        fl = self.flavor
        block = RawBlock(line)
        blocks = [block]
        i, n = 0, len(text)
        if self.state.open_comment is not None:
            i = self._continue_comment(text, block)
            if i < 0:
                return []
        while i < n and text[i] in _SPACE:
            i += 1
        if i == n:
            return [b for b in blocks if not b.is_empty()]
        if fl.percent_delimiter and text.strip() == "%":
            return []
        if fl.directive_prefix and text.startswith(fl.directive_prefix, i):
            block.named = (text[i:].strip(), "", i + 1)
            return blocks
        if fl.block_delete and text[i] == "/":
            block.deleted = True
            i += 1
        if self._named_ok and self._starts_named(text, i):
            self._read_named(text, i, block)
            return blocks
        if fl.assignments and (call := _CALL.match(text, i)):
            i = self._read_call(text, i, call, block)
        while i < n:
            c = text[i]
            if c in _SPACE:
                i += 1
            elif c in fl.line_comments:
                block.comments.append((text[i + 1 :].strip(), i + 1))
                break
            elif c in fl.statement_separators:
                block = RawBlock(line)
                blocks.append(block)
                i += 1
            elif c == "(" and fl.paren_comments:
                i = self._paren_comment(text, i, block)
            elif c == "*" and fl.checksum:
                self._check_sum(text, i, line)
                i = self._skip_checksum(text, i)
            elif fl.assignments and (c.isalpha() or c == "_") and (found := self._assignment(text, i)):
                name, value, col, i = found
                if name in fl.words:  # "X=10" is "X10"
                    block.words.append((name, value, col))
                else:
                    block.assignments.append((name, value, col))
            elif (c.isalpha() and c.isascii() and (c.isupper() or not fl.case_sensitive)) or (
                    c in "@^" and fl.polar_words):
                i = self._word(text, i, block)
            else:
                hint = ""
                if c in "#[" and fl.parameters:
                    hint = " (parameters and expressions are evaluated by the preprocess stage)"
                self.diagnostics.report(line, i + 1, f"unexpected character {c!r}{hint}", text)
                i = self._skip_garbage(text, i)
        return [b for b in blocks if not b.is_empty() or b.deleted]

    # -- pieces -------------------------------------------------------------

    def _continue_comment(self, text: str, block: RawBlock) -> int:
        """Go on with a multi-line comment; -1 when it does not end here."""
        end = text.find(")")
        parts = self.state.open_comment
        assert parts is not None
        if end < 0:
            parts.append(text)
            return -1
        parts.append(text[:end])
        block.comments.append((" ".join(p.strip() for p in parts).strip(), 1))
        self.state.open_comment = None
        return end + 1

    def _paren_comment(self, text: str, i: int, block: RawBlock) -> int:
        end = text.find(")", i + 1)
        if end < 0:
            if self.flavor.multiline_comments:
                self.state.open_comment = [text[i + 1 :]]
                self.state.open_comment_start = (block.line, i + 1)
                return len(text)
            self.diagnostics.report(block.line, i + 1, "comment is not closed with ')'", text)
            block.comments.append((text[i + 1 :].strip(), i + 1))
            return len(text)
        body = text[i + 1 : end]
        if "(" in body:  # an error; the comment then runs to its matching ')' (or the line's end)
            self.diagnostics.report(block.line, i + 1, "nested comment", text)
            end = _matching_paren(text, i)
            body = text[i + 1 : end]
        block.comments.append((body.strip(), i + 1))
        return end + 1

    def _word(self, text: str, i: int, block: RawBlock) -> int:
        """Read a letter and its number starting at ``text[i]``."""
        fl = self.flavor
        letter = text[i].upper()
        col = i + 1
        j = i + 1
        n = len(text)
        while j < n and text[j] in _SPACE:
            j += 1
        start = j
        if j < n and text[j] in "+-":
            j += 1
        digits = 0
        dot = False
        while j < n:
            c = text[j]
            if c in _DIGITS:
                digits += 1
            elif c == "." and not dot:
                dot = True
            elif not (fl.spaces_in_numbers and c in _SPACE and digits + dot):
                break
            j += 1
        number = text[start:j].translate(_NO_SPACE)
        if fl.block_split == "single" and letter not in "GM":
            if j < n and text[j] == '"':  # firmware string argument: P"MK3S"
                end = text.find('"', j + 1)
                end = n if end < 0 else end + 1
                block.add_text(text[i:end].strip())
                return end
            if digits and j < n and (text[j] in "._" or text[j].isalnum()):
                end = j  # a version or name such as U3.13.0 is kept as text
                while end < n and not text[end].isspace() and text[end] not in fl.line_comments and not (
                        fl.checksum and text[end] == "*"):
                    end += 1
                block.add_text(text[i:end])
                return end
        if digits == 0:
            if fl.block_split == "single" and letter == "F":  # no flag: firmware reads a missing number as 0
                # and keeps its feed rate (Marlin sets it only from an F above 0)
                self.diagnostics.warn(block.line, col, "word 'F' has no number: the feed rate stays as it was", text)
                return max(j, i + 1)
            if fl.block_split == "single" and letter not in "GM" and (j >= n or not text[j].isdigit()):
                block.flags.append((letter, col))
                return max(j, i + 1)
            self.diagnostics.report(block.line, col, f"word {letter!r} has no number", text)
            return max(j, i + 1)
        value = float(number)
        if not abs(value) < _LARGEST or (letter in "GM" and not 0 <= value < 10000):
            self.diagnostics.report(block.line, col, f"number out of range for {letter}", text)
            return j
        block.words.append((letter, value, col))
        if fl.code_assignments and j < n and text[j] == "=" and letter in "GM":
            k = j + 1
            while k < n and (text[k] in _DIGITS or text[k] in ".+-"):
                k += 1
            try:
                block.code_value = float(text[j + 1 : k])
            except ValueError:
                self.diagnostics.report(block.line, j + 1, "'=' must be followed by a number", text)
            return k
        code = code_label(letter, round(value * 10))
        if code in fl.string_codes and letter in "GM":
            rest = text[j:]
            cut = min((p for p in (rest.find(c) for c in fl.line_comments) if p >= 0), default=-1)
            if code in ("M117", "M118"):  # the message is the whole rest of the line
                cut = -1
            arg = rest if cut < 0 else rest[:cut]
            star = arg.rfind("*") if fl.checksum else -1
            if star >= 0 and arg[star + 1:].strip().isdigit():  # Marlin strips the checksum first
                self._check_sum(text, j + star, block.line)
                arg = arg[:star]
            block.add_text(arg.strip())
            if cut >= 0:
                block.comments.append((rest[cut + 1 :].strip(), j + cut + 1))
            return n
        return j

    def _assignment(self, text: str, i: int) -> tuple[str, float, int, int] | None:
        """A Sinumerik ``NAME=value`` at ``text[i]``: (name, value, column, end), or None.

        A single letter the flavor maps to a parameter stays a word
        (Sinumerik also accepts ``X=10`` for ``X10``); every other name is an
        assignment to an address with an extension (``H[10]``, ``R1``) or to
        a variable or machine data (``EM``), kept for the parse stage.
        """
        m = _ASSIGNMENT.match(text, i)
        if m is None:
            return None
        name = re.sub(r"\s+", "", m.group(1)).upper()
        value = float(m.group(2))
        return name, value, i + 1, m.end()

    def _read_call(self, text: str, i: int, call: "re.Match[str]", block: RawBlock) -> int:
        """A Sinumerik cycle or subprogram call ``NAME(arguments)``, kept as a named command."""
        close = text.find(")", call.end())
        if close < 0:
            self.diagnostics.report(block.line, call.end(), f"call {call.group(1)!r} is not closed with ')'", text)
            close = len(text) - 1
        block.named = (call.group(1).upper(), text[call.end():close].strip(), i + 1)
        return close + 1

    def _starts_named(self, text: str, i: int) -> bool:
        """A name of two or more letters (``SET_VELOCITY_LIMIT``, ``Pocket``)."""
        j = i
        while j < len(text) and (text[j].isalnum() or text[j] == "_") and text[j].isascii():
            j += 1
        word = text[i:j]
        return len(word) >= 2 and word[0].isalpha() and (word[1].isalpha() or word[1] == "_")

    def _read_named(self, text: str, i: int, block: RawBlock) -> None:
        j = i
        while j < len(text) and (text[j].isalnum() or text[j] == "_"):
            j += 1
        rest = text[j:]
        if not self.flavor.wizards:  # Klipper: ';' comments still end the line
            for c in self.flavor.line_comments:
                k = rest.find(c)
                if k >= 0:
                    block.comments.append((rest[k + 1 :].strip(), j + k + 1))
                    rest = rest[:k]
        name = text[i:j] if self.flavor.wizards else text[i:j].upper()
        block.named = (name, rest.strip(), i + 1)

    def _check_sum(self, text: str, i: int, line: int) -> None:
        """Marlin host protocol: ``*n`` is the XOR of every byte before it."""
        digits = text[i + 1 : self._skip_checksum(text, i)]
        if not digits.isdigit():
            self.diagnostics.report(line, i + 1, "checksum '*' without a number", text)
            return
        expected = 0
        for b in text[:i].encode("utf-8", "replace"):
            expected ^= b
        if expected != int(digits):
            self.diagnostics.warn(line, i + 1, f"checksum {digits} does not match the line ({expected})", text)

    @staticmethod
    def _skip_checksum(text: str, i: int) -> int:
        j = i + 1
        while j < len(text) and text[j] in _DIGITS:
            j += 1
        return j

    def _skip_garbage(self, text: str, i: int) -> int:
        """Skip to the next letter, space or comment after a bad character."""
        j = i + 1
        while j < len(text) and not (text[j].isalpha() or text[j] in _SPACE or text[j] in self.flavor.line_comments or text[j] == "("):
            j += 1
        return j


def _matching_paren(text: str, start: int) -> int:
    """Index of the ')' closing the '(' at ``start``, counting nested pairs; the line's end if none."""
    depth = 0
    for k in range(start, len(text)):
        depth += {"(": 1, ")": -1}.get(text[k], 0)
        if depth == 0:
            return k
    return len(text)
