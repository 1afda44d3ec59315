"""Parse stage: the compiled loops (Numba) give the NumPy passes' command table, to the last bit.

The NumPy passes are the reference (themselves checked against the
splitter and the golden comparisons); the compiled loops of
:mod:`gcodekit.parse.rows_kernel` must give identical block summaries, rows, parameters
(bit for bit) and diagnostics on every input, and the pipeline the same
operation whichever builds the rows.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from test_read import FAST_FLAVORS, program

import gcodekit
from gcodekit.errors import Diagnostics
from gcodekit.parse import GcodeParser, parser, rows_kernel
from gcodekit.parse.table import SparseColumn
from gcodekit.read import read_file, read_text
from gcodekit.testing import assert_operations_equal

if rows_kernel.compiled() is None:
    pytest.skip("Numba is not installed (pip install 'gcodekit[fast]')", allow_module_level=True)


def _same_array(a, b, what):
    if isinstance(a, SparseColumn):
        assert isinstance(b, SparseColumn) and a.size == b.size, what
        _same_array(a.rows, b.rows, what)
        _same_array(a.values, b.values, what)
        return
    assert a.dtype == b.dtype and a.shape == b.shape, what
    if a.dtype.kind == "f":  # bit for bit: -0.0 and 0.0 differ
        assert np.array_equal(a.view(np.int64), b.view(np.int64)), what
    else:
        assert np.array_equal(a, b), what


def assert_same_tables(blocks, flavor: str) -> None:
    n_letter = GcodeParser(flavor)._n_letter
    ref = parser._block_words(blocks.word_block, blocks.word_letter, len(blocks), n_letter)
    got = rows_kernel.block_words_compiled(blocks.word_block, blocks.word_letter, len(blocks), n_letter, parser._AXIS)
    for name, a, b in zip(("n_codes", "has_param", "has_axis", "code_word"), ref, got):
        _same_array(a, b, name)
    tables, said = [], []
    for engine in ("numpy", "numba"):
        diagnostics = Diagnostics("t")
        tables.append(GcodeParser(flavor, diagnostics, engine=engine).parse(blocks))
        said.append([str(d) for d in diagnostics])
    ref, got = tables
    assert said[0] == said[1]
    for field in ref.__dataclass_fields__:
        a, b = getattr(ref, field), getattr(got, field)
        if isinstance(a, np.ndarray):
            _same_array(a, b, field)
        elif field == "params":
            assert list(a) == list(b)
            for letter in a:
                _same_array(a[letter], b[letter], letter)
        else:
            assert a == b, field


@settings(max_examples=300, deadline=None)
@given(program, st.sampled_from(FAST_FLAVORS))
@example("G1 X1 X2 Y1 Y2 Y3 E-0\nG1 Y1 X1 Y2 X2\n", "marlin")  # repeated letters, in an order not the table's
@example("T1\nT0 T2\nT1 M6\nM6 T3\nG1 T4 X1\n", "marlin")  # tool words: the command, or a parameter
@example("N10 G1 X1\nN20 X2\n", "rs274ngc")  # line numbers are no parameters
@example("G1 X1 X2\nX1 Y1 Y2\n", "rs274ngc")  # repeats are errors in rs274
@example("; only a comment\n\nG92.1\nM104.5 S1\n", "marlin")
def test_compiled_rows_match_numpy_rows(text, flavor):
    assert_same_tables(read_text(text, flavor=flavor), flavor)


@pytest.mark.parametrize("folder, name, flavor", [
    ("fff", "cylinder_marlin2.gcode", "marlin"),
    ("fff", "cube20_klipper.gcode", "klipper"),
    ("fff", "cura_cube20_ender3.gcode", "marlin"),
    ("realworld", "bambustudio_1.7.6_x1_cube.gcode", "marlin"),
    ("realworld", "fusion360_sheeptile.nc", "rs274ngc"),
    ("realworld", "vectric_demo.gcode", "grbl"),
])
def test_the_corpus_parses_the_same(shared_dir, folder, name, flavor):
    assert_same_tables(read_file(shared_dir / "corpus" / folder / name, flavor=flavor), flavor)


def test_linuxcnc_programs_parse_the_same(shared_dir):
    files = sorted((shared_dir / "corpus" / "linuxcnc" / "nc_files").glob("*.ngc"))[:40]
    assert files
    for path in files:
        assert_same_tables(read_file(path, flavor="rs274ngc"), "rs274ngc")


def test_the_operation_is_the_same_whichever_engine_parses_it(shared_dir, monkeypatch):
    path = shared_dir / "corpus" / "fff" / "cylinder_marlin2.gcode"
    monkeypatch.setattr(rows_kernel, "COMPILED_FROM_BLOCKS", 1 << 40)
    by_numpy = gcodekit.gcode_to_operation(path, "marlin")
    monkeypatch.setattr(rows_kernel, "COMPILED_FROM_BLOCKS", 0)
    compiled = gcodekit.gcode_to_operation(path, "marlin")
    assert_operations_equal(compiled, by_numpy)
    assert np.array_equal(np.asarray(compiled.waypoints["time"]), np.asarray(by_numpy.waypoints["time"]))
    assert [str(d) for d in compiled.diagnostics] == [str(d) for d in by_numpy.diagnostics]


def test_the_engine_is_a_checked_choice():
    with pytest.raises(ValueError, match="engine"):
        GcodeParser("marlin", engine="fortran")


def test_auto_takes_the_compiled_loop_only_for_large_chunks_once_numba_is_loaded():
    assert not rows_kernel.use_compiled("auto", rows_kernel.COMPILED_FROM_BLOCKS - 1)
    assert rows_kernel.use_compiled("auto", rows_kernel.COMPILED_FROM_BLOCKS)  # numba is loaded here
    assert not rows_kernel.use_compiled("numpy", 1 << 30)
    assert rows_kernel.use_compiled("numba", 1)


def test_without_numba_the_numpy_passes_parse_and_numba_is_asked_for_by_name():
    code = """
import sys
sys.modules["numba"] = None
from gcodekit.errors import MissingDependencyError
from gcodekit.parse import GcodeParser, parser, rows_kernel
from gcodekit.read import read_text
rows_kernel.COMPILED_FROM_BLOCKS = 0
table = GcodeParser("marlin").parse(read_text("G1 X1.5\\nT2\\n", flavor="marlin"))
assert table.param("X")[0] == 1.5 and table.number.tolist() == [10, 20], table
try:
    GcodeParser("marlin", engine="numba")
except MissingDependencyError as exc:
    print("asked:", exc)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "asked: the compiled parser needs Numba: pip install 'gcodekit[fast]'" in out.stdout
