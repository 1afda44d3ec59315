"""Emulate stage: the compiled forward fill (Numba) gives NumPy's columns, and the machine the same operation, to the last bit.

:func:`gcodekit.emulate.fill.forward_fill_numpy` is the reference; the
compiled loop copies the same words, so every waypoint column must agree
bit for bit whichever fills, on hand cases and on corpus programs of the
Marlin, Klipper and LinuxCNC machines.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from test_linuxcnc_golden import CASES, RS274_STANDALONE, tool_table

import gcodekit
from gcodekit.emulate import fill

if fill.compiled() is None:
    pytest.skip("Numba is not installed (pip install 'gcodekit[fast]')", allow_module_level=True)

words = st.lists(st.one_of(st.just(np.nan), st.floats(allow_nan=False), st.sampled_from([0.0, -0.0])), max_size=60)


@settings(max_examples=300, deadline=None)
@given(words, st.one_of(st.floats(), st.just(-0.0)))
@example([], 1.0)
@example([np.nan, np.nan], np.nan)
@example([np.nan, -0.0, np.nan, 2.5, np.inf, np.nan], -0.0)
def test_compiled_fill_matches_numpy(values, initial):
    values = np.array(values, np.float64)
    ref = fill.forward_fill_numpy(values, initial)
    got = fill.compiled()(values, float(initial))
    assert got.dtype == ref.dtype and got.tobytes() == ref.tobytes()


def _columns(op) -> dict[str, bytes]:
    return {k: np.ascontiguousarray(v).tobytes() for k, v in op.waypoints.items()}


def _both(monkeypatch, run):
    monkeypatch.setattr(fill, "COMPILED_FROM", 1 << 60)
    by_numpy = run()
    monkeypatch.setattr(fill, "COMPILED_FROM", 0)
    compiled = run()
    assert _columns(compiled) == _columns(by_numpy)
    assert [str(d) for d in compiled.diagnostics] == [str(d) for d in by_numpy.diagnostics]


@pytest.mark.parametrize("name, machine", [("cylinder_marlin2.gcode", "marlin"), ("cube20_klipper.gcode", "klipper"),
                                           ("vase_spiral_marlin2.gcode", "marlin")])
def test_printer_programs_emulate_the_same(shared_dir, monkeypatch, name, machine):
    path = shared_dir / "corpus" / "fff" / name
    _both(monkeypatch, lambda: gcodekit.gcode_to_operation(path, machine, plan=False))


def test_linuxcnc_programs_emulate_the_same(monkeypatch):
    cases = sorted(p.name for p in CASES.glob("*.ngc"))[:25]
    assert cases
    for name in cases:
        _both(monkeypatch, lambda: gcodekit.gcode_to_operation(CASES / name, plan=False, tool_table=tool_table(name),
                                                               **RS274_STANDALONE))


def test_hand_cases_emulate_the_same(monkeypatch):
    text = "G21 G90\nG0 X1 Y-0 Z0.2\nG1 X5 F600\nY3\nG91\nG1 X1 Y1\nG90 M3 S1000\nG1 X-0 S200\nG20 G1 X1 F10\n"
    _both(monkeypatch, lambda: gcodekit.gcode_to_operation(text, "linuxcnc", plan=False))
    printer = "G21\nG92 E0\nG1 X1 E1 F1200\nG1 X2 E2\nM83\nG1 X3 E0.5\nG1 E-1 F2400\nG0 Z5\n"
    _both(monkeypatch, lambda: gcodekit.gcode_to_operation(printer, "marlin", plan=False))


def test_without_numba_numpy_fills():
    code = """
import sys
sys.modules["numba"] = None
import numpy as np
from gcodekit.emulate import fill
fill.COMPILED_FROM = 0
print(fill.forward_fill(np.array([np.nan, 1.0, np.nan]), 5.0).tolist())
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[5.0, 1.0, 1.0]"
