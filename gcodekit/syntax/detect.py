"""Syntax stage: guess a program's flavor from its first lines.

Each flavor file's ``[detect]`` rules turn evidence into points (see
:func:`detect_flavor`); the highest score wins and ties go to the higher
``priority``.  Like xarray's ``guess_can_open``, detection only looks at the
head of the file, so it is cheap enough to run on every open.
"""

from __future__ import annotations

import functools
import os
import re
from dataclasses import dataclass, field

from .flavor import DetectRules, Flavor
from .loader import list_flavors, load_flavor

#: Detection reads at most this much of the text it is given.
HEAD_CHARS = 64 * 1024
HEAD_LINES = 4000

#: Points per piece of evidence.  A header match (slicer banner, dialect-only
#: command) outweighs any number of shared codes a short head can hold; what
#: the dialect cannot read (``against``) outweighs a header and what else a
#: short head holds.  The file name is weak evidence: tools name files as
#: their users like (CAM posts write ``.gcode``, slicers ``.nc``), so the
#: dialect's own extension (``.ngc``) only tips a balance the content left
#: even, and alone stays below :data:`MIN_SCORE`; one unrelated dialects
#: share (``.nc``, ``.tap``) counts less still.
HEADER_POINTS = 10.0
AGAINST_POINTS = 20.0
EXTENSION_POINTS = 2.0
SHARED_EXTENSION_POINTS = 0.5
HINT_POINTS = 3.0
E_WORD_POINTS = 2.0
CODE_POINTS = 1.0
COMMENT_POINTS = 1.0
#: A header's line is quoted in the reasons up to this many characters.
_SHOWN_CHARS = 60
#: Below this best score the evidence is too thin and a default is used.
MIN_SCORE = 3.0
#: Below this best score (less than a header or a unique extension) the choice is weak.
STRONG_SCORE = 10.0
#: Candidates within this many points of the winner are reported as close.
CLOSE_POINTS = 1.0
#: With fewer moves than this in the head and nothing else to go by, the file extension picks the default.
FEW_MOVES = 10

_COMMENTS = re.compile(r"\([^()\n]*\)|;[^\n]*")
_GM_CODE = re.compile(r"(?<![A-Za-z_#<])([GgMm])[ \t]*0*(\d+(?:\.\d+)?)")
# Extended commands and wizards start a line with two letters: PRINT_START, Pocket.
_NAME = re.compile(r"^[ \t]*([A-Za-z_]{2}\w*)", re.M)
# An E word after a G0-G3 on its line, found in two linear searches (one regex with both
# backtracks over every pair of positions: minutes on one long line)
_MOVE_CODE = re.compile(r"\b[Gg]0*[0-3]\b")
_E_AFTER = re.compile(r"[ \t][Ee][-+]?\.?\d")
# A move line: G0-G3, or an axis word opening the line (the motion mode in force moves it)
_MOVE_LINE = re.compile(r"(?im)^[ \t]*(?:N\d+[ \t]*)?(?:G0*[0-3](?![\d.])|[XYZ][ \t]*[-+.\d])")


@dataclass(frozen=True)
class Detection:
    """The outcome of :func:`detect_flavor`.

    Attributes
    ----------
    name : str
        The chosen flavor.
    score : float
        Its points (0 when a default was used for lack of evidence).
    reasons : tuple of str
        The evidence for the choice, in words.
    candidates : tuple of (str, float)
        Every flavor that scored, best first.
    weak : bool
        The evidence is thin: a default was used, the winner scored less
        than a header's worth, or a flavor on other evidence came close.
    """

    name: str
    score: float
    reasons: tuple[str, ...]
    candidates: tuple[tuple[str, float], ...]
    weak: bool = False

    def rules_out(self, flavor: Flavor) -> bool:
        """The evidence names a dialect ``flavor`` cannot read: a header's worth of points
        (:data:`STRONG_SCORE`) for a flavor that is neither ``flavor`` nor one it inherits from (Klipper
        reads Marlin's programs, Marlin not Klipper's), and no candidate within :data:`CLOSE_POINTS` of it
        that is (Cura's ``;FLAVOR:Marlin`` beside Klipper's ``START_PRINT`` does not rule Marlin out)."""
        if self.score < STRONG_SCORE:
            return False
        readable = {flavor.name, *flavor.lineage}
        return all(name not in readable for name, score in self.candidates if score >= self.score - CLOSE_POINTS)

    @property
    def evidence(self) -> tuple[str, ...]:
        """The reasons that carry the choice: the header matches (a slicer banner, a dialect-only
        command), else every reason but the close candidates."""
        headers = tuple(r for r in self.reasons if r.startswith("header"))
        return headers or tuple(r for r in self.reasons if not r.startswith("close candidates"))


@dataclass(frozen=True)
class _Rules:
    name: str
    priority: int
    header: tuple[re.Pattern[str], ...]
    hints: tuple[re.Pattern[str], ...]
    against: tuple[re.Pattern[str], ...]
    codes: frozenset[str]
    extensions: tuple[str, ...]
    shared_extensions: tuple[str, ...]
    comment: str
    extrudes: bool


@functools.lru_cache(maxsize=1)
def _all_rules() -> tuple[_Rules, ...]:
    rules = []
    for name in list_flavors():
        flavor = load_flavor(name)
        d = flavor.detect
        rules.append(
            _Rules(
                name,
                d.priority,
                tuple(re.compile(p) for p in d.header),
                tuple(re.compile(p) for p in d.hints),
                tuple(re.compile(p) for p in d.against),
                frozenset(d.codes),
                d.extensions,
                d.shared_extensions,
                d.comment,
                "e" in flavor.words.values(),
            )
        )
    return tuple(rules)


def _codes_in(text: str) -> set[str]:
    """Normalized codes (``G1``, ``M104``, ``PRINT_START``) outside comments."""
    bare = _COMMENTS.sub("", text)
    codes = {f"{m[1].upper()}{m[2]}" for m in _GM_CODE.finditer(bare)}
    codes.update(m[1].upper() for m in _NAME.finditer(bare))
    return codes


def _comment_style(lines: list[str]) -> str:
    semi = sum(";" in line for line in lines)
    paren = sum("(" in line for line in lines)
    return ";" if semi > paren else "(" if paren > semi else ""


@dataclass(frozen=True)
class _Evidence:
    """What the head of a program shows, read once for every flavor's rules."""

    head: str
    bare: str  # the head without comments
    codes: set[str]
    style: str  # the comment style most lines use
    suffix: str
    e_words: bool = False  # E words on moves (see _e_words_on_moves)
    moves: int = 0  # move lines in the head (see _MOVE_LINE)
    found: dict[tuple[str, bool], re.Match[str] | None] = field(default_factory=dict, compare=False)

    def matches(self, pattern: re.Pattern[str], bare: bool = False) -> bool:
        """Whether ``pattern`` occurs in the head (``bare``: without comments), searched once for all the
        flavors whose rules share it (five printer flavors' ``against`` tool change, for one)."""
        key = (pattern.pattern, bare)
        if key not in self.found:
            self.found[key] = pattern.search(self.bare if bare else self.head)
        return self.found[key] is not None

    def where(self, pattern: re.Pattern[str]) -> str:
        """The head's line ``pattern`` matched first (after :meth:`matches`), quoted, and its number."""
        match = self.found[(pattern.pattern, False)]
        start = self.head.rfind("\n", 0, match.start()) + 1
        end = self.head.find("\n", match.end())
        line = self.head[start:end if end >= 0 else len(self.head)].strip()
        shown = line if len(line) <= _SHOWN_CHARS else line[:_SHOWN_CHARS] + "..."
        return f"{shown!r} on line {self.head.count(chr(10), 0, start) + 1}"


def _e_words_on_moves(bare: str) -> bool:
    """Whether some line has an E word after a G0-G3 (an extruding move)."""
    for line in bare.splitlines():
        move = _MOVE_CODE.search(line)
        if move and _E_AFTER.search(line, move.end()):
            return True
    return False


def _score(rules: DetectRules, evidence: _Evidence) -> tuple[float, list[str]]:
    """Points of one flavor's rules against the evidence, and why (see :func:`detect_flavor`)."""
    score, reasons = 0.0, []
    for pattern in rules.header:
        if evidence.matches(pattern):
            score += HEADER_POINTS
            reasons.append(f"header {evidence.where(pattern)}")
    for pattern in rules.against:
        if evidence.matches(pattern):
            score -= AGAINST_POINTS
            reasons.append(f"against: text matches /{pattern.pattern}/")
    for pattern in rules.hints:
        if evidence.matches(pattern, bare=True):
            score += HINT_POINTS
            reasons.append(f"code matches /{pattern.pattern}/")
    suffix = evidence.suffix
    if suffix and suffix in rules.extensions:
        score += EXTENSION_POINTS
        reasons.append(f"file extension {suffix}")
    elif suffix and suffix in rules.shared_extensions:
        score += SHARED_EXTENSION_POINTS
        reasons.append(f"file extension {suffix} (other dialects use it too)")
    if evidence.e_words and rules.extrudes:
        score += E_WORD_POINTS
        reasons.append("E words on moves")
    typical = sorted(rules.codes & evidence.codes)
    if typical:
        score += CODE_POINTS * len(typical)
        reasons.append(f"typical codes {', '.join(typical)}")
    if evidence.style and evidence.style == rules.comment:
        score += COMMENT_POINTS
        reasons.append(f"{evidence.style!r} comments")
    return score, reasons


def detect_flavor(text_head: str, filename: str | os.PathLike[str] | None = None) -> Detection:
    """Guess the flavor of a program from its head and file name.

    Points per flavor: 10 for each ``[detect] header`` regex found (slicer
    banners such as ``;FLAVOR:Marlin``, dialect-only syntax such as
    LinuxCNC's ``o<name> sub`` and ``#<name>`` or Klipper's
    ``PRINT_START``), 20 taken away for each ``against`` regex found (text
    the dialect cannot read so: words after ``;`` in Fanuc, a line that is
    only a parenthesised comment in a printer firmware), 2 for one of the
    flavor's file extensions (``.ngc``) and 0.5 for one it shares with
    other dialects (``.nc``, ``.tap``) -- the name alone never decides --,
    3 for each ``hints`` regex found in the code, 2 for E words on moves if
    the flavor extrudes, 1 for each typical code present and 1 for the usual
    comment style.  The best score wins; equal scores go to the higher
    ``priority``.  Below 3 points the evidence is too thin and a default is
    used: ``"marlin"`` for programs with E words on moves and without
    parenthesised comments, the flavor the file extension names when the
    head holds fewer than 10 moves (an empty ``.gcode`` file),
    ``"rs274ngc"`` (the reference language) otherwise.  The choice is
    ``weak`` below 10 points (unless the file has the winner's own
    extension, which confirms it) or with a candidate on other headers
    within a point of the winner.

    Parameters
    ----------
    text_head : str
        The start of the program; only the first 64 KiB and 4000 lines are
        read.
    filename : str or path-like, default: None
        Its file name, whose suffix is evidence too.

    Returns
    -------
    Detection
        The name, its score, the reasons and every candidate that scored.

    See Also
    --------
    guess_flavor : the same, returning the loaded Flavor.

    Examples
    --------
    A Cura banner names the firmware.

    >>> d = detect_flavor(";FLAVOR:Marlin\\nM82\\nG1 X1 E0.5\\n")
    >>> d.name, d.candidates[0][0]
    ('marlin', 'marlin')
    """
    lines = text_head[:HEAD_CHARS].splitlines()[:HEAD_LINES]
    head = "\n".join(lines)
    bare = _COMMENTS.sub("", head)
    evidence = _Evidence(head, bare, _codes_in(head), _comment_style(lines),
                         os.path.splitext(os.fspath(filename))[1].lower() if filename is not None else "",
                         _e_words_on_moves(bare), len(_MOVE_LINE.findall(bare)))
    e_words, style = evidence.e_words, evidence.style
    scored = []
    for rules in _all_rules():
        score, reasons = _score(rules, evidence)
        scored.append((score, rules.priority, rules.name, reasons))

    scored.sort(key=lambda s: (-s[0], -s[1], s[2]))
    candidates = tuple((name, score) for score, _, name, _ in scored if score > 0)
    best_score, _, best, reasons = scored[0]
    if best_score < MIN_SCORE:
        unread = {name for score, _, name, _ in scored if score < 0}  # text the flavor cannot read
        by_name = _extension_default(evidence.suffix, unread) if evidence.moves < FEW_MOVES else None
        if e_words and style != "(":
            default, why = "marlin", "E words on moves"
        elif by_name is not None:
            default, why = by_name, f"file extension {evidence.suffix}, with too few moves to tell"
        else:
            default, why = "rs274ngc", "the reference language"
        return Detection(
            default,
            0.0,
            (f"no flavor scored {MIN_SCORE:g} points; default {default!r} ({why})",),
            candidates,
            weak=True,
        )
    close = [(n, s) for n, s in candidates[1:] if s >= best_score - CLOSE_POINTS]
    if close:
        listed = ", ".join(f"{n} ({s:g})" for n, s in close)
        by = "priority" if close[0][1] == best_score else "score"
        reasons = [*reasons, f"close candidates: {listed}; chose {best!r} by {by}"]
    # a close candidate on the same headers is a relative (Klipper's banners are Marlin's): no doubt there
    headers = {name: {r for r in why if r.startswith("header")} for _, _, name, why in scored}
    rival = any(headers[name] != headers[best] for name, _ in close)
    # the dialect's own extension (.ngc) does not decide, but it confirms what the content chose
    confirmed = any(r.name == best and evidence.suffix in r.extensions for r in _all_rules())
    return Detection(best, best_score, tuple(reasons), candidates,
                     weak=rival or (best_score < STRONG_SCORE and not confirmed))


def _extension_default(suffix: str, unread: set[str]) -> str | None:
    """The flavor a file name suggests when nothing else does: its own extension first, then a shared one
    (never one in ``unread``, whose ``against`` rules matched)."""
    for field in ("extensions", "shared_extensions"):
        claims = [r for r in _all_rules() if suffix and suffix in getattr(r, field) and r.name not in unread]
        if claims:
            return max(claims, key=lambda r: (r.priority, r.name)).name
    return None


def guess_flavor(text_head: str, filename: str | os.PathLike[str] | None = None) -> Flavor:
    """Load the flavor :func:`detect_flavor` chooses.

    Examples
    --------
    >>> guess_flavor("(Part name: Dome)\\n#TRAFO ON\\nG00 X1 Y2 Z3\\n").name
    'beckhoff_ded'
    """
    return load_flavor(detect_flavor(text_head, filename).name)
