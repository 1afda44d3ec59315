"""Lathe cycles G70-G72 (gcodekit.emulate.lathe) on small profiles worked out by hand.

Reference: LinuxCNC 2.9.0~pre1 rs274 (run_rs274.sh); the corpus programs are
golden cases in tests/golden/linuxcnc.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import gcodekit

# A straight face from the cycle point's height down to X2 Z0, a taper to X4 Z-5, a step to X5.
PROFILE = """G18 G21 F100
O100 SUB
G1 X2 Z0
G1 X4 Z-5
G1 X5
O100 ENDSUB
G0 X6 Z1
{cycle}
M2
"""


def moves(cycle: str) -> list[tuple[str, float, float]]:
    op = gcodekit.gcode_to_operation(PROFILE.format(cycle=cycle), machine="linuxcnc", plan=False)
    assert not [d for d in op.diagnostics if d.severity == "error"]
    m = op.motions()
    return [(r.motion, round(r.x, 4), round(r.z, 4)) for r in m.itertuples()][1:]  # after the G0 to X6 Z1


def test_rough_turning_passes() -> None:
    """G71 I0.5 R0.3 D0.2: passes every 0.5 in X, each ended 0.2 off the profile and left at 45 degrees by R."""
    got = moves("G71 Q100 X6 Z1 D0.2 I0.5 R0.3")
    # the cycle point, the approach and the first pass: X6 meets the step (Z-5) moved 0.2 towards Z+
    assert got[:7] == [("rapid", 6.0, 1.0)] * 3 + [("feed", 6.0, -4.8), ("rapid", 6.3, -4.5),
                                                   ("rapid", 6.3, 0.7), ("rapid", 6.0, 1.0)]
    # the pass at X4 ends on the taper moved 0.2 along its normal (2, 5)/sqrt(29) in (Z, X)
    n = math.sqrt(29.0)
    x_on_taper = 4.0 - 1.0 / n
    z_end = -(x_on_taper - 2.0) * 2.5 + 0.4 / n
    passes = [m for m in got if m[0] == "feed" and m[1] == 4.0]
    assert passes and passes[0][2] == pytest.approx(z_end, abs=1e-4) == -4.4615


def test_finishing_pass_follows_the_profile() -> None:
    """G70 D0 P1: rapid to the cycle point and along the profile's first block, then feed along the rest."""
    got = moves("G70 Q100 X6 Z1")
    assert got == [("rapid", 6.0, 1.0), ("rapid", 6.0, 1.0), ("rapid", 2.0, 0.0),
                   ("feed", 4.0, -5.0), ("feed", 5.0, -5.0)]


def test_profile_reads_its_own_point() -> None:
    """Inside the profile #<_x> and #<_z> are the profile's point so far (rs274 moves nothing while reading)."""
    program = PROFILE.replace("G1 X2 Z0", "G1 X[#<_x> - 4] Z[#<_z> - 1]").format(cycle="G70 Q100 X6 Z1")
    op = gcodekit.gcode_to_operation(program, machine="linuxcnc", plan=False)
    m = op.motions()
    assert np.allclose(m[["x", "z"]].to_numpy()[3], [2.0, 0.0])


@pytest.mark.parametrize("cycle, message", [
    ("G71 X6 Z1 D0.2", "G7x.x  requires a Q word"),
    ("G71 Q100 X6 Z1 D0.2 I0", "G7X error: I must be greater than zero."),
])
def test_errors_as_rs274(cycle: str, message: str) -> None:
    """rs274's messages; it names the cycle's line (for I0 it names the profile's endsub, we the cycle)."""
    op = gcodekit.gcode_to_operation(PROFILE.format(cycle=cycle), machine="linuxcnc", plan=False)
    errors = [d for d in op.diagnostics if d.severity == "error"]
    assert errors[0].message == message and errors[0].line == 8


def test_plane_must_be_xz() -> None:
    program = PROFILE.replace("G18", "G17").format(cycle="G71 Q100 X6 Z1 D0.2")
    op = gcodekit.gcode_to_operation(program, machine="linuxcnc", plan=False)
    errors = [d for d in op.diagnostics if d.severity == "error"]
    assert errors[0].message == "G71.0 can only be used in XZ plane (G18)" and errors[0].line == 8


@pytest.mark.parametrize("cycle, refused", [("G71", True), ("G72", True), ("G70", False)])
def test_only_g70_runs_under_compensation(cycle: str, refused: bool) -> None:
    """rs274: "G71.0 cannot be used with cutter compensation enabled", on the cycle's line; G70 may run."""
    program = PROFILE.replace("G0 X6 Z1", "G0 X6 Z1\nG42.1 D0.4 L2").format(cycle=f"{cycle} Q100 X6 Z1 D0.2 I0.5")
    op = gcodekit.gcode_to_operation(program, machine="linuxcnc", plan=False)
    errors = [(d.line, d.message) for d in op.diagnostics if d.severity == "error"]
    refusal = (9, f"{cycle}.0 cannot be used with cutter compensation enabled")
    assert (refusal in errors) == refused


def test_axis_words_alone_continue_in_the_cycles_last_mode() -> None:
    """rs274 (checked with run_rs274.sh): after this G71, whose last move climbs back to X6, the mode
    is G1; after a G70 whose profile ends in an arc it is that arc's, so "X8 Z4" then lacks its I/K
    ("R i j k words all missing for arc")."""
    arc_end = PROFILE.replace("G1 X5\n", "G2 X6 Z-7 I2 K0\n")
    after_rough = gcodekit.gcode_to_operation(PROFILE.format(cycle="G71 Q100 X6 Z1 D0.2 I0.5\nX8 Z4"),
                                              machine="linuxcnc", plan=False)
    last = after_rough.motions().iloc[-1]
    assert (last.motion, last.x, last.z, last.line) == ("feed", 8.0, 4.0, 9)
    after_finish = gcodekit.gcode_to_operation(arc_end.format(cycle="G70 Q100 X6 Z1\nX8 Z4"),
                                               machine="linuxcnc", plan=False)
    errors = [(d.line, d.message) for d in after_finish.diagnostics if d.severity == "error"]
    assert errors == [(9, "R i j k words all missing for arc")]


def test_cycle_arcs_are_measured_along_the_arc() -> None:
    """A quarter circle of radius 2 in a G70 profile is pi long and cut at F, not at the rapid rate;
    axis words with K after it cut the next arc of the cycle's mode (own golden case lathe_arc_after_cycle)."""
    text = ("G18 G21 F120\nO100 SUB\nG0 X2 Z0\nG3 X4 Z-2 K-2\nO100 ENDSUB\nG0 X6 Z2\n"
            "G70 Q100 X6 Z2\nX6 Z-4 K-2\nM2\n")
    op = gcodekit.gcode_to_operation(text, machine="linuxcnc", plan=False)
    w = op.waypoints
    arcs = np.flatnonzero(np.asarray(w["motion"]) == 4)  # G3
    assert len(arcs) == 2
    for i in arcs:  # both quarter circles of radius 2
        assert w["distance"][i] == pytest.approx(math.pi)
        assert w["time"][i] == pytest.approx(math.pi / 120 * 60)  # seconds at 120 mm/min
    assert (w["x"][arcs[1]], w["z"][arcs[1]], w["cx"][arcs[1]], w["cz"][arcs[1]]) == (6.0, -4.0, 4.0, -4.0)


def test_a_roughing_cycle_that_makes_no_progress_is_an_error_not_a_hang() -> None:
    """LinuxCNC's tests/interp/g71-endless-loop profile (a step back up the face): rs274 2.9 emits the
    same zero-length feed forever; gcodekit reports the cycle and goes on."""
    text = ("G21 G18 G8 G91.1\nO200 SUB\nG01 X10 Z0\nG01 X10 Z-14\nG01 X3\nG01 X7 Z-22\nO200 ENDSUB\n"
            "F225\nG71.2 Q200 X15.0 Z0 D0.04 I0.5 R1\nG0 X20\nM2\n")
    op = gcodekit.gcode_to_operation(text, machine="linuxcnc", plan=False)
    assert [d.line for d in op.diagnostics.errors] == [9]
    assert "stop making progress" in op.diagnostics.errors[0].message
    assert op.motions().iloc[-1].x == 20.0  # the program went on after the cycle


def test_profile_block_before_any_motion_word_is_a_line() -> None:
    """rs274 (run_rs274.sh, after G0, G1, G2 and G80 alike; LinuxCNC's tests/interp/g71-endless-loop2):
    ``Z-333`` opening the profile is a line from the cycle point, so the pass runs down X168 first."""
    text = ("G18 G21\nF100\nO2 SUB\nZ-333\nG1 X170\nZ-415\nO2 ENDSUB\nG2 X168 Z0 R100\n"
            "G71 Q2 X168 Z0\nG0 X300 Z10\nM30\n")
    op = gcodekit.gcode_to_operation(text, machine="linuxcnc", plan=False)
    cycle = op.motions().query("line == 9")
    assert list(zip(cycle.motion, cycle.x, cycle.z)) == [
        ("rapid", 168.0, 0.0), ("rapid", 168.0, 0.0), ("feed", 168.0, -333.0), ("feed", 170.0, -333.0),
        ("feed", 170.0, -415.0)]


def test_profile_is_data_on_the_cycle_row() -> None:
    """The profile the Q subroutine gives is carried as words on the cycle's row, not in its comment."""
    op = gcodekit.gcode_to_operation(PROFILE.format(cycle="G70 Q100 X6 Z1 (finish)"), machine="linuxcnc", plan=False)
    row = next(i for i in range(len(op.table)) if op.table.command(i).name == "lathe_finish")
    cmd = op.table.command(row)
    assert cmd.comment == "finish" and op.table.profiles[row] is cmd.profile
    assert [[(w.letter, w.value) for w in b.words] for b in cmd.profile.blocks] == [
        [("G", 1.0), ("X", 2.0), ("Z", 0.0)], [("G", 1.0), ("X", 4.0), ("Z", -5.0)], [("G", 1.0), ("X", 5.0)]]


def test_exported_program_runs_without_the_subroutine() -> None:
    """The G-code writer puts the profile after the cycle's comment, where reading the output finds it again."""
    from gcodekit.export.gcode import GcodeExporter

    op = gcodekit.gcode_to_operation(PROFILE.format(cycle="G71 Q100 X6 Z1 D0.2 I0.5 R0.3 (rough)"),
                                     machine="linuxcnc", plan=False)
    text = GcodeExporter("rs274ngc").to_gcode(op)
    assert "O100" not in text.upper() and "(rough g7x profile: G1 X2 Z0; G1 X4 Z-5; G1 X5)" in text
    again = gcodekit.gcode_to_operation(text, machine="linuxcnc", plan=False)
    assert not again.diagnostics.items
    cycle = next(i for i in range(len(again.table)) if again.table.command(i).name == "lathe_rough")
    assert again.table.command(cycle).comment == "rough"
    np.testing.assert_allclose(again.motions()[["x", "z"]].to_numpy(), op.motions()[["x", "z"]].to_numpy())
