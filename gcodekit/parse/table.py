"""Parse stage output: commands as columns, one row per command.

Rows are in execution order.  Parameters are float columns keyed by word
letter (NaN where a command has no such word); letters used by few rows are
kept sparse, and the words of a program's table written with a few
decimals as int32 units (:class:`DecimalColumn`).  :meth:`CommandTable.command`
builds the typed object of a row.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..columns import ColumnReader
from ..lathe_profile import LatheProfile
from ..syntax.flavor import COMMANDS, code_label
from .commands import COMMAND_CLASSES, Command, Kind

#: Normalized command names by id; id 0 is "" (no code or unknown code).
NAMES: tuple[str, ...] = ("",) + tuple(sorted(COMMANDS))
NAME_ID: dict[str, int] = {n: i for i, n in enumerate(NAMES)}

#: Motion modes carried by the ``motion`` column.
MOTION_NONE, MOTION_RAPID, MOTION_LINEAR, MOTION_CW, MOTION_CCW, MOTION_CYCLE = range(6)
MOTION_NAMES = ("", "rapid", "feed", "arc_cw", "arc_ccw")
MOTION_OF_NAME = {"rapid": MOTION_RAPID, "linear": MOTION_LINEAR, "arc_cw": MOTION_CW, "arc_ccw": MOTION_CCW}
#: Splines (G5 cubic, G5.1 quadratic, G5.2 NURBS): table motion modes only; their
#: waypoints are the chords that follow the curve (MOTION_LINEAR)
MOTION_CUBIC, MOTION_QUADRATIC, MOTION_NURBS = 6, 7, 8
SPLINE_MOTIONS = (MOTION_CUBIC, MOTION_QUADRATIC, MOTION_NURBS)
#: G33 spindle-synchronized moves: a table motion mode; the waypoint is MOTION_LINEAR
MOTION_THREAD = 9
#: Canned cycles: the command table's motion is MOTION_CYCLE (never a waypoint's)
CYCLE_NAMES = ("cycle_chip_break", "cycle_drill", "cycle_drill_dwell", "cycle_peck", "cycle_bore",
               "cycle_bore_stop", "cycle_bore_dwell", "cycle_tap", "cycle_tap_left", "cycle_back_bore",
               "cycle_bore_manual", "cycle_thread") + tuple(LATHE_CYCLE_NAMES := (
                   "lathe_finish", "lathe_rough", "lathe_rough_no_pockets", "lathe_rough_pockets",
                   "lathe_face", "lathe_face_no_pockets", "lathe_face_pockets"))

#: in_ids compares up to this many ids one by one, and looks more up in a table
_COMPARED_IDS = 8
#: A parameter present in fewer rows than this share is kept sparse: a row index and a value
#: (16 bytes) per word against 8 bytes per row (a slicer's F words: 8 -> 0.6 bytes per row)
_SPARSE_BELOW = 1 / 3


def in_ids(values: np.ndarray, ids) -> np.ndarray:
    """``np.isin(values, ids)`` for small codes (0..255, the uint8 columns).

    A few ids are compared one by one (each comparison of a uint8 column
    costs about a twentieth of a fancy-indexed lookup); more are looked up
    in a table with ``take`` (a third of the cost of ``lut[values]``).
    """
    ids = np.asarray(ids, np.int64)
    if ids.size <= _COMPARED_IDS:
        out = np.zeros(np.shape(values), bool)
        for i in set(ids.ravel().tolist()):
            out |= values == i
        return out
    lut = np.zeros(256, bool)
    lut[ids] = True
    return lut.take(values)


@dataclass
class SparseColumn:
    """A mostly-NaN column stored as sorted row indices and values."""

    rows: np.ndarray
    values: np.ndarray
    size: int

    def dense(self) -> np.ndarray:
        out = np.full(self.size, np.nan)
        out[self.rows] = self.values
        return out

    def window(self, start: int, stop: int) -> np.ndarray:
        """``dense()[start:stop]``, without the column's other rows."""
        lo, hi = np.searchsorted(self.rows, (start, stop))
        out = np.full(stop - start, np.nan)
        out[self.rows[lo:hi] - start] = self.values[lo:hi]
        return out

    def at(self, i: int) -> float:
        k = np.searchsorted(self.rows, i)
        return float(self.values[k]) if k < self.rows.size and self.rows[k] == i else float("nan")


@dataclass
class DecimalColumn(ColumnReader):
    """A dense column of words written with at most ``places`` decimals, stored as int32 units.

    ``X12.345`` is 12345 units at 3 places.  The value read back is
    ``units / 10**places``, one correctly rounded division, which is the
    double nearest the written decimal: the parser's own value, to the last
    bit (:meth:`encode` checks every value).  Half the size of a float64
    column; NaN (no word) is stored as :data:`NO_WORD`.
    """

    units: np.ndarray
    places: int

    #: The units of a row with no word
    NO_WORD = np.iinfo(np.int32).min

    @property
    def size(self) -> int:
        return int(self.units.size)

    @property
    def dtype(self) -> np.dtype:
        """The values' dtype (float64; the units are int32)."""
        return np.dtype(np.float64)

    @property
    def nbytes(self) -> int:
        return int(self.units.nbytes)

    def __getitem__(self, index) -> np.ndarray | float:
        """The values of the rows ``index`` (an int, a slice or indices, as the units take them), as float64;
        a Python float for an int."""
        units = self.units[index]
        if np.ndim(units) == 0:
            return float("nan") if units == self.NO_WORD else float(units / 10.0 ** self.places)
        return self._values(units)

    def _values(self, units: np.ndarray) -> np.ndarray:
        out = np.divide(units, 10.0 ** self.places)
        out[units == self.NO_WORD] = np.nan
        return out

    def dense(self) -> np.ndarray:
        return self._values(self.units)

    def window(self, start: int, stop: int) -> np.ndarray:
        return self._values(self.units[start:stop])

    def at(self, i: int) -> float:
        return self[i]

    @classmethod
    def encode(cls, values: np.ndarray, max_places: int = 6, block: int = 1 << 18) -> "DecimalColumn | None":
        """``values`` as units at the fewest places that give every value back bit for bit, or None.

        None when some value needs more than ``max_places`` decimals or more
        than int32 units, or is -0.0 or infinite (program arithmetic gives
        such values; written words rarely do).  Encoded ``block`` values at
        a time, as the table joiner encodes chunks (the units so far scaled
        when a block needs more places), so no second float copy is made.
        """
        values = np.asarray(values)
        if values.dtype != np.float64 or values.ndim != 1:
            return None
        units, places = np.empty(values.size, np.int32), 0
        for lo in range(0, values.size, block):
            found = fewest_units(values[lo:lo + block], places, max_places)
            if found is None or (found[0] > places and not scale_units(units[:lo], places, found[0])):
                return None
            places, units[lo:lo + block] = found
        return cls(units, places)


def fewest_units(values: np.ndarray, start: int = 0, max_places: int = 6) -> tuple[int, np.ndarray] | None:
    """The fewest decimal places from ``start`` at which :func:`decimal_units` takes ``values``, and the units;
    None when no number of places up to ``max_places`` does."""
    for places in range(start, max_places + 1):
        units = decimal_units(values, places)
        if units is not None:
            return places, units
    return None


def scale_units(units: np.ndarray, places: int, to: int) -> bool:
    """Rewrite ``units`` at ``places`` decimals in place at ``to`` places (the same values); False, and
    nothing written, where one would pass int32."""
    given = units != DecimalColumn.NO_WORD
    factor = 10 ** (to - places)
    if given.any() and np.abs(units[given].astype(np.int64)).max() * factor >= 2 ** 31 - 1:
        return False
    units[given] *= factor
    return True


def decimal_units(values: np.ndarray, places: int) -> np.ndarray | None:
    """``values`` as int32 units at ``places`` decimals (NaN as ``NO_WORD``), or None unless each comes
    back bit for bit (see :class:`DecimalColumn`)."""
    if values.dtype != np.float64:
        return None
    given = ~np.isnan(values)
    scaled = values * 10.0 ** places
    if not (np.abs(scaled[given]) < 2.0 ** 31 - 1).all():
        return None
    units = np.where(given, np.rint(scaled), DecimalColumn.NO_WORD).astype(np.int32)
    back = np.divide(units, 10.0 ** places)
    back[~given] = np.nan
    if not np.array_equal(back.view(np.int64), values.view(np.int64)):  # -0.0 and NaN payloads too
        return None
    return units


@dataclass
class CommandTable:
    """Columns of parsed commands.

    Attributes
    ----------
    line : ndarray of int32
        1-based source line of each command.
    kind : ndarray of uint8
        :class:`~gcodekit.parse.commands.Kind` of each command.
    letter : ndarray of uint8
        Code letter (``ord('G')``, ``ord('M')``, ``ord('T')``), ``ord('@')``
        for named commands, 0 for none.
    number : ndarray of int32
        Code number times ten (``G92.1`` is 921), -1 for none.
    name : ndarray of uint8
        Index into :data:`NAMES`.
    motion : ndarray of uint8
        Motion mode in force for the command (see :data:`MOTION_NAMES`).
    params : dict of str to ndarray, SparseColumn or DecimalColumn
    comment_rows : ndarray of int32
        Row of each comment (sorted); a row may have several.
    comment_offsets : ndarray of int64
        Comment ``k`` is ``comment_data[offsets[k]:offsets[k+1]]`` (UTF-8).
    comment_data : bytes
    named : dict of int to tuple
        Named commands by row: ``(name, argument text)``.
    texts : dict of int to str
        String arguments of ordinary commands by row (``M117 Hello``).
    deleted : ndarray of int64
        Rows from block-delete (``/``) lines, skipped when the machine's
        block-delete switch is on.
    profiles : dict of int to LatheProfile
        Lathe cycles (G70-G72) by row: the profile of the cycle's ``Q``
        subroutine (see :mod:`gcodekit.lathe_profile`).
    """

    line: np.ndarray
    kind: np.ndarray
    letter: np.ndarray
    number: np.ndarray
    name: np.ndarray
    motion: np.ndarray
    params: dict[str, np.ndarray | SparseColumn | DecimalColumn]
    comment_rows: np.ndarray
    comment_offsets: np.ndarray
    comment_data: bytes
    named: dict[int, tuple[str, str]] = field(default_factory=dict)
    texts: dict[int, str] = field(default_factory=dict)
    deleted: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    profiles: dict[int, LatheProfile] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.line.size)

    def param(self, letter: str) -> np.ndarray:
        """Dense float column of a word letter (all NaN if never used)."""
        col = self.params.get(letter)
        if col is None:
            return np.full(len(self), np.nan)
        return col.dense() if isinstance(col, (SparseColumn, DecimalColumn)) else col

    def param_at(self, letter: str, rows: np.ndarray) -> np.ndarray:
        """The word ``letter`` of the commands ``rows`` (NaN where not given), without a dense column."""
        col = self.params.get(letter)
        if col is None:
            return np.full(np.shape(rows), np.nan)
        if not isinstance(col, SparseColumn):
            return col[rows]
        k = np.minimum(np.searchsorted(col.rows, rows), max(col.rows.size - 1, 0))
        found = col.rows[k] == rows if col.rows.size else np.zeros(np.shape(rows), bool)
        return np.where(found, col.values[k] if col.rows.size else np.nan, np.nan)

    def code(self, i: int) -> str:
        letter, number = int(self.letter[i]), int(self.number[i])
        if letter == ord("@"):
            return self.named[i][0]
        if letter == 0:
            return ""
        return code_label(chr(letter), number)

    def comment_of(self, i: int) -> str | None:
        """Comment text of row ``i`` (several comments joined by a space), or None."""
        lo, hi = np.searchsorted(self.comment_rows, [i, i + 1])
        return self._comments(int(lo), int(hi))

    def _comments(self, lo: int, hi: int) -> str | None:
        """Comments ``lo:hi`` joined by a space, or None when there are none."""
        return None if lo == hi else " ".join(self.comment(k) for k in range(lo, hi))

    def comment(self, k: int) -> str:
        a, b = self.comment_offsets[k], self.comment_offsets[k + 1]
        return self.comment_data[a:b].decode("utf-8", "replace").strip()

    def command(self, i: int) -> Command:
        """The typed :class:`Command` of row ``i``."""
        n = len(self)
        if not -n <= i < n:
            raise IndexError(f"command {i} out of range for {n} commands")
        i %= n
        params = {}
        for letter, col in self.params.items():
            v = col.at(i) if isinstance(col, (SparseColumn, DecimalColumn)) else float(col[i])
            if v == v:
                params[letter] = v
        return self._command(i, params, self.comment_of(i))

    def commands(self, start: int, stop: int) -> list[Command]:
        """``[command(i) for i in range(start, stop)]``, each column read once for the whole block.

        For walking a long table: the rows' words and comments are looked up
        a block at a time instead of a search per row and column.
        """
        start, stop = max(start, 0), min(stop, len(self))
        if stop <= start:
            return []
        columns = [(letter, np.asarray(col.window(start, stop) if isinstance(col, (SparseColumn, DecimalColumn))
                                       else col[start:stop], float).tolist())
                   for letter, col in self.params.items()]
        bounds = np.searchsorted(self.comment_rows, np.arange(start, stop + 1)).tolist()
        out = []
        for j in range(stop - start):
            params = {letter: v for letter, values in columns if (v := values[j]) == v}
            out.append(self._command(start + j, params, self._comments(bounds[j], bounds[j + 1])))
        return out

    def _command(self, i: int, params: dict[str, float], comment: str | None) -> Command:
        cls = COMMAND_CLASSES[Kind(int(self.kind[i]))]
        named = self.named.get(i)
        return cls(
            code=self.code(i),
            params=params,
            line=int(self.line[i]),
            comment=comment,
            name=NAMES[int(self.name[i])],
            text=named[1] if named else self.texts.get(i, ""),
            profile=self.profiles.get(i),
        )

    def compact(self) -> "CommandTable":
        """Store rarely used parameters sparsely (saves memory on big programs)."""
        n = len(self)
        for letter, col in list(self.params.items()):
            if isinstance(col, SparseColumn):
                continue
            given = col.units != DecimalColumn.NO_WORD if isinstance(col, DecimalColumn) else ~np.isnan(col)
            if np.count_nonzero(given) < _SPARSE_BELOW * n:  # counted first: a dense column's rows are not listed
                rows = np.flatnonzero(given)
                self.params[letter] = SparseColumn(rows.astype(np.int64), col[rows], n)
        return self

    def store_decimals(self) -> "CommandTable":
        """Store each dense parameter whose words all have a few decimals as a :class:`DecimalColumn`
        (half the memory; the same values to the last bit)."""
        for letter, col in list(self.params.items()):
            if isinstance(col, np.ndarray):
                encoded = DecimalColumn.encode(col)
                if encoded is not None:
                    self.params[letter] = encoded
        return self
