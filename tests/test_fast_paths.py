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
from gcodekit.parse.table import NAME_ID, SparseColumn, in_ids
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
