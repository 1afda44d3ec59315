"""Output: write commands back as G-code text or as table rows.

:class:`GcodeExporter` turns parsed :class:`~gcodekit.parse.commands.Command`
objects (a list, or an :class:`~gcodekit.model.operation.Operation`) into
the text of a target flavor, or into flat dict/DataFrame rows.  It uses the
same flavor files as the parser, so parsing what it writes gives back the
same commands (code, name, parameters to the printed precision, comments),
and writing in another flavor translates each command through its
normalized ``name`` (``program_end`` is ``M2`` or ``M30`` in RS274NGC).

What the target flavor cannot say is never passed on silently:

* a command with no code for its ``name`` in the target, whose code means
  nothing there either, is written as in the source after a warning comment
  (the target will treat it as a generic command);
* a command that would mean something else in the target (Marlin's ``M30``
  "delete SD file" is RS274NGC's program end), or that the target cannot
  read at all (Klipper's ``SET_VELOCITY_LIMIT`` in RS274NGC, Beckhoff's
  ``#TRAFO ON`` in Marlin), is written as a comment instead;
* words, string arguments and ``=`` values the target has no place for get
  a warning comment (words are kept: gcodekit reads any letter).

``mode="strict"`` raises :class:`GcodeExportError` at the first of these;
lenient mode also issues one :class:`UserWarning` per call that met any.
Parameter values are not converted between dialects (Marlin's ``G4 P`` is
milliseconds, RS274NGC's seconds).

Examples
--------
>>> from gcodekit.parse.commands import Move, M
>>> ex = GcodeExporter("marlin")
>>> ex.command_to_gcode(Move("G1", {"X": 10.0, "Y": -0.0000001, "F": 1200.0}, name="linear", comment="edge"))
'G1 X10 Y0 F1200 ; edge'
>>> GcodeExporter("rs274ngc").command_to_gcode(M("M30", name="program_end", comment="done"))
'M30 (done)'
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Iterable

from ..errors import Diagnostic, GcodeError, check_choice
from ..lathe_profile import written_comment
from ..parse.commands import MOTION_KINDS, Command, Kind
from ..parse.table import MOTION_NAMES
from ..syntax import Flavor, load_flavor

if TYPE_CHECKING:
    import pandas as pd

    from ..model.operation import Operation

__all__ = ["GcodeExporter", "GcodeExportError", "format_number"]

_LETTER_CODE = re.compile(r"^[GMT]\d+(\.\d+)?$")
_IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_MOTIONS = ("rapid", "linear", "arc_cw", "arc_ccw")
# Words of a move in the order machinists and slicers write them.
_MOVE_ORDER = {c: k for k, c in enumerate("XYZABCUVWIJKREF")}
_OTHER_ORDER = {c: k for k, c in enumerate("XYZABCUVWEF")}  # M201 X Y Z E; M204 P R T as given
_PAREN_SWAP = str.maketrans("()", "[]")


class GcodeExportError(GcodeError, ValueError):
    """A command cannot be written faithfully in the target flavor (strict mode)."""


def format_number(value: float, precision: int = 6) -> str:
    """A G-code number: fixed point, trailing zeros trimmed, never ``-0``.

    Parameters
    ----------
    value : float
    precision : int, default: 6
        Digits after the decimal point.

    Raises
    ------
    ValueError
        For NaN or infinity, which no controller reads.

    Examples
    --------
    >>> format_number(1.50), format_number(-1e-9), format_number(1e20), format_number(2.0000004)
    ('1.5', '0', '100000000000000000000', '2')
    """
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write {value} as a G-code number")
    text = f"{value:.{precision}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "", "-") else text


@dataclass
class _State:
    """What carries from one command to the next while writing a program."""

    source: Flavor | None = None
    motion: str = ""          # motion mode in force in the source
    target_motion: str = ""   # motion mode the target's reader will have
    number: int = 0           # last line number written
    warned: set[str] = field(default_factory=set)
    problems: list[str] = field(default_factory=list)
    file: str = "<commands>"


class GcodeExporter:
    """Write commands as G-code of one flavor, or as flat table rows.

    Parameters
    ----------
    flavor : str or Flavor, default: "rs274ngc"
        Target dialect: its comment syntax, codes, line numbers, checksums.
    precision : int, default: 6
        Digits after the decimal point of parameter values.
    line_numbers : bool, default: False
        Number the lines (``N1``, ``N2``, ...); comment lines, named
        commands and directives are not numbered.
    comments : bool, default: True
        Write comments (the program's and the exporter's warnings).
    checksum : bool, default: False
        Marlin/RepRapFirmware host protocol: ``N<n> ... *<xor>`` on every
        numbered line (implies ``line_numbers``); a comment follows the
        checksum.  Number 1 comes first, as Marlin expects after a reset.
    mode : {"lenient", "strict"}, default: "lenient"
        Strict raises :class:`GcodeExportError` when a command cannot be
        written faithfully; lenient writes a warning comment instead.

    Raises
    ------
    ConfigError
        For an unknown flavor or mode, line numbers in a flavor without
        them, or checksums in a flavor without the host protocol.

    See Also
    --------
    gcodekit.parse_program : reads what this writes.

    Examples
    --------
    A Marlin program written for LinuxCNC keeps its moves, and a warning
    counts what LinuxCNC has no code for:

    >>> import gcodekit, warnings
    >>> op = gcodekit.parse_program("G1 X10 F600 ; go\\nM104 S200\\n", flavor="marlin")
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     text = GcodeExporter("rs274ngc").to_gcode(op)
    >>> print(text, end="")
    G1 X10 F600 (go)
    (gcodekit: M104 [set_hotend_temp] has no rs274ngc code; written as in the source)
    M104 S200
    >>> print(caught[0].message)
    1 problem(s) writing rs274ngc: M104 [set_hotend_temp] has no rs274ngc code; written as in the source
    """

    def __init__(self, flavor: str | Flavor = "rs274ngc", *, precision: int = 6, line_numbers: bool = False,
                 comments: bool = True, checksum: bool = False, mode: str = "lenient"):
        from ..errors import ConfigError

        self.flavor = flavor if isinstance(flavor, Flavor) else load_flavor(flavor)
        if not isinstance(precision, int) or not 0 <= precision <= 15:
            raise ConfigError(f"precision={precision!r} must be an integer from 0 to 15")
        self.precision = precision
        self.mode = check_choice("mode", mode, ("lenient", "strict"))
        self.comments = bool(comments)
        self.checksum = bool(checksum)
        self.line_numbers = bool(line_numbers) or self.checksum
        fl = self.flavor
        if self.checksum and not fl.checksum:
            raise ConfigError(f"flavor {fl.name!r} has no host-protocol checksums (marlin and reprapfirmware do)")
        if self.line_numbers and not fl.line_number_letter:
            raise ConfigError(f"flavor {fl.name!r} has no line numbers")

    def __repr__(self) -> str:
        return f"GcodeExporter({self.flavor.name!r}, precision={self.precision})"

    # -- text -----------------------------------------------------------------

    def command_to_gcode(self, cmd: Command) -> str:
        """One command as G-code text of the target flavor.

        Usually one line; a warning comment, or a comment that cannot share
        the command's line (``M117`` messages, directives), goes on a line
        before it.  With line numbers the command's source ``line`` is used.

        Examples
        --------
        >>> from gcodekit.parse.commands import Config
        >>> GcodeExporter("klipper").command_to_gcode(Config("SET_VELOCITY_LIMIT", text="ACCEL=500", name="set_accel"))
        'SET_VELOCITY_LIMIT ACCEL=500'
        """
        state = _State(number=max(cmd.line, 1) - 1)
        lines = self._lines(cmd, state, deleted=False)
        self._warn(state)
        return "\n".join(lines)

    def to_gcode(self, commands: "Operation | Iterable[Command]", *, source_flavor: str | Flavor | None = None) -> str:
        """A whole program as G-code text of the target flavor.

        Parameters
        ----------
        commands : Operation or iterable of Command
        source_flavor : str or Flavor, default: the operation's flavor
            Dialect the commands were read in.  It tells a code the source
            did not know from one with no name given (a hand-made
            ``Command("G1")``), and the motion mode a program starts in.

        Returns
        -------
        str
            One line per command (plus warning comments), ending in a newline.
        """
        table = getattr(commands, "table", None)
        source = source_flavor if source_flavor is not None else getattr(commands, "flavor", None)
        if isinstance(source, str):
            source = load_flavor(source)
        state = _State(source=source, motion=source.initial_motion if source else "",
                       target_motion=self.flavor.initial_motion, file=getattr(commands, "file", "<commands>"))
        deleted = set(table.deleted.tolist()) if table is not None else set()
        motion_col = table.motion if table is not None else None
        items = commands.commands if table is not None else commands
        out: list[str] = []
        cycle = ""  # the last canned cycle: the table's motion column says only "a cycle"
        for i, cmd in enumerate(items):
            if cmd.name.startswith("cycle_"):
                cycle = cmd.name
            if motion_col is not None:  # exact, G53 G0 included
                k = int(motion_col[i])
                mode = MOTION_NAMES[k] if k < len(MOTION_NAMES) else cycle
                state.motion = "linear" if mode == "feed" else mode
            else:
                state.motion = _next_motion(state.motion, cmd.name)
            out.extend(self._lines(cmd, state, deleted=i in deleted))
        self._warn(state)
        return "\n".join(out) + "\n" if out else ""

    # -- rows -----------------------------------------------------------------

    def command_to_dict(self, cmd: Command) -> dict:
        """One command as a flat row: line, code, name, kind, each parameter, comment, text.

        Examples
        --------
        >>> from gcodekit.parse.commands import MoveExtrude
        >>> GcodeExporter("marlin").command_to_dict(MoveExtrude("G1", {"X": 1.0, "E": 0.5}, line=3, name="linear"))
        {'line': 3, 'code': 'G1', 'name': 'linear', 'kind': 'move_extrude', 'X': 1.0, 'E': 0.5, 'comment': None, 'text': ''}
        """
        row: dict = {"line": cmd.line, "code": cmd.code, "name": cmd.name, "kind": cmd.kind.name.lower()}
        row.update(cmd.params)
        row["comment"] = written_comment(cmd.comment, cmd.profile)  # a lathe cycle's profile goes as written
        row["text"] = cmd.text
        return row

    def to_dataframe(self, commands: "Operation | Iterable[Command]") -> "pd.DataFrame":
        """Commands as a DataFrame, one row per command (see :meth:`command_to_dict`).

        Parameter columns are floats, NaN where a command has no such word,
        in the order X Y Z A B C U V W I J K R E F then alphabetical;
        ``kind`` is categorical like ``Operation.to_dataframe``.
        """
        import pandas as pd

        items = commands.commands if hasattr(commands, "table") else commands
        rows = [self.command_to_dict(c) for c in items]
        fixed = ("line", "code", "name", "kind", "comment", "text")
        letters = sorted({k for r in rows for k in r if k not in fixed},
                         key=lambda k: (_MOVE_ORDER.get(k, len(_MOVE_ORDER)), k))
        frame = pd.DataFrame({
            "line": pd.array([r["line"] for r in rows], dtype="int64"),
            "code": pd.Series([r["code"] for r in rows], dtype=object),
            "name": pd.Series([r["name"] for r in rows], dtype=object),
            "kind": pd.Categorical([r["kind"] for r in rows], categories=[k.name.lower() for k in Kind]),
        })
        for k in letters:
            frame[k] = pd.Series([r.get(k, math.nan) for r in rows], dtype="float64")
        frame["comment"] = pd.Series([r["comment"] for r in rows], dtype=object)
        frame["text"] = pd.Series([r["text"] for r in rows], dtype=object)
        return frame

    # -- one command ----------------------------------------------------------

    def _lines(self, cmd: Command, state: _State, *, deleted: bool) -> list[str]:
        fl = self.flavor
        problems: list[str] = []
        before: list[str] = []
        code = cmd.code
        if not code and not cmd.params and not cmd.text:  # a comment line (or nothing)
            return [self._comment_line(cmd.comment)] if self.comments and cmd.comment is not None else []

        skip = None
        extra_motion = ""
        if not code:
            if cmd.kind in MOTION_KINDS and state.motion and (
                    fl.block_split == "single" or state.target_motion != state.motion):
                code = self._code_for(state.motion)
                if code is None:
                    skip = f"{state.motion} moves have no {fl.name} code"
        elif _LETTER_CODE.match(code):
            code, skip = self._translate(cmd, state, problems)
            if (code and cmd.name == "machine_coordinates" and fl.block_split == "modal"
                    and state.motion in ("rapid", "linear")):
                extra_motion = self._code_for(state.motion) or ""  # LinuxCNC: G53 needs G0 or G1
        elif not self._readable_named(code):
            skip = f"{fl.name} cannot read {code!r}"
        elif cmd.name and fl.codes.get(code.upper()) != cmd.name:
            problems.append(f"{code} [{cmd.name}] has no {fl.name} code; written as in the source")

        source_text = _source_text(cmd, self.precision)
        if skip is not None:
            self._problem(f"skipped {source_text!r}: {skip}", cmd, state, dedupe=False, out=before)
            return before

        words = self._words(cmd, code, problems)
        if extra_motion:
            words.insert(1, extra_motion)
        body = " ".join(words)
        name = fl.codes.get(code.upper() if code and not _LETTER_CODE.match(code) else code)
        state.target_motion = _next_motion(state.target_motion, name or "")
        if extra_motion:
            state.target_motion = state.motion

        # a lathe cycle's profile is written after its comment, so the output runs without the subroutine
        comment = written_comment(cmd.comment, cmd.profile) if self.comments else None
        shares_line = not (code in ("M117", "M118") and code in fl.string_codes) and not (
            code and not _LETTER_CODE.match(code) and (fl.wizards or code.startswith(fl.directive_prefix or "\0")))
        if comment is not None and not shares_line:
            before.append(self._comment_line(comment))
            comment = None
        for p in problems:
            self._problem(p, cmd, state, dedupe=True, out=before)

        named = bool(code) and not _LETTER_CODE.match(code)
        if self.line_numbers and not named and body:
            state.number += 1
            body = f"{fl.line_number_letter}{state.number} {body}"
        if deleted and fl.block_delete:
            body = "/" + body
        if self.checksum and not named and body:
            if cmd.text:  # gcodekit's reader (unlike Marlin) would take '*nn' into 'U3.13.0'
                body += " "
            body = f"{body}*{_xor(body)}"
        if comment is not None:
            body = f"{body} {self._comment(comment)}" if body else self._comment_line(comment)
        return before + [body]

    def _translate(self, cmd: Command, state: _State, problems: list[str]) -> tuple[str, str | None]:
        """Target code of a G/M/T command, or a reason to skip it."""
        fl, code, name = self.flavor, cmd.code, cmd.name
        here = fl.command(code)
        if not name:
            known_in_source = state.source is not None and state.source.command(code) is not None
            if here and state.source is not None and not known_in_source:
                return code, f"{code} is not a {state.source.name} code but means {here} in {fl.name}"
            return code, None
        if here == name:
            return code, None
        best = self._code_for(name)
        if best is not None:
            return best, None
        if here is None:
            problems.append(f"{code} [{name}] has no {fl.name} code; written as in the source")
            return code, None
        return code, f"{name} has no {fl.name} code and {code} means {here} there"

    def _code_for(self, name: str) -> str | None:
        """The plainest G/M code of the target for a normalized name (``M2`` before ``M30``)."""
        codes = [c for c in self.flavor.codes_for(name) if _LETTER_CODE.match(c)]
        if not codes:
            return None
        return min(codes, key=lambda c: (len(c), "." in c, c))

    def _readable_named(self, code: str) -> bool:
        fl = self.flavor
        if fl.directive_prefix and code.startswith(fl.directive_prefix):
            return True
        return bool(_IDENTIFIER.match(code)) and (fl.extended_commands or fl.wizards)

    def _words(self, cmd: Command, code: str, problems: list[str]) -> list[str]:
        fl = self.flavor
        head = code
        params = dict(cmd.params)
        value = params.pop("value", None)
        if value is not None:
            if fl.code_assignments and code:
                head = f"{code}={format_number(value, self.precision)}"
            else:
                problems.append(f"{fl.name} cannot give {code or 'a block'} a value with '='; value dropped")
        words = [head] if head else []
        target_name = fl.command(code) or ""
        move = not code or cmd.name in _MOTIONS or target_name in _MOTIONS or target_name.startswith("cycle_")
        order = _MOVE_ORDER if move else _OTHER_ORDER
        letters = sorted(params, key=lambda k: order.get(k, len(order)))
        for k in letters:
            if len(k) != 1 or not k.isalpha():
                problems.append(f"{fl.name} has no word for parameter {k!r}; dropped")
                continue
            if k.upper() not in fl.words:
                problems.append(f"{k} words are not {fl.name} words; written as in the source")
            words.append(f"{k.upper()}{format_number(params[k], self.precision)}")
        if cmd.text:
            named = bool(code) and not _LETTER_CODE.match(code)
            if named or fl.block_split == "single":
                words.append(cmd.text)
            else:
                problems.append(f"{fl.name} cannot read string arguments; {cmd.text!r} dropped")
        return words

    # -- comments and problems ----------------------------------------------------

    def _comment(self, text: str) -> str:
        """A comment after a command: paren style where the flavor has it."""
        fl = self.flavor
        text = " ".join(text.splitlines())
        if fl.paren_comments:
            if "(" not in text and ")" not in text:
                return f"({text})"
            if fl.line_comments:  # parens inside: a line comment keeps them
                return f"{fl.line_comments[0]} {text}"
            return f"({text.translate(_PAREN_SWAP)})"  # Fanuc, FreeCAD: no other comment syntax
        return f"{fl.line_comments[0]} {text}"

    def _comment_line(self, text: str) -> str:
        c = self._comment(text)
        return c.replace(" ", "", 1) if c[:1] in self.flavor.line_comments else c

    def _problem(self, message: str, cmd: Command, state: _State, *, dedupe: bool, out: list[str]) -> None:
        if self.mode == "strict":
            raise GcodeExportError(message, Diagnostic(state.file, cmd.line, 1, "error", message,
                                                       _source_text(cmd, self.precision)))
        state.problems.append(message)
        if dedupe:
            if message in state.warned:
                return
            state.warned.add(message)
        if self.comments:
            out.append(self._comment_line(f"gcodekit: {message}"))

    def _warn(self, state: _State) -> None:
        if state.problems:
            first = "; ".join(dict.fromkeys(state.problems[:3]))
            warnings.warn(f"{len(state.problems)} problem(s) writing {self.flavor.name}: "
                          f"{first}", UserWarning, stacklevel=3)


def _next_motion(motion: str, name: str) -> str:
    """Motion mode after a command: motion codes and canned cycles set it, G80 clears it."""
    if name in _MOTIONS or name.startswith("cycle_"):
        return name
    return "" if name == "cancel_cycle" else motion


def _xor(text: str) -> int:
    """Marlin host checksum: XOR of every byte before ``*``."""
    out = 0
    for b in text.encode("utf-8"):
        out ^= b
    return out


def _source_text(cmd: Command, precision: int) -> str:
    """The command as its source wrote it, for warnings and error messages."""
    params = dict(cmd.params)
    value = params.pop("value", None)
    head = cmd.code if value is None else f"{cmd.code}={format_number(value, precision)}"
    words = [head] if head else []
    words += [f"{k}{format_number(v, precision)}" for k, v in params.items()]
    if cmd.text:
        words.append(cmd.text)
    return " ".join(words)
