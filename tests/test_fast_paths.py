"""The shortcuts taken for speed and memory (issue 25) give what the plain formulations give.

Each test computes a value both ways: the shortcut the library takes and the
general formula it replaces (written out here), on inputs where the shortcut
applies and where it does not.
"""

from __future__ import annotations

import numpy as np
import pytest

import gcodekit
from gcodekit.parse import GcodeParser
from gcodekit.parse.join import TableJoiner
from gcodekit.parse.table import NAME_ID, DecimalColumn, SparseColumn, in_ids
from gcodekit.plan.moves import PlannerMoves, in_force
from gcodekit.read import read_text


def test_in_ids_is_isin_for_byte_codes():
    rng = np.random.default_rng(1)
    values = rng.integers(0, 256, 5000).astype(np.uint8)
    for ids in ([], [0], [3, 7, 255], list(range(0, 256, 3)), np.array([12, 12, 40], np.uint8)):
        assert np.array_equal(in_ids(values, ids), np.isin(values, ids))


def test_param_at_reads_dense_sparse_and_missing_columns():
    op = gcodekit.parse_program("G1 X1 F100\nM204 S500\nG1 X2\nM204 P700 T900\nG1 Y3\n", flavor="marlin")
    t = op.table
    t.params["S"] = SparseColumn(np.array([1]), np.array([500.0]), len(t))
    rows = np.array([0, 1, 3, 4, 1])
    for letter in ("X", "S", "P", "Q"):
        assert np.array_equal(t.param_at(letter, rows), t.param(letter)[rows], equal_nan=True), letter
    empty = SparseColumn(np.zeros(0, np.int64), np.zeros(0), len(t))
    t.params["R"] = empty
    assert np.isnan(t.param_at("R", rows)).all()


def test_commands_read_a_block_as_command_reads_each_row():
    # sparse and dense words, two comments on one line, a named command, a string argument, a comment line
    text = ("; start\nG28 ; home (all axes)\nM117 Hello there\nG1 X1 Y2 F100 ; edge ; second\n"
            "SET_VELOCITY_LIMIT VELOCITY=100\n" + "".join(f"G1 X{i} E{i / 10}\n" for i in range(40))
            + "M104 S200 T0\nG4 P5\n")
    t = gcodekit.parse_program(text, flavor="klipper").table
    t.compact()
    assert any(isinstance(c, SparseColumn) for c in t.params.values()) and t.named and t.texts
    n = len(t)
    for start, stop in [(0, n), (0, 1), (3, 9), (n - 2, n), (2, 2), (-5, 4), (n - 1, n + 10)]:
        expected = [t.command(i) for i in range(max(start, 0), min(stop, n))]
        assert t.commands(start, stop) == expected, (start, stop)
    assert [c.comment for c in t.commands(0, 4)] == ["start", "home (all axes)", None, "edge ; second"]


def _bits(values) -> np.ndarray:
    return np.asarray(values, np.float64).view(np.int64)


def _chunk(text: str, flavor: str = "marlin"):
    """The parser's own table of ``text`` (float columns, as each chunk has before the chunks are joined)."""
    return GcodeParser(flavor).parse(read_text(text, flavor))


@pytest.mark.parametrize("places", range(7))
def test_decimal_columns_give_the_parsed_words_back_bit_for_bit(places):
    # words written with `places` decimals, read by the parser itself, some rows without the word
    rng = np.random.default_rng(places)
    units = rng.integers(-2_000_000_000 // 10 ** (6 - places), 2_000_000_000 // 10 ** (6 - places), 3000)
    words = [f"{u / 10 ** places:.{places}f}" for u in units.tolist()]
    text = "".join(f"G1 X{w}\n" if i % 7 else "M400\n" for i, w in enumerate(words))
    parsed = _chunk(text).param("X")
    assert parsed.dtype == np.float64
    col = DecimalColumn.encode(parsed)
    assert col is not None and col.places <= places and col.units.dtype == np.int32
    assert np.array_equal(_bits(col.dense()), _bits(parsed))  # NaN where no word, the same doubles elsewhere
    rows = np.array([0, 5, 7, 2999, 14])
    assert np.array_equal(_bits(col[rows]), _bits(parsed[rows]))
    assert np.array_equal(_bits(col.window(3, 40)), _bits(parsed[3:40]))
    assert _bits(col.at(7)) == _bits(parsed[7]) and np.isnan(col.at(0))


def test_decimal_columns_refuse_what_they_cannot_give_back():
    assert DecimalColumn.encode(np.array([1.5, 0.1 + 0.2])) is None  # program arithmetic, not a written word
    assert DecimalColumn.encode(np.array([1.0, -0.0])) is None  # -0.0 would come back as 0.0
    assert DecimalColumn.encode(np.array([1.0, 3e9])) is None  # past int32
    assert DecimalColumn.encode(np.array([1.0, np.inf])) is None
    assert DecimalColumn.encode(np.array([0.1234567])) is None  # seven decimals
    assert DecimalColumn.encode(np.array([1, 2], np.int64)) is None
    # the first 4096 values need none, a later one three: the places grow until all come back
    later = np.r_[np.arange(5000.0), 1.125]
    col = DecimalColumn.encode(later, block=1000)
    assert col is not None and col.places == 3 and np.array_equal(col.dense(), later)


def test_a_table_with_decimal_columns_reads_as_before():
    text = "".join(f"G1 X{i * 0.125:.3f} Y{i % 7} E{i * 0.01:.5f}\n" for i in range(500)) + "G1 X1e-3\nM400\n"
    t = _chunk(text)
    before = {letter: t.param(letter).copy() for letter in t.params}
    commands = [t.command(i) for i in range(len(t))]
    t.store_decimals()
    assert {letter for letter, c in t.params.items() if isinstance(c, DecimalColumn)} == {"X", "Y", "E"}
    for letter, values in before.items():
        assert np.array_equal(_bits(t.param(letter)), _bits(values)), letter
        assert np.array_equal(_bits(t.param_at(letter, np.array([3, 500, 501]))), _bits(values[[3, 500, 501]]))
    assert [t.command(i) for i in range(len(t))] == commands == t.commands(0, len(t))


def test_an_emulated_program_keeps_its_words_as_decimals_and_plans_alike():
    text = "M83\nG1 F1800\n" + "".join(f"G1 X{i % 50 * 0.4:.3f} Y{i // 50 * 0.4:.3f} E0.02\n" for i in range(2000))
    op = gcodekit.gcode_to_operation(text, "marlin")
    assert isinstance(op.table.params["X"], DecimalColumn) and op.table.params["X"].places == 1
    as_parsed = _chunk(text)
    for letter in ("X", "Y", "E"):
        assert np.array_equal(_bits(op.table.param(letter)), _bits(as_parsed.param(letter))), letter
    assert op.to_dataframe()["x"].iloc[-1] == pytest.approx(49 * 0.4)  # the last word, X19.6
    again = gcodekit.emulate_operation(gcodekit.Operation(op.table, file="again", flavor=op.flavor), "marlin")
    for key in ("x", "y", "de", "feed", "distance"):  # the machine reads a table of decimal columns alike
        assert np.array_equal(_bits(again.waypoints[key]), _bits(op.waypoints[key])), key


def _joined(texts: list[str]):
    """The chunks' tables joined, and the parser's float columns of each letter one after another."""
    joiner, chunks = TableJoiner(), [_chunk(text) for text in texts]
    floats = {letter: np.concatenate([c.param(letter) for c in chunks]) for c in chunks for letter in c.params}
    for c in chunks:
        joiner.add(c)
    return joiner.finish(), floats


def test_joined_chunks_keep_decimal_units_while_they_give_every_word_back():
    # X gains a decimal in the second chunk (the first chunk's units scaled by 10), Y is given by few rows
    # of the first chunk (sparse there) and densely after, E turns to floats at the computed-looking word
    # of the last chunk, Z passes int32 at three places in the third chunk
    texts = ["".join(f"G1 X{i}.25 E1.5\n" for i in range(60)) + "G1 Y3\n",
             "".join(f"G1 X{i}.125 Y{i}.5 E2\n" for i in range(60)),
             "".join(f"G1 X{i} Y1 Z{i}.001 E0.30000000000000004\n" for i in range(60)),
             "".join(f"G1 X{i} Z3000000.5 E3\n" for i in range(60))]
    table, floats = _joined(texts)
    kinds = {letter: type(c).__name__ for letter, c in table.params.items()}
    assert kinds == {"X": "DecimalColumn", "Y": "DecimalColumn", "E": "ndarray", "Z": "ndarray"}, kinds
    assert table.params["X"].places == 3 and table.params["Y"].places == 1
    for letter, values in floats.items():
        assert np.array_equal(_bits(table.param(letter)), _bits(values)), letter


def test_joined_decimal_column_given_by_few_rows_is_kept_sparse():
    # Y in every row of a short chunk (dense there), then in no row of a long one: 10 of 210 rows in all
    texts = ["".join(f"G1 X{i}.5 Y{i}.25\n" for i in range(10)), "G1 X2\n" * 200]
    table, floats = _joined(texts)
    assert isinstance(table.params["Y"], SparseColumn) and isinstance(table.params["X"], DecimalColumn)
    assert np.array_equal(_bits(table.param("Y")), _bits(floats["Y"]))


def _moves(rows):
    n = len(rows)
    return PlannerMoves(np.zeros((n, 4)), np.ones((n, 4)), np.ones(n), np.asarray(rows, np.int64), np.arange(n))


@pytest.mark.parametrize("set_rows", [[], [0, 2], [50, 60], [5, 15, 25], [0, 100]])
def test_in_force_shortcuts_agree_with_the_search(set_rows):
    moves = _moves(np.arange(10, 40, 3))
    rows = np.array(set_rows, np.int64)
    values = np.arange(1.0, rows.size + 1.0) * 7.0
    k = np.searchsorted(rows, moves.row, side="left") - 1  # the general rule, written out
    expected = np.where(k >= 0, values[np.maximum(k, 0)], -1.0) if rows.size else np.full(len(moves), -1.0)
    assert np.array_equal(in_force(moves, rows, values, -1.0), expected)


def test_names_from_the_parsers_table_match_the_flavor():
    text = "".join(f"G{g}\nM{m} S1\nT{t}\n" for g, m, t in zip((0, 1, 28, 92.1, 9999.9, 1),
                                                             (104, 82, 83, 9999, 117, 600), range(6)))
    parser = GcodeParser("marlin")
    first = parser.parse(read_text(text, "marlin"))
    again = parser.parse(read_text(text, "marlin"))  # now from the table
    assert np.array_equal(first.name, again.name)
    named = {first.code(i): first.name[i] for i in range(len(first))}
    assert named["G9999.9"] == 0  # no such code: no name
    assert named["G1"] == NAME_ID["linear"] and named["M104"] == NAME_ID["set_hotend_temp"]
    assert named["M82"] == NAME_ID["extrude_absolute"] and named["G28"] == NAME_ID["home"]
