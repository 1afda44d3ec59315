"""The optional compiler every compiled kernel goes through (``gcodekit.jit``)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from gcodekit.jit import compile_loops, numba_loaded


def _ratio(a, b):
    return a / b


def _ratio_numpy_model(a, b):  # its own function: Numba's disk cache keys a function, not its options
    return a / b


def _total(values):
    out = 0.0
    for v in values:
        out += v
    return out


def test_the_loops_compile_in_order_and_compute_what_python_does():
    pytest.importorskip("numba")
    import numpy as np

    ratio, total = compile_loops(_ratio, _total)
    values = np.array([0.1, 0.2, 0.3])
    assert total(values) == _total(values) == 0.1 + 0.2 + 0.3  # the same additions in the same order
    assert ratio(3.0, 4.0) == 0.75
    assert numba_loaded()


def test_options_reach_numba_a_division_by_zero_is_inf_with_numpy_s_error_model():
    pytest.importorskip("numba")
    (python_model,) = compile_loops(_ratio)
    (numpy_model,) = compile_loops(_ratio_numpy_model, error_model="numpy")
    with pytest.raises(ZeroDivisionError):
        python_model(1.0, 0.0)
    assert numpy_model(1.0, 0.0) == float("inf")


def test_without_numba_there_is_nothing_to_compile():
    code = """
import sys
sys.modules["numba"] = None  # as if not installed: importing it fails
from gcodekit.jit import compile_loops, numba_loaded
from gcodekit.plan import kernels
print(compile_loops(len), numba_loaded(), kernels.compiled())
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["None", "False", "None"]
