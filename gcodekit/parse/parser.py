"""Parse stage: :class:`~gcodekit.read.Blocks` to a :class:`CommandTable`.

Blocks holding at most one code (nearly every line of a slicer's output)
are parsed in bulk with NumPy; compound blocks go through :mod:`.split`.
The motion mode (G0/G1/G2/G3) is modal: a block of axis words alone moves
in the last mode set, which is a forward fill over the rows.

Examples
--------
>>> from gcodekit.read import read_text
>>> from gcodekit.parse import GcodeParser
>>> table = GcodeParser("rs274ngc").parse(read_text("G1 X1 F100\\nY2\\n"))
>>> [str(table.command(i)) for i in range(len(table))]
['G1 F100 X1', 'Y2']
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import Diagnostics, MissingDependencyError, check_choice
from ..read import Blocks
from ..syntax import Flavor, load_flavor
from ..syntax.flavor import code_label
from .commands import Kind
from . import rows_kernel
from .lathe_profiles import lathe_profiles
from .split import AXIS_CONSUMERS, AXIS_LETTERS, Part, code_name, split_block
from .word_checks import MODAL_USERS, WORD_USERS, stray_letters, stray_word_message, user_code_keys
from .table import (CYCLE_NAMES, LATHE_CYCLE_NAMES, MOTION_CCW, MOTION_CUBIC, MOTION_CW, MOTION_CYCLE, MOTION_LINEAR, MOTION_NONE, MOTION_NURBS, MOTION_OF_NAME,
                    MOTION_QUADRATIC, MOTION_THREAD, NAME_ID, CommandTable, in_ids)

_G, _M, _T, _NAMED = ord("G"), ord("M"), ord("T"), ord("@")
#: LinuxCNC's log comments: (LOGOPEN,file), (LOGAPPEND,file), (LOG,text), (LOGCLOSE)
_LOG_COMMENT = re.compile(rb"(?i)\s*(?:log(?:open|append)?\s*,|logclose\s*$)")
_LOG_HINT = re.compile(rb"(?i)log")
_KEEP = 255  # "this row does not set the motion mode"
_CODE_TENTHS = 100_000  # G and M numbers below 10000, in tenths: the names the parser keeps in a table
_UNNAMED = 255  # a slot of that table not yet named
#: Parameter letters and their row in the per-chunk parameter table.
PARAM_LETTERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZ@^"
_LETTER_ROW = np.full(256, -1, np.int64)
_LETTER_ROW[[ord(c) for c in PARAM_LETTERS]] = np.arange(len(PARAM_LETTERS))

#: Axis word letters (by byte)
_AXIS = np.zeros(256, bool)
_AXIS[[ord(c) for c in AXIS_LETTERS]] = True

#: Motion modes by command name.  A probe (G38.x) is a straight feed to its
#: target: without a probe input it never trips, as in rs274 standalone.
_MOTION_MODES = {**MOTION_OF_NAME, "probe": MOTION_LINEAR, "spline_cubic": MOTION_CUBIC,
                 "spline_quadratic": MOTION_QUADRATIC, "nurbs_start": MOTION_NURBS, "thread": MOTION_THREAD,
                 "rigid_tap": MOTION_THREAD}


class GcodeParser:
    """Turn blocks into typed command rows for one flavor.

    Parameters
    ----------
    flavor : Flavor or str
    diagnostics : Diagnostics, default: a new lenient collector
        Receives unknown codes, repeated words and moves without a motion mode.
    engine : {"auto", "numba", "numpy"}, default: "auto"
        Who builds the rows of one-code blocks: NumPy passes (the
        reference), the compiled loop of :mod:`.rows_kernel` (Numba must be
        installed), or "auto": the compiled loop for large chunks once Numba
        is loaded.  Both give the same rows.

    The parser keeps the modal motion mode between calls, so a long program
    can be parsed chunk by chunk.
    """

    def __init__(self, flavor: Flavor | str, diagnostics: Diagnostics | None = None, *, engine: str = "auto"):
        self.engine = check_choice("engine", engine, ("auto", "numba", "numpy"))
        if engine == "numba" and rows_kernel.compiled() is None:
            raise MissingDependencyError("the compiled parser needs Numba: pip install 'gcodekit[fast]'")
        self.flavor = load_flavor(flavor) if isinstance(flavor, str) else flavor
        self.diagnostics = Diagnostics() if diagnostics is None else diagnostics
        self.motion = MOTION_OF_NAME.get(self.flavor.initial_motion, MOTION_NONE)
        self.probe = -1  # code number (382 .. 385) of the probe mode in force, -1 for none
        self._n_letter = ord(self.flavor.line_number_letter) if self.flavor.line_number_letter else -1
        self._modal = self.flavor.block_split == "modal"
        self._modal_motion = self.flavor.block_split != "single"  # firmware needs a code on every move
        self._name_cache: dict[int, int] = {}
        # name ids by slot (see _name_ids): G numbers, M numbers, then the other letters
        self._name_table = np.full(2 * _CODE_TENTHS + 256, _UNNAMED, np.uint8)
        self._unknown_reported: set[str] = set()
        self._extruder_letters = tuple(k for k, v in self.flavor.words.items() if v == "e" and k != "E")
        self._cycle_ids = np.array([NAME_ID[n] for n in CYCLE_NAMES], np.uint8)
        self._lathe_ids = np.array([NAME_ID[n] for n in LATHE_CYCLE_NAMES], np.uint8)
        self._log_comments = self.flavor.state_parameters == "linuxcnc"  # said once per program

    def _note_log_comment(self, blocks: Blocks) -> None:
        """Warn, once, at LinuxCNC's first ``(LOGOPEN,...)``, ``(LOGAPPEND,...)``, ``(LOG,...)`` or
        ``(LOGCLOSE)`` comment: the interpreter writes such comments to a log file; gcodekit writes none."""
        offsets, data = blocks.comment_offsets, blocks.comment_data
        for k in range(len(offsets) - 1):
            if _LOG_COMMENT.match(data[offsets[k]:offsets[k + 1]]):
                line = int(blocks.block_line[blocks.comment_block[k]])
                self.diagnostics.warn(line, int(blocks.comment_col[k]), "LinuxCNC writes (LOG,...) comments to the "
                                      "file (LOGOPEN,...) opens; gcodekit runs them as plain comments and writes no "
                                      "log file")
                self._log_comments = False
                return

    # -- public ---------------------------------------------------------------

    def parse(self, blocks: Blocks) -> CommandTable:
        """Commands of ``blocks``, continuing the modal state of earlier calls."""
        if self._log_comments and _LOG_HINT.search(blocks.comment_data):
            self._note_log_comment(blocks)
        n_blocks = len(blocks)
        wb, wl = blocks.word_block, blocks.word_letter
        compiled = rows_kernel.use_compiled(self.engine, n_blocks)
        if compiled:
            n_codes, has_param, has_axis, code_word = rows_kernel.block_words_compiled(wb, wl, n_blocks,
                                                                                       self._n_letter, _AXIS)
        else:
            n_codes, has_param, has_axis, code_word = _block_words(wb, wl, n_blocks, self._n_letter)
        has_comment = np.bincount(blocks.comment_block, minlength=n_blocks) > 0

        compound = n_codes >= 2
        if blocks.extras:
            compound[list(blocks.extras)] = True
        if self._modal_motion:
            compound |= self._axis_words_on_non_consumer(blocks, has_axis, n_codes, code_word)
        if self.flavor.block_split == "sequential":
            compound |= has_param & (n_codes == 1) & self._params_before_code(wb, _is_code(wl), n_blocks)
        simple = ~compound & ((n_codes == 1) | has_param | has_comment)

        fast = self._simple_rows(blocks, simple, compiled)
        slow = self._compound_rows(blocks, np.flatnonzero(compound))
        rows = _merge_rows(fast, slow)
        _read_as_e(rows["params"], self._extruder_letters)
        rows["line"] = blocks.block_line[rows["block"]]
        self._classify(rows)
        return self._table(blocks, rows)

    def _table(self, blocks: Blocks, rows: dict) -> CommandTable:
        block = rows["block"]
        first_row = np.full(len(blocks), -1, np.int64)
        first_row[block[::-1]] = np.arange(block.size)[::-1]
        profiles, comments = lathe_profiles(blocks, block, np.flatnonzero(in_ids(rows["name"], self._lathe_ids)))
        comment_rows = first_row[comments.block]
        parts = rows["parts_by_row"]
        named = {i: p.named for i, p in parts.items() if p.named is not None}
        texts = {i: p.text for i, p in parts.items() if p.text}
        deleted = [first_row[b] for b, x in blocks.extras.items() if x.deleted and first_row[b] >= 0]
        return CommandTable(
            line=rows["line"].astype(np.int32),
            kind=rows["kind"],
            letter=rows["letter"],
            number=rows["number"],
            name=rows["name"],
            motion=rows["motion"],
            params=rows["params"],
            comment_rows=comment_rows.astype(np.int32),
            comment_offsets=comments.offsets,
            comment_data=comments.data,
            named=named,
            texts=texts,
            deleted=np.array(sorted(deleted), np.int64),
            profiles=profiles,
        ).compact()

    # -- bulk path ------------------------------------------------------------

    def _axis_words_on_non_consumer(self, blocks, has_axis, n_codes, code_word) -> np.ndarray:
        """Blocks like ``G90 X0``: one code that does not take the axis words."""
        candidates = np.flatnonzero(has_axis & (n_codes == 1))
        words = code_word[candidates]
        names = self._name_ids(blocks.word_letter[words], blocks.word_value[words])
        consumer_ids = np.array([NAME_ID[n] for n in AXIS_CONSUMERS if n in NAME_ID])
        out = np.zeros(len(blocks), bool)
        out[candidates] = ~in_ids(names, consumer_ids)
        return out

    @staticmethod
    def _params_before_code(wb, is_code, n_blocks) -> np.ndarray:
        """GER: ``X1 G1 Y2`` is two statements, so it needs the splitter."""
        first_word = np.full(n_blocks, -1)
        first_code = np.full(n_blocks, -1)
        idx = np.arange(wb.size)
        first_word[wb[::-1]] = idx[::-1]
        codes = np.flatnonzero(is_code)
        first_code[wb[codes][::-1]] = codes[::-1]
        return first_word < first_code

    def _simple_rows(self, blocks: Blocks, simple: np.ndarray, compiled: bool) -> dict:
        rows_blocks = np.flatnonzero(simple)
        if compiled:
            letter, number, present, table, repeats = rows_kernel.simple_rows_compiled(
                blocks.word_block, blocks.word_letter, blocks.word_value, rows_blocks, len(blocks), self._n_letter,
                _LETTER_ROW)
        else:
            letter, number, present, table, repeats = self._simple_rows_numpy(blocks, rows_blocks, simple,
                                                                              self._n_letter)
        for row, j, word in repeats.tolist():
            line = int(blocks.block_line[blocks.word_block[word]])
            self.diagnostics.report(line, int(blocks.word_col[word]),
                                    f"more than one {PARAM_LETTERS[present[j]]} word in the block; the first is used",
                                    severity="error" if self._modal else "warning")
        params = {PARAM_LETTERS[k]: table[j].copy() for j, k in enumerate(present.tolist())}
        return {
            "block": rows_blocks,
            "sub": np.zeros(rows_blocks.size, np.int32),
            "letter": letter,
            "number": number,
            "params": params,
        }

    @staticmethod
    def _simple_rows_numpy(blocks: Blocks, rows_blocks: np.ndarray, simple: np.ndarray, n_letter: int):
        """The rows of one-code blocks by NumPy passes (the reference of :mod:`.rows_kernel`)."""
        wb, wl, wv = blocks.word_block, blocks.word_letter, blocks.word_value
        is_code = _is_code(wl)
        is_param = ~is_code & (wl != n_letter)
        n = rows_blocks.size
        row_of_block = np.full(len(blocks), -1, np.int64)
        row_of_block[rows_blocks] = np.arange(n)
        letter = np.zeros(n, np.uint8)
        number = np.full(n, -1, np.int32)
        code_words = np.flatnonzero(is_code & simple[wb])
        r = row_of_block[wb[code_words]]
        letter[r] = wl[code_words]
        number[r] = np.round(wv[code_words] * 10).astype(np.int32)

        pw = np.flatnonzero(is_param & simple[wb])
        prow = row_of_block[wb[pw]]
        pletter = _LETTER_ROW[wl[pw]]
        # A lone T word is the command itself (printer tool change, RS274 tool select).
        t_words = pw[(wl[pw] == _T) & (letter[prow] == 0)]
        if t_words.size:
            tr = row_of_block[wb[t_words]]
            letter[tr] = _T
            number[tr] = np.round(wv[t_words] * 10).astype(np.int32)
            keep = ~((wl[pw] == _T) & np.isin(prow, tr))
            pw, prow, pletter = pw[keep], prow[keep], pletter[keep]
        # one row of the table per letter the chunk uses
        present = np.flatnonzero(np.bincount(pletter, minlength=len(PARAM_LETTERS)))
        slot = np.zeros(len(PARAM_LETTERS), np.int64)
        slot[present] = np.arange(present.size)
        pslot = slot[pletter]
        table = np.full((present.size, n), np.nan)
        table[pslot, prow] = wv[pw]
        return letter, number, present, table, _first_of_repeats(wv, table, pw, prow, pslot, present.size, n)

    # -- compound blocks ------------------------------------------------------

    def _compound_rows(self, blocks: Blocks, which: np.ndarray) -> dict:
        rows: list[tuple[int, int, Part]] = []
        starts = np.searchsorted(blocks.word_block, which)
        ends = np.searchsorted(blocks.word_block, which, side="right")
        for b, lo, hi in zip(which.tolist(), starts.tolist(), ends.tolist()):
            words = [(chr(blocks.word_letter[k]), float(blocks.word_value[k])) for k in range(lo, hi)]
            extra = blocks.extras.get(b)
            line = int(blocks.block_line[b])
            if extra is not None:
                words += [(f, 0.0) for f, _ in extra.flags]
            parts, problems = split_block(words, self.flavor, self.flavor.line_number_letter)
            for message in problems:
                self.diagnostics.report(line, 1, message, severity="error" if self._modal else "warning")
            if extra is not None and extra.named is not None:
                parts = [Part("@", named=extra.named[:2])] + parts
            if extra is not None and extra.assignments:  # Sinumerik "EM=1": set before the block moves
                parts = [Part("@", params={"value": value}, named=(name, f"{value:g}"))
                         for name, value, _ in extra.assignments] + parts
            if extra is not None and extra.code_value is not None and parts:
                parts[0].params["value"] = extra.code_value
            if not parts:
                parts = [Part("")]
            if extra is not None and extra.text:
                parts[0].text = extra.text
            for sub, part in enumerate(parts):
                rows.append((b, sub, part))
        n = len(rows)
        letters = sorted({k for _, _, p in rows for k in p.params})
        params = {k: np.full(n, np.nan) for k in letters}
        for i, (_, _, p) in enumerate(rows):
            for k, v in p.params.items():
                params[k][i] = v
        return {
            "block": np.array([b for b, _, _ in rows], np.int64),
            "sub": np.array([s for _, s, _ in rows], np.int32),
            "letter": np.array([ord(p.letter) if p.letter else 0 for _, _, p in rows], np.uint8),
            "number": np.array([round(p.number * 10) if p.letter in ("G", "M", "T") else -1
                                for _, _, p in rows], np.int32),
            "params": params,
            "parts": [p for _, _, p in rows],
        }

    # -- classification -------------------------------------------------------

    def _name_ids(self, letters: np.ndarray, values_or_tenths: np.ndarray, tenths: bool = False) -> np.ndarray:
        """Normalized-name ids for codes given by letter and number.

        Names already met are looked up in a table (G and M numbers in
        tenths below :data:`_CODE_TENTHS`, other letters by the letter);
        the rest are named by the flavor and added to it.
        """
        numbers = values_or_tenths if tenths else np.round(values_or_tenths * 10)
        is_g, is_m = letters == _G, letters == _M
        numbers = np.where(is_g | is_m, numbers, 0)
        in_range = (numbers >= 0) & (numbers < _CODE_TENTHS)
        slot = np.where(is_g, 0, np.where(is_m, _CODE_TENTHS, 2 * _CODE_TENTHS + letters.astype(np.int64)))
        slot = np.where(in_range, slot + np.where(in_range, numbers, 0).astype(np.int64), -1)
        ids = self._name_table[slot]
        unknown = np.flatnonzero((ids == _UNNAMED) | (slot < 0))
        if unknown.size:
            keys = letters[unknown].astype(np.int64) * 1_000_000 + numbers[unknown].astype(np.int64)
            uniq, inverse = np.unique(keys, return_inverse=True)
            named = np.empty(uniq.size, np.uint8)
            for i, key in enumerate(uniq.tolist()):
                if key not in self._name_cache:
                    letter, number = divmod(key, 1_000_000)
                    name = code_name(self.flavor, chr(letter), number / 10) if letter else ""
                    self._name_cache[key] = NAME_ID.get(name, 0)
                named[i] = self._name_cache[key]
            ids[unknown] = named[inverse]
            known = slot[unknown] >= 0
            self._name_table[slot[unknown][known]] = ids[unknown][known]
        return ids

    def _classify(self, t: dict) -> None:
        """Fill name, motion and kind of every row."""
        letter, number, params = t["letter"], t["number"], t["params"]
        n = letter.size
        name = self._name_ids(letter, number, tenths=True)
        name[(letter == _T) | (letter == _NAMED)] = 0
        for i, part in t.get("parts_by_row", {}).items():
            if part.named is not None:  # Klipper's extended commands are named in [codes] too
                name[i] = NAME_ID.get(self.flavor.codes.get(part.named[0].upper(), ""), 0)
        self._report_unknown(t, name)

        sets = _SETS_MOTION.take(name)
        # After a lathe cycle (G70-G72) rs274 is in the mode of the cycle's last move,
        # which only the machine knows: axis words alone stay cycle rows for it to settle
        lathe = in_ids(name, self._lathe_ids)
        g53 = name == NAME_ID["machine_coordinates"]
        for i in np.flatnonzero(g53 & (letter != 0)):
            part = t.get("parts_by_row", {}).get(int(i))
            if part is not None and part.motion:
                sets[i] = MOTION_OF_NAME.get(part.motion, _KEEP)
        motion = _forward_fill_modes(sets, self.motion)
        # G38.x is a motion mode too: axis words alone after it probe again (rs274)
        probe_sets = np.where(sets == _KEEP, -2, np.where(name == NAME_ID["probe"], number, -1))
        last_set = np.where(probe_sets != -2, np.arange(n), -1)
        np.maximum.accumulate(last_set, out=last_set)
        probe = np.where(last_set >= 0, probe_sets[np.maximum(last_set, 0)], self.probe)
        if n:
            self.motion, self.probe = int(motion[-1]), int(probe[-1])
        motion[lathe] = MOTION_CYCLE

        def has(letters: str) -> np.ndarray:
            out = np.zeros(n, bool)
            for c in letters:
                if c in params:
                    out |= ~np.isnan(params[c])
            return out

        has_axes, has_e, has_s, has_f = has("XYZABCUVW@^"), has("E"), has("S"), has("F")
        arc = (motion == 3) | (motion == 4)
        has_axes |= arc & has("IJKR")  # "G2 I5" is a full circle from where the tool is
        is_motion_name = in_ids(name, [NAME_ID[m] for m in _MOTION_MODES] + self._cycle_ids.tolist())
        implicit = (letter == 0) & has_axes if self._modal_motion else np.zeros(n, bool)
        probing = implicit & (probe >= 0) & (motion == MOTION_LINEAR)
        name[probing] = NAME_ID["probe"]
        number[probing] = probe[probing]
        moving = (is_motion_name | implicit) & (has_axes | has_e) | lathe

        kind = np.full(n, Kind.CONFIG, np.uint8)
        kind[letter == _G] = Kind.G
        kind[letter == _M] = Kind.M
        kind[(letter == 0) & has_f] = Kind.FEED_RATE
        kind[(letter == 0) & has_s & ~has_f] = Kind.MILL
        kind[(letter == 0) & ~(has_f | has_s | has_axes | has_e)] = Kind.COMMENT
        kind[is_motion_name & ~(has_axes | has_e) & has_f] = Kind.FEED_RATE
        named_kind = _KIND_OF_NAME.take(name)
        kind = np.where(named_kind != _KEEP, named_kind, kind)
        lin = moving & ~arc
        kind[lin] = Kind.MOVE
        kind[lin & has_s & ~has_e] = Kind.MOVE_MILL
        kind[lin & has_e] = Kind.MOVE_EXTRUDE
        kind[lin & has_e & ~has_axes] = Kind.EXTRUDE
        circ = moving & arc
        kind[circ] = Kind.ARC
        kind[circ & has_s & ~has_e] = Kind.ARC_MILL
        kind[circ & has_e] = Kind.ARC_EXTRUDE
        kind[g53] = Kind.MACHINE_COORDINATES

        lost = implicit & (motion == MOTION_NONE)
        for i in np.flatnonzero(lost)[:100].tolist():
            self.diagnostics.report(int(t["line"][i]), 1, "axis words but no motion mode (G0/G1/G2/G3) is in force")
        kind[lost] = Kind.CONFIG
        orphan = (letter == 0) & (has_axes | has_e) & (not self._modal_motion)
        for i in np.flatnonzero(orphan)[:100].tolist():
            self.diagnostics.warn(int(t["line"][i]), 1, "words without a command are ignored by this firmware")
        kind[orphan] = Kind.CONFIG
        if self.flavor.required_axes:
            straight = in_ids(name, [NAME_ID["rapid"], NAME_ID["linear"]])
            missing = np.zeros(n, bool)
            for letter in self.flavor.required_axes:
                missing |= ~has(letter)
            for i in np.flatnonzero(straight & missing)[:100].tolist():
                absent = ",".join(c for c in self.flavor.required_axes if c not in params or np.isnan(params[c][i]))
                self.diagnostics.warn(int(t["line"][i]), 1, f"motion without {absent} (this dialect writes every axis)")
        if self.flavor.rs274ngc_block_checks:
            self._report_stray_words(t, motion, implicit)
        t["name"], t["motion"], t["kind"] = name, motion, kind

    def _report_stray_words(self, t: dict, motion: np.ndarray, implicit: np.ndarray) -> None:
        """RS274NGC: a word no code of its block uses (``G1 X1 R5``) is an error (see :mod:`.word_checks`)."""
        letter, number, params = t["letter"], t["number"], t["params"]
        keys = letter.astype(np.int64) * 1_000_000 + number.astype(np.int64)
        modal = {MOTION_CW: "arc", MOTION_CCW: "arc", MOTION_CYCLE: "cycle", MOTION_THREAD: "thread",
                 MOTION_NURBS: "nurbs", MOTION_CUBIC: "spline", MOTION_QUADRATIC: "spline"}
        suspect = np.zeros(letter.size, bool)
        for c in WORD_USERS:
            if c not in params:
                continue
            by_own_code = np.isin(keys, user_code_keys(c))
            by_mode = implicit & np.isin(motion, [m for m, mode in modal.items() if c in MODAL_USERS[mode]])
            suspect |= ~np.isnan(params[c]) & ~by_own_code & ~by_mode
        reported = 0
        for block in np.unique(t["block"][suspect]).tolist():
            rows = np.flatnonzero(t["block"] == block)
            codes = [code_label(chr(letter[i]), int(number[i])) for i in rows if letter[i] in (_G, _M)]
            given = {c for c in WORD_USERS if c in params and (~np.isnan(params[c][rows])).any()}
            moving = [int(motion[i]) for i in rows if implicit[i]]
            for c in stray_letters(given, codes, modal.get(moving[0]) if moving else None):
                if reported < 100:
                    self.diagnostics.report(int(t["line"][rows[0]]), 1, stray_word_message(c))
                reported += 1

    def _report_unknown(self, t: dict, name: np.ndarray) -> None:
        letter, number = t["letter"], t["number"]
        unknown = np.flatnonzero((name == 0) & ((letter == _G) | (letter == _M)))
        for i in unknown.tolist():
            code = code_label(chr(letter[i]), int(number[i]))
            if code in self._unknown_reported:
                continue
            self._unknown_reported.add(code)
            line = int(t["line"][i])
            what = self.flavor.firmware_codes.get(code)
            if what is not None:
                self.diagnostics.report(line, 1, f"{code} ({what}) is a {self.flavor.name} code gcodekit does not "
                                        "model; kept as a generic command", severity="info")
            elif self.flavor.other_codes and code not in self.flavor.other_codes:
                # the dialect's list is complete: LinuxCNC stops here (convert_g / convert_m)
                self.diagnostics.report(line, 1, f"Unknown {code[0].lower()} code used: {code} "
                                        f"is not a {self.flavor.name} code", kind="machine")
            elif code in self.flavor.other_codes:
                self.diagnostics.warn(line, 1, f"{code} is a {self.flavor.name} code gcodekit does not emulate; "
                                      "kept as a generic command")
            else:  # firmware add codes freely (M900, M620, ...): say once, quietly, that it does nothing here
                self.diagnostics.report(line, 1, f"{code} has no meaning in gcodekit's {self.flavor.name} flavor; "
                                        "kept as a command without effect on the path", severity="info",
                                        kind="unknown_code")


def _by_name(pairs) -> np.ndarray:
    """A table from name id to value, :data:`_KEEP` for the names not in ``pairs`` (later pairs win)."""
    table = np.full(256, _KEEP, np.uint8)
    for name, value in pairs:
        table[NAME_ID[name]] = value
    return table


#: The motion mode each command name sets (:data:`_KEEP`: none)
_SETS_MOTION = _by_name([*_MOTION_MODES.items(), ("cancel_cycle", MOTION_NONE), ("nurbs_end", MOTION_NONE),
                         *((c, MOTION_CYCLE) for c in CYCLE_NAMES)])
#: The kind a command name gives its row whatever its words (:data:`_KEEP`: decided by the words)
_KIND_OF_NAME = _by_name([("dwell", Kind.DWELL), ("distance_absolute", Kind.ABSOLUTE_POSITION),
                          ("distance_incremental", Kind.INCREMENTAL_POSITION),
                          *((f"work_offset_{k}", Kind.WORK_COORDINATES) for k in range(1, 10))])


def _is_code(word_letter: np.ndarray) -> np.ndarray:
    return (word_letter == _G) | (word_letter == _M)


def _block_words(wb: np.ndarray, wl: np.ndarray, n_blocks: int, n_letter: int):
    """Per block: its number of G and M codes, whether it has parameter words and axis words, and
    its last code word (-1 for none); the NumPy reference of :func:`.rows_kernel.block_words_compiled`."""
    is_code = _is_code(wl)
    is_param = ~is_code & (wl != n_letter)
    n_codes = np.bincount(wb[is_code], minlength=n_blocks)
    has_param = np.bincount(wb[is_param], minlength=n_blocks) > 0
    has_axis = np.bincount(wb[is_param & _AXIS.take(wl)], minlength=n_blocks) > 0
    code_word = np.full(n_blocks, -1, np.int64)
    code_words = np.flatnonzero(is_code)
    code_word[wb[code_words]] = code_words
    return n_codes, has_param, has_axis, code_word


def _first_of_repeats(word_value: np.ndarray, table: np.ndarray, pw, prow, pslot, width: int,
                      n_rows: int) -> np.ndarray:
    """A letter given twice in a block: keep the first value in ``table``.

    ``pslot`` is each parameter word's row of ``table``.  Returns the
    repeats as (row, table row, second word), for the diagnostics.
    """
    if not pw.size:
        return np.empty((0, 3), np.int64)
    counts = np.bincount(prow * width + pslot, minlength=n_rows * width)
    found = []
    for key in np.flatnonzero(counts > 1).tolist():
        row, j = divmod(key, width)
        words = pw[(prow == row) & (pslot == j)]
        table[j, row] = word_value[words[0]]
        found.append((row, j, int(words[1])))
    return np.array(found, np.int64).reshape(-1, 3)


def _forward_fill_modes(sets: np.ndarray, initial: int) -> np.ndarray:
    """Motion mode of each row: the last mode set at or before it."""
    idx = np.where(sets != _KEEP, np.arange(sets.size), -1)
    np.maximum.accumulate(idx, out=idx)
    out = np.where(idx >= 0, sets[np.maximum(idx, 0)], initial).astype(np.uint8)
    return out


def _read_as_e(params: dict, letters: tuple[str, ...]) -> None:
    """The flavor's other extruder letters (MakerBot's A and B) become E words, one extruder at a time."""
    for letter in letters:
        col = params.pop(letter, None)
        if col is not None:
            e = params.get("E")
            params["E"] = col if e is None else np.where(np.isnan(col), e, col)


def _merge_rows(fast: dict, slow: dict) -> dict:
    """Rows of both paths in block order (their blocks never overlap)."""
    if slow["block"].size == 0:
        merged = fast
        merged["parts_by_row"] = {}
    else:
        at = np.searchsorted(fast["block"], slow["block"])
        merged = {k: np.insert(fast[k], at, slow[k]) for k in ("block", "sub", "letter", "number")}
        n = merged["block"].size
        slow_rows = at + np.arange(at.size)
        fast_rows = np.setdiff1d(np.arange(n), slow_rows, assume_unique=True)
        params = {}
        for k in sorted(set(fast["params"]) | set(slow["params"])):
            col = np.full(n, np.nan)
            if k in fast["params"]:
                col[fast_rows] = fast["params"][k]
            if k in slow["params"]:
                col[slow_rows] = slow["params"][k]
            params[k] = col
        merged["params"] = params
        merged["parts_by_row"] = dict(zip(slow_rows.tolist(), slow["parts"]))
    return merged
