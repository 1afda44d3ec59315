"""Runaway programs stop at a limit, with an error naming their line, before the memory is spent.

The cases of issue 14 are here as regressions: each once ran for tens of
seconds and took gigabytes (or never stopped).  The expected counts are
worked out by hand in each test.  Nothing here measures time: a program
that ran away would exhaust the suite's memory or never finish, and the
fuzz suite (tests/test_fuzz.py) runs such programs under real time and
memory limits.
"""

from __future__ import annotations

import pytest
from cli_helpers import run

import gcodekit
from gcodekit.errors import ConfigError, GcodeLimitError
from gcodekit.limits import MAX_ITERATIONS, MAX_MOTIONS
from gcodekit.parse.table import NAME_ID


def limit_errors(op) -> list:
    return [d for d in op.diagnostics.errors if "max_motions" in d.message or "max_iterations" in d.message]


def test_a_canned_cycle_repeated_a_billion_times_is_refused_before_it_runs():
    op = gcodekit.gcode_to_operation("G21 G90 G0 Z5\nG81 X1 Y1 Z-1 R1 L999999999 F100\nG0 X50\nM2\n",
                                     "linuxcnc", plan=False)
    (error,) = limit_errors(op)
    assert (error.line, error.column) == (2, 1) and "max_motions=50,000,000" in error.message
    assert len(op.motions()) == 1  # the first rapid; nothing after the runaway block


def test_a_cycle_that_fits_runs_and_counts_against_the_limit():
    # G98 G81 from Z5, R at 1 (R-4 in G91), down to -1 (Z-2), three holes 1 mm apart in X: per hole a
    # rapid over it at Z5, a rapid to R, the feed down and the rapid back to Z5: 4 moves; 13 with the G0.
    text = "G21 G90 G0 Z5\nG91 G98 G81 X1 Y0 Z-2 R-4 L3 F100\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    assert len(op.motions()) == 13 and not op.diagnostics.errors
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, max_motions=10)
    (error,) = limit_errors(op)
    assert error.line == 2 and "max_motions=10" in error.message


def test_a_peck_of_a_micron_is_refused_before_it_is_expanded():
    # 101 mm at 0.00001 mm a peck is ten million pecks, three moves each
    op = gcodekit.gcode_to_operation("G21 G90 G0 Z5\nG83 X1 Y1 Z-100 R1 Q0.00001 F100\nM2\n", "linuxcnc",
                                     plan=False, max_motions=1_000_000)
    (error,) = limit_errors(op)
    assert error.line == 2 and "30,300,008 motions" in error.message


def test_a_thread_of_countless_passes_is_refused():
    op = gcodekit.gcode_to_operation("G18 G21 G90 G0 X10 Z5 S100 M3\nG76 P1 Z-10 I-0.5 J0.0000001 K1 R9\nM2\n",
                                     "linuxcnc", plan=False)
    (error,) = limit_errors(op)
    assert error.line == 2 and "countless motions" in error.message


def test_m98_repeats_beyond_the_iteration_limit_are_refused_up_front():
    text = "O1\nM98 P1000 L999999999\nM30\nO1000\nG1 X1 F100\nG1 X0\nM99\n"
    op = gcodekit.gcode_to_operation(text, "fanuc", plan=False)
    (error,) = limit_errors(op)
    assert error.line == 2 and "M98 L999999999: 999,999,998 repeats" in error.message
    assert len(op.motions()) == 0
    op = gcodekit.gcode_to_operation(text.replace("L999999999", "L3"), "fanuc", plan=False)
    assert len(op.motions()) == 6 and not op.diagnostics.errors


def test_a_repeat_loop_beyond_the_limit_is_refused_up_front():
    op = gcodekit.gcode_to_operation("o1 repeat [1000000000]\nG1 X1 F100\nG1 X0\no1 endrepeat\nM2\n",
                                     "linuxcnc", plan=False)
    (error,) = limit_errors(op)
    assert error.line == 1 and "999,999,999 repeats" in error.message and len(op.motions()) == 0


def test_an_endless_moving_loop_stops_at_the_iteration_limit():
    text = "#1=0\no100 while [1]\nG1 X[#1 MOD 10] F1000\n#1=[#1+1]\no100 endwhile\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, max_iterations=2_000)
    (error,) = limit_errors(op)
    assert error.line == 5 and "more than max_iterations=2,000 loop iterations" in error.message
    assert len(op.motions()) == 2_001  # the first pass and 2,000 jumps back
    assert MAX_ITERATIONS == 100_000


ENDLESS = "this loop never ends"


def test_an_endless_probing_loop_stops_when_an_iteration_changes_nothing(shared_dir):
    """explore.sh seed 3151337617 case 82: LinuxCNC's smartprobe.ngc without its ``#10=[#10+1]``.  Each
    iteration reads the probe's result, so each costs a machine run, and reaching max_iterations took 113 s.
    The second O2 iteration leaves every parameter and the machine as the first did: the loop stops there."""
    text = (shared_dir / "corpus" / "linuxcnc" / "nc_files" / "smartprobe.ngc").read_text()
    assert text.count("#10=[#10+1]") == 1
    op = gcodekit.gcode_to_operation(text.replace("#10=[#10+1]", ""), "linuxcnc", plan=False)
    (error,) = [d for d in op.diagnostics.errors if ENDLESS in d.message]
    assert error.text.strip() == "O4 while [#5070 NE 0]" and error.severity == "error"
    # the probes of three passes over the O4 test: the first pass, the one that repeats it, and the run up to
    # the test that shows the repeat (G38.5, G38.3 in the O4 loop, G38.2 after it, and the first G0 Z)
    assert 3 <= int((op.table.name == NAME_ID["probe"]).sum()) <= 9
    with pytest.raises(GcodeLimitError, match=ENDLESS):
        gcodekit.gcode_to_operation(text.replace("#10=[#10+1]", ""), "linuxcnc", plan=False, mode="strict")


@pytest.mark.parametrize("loop", [
    # the same probe at the same place, and a result nothing changes
    "#1=1\no1 while [#1 GT 0]\nG38.3 Z-1 F100\n#2=#5063\nG0 Z1\no1 endwhile\nM2\n",
    # do-while, reading the machine's position
    "G0 X0\no2 do\nG1 X5 F100\nG1 X0\n#3=#5420\no2 while [#3 LT 1]\nM2\n",
])
def test_endless_loops_reading_the_machine_are_stopped_early(loop):
    op = gcodekit.gcode_to_operation(loop, "linuxcnc", plan=False)
    assert [d.line for d in op.diagnostics.errors if ENDLESS in d.message] == [2 if "o1" in loop else 6]
    assert len(op.motions()) <= 12


def test_a_loop_that_changes_only_the_machine_is_not_called_endless():
    """No parameter changes here (the test reads the position, which the G91 moves change): the machine's
    state differs at every test, and the loop ends at X = 10 after ten moves."""
    text = "G91\no1 while [#5420 LT 10]\nG1 X1 F600\no1 endwhile\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    assert not op.diagnostics.errors
    assert op.waypoints["x"].max() == 10.0 and len(op.motions()) == 10


def test_a_loop_without_the_machine_is_left_to_the_iteration_limit():
    """Its iterations are cheap; nothing is compared (the same parameters at each test: X0 written forever)."""
    op = gcodekit.gcode_to_operation("o1 while [1]\nG1 X0 F600\no1 endwhile\nM2\n", "linuxcnc", plan=False,
                                     max_iterations=500)
    assert [d.message for d in limit_errors(op)] == ["more than max_iterations=500 loop iterations"]


def test_generated_blocks_count_against_max_motions():
    text = "#1=0\no100 while [#1 LT 500]\nG1 X[#1 MOD 10] F1000\n#1=[#1+1]\no100 endwhile\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, max_motions=300)
    (error,) = limit_errors(op)
    assert error.line == 3 and "more than max_motions=300 blocks" in error.message
    assert len(op.motions()) == 300


def test_plain_blocks_beyond_the_limit_are_not_run():
    text = "".join(f"G1 X{k} F600\n" for k in range(1, 101))
    op = gcodekit.gcode_to_operation(text, "marlin", plan=False, max_motions=40)
    (error,) = limit_errors(op)
    assert error.line == 41 and len(op.motions()) == 40
    assert op.motions()["x"].max() == 40


def test_arc_chords_beyond_the_limit_are_planned_coarser():
    # Klipper cuts arcs into 1 mm chords: a full circle of radius 1e8 mm would be 6.3e8 of them
    op = gcodekit.gcode_to_operation("G21\nG90\nG0 X0 Y0\nG2 X0 Y0 I100000000 J0 F1000\n", "klipper",
                                     max_motions=10_000)
    (error,) = limit_errors(op)
    assert error.line == 4 and "628,318,530 moves" in error.message  # floor(2 pi 1e8 / 1 mm)
    moves, _ = op.plan
    assert len(moves) <= 10_000


def test_limits_are_whole_positive_numbers():
    for bad in (0, -5, 1.5, "10"):
        with pytest.raises(ConfigError, match="max_motions"):
            gcodekit.gcode_to_operation("G1 X1\n", "marlin", max_motions=bad)
    assert MAX_MOTIONS == 50_000_000


def test_strict_mode_raises_the_limit_error():
    with pytest.raises(GcodeLimitError, match=r"<string>:2:1: .*max_motions"):
        gcodekit.gcode_to_operation("G0 Z5\nG81 X1 Y1 Z-1 R1 L999999999 F100\n", "linuxcnc", mode="strict")


def test_the_command_line_sets_the_limits(tmp_path, capsys):
    program = tmp_path / "loop.ngc"
    program.write_text("#1=0\no100 while [#1 LT 50]\nG1 X#1 F100\n#1=[#1+1]\no100 endwhile\nM2\n")
    status, out, _ = run(["info", program, "--max-iterations", "20"], capsys)
    assert status == 0 and "loop.ngc:5:1: error: more than max_iterations=20 loop iterations" in out
    status, out, _ = run(["info", program, "--max-motions", "10", "--json"], capsys)
    assert "more than max_motions=10 blocks" in out
    with pytest.raises(SystemExit):
        run(["info", program, "--max-motions", "0"], capsys)


NESTED_LOOPS = ("G21 G90 G1 F100\n#1 = 0\no100 repeat [1000]\n  o200 repeat [1000]\n    #1 = [#1 + 1]\n"
                "  o200 endrepeat\no100 endrepeat\nG1 X1\nM2\n")


@pytest.mark.parametrize("command", [["translate"], ["export", "--to", "csv"], ["export", "--to", "events"],
                                     ["render", "-o", "{tmp}/out.png"]])
def test_every_command_stops_at_the_limit_with_infos_message(tmp_path, capsys, command):
    # two nested repeat [1000] loops: each outer turn runs 999 inner repeats and one outer repeat, 1000
    # iterations, so after two turns max_iterations=2,000 is spent and the third turn's 999 are refused
    program = tmp_path / "loops.ngc"
    program.write_text(NESTED_LOOPS)
    limits = ["--max-iterations", "2000"]
    status, out, _ = run(["info", program, *limits], capsys)
    message = f"{program}:4:3: error: o200 repeat [1000]: 999 repeats, more than the 0 iterations left of " \
              "max_iterations=2,000"
    assert status == 0 and message in out  # info reports it in its summary
    if command[0] == "render":
        pytest.importorskip("pyvista")
    status, out, err = run([*(c.format(tmp=tmp_path) for c in command), program, *limits], capsys)
    assert status == 1 and message in err  # a partial output: said, and a failing status


def test_notebook_reads_the_program_under_the_limits(tmp_path, capsys):
    pytest.importorskip("nbformat")
    program = tmp_path / "loops.ngc"
    program.write_text(NESTED_LOOPS)
    status, _, _ = run(["notebook", program, "-o", tmp_path / "n.ipynb", "--max-iterations", "2000"], capsys)
    text = (tmp_path / "n.ipynb").read_text()
    assert status == 0 and "max_iterations = 2000" in text and "max_iterations=max_iterations" in text
