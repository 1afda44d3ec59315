"""G33 spindle-synchronized moves: feed from the spindle, rs274's errors (checked in rs274 2.9)."""

from __future__ import annotations

import pytest

import gcodekit


def run(body: str):
    return gcodekit.gcode_to_operation("G21 G18 G0 X0 Z0\nF10\n" + body + "\nM2\n", "linuxcnc", plan=False)


def test_g33_moves_at_k_per_revolution():
    op = run("S400 M3\nG33 Z-20 K1.5\nG33 X5 Z-25 K2\nG1 X10")
    m = op.motions()
    assert m[["x", "z"]].values.tolist()[1:] == [[0.0, -20.0], [5.0, -25.0], [10.0, -25.0]]
    assert m["feed"].tolist()[1:] == [600.0, 800.0, 10.0]  # K x 400 rpm, then the modal F again
    assert m["time"].iloc[1] == pytest.approx(20 / 600 * 60)  # 20 mm at 600 mm/min


@pytest.mark.parametrize("body, line, message", [
    ("S400 M3\nG33 Z-1", 4, "K word missing with g33/g33.1"),
    ("G33 Z-1 K0.1", 3, "Spindle not turning in G33"),
    ("S400 M3\nG33 Z-1 K0.1\nZ-2", 5, "K word missing with g33/g33.1"),  # G33 is modal, K is not
    ("S400 M3\nG33 Z-1 K0.1 F50", 4, "F word used with a g33/g33.1"),
])
def test_errors_as_rs274_words_them(body, line, message):
    problems = [(d.line, d.message) for d in run(body).diagnostics if d.severity == "error"]
    assert problems[:1] == [(line, message)]
