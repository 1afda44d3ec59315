"""A lathe cycle's profile as data: the blocks of its ``Q`` subroutine, read once.

G70-G72 cut along a profile the program writes as a subroutine, named by
the cycle's ``Q`` word.  rs274 reads that subroutine when the cycle runs,
so the preprocess stage (:mod:`gcodekit.preprocess.flow.lathe_profile_capture`) runs it
there and attaches what it read to the cycle's line as a
:class:`LatheProfile`.  The read stage carries it with the line's blocks,
the parse stage keeps it by row (``CommandTable.profiles``, and
``Command.profile``), the machine cuts it (:mod:`gcodekit.emulate.lathe`)
and writers put it back into text.  Every stage uses the same words, read
here once.

The written form: a cycle line may carry its profile itself, as a comment
``(g7x profile: G0 X8 Z0; G1 X16 Z-20; ...)`` -- blocks separated by ``;``
after :data:`TAG`.  gcodekit's writers (the transpiler, the G-code exporter)
write it so that their output runs without the subroutine, and the parse
stage reads it back from a cycle line whose profile was not captured.

Examples
--------
>>> profile = LatheProfile.from_text("G0 X8 Z0; g1 x16 z -20")
>>> [(w.letter, w.value) for w in profile.blocks[1].words]
[('G', 1.0), ('X', 16.0), ('Z', -20.0)]
>>> profile.text(lambda w: f"{w.letter}{w.value * 2:g}" if w.letter in "XZ" else None)
'G0 X16 Z0; g1 X32 Z-40'
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

#: Starts the written form of a profile in a cycle line's comment
TAG = "g7x profile:"

# A word as rs274 reads it once blanks are gone and letters folded: a letter and a plain number
_WORD = re.compile(r"([a-z])([-+]?(?:\d+\.?\d*|\.\d+))")
_BLANKS = frozenset(" \t\r\n\f\v")


@dataclass(frozen=True, slots=True)
class ProfileWord:
    """One word of a profile block: its letter (upper case), value and place in the block's text."""

    letter: str
    value: float
    start: int
    end: int


@dataclass(frozen=True, slots=True)
class ProfileBlock:
    """One block of the profile: its code as written (parameters substituted) and its words.

    ``text`` holds no ``;``, ``(`` or ``)``, so it can stand in the written form.
    """

    text: str
    words: tuple[ProfileWord, ...]

    @classmethod
    def read(cls, text: str) -> ProfileBlock:
        """A block with the words of ``text``, read as rs274 reads them (blanks inside words ignored)."""
        kept = [i for i, c in enumerate(text) if c not in _BLANKS]
        # only ASCII letters fold (as C's tolower), so positions stay put
        chars = "".join(text[i].lower() if text[i].isascii() else text[i] for i in kept)
        words = tuple(ProfileWord(m.group(1).upper(), float(m.group(2)), kept[m.start()], kept[m.end() - 1] + 1)
                      for m in _WORD.finditer(chars))
        return cls(text, words)


@dataclass(frozen=True, slots=True)
class LatheProfile:
    """The blocks a lathe cycle's ``Q`` subroutine gave, in order."""

    blocks: tuple[ProfileBlock, ...]

    @classmethod
    def from_text(cls, text: str) -> LatheProfile:
        """A profile from the body of its written form: blocks separated by ``;``."""
        return cls(tuple(ProfileBlock.read(piece.strip()) for piece in text.split(";")))

    def text(self, word: Callable[[ProfileWord], str | None] | None = None) -> str:
        """The body of the written form: the blocks joined by ``"; "``.

        ``word``, when given, rewrites each word: it returns the new text of
        the word, or None to keep it as written.
        """
        if word is None:
            return "; ".join(b.text for b in self.blocks)
        out = []
        for block in self.blocks:
            pieces, at = [], 0
            for w in block.words:
                new = word(w)
                if new is not None:
                    pieces += [block.text[at:w.start], new]
                    at = w.end
            out.append("".join(pieces) + block.text[at:])
        return "; ".join(out)


def written_comment(comment: str | None, profile: LatheProfile | None, body: str | None = None) -> str | None:
    """A cycle line's comment as gcodekit writes it: the program's comment, then the profile's written form.

    ``body`` replaces ``profile.text()`` (a writer that rewrites the words).
    """
    if profile is None:
        return comment
    written = f"{TAG} {profile.text() if body is None else body}"
    return f"{comment} {written}" if comment else written


def read_written(comment: str) -> tuple[str | None, LatheProfile] | None:
    """The program's own comment and the profile of a comment holding a written profile, or None."""
    if TAG not in comment:
        return None
    before, after = comment.split(TAG, 1)
    return before.strip() or None, LatheProfile.from_text(after.strip())
