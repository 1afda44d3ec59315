"""A large program's waypoints kept compactly (runs, decimal units, the times a plan replaces dropped) give the
same columns and the same plans, bit for bit, as the plain arrays the pipeline kept before.

The reference is the same program read with the compaction turned off
(every column a float array, the emulator's times kept while planning)
and planned by the NumPy code: the path every golden, Klipper and
PrusaSlicer comparison checks.
"""

from __future__ import annotations

import numpy as np
import pytest

import gcodekit
from gcodekit import columns
from gcodekit.columns import RunColumn, Waypoints
from gcodekit.parse.table import DecimalColumn
from gcodekit.pipeline import assemble
from gcodekit.plan import kernels
from gcodekit.plan.times import PlannedTimes

ENGINES = ["numpy"] + (["numba"] if kernels.compiled() is not None else [])
FIELDS = ("start_v", "cruise_v", "end_v", "accel", "accel_t", "cruise_t", "decel_t")


def _print(layers: int = 40, per_layer: int = 500) -> str:
    """A print of about 20,000 moves (several read chunks): absolute X Y with three decimals, relative E with
    five, a travel feed and a print feed, z-hops, a retraction, a dwell and a move at F0 on the way."""
    rng = np.random.default_rng(3)
    lines = ["G21", "G90", "M83", "G28", "G1 Z0.2 F600"]
    for layer in range(layers):
        z = 0.2 + 0.2 * layer
        lines.append(f"G1 Z{z:.2f} F600")
        xy = np.round(rng.uniform(10, 190, size=(per_layer, 2)), 3)
        e = np.round(rng.uniform(0.001, 0.2, size=per_layer), 5)
        for k, ((x, y), de) in enumerate(zip(xy, e)):
            if k % 97 == 0:
                lines += ["G1 E-0.8 F2100", f"G1 Z{z + 0.4:.2f} F600", f"G0 X{x:.3f} Y{y:.3f} F9000",
                          f"G1 Z{z:.2f} F600", "G1 E0.8 F2100"]
            else:
                lines.append(f"G1 X{x:.3f} Y{y:.3f} E{de:.5f} F{1800 if k > 100 else 1200}")
        if layer == 5:
            lines += ["G4 P250", "M400"]
    lines += ["G1 X20 F0", "M104 S0"]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def program() -> str:
    return _print()


def _plain(monkeypatch, text: str, machine: str):
    """The program read with every compaction off, planned by the NumPy code (the compiled loops' reference)."""
    with monkeypatch.context() as m:
        m.setattr(assemble, "WRITTEN", ())
        m.setattr(columns.GrowingRuns, "FEW_RUNS", 0)
        m.setattr(columns.GrowingRuns, "MIN_VALUES_PER_RUN", 1 << 40)
        m.setattr(gcodekit.pipeline, "times_every_move", lambda name: False)
        with kernels.using("numpy"):
            op = gcodekit.gcode_to_operation(text, machine)
    assert all(type(op.waypoints.stored(k)) is np.ndarray for k in op.waypoints if k != "time")  # (times: planned)
    return op


def _bits(a) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a)).view(np.uint8)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("machine", ["marlin", "klipper"])
def test_compact_waypoints_plan_as_the_plain_ones(program, monkeypatch, machine, engine):
    with kernels.using(engine):
        op = gcodekit.gcode_to_operation(program, machine)
    plain = _plain(monkeypatch, program, machine)
    w = op.waypoints
    assert isinstance(w, Waypoints)
    # what the planner reads, still compact after planning: nothing decoded the whole column
    assert isinstance(w.stored("x"), DecimalColumn) and w.stored("x").places == 3
    assert isinstance(w.stored("de"), DecimalColumn) and w.stored("de").places == 5
    assert isinstance(w.stored("feed"), RunColumn) and isinstance(w.stored("z"), RunColumn)
    assert w.stored("feed").nbytes < np.asarray(plain.waypoints["feed"]).nbytes / 5
    assert isinstance(w.stored("time"), PlannedTimes)  # computed when read
    moves, result = op.plan
    ref_moves, ref_result = plain.plan
    for field in ("speed_v", "row", "waypoint", "length_d"):
        np.testing.assert_array_equal(_bits(getattr(moves, field)), _bits(getattr(ref_moves, field)), field)
    for field in FIELDS:
        np.testing.assert_array_equal(_bits(getattr(result.phases(), field)), _bits(getattr(ref_result.phases(), field)),
                                      field)
    assert list(w) == list(plain.waypoints)
    for key in plain.waypoints:  # every column, decoded, the plain one; the planned times too
        np.testing.assert_array_equal(_bits(w[key]), _bits(plain.waypoints[key]), key)
    assert [str(d) for d in op.diagnostics] == [str(d) for d in plain.diagnostics]


def test_the_times_a_plan_replaces_are_dropped_and_the_rest_kept():
    w = {"time": np.array([1.0, 0.5, np.nan, 2.0, np.inf, 0.0, 3.0]),
         "motion": np.array([1, 0, 2, 0, 1, 0, 3], np.uint8)}
    kept = np.asarray(gcodekit.plan.times_to_plan(w))
    np.testing.assert_array_equal(kept, [0.0, 0.5, np.nan, 2.0, np.inf, 0.0, 0.0])
    assert gcodekit.plan.times_every_move("marlin") and gcodekit.plan.times_every_move("klipper")
    assert not gcodekit.plan.times_every_move("grbl")  # it keeps the emulator's time of rotary-only moves
    assert not gcodekit.plan.times_every_move("motion_profile")  # it plans at the emulator's speeds
