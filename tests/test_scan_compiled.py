"""Read stage: the compiled scanner (Numba) gives the NumPy scanner's arrays, to the last bit.

The NumPy scanner is the reference (itself checked against the per-line
tokenizer in test_read.py); the compiled loop must return identical words,
values (bit for bit), columns, comments and irregular lines on every input,
and the pipeline must give the same operation whichever reads the chunks.
"""

from __future__ import annotations

import gzip
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from test_read import FAST_FLAVORS, program

import gcodekit
import gcodekit.read as read
from gcodekit.errors import Diagnostics
from gcodekit.read import Blocks, iter_blocks, iter_lines
from gcodekit.read.scan import scan
from gcodekit.syntax import load_flavor
from gcodekit.testing import assert_operations_equal

kernel = pytest.importorskip("gcodekit.read.scan_kernel")
if kernel.compiled() is None:
    pytest.skip("Numba is not installed (pip install 'gcodekit[fast]')", allow_module_level=True)


def assert_same_scan(data: bytes, flavor_name: str, max_line_length: int | None = 65536) -> None:
    flavor = load_flavor(flavor_name)
    ref = scan(data, flavor, max_line_length)
    got = kernel.scan_compiled(data, flavor, max_line_length)
    for field in ref.__dataclass_fields__:
        a, b = getattr(ref, field), getattr(got, field)
        if isinstance(a, np.ndarray):
            assert a.shape == b.shape, field
            if a.dtype.kind == "f":  # bit for bit: -0.0 and 0.0 differ
                assert b.dtype == a.dtype and np.array_equal(a.view(np.int64), b.view(np.int64)), field
            else:
                assert np.array_equal(a, b), field
        else:
            assert a == b, field


@settings(max_examples=400, deadline=None)
@given(program, st.sampled_from(FAST_FLAVORS))
@example("M23 G0\n", "marlin")
@example("G1 X-0 Y-0.000 E+.5\n", "marlin")  # negative zero stays negative zero
@example("G1 X1 2\nG1 X 12\nG1X1.2.3\n", "rs274ngc")  # a blank inside a number; two points
@example("L100023 X1\n", "marlin")  # a huge number whose key passes for M23's (as the NumPy scanner reads it)
@example("G10000 X1\nM-1\nG1 X1234567890123456\n", "marlin")  # odd codes; sixteen digits
@example("x1 y2 ; lower case\n", "marlin")
def test_compiled_scanner_matches_numpy_scanner(text, flavor):
    assert_same_scan(text.encode("utf-8", "surrogateescape"), flavor)


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=300).map(lambda b: b + b"\n"), st.sampled_from(["marlin", "klipper", "rs274ngc", "grbl"]))
def test_compiled_scanner_matches_on_any_bytes(data, flavor):
    assert_same_scan(data, flavor)


def test_long_lines_are_left_to_the_tokenizer_by_both():
    data = b"G1 X1\n" + b"G1 X" + b"1" * 50 + b"\n" + b";" + b"c" * 100 + b"\n"
    assert_same_scan(data, "marlin", max_line_length=40)
    assert_same_scan(data, "marlin", max_line_length=None)


def test_the_corpus_scans_the_same(shared_dir):
    for name, flavor in (("cylinder_marlin2.gcode", "marlin"), ("cube20_klipper.gcode", "klipper"),
                         ("cura_cube20_ender3.gcode", "marlin")):
        for chunk in iter_lines(shared_dir / "corpus" / "fff" / name):
            assert_same_scan(chunk, flavor)


def test_iter_blocks_gives_the_same_blocks_with_either_engine(shared_dir):
    path = shared_dir / "corpus" / "fff" / "cube20_marlin2.gcode"
    flavor = load_flavor("marlin")

    def blocks(engine):
        diagnostics = Diagnostics(str(path))
        parts = list(iter_blocks(iter_lines(path, diagnostics), flavor, diagnostics, engine=engine))
        return Blocks.concat(parts), [str(d) for d in diagnostics], len(parts)

    (a, da, na), (b, db, nb) = blocks("numpy"), blocks("numba")
    assert nb <= na  # the compiled loop reads larger chunks
    assert da == db
    for field in ("block_line", "word_block", "word_letter", "word_col", "comment_block", "comment_col",
                  "comment_offsets"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    assert np.array_equal(a.word_value.view(np.int64), b.word_value.view(np.int64))
    assert a.comment_data == b.comment_data


def test_the_operation_is_the_same_whichever_engine_reads_it(tmp_path, shared_dir, monkeypatch):
    # the cylinder three times over: past the size from which "auto" switches to the compiled loop
    text = (shared_dir / "corpus" / "fff" / "cylinder_marlin2.gcode").read_bytes()
    path = tmp_path / "three.gcode.gz"
    path.write_bytes(gzip.compress(text * 3, compresslevel=1))
    monkeypatch.setattr(read, "COMPILED_AFTER_BYTES", 1 << 40)
    by_numpy = gcodekit.gcode_to_operation(path, "marlin")
    monkeypatch.setattr(read, "COMPILED_AFTER_BYTES", len(text))
    monkeypatch.setattr(read, "COMPILED_CHUNK_BYTES", 1 << 20)
    mixed = gcodekit.gcode_to_operation(path, "marlin")
    assert mixed.n_lines == by_numpy.n_lines == 3 * text.count(b"\n")
    assert_operations_equal(mixed, by_numpy)
    assert np.array_equal(np.asarray(mixed.waypoints["time"]), np.asarray(by_numpy.waypoints["time"]))
    assert [str(d) for d in mixed.diagnostics] == [str(d) for d in by_numpy.diagnostics]


def test_the_engine_is_a_checked_choice():
    flavor = load_flavor("marlin")
    with pytest.raises(ValueError, match="engine"):
        list(iter_blocks([b"G1 X1\n"], flavor, Diagnostics(), engine="fortran"))


def test_without_numba_the_numpy_scanner_reads_and_numba_is_asked_for_by_name():
    # a fresh interpreter in which importing numba fails
    code = """
import sys
sys.modules["numba"] = None
import gcodekit, gcodekit.read as read
from gcodekit.errors import Diagnostics, MissingDependencyError
from gcodekit.syntax import load_flavor
read.COMPILED_AFTER_BYTES = 0
blocks = list(read.iter_blocks([b"G1 X1.5\\n"] * 3, load_flavor("marlin"), Diagnostics()))
assert [b.word_value.tolist() for b in blocks] == [[1.0, 1.5]] * 3, blocks
try:
    list(read.iter_blocks([b"G1 X1\\n"], load_flavor("marlin"), Diagnostics(), engine="numba"))
except MissingDependencyError as exc:
    print("asked:", exc)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "asked: the compiled scanner needs Numba: pip install 'gcodekit[fast]'" in out.stdout


def test_import_gcodekit_leaves_numba_unloaded():
    out = subprocess.run([sys.executable, "-c", "import sys, gcodekit; print('numba' in sys.modules)"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_the_progress_bar_counts_the_text_and_names_the_planning(tmp_path, shared_dir, capsys):
    text = (shared_dir / "corpus" / "fff" / "cube20_marlin2.gcode").read_bytes()
    path = tmp_path / "cube.gcode.gz"
    path.write_bytes(gzip.compress(text))
    gcodekit.gcode_to_operation(path, "marlin", progress=True)
    err = capsys.readouterr().err
    assert "cube.gcode.gz" in err and "planning" in err and "(marlin)" in err
    assert f"{len(text) / 1000:.0f}k" in err.replace("kB", "k")  # every byte of the text counted
    assert "%|" not in err  # no share of an unknown total
    gcodekit.gcode_to_operation(shared_dir / "corpus" / "fff" / "cube20_marlin2.gcode", "marlin", progress=True)
    assert "100%|" in capsys.readouterr().err
