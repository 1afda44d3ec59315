"""The worksheets in notebooks/worksheets/: the curriculum a course adopts.

- every exercise's answer worked out by hand here and accepted by its check; wrong answers refused with
  feedback that never holds the expected value;
- every write-the-G-code exercise: the teacher's program passes, the starting program and three plausible
  wrong programs fail with feedback naming what is wrong;
- nbgrader's own commands (generate_assignment, autograde, generate_feedback, through its Python API) on the
  source worksheets in a course directory: the teacher's answers score full marks, the released worksheet
  (answers left empty) and a hand-in of wrong answers score zero, and every notebook runs to its end;
- the facts the worksheets state about their programs (line numbers, what a line says).

The checks run in this process (each worksheet's code cells executed once, without a kernel); the notebooks
run in kernels only under nbgrader, once per hand-in, the three hand-ins graded side by side; the HTML tests
convert the autograded right hand-ins.
"""

from __future__ import annotations

import ast
import contextlib
import io
import math
import os
import re
import shutil
from pathlib import Path

import pytest

pytest.importorskip("nbgrader")

import nbformat  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
WORKSHEETS = ROOT / "notebooks" / "worksheets"
NAMES = sorted(p.stem for p in WORKSHEETS.glob("[0-9][0-9]-*.ipynb"))
_WIDGET_CELL = re.compile(r"^(LayerViewer|VelocityPlot|StageDiff)\(|\.view\(|^diff$")

#: E per mm of path of a 0.45 x 0.2 mm line with 1.75 mm filament.
_E_PER_MM = 0.45 * 0.2 / (math.pi * 1.75**2 / 4)


def _corner_speed(accel: float, deviation: float, theta_degrees: float) -> float:
    """Junction deviation's corner speed (mm/s) where the path makes the angle theta (90: a square corner)."""
    s = math.sin(math.radians(theta_degrees) / 2)
    return math.sqrt(accel * deviation * s / (1 - s))


def _scv_saving() -> float:
    """Seconds the zigzag saves on Klipper with square_corner_velocity 20 instead of 5, set in a printer.cfg."""
    import tempfile

    import gcodekit

    program = str(WORKSHEETS / "programs" / "zigzag.gcode")
    with tempfile.TemporaryDirectory() as folder:
        cfg = Path(folder) / "printer.cfg"
        cfg.write_text("[printer]\nmax_velocity: 300\nmax_accel: 3000\nsquare_corner_velocity: 20\n")
        fast = gcodekit.gcode_to_operation(program, "klipper", machine_config=cfg).get_statistics()["time_s"]
    return gcodekit.gcode_to_operation(program, "klipper").get_statistics()["time_s"] - fast


def _value(v):
    return v() if callable(v) else v


#: Answers worked out by hand from each exercise's text, independent of the notebooks' solution cells
#: (a callable: worked out by gcodekit along another road than the check's).
HAND = {
    "01-modal-state-units-offsets": {
        1: (100 + 10, 50, -1 + 25),  # G54 origin X100 Y50; tip at Z-1, the reference point 25 mm above it
        2: (100 + 30, 50 + 5),  # X10, then steps X10 Y5 and X10
        3: 100 + 25.4,  # G20 G1 X1 in G90: 25.4 mm from the G54 origin
    },
    "02-arcs-planes-helices": {1: math.hypot(2 * math.pi * 10, 2)},
    "03-tools-and-length-offsets": {1: -2 + 25 - 40},  # reference point at -2 + 25, tip 40 below it
    "04-canned-cycles": {1: 4},  # pecks to R2-3=-1, -4, -7, -10
    "05-feeds-and-speeds": {1: 1000 * 150 / (math.pi * 6), 3: 6 * 2 * 640 / 1000},
    "06-cutter-compensation-and-stages": {1: 50 + 40 - 3, 3: "climb"},
    "07-planned-against-naive-time": {
        1: 2 * 100 / 3000 + (100 - 100**2 / 3000) / 100,  # two ramps of v/a, the rest at 100 mm/s
        2: (100 + 2 + 100 + 2 + 100 + 6 * math.sqrt(0.5) + 26 + 103) / (2500 / 60),
        3: 5.0,  # Klipper's square_corner_velocity at a 90-degree corner
        5: lambda: _scv_saving(),  # planned through a printer.cfg, not the program's SET_VELOCITY_LIMIT
        6: _corner_speed(3000, 5**2 * (math.sqrt(2) - 1) / 3000, 135),
        7: 0.04 * _E_PER_MM * (100 - 5),  # cruise at F6000, the square corner at scv 5
    },
    "08-extrusion-retraction-temperatures": {
        1: 0.45 * 0.2 * 50 / (math.pi * 1.75**2 / 4),
        3: 12 / (0.45 * 0.2),
        4: (60 - 25) / 0.5 + (210 - 25) / 2.5,  # M109 sets the nozzle's target only once the bed is hot
    },
    "09-beads-layers-heat-and-5-axis": {
        1: 0.45 * 0.2 / ((0.45 - 0.2) * 0.2 + math.pi * 0.2**2 / 4),
        3: (math.sin(math.radians(30)), 0.0, math.cos(math.radians(30))),
    },
}

#: Plausible wrong answers to the numeric exercises: a step left out or a unit confused.
WRONG = {
    "01-modal-state-units-offsets": {1: (110, 50, -1), 2: (120, 55), 3: 25.4},
    "02-arcs-planes-helices": {1: 2 * math.pi * 10},
    "03-tools-and-length-offsets": {1: -2},
    "04-canned-cycles": {1: 3},
    "05-feeds-and-speeds": {1: 150 / (math.pi * 6), 3: 6 * 2 * 640},
    "06-cutter-compensation-and-stages": {1: 90, 3: "conventional"},
    "07-planned-against-naive-time": {
        1: 1.0, 2: 437.24 / 2500, 3: 100.0,
        5: 4.6,  # the new time instead of the saving
        6: _corner_speed(3000, 5**2 * (math.sqrt(2) - 1) / 3000, 45),  # the turn's 45 degrees taken for theta
        7: 0.04 * _E_PER_MM * 100,  # slowed down to a stop
    },
    "08-extrusion-retraction-temperatures": {
        1: 0.45 * 0.2 * 50 / (math.pi * 1.75**2), 3: 12 * 0.45 * 0.2,
        4: (210 - 25) / 2.5,  # as if both heated at once
    },
    "09-beads-layers-heat-and-5-axis": {1: 1.0, 3: (0.0, 0.5, math.cos(math.radians(30)))},
}


def _program(name: str, k: int) -> str:
    """The teacher's program of exercise ``k`` (from the solution cell of the source worksheet)."""
    return _namespace(name)[f"program_{k}"]


def _edit(name: str, k: int, old: str, new: str) -> str:
    text = _program(name, k)
    assert old in text, (name, k, old)
    return text.replace(old, new, 1)


#: For each write-the-G-code exercise, three plausible wrong programs (made by editing the teacher's) and what
#: the feedback must name for each.
WRONG_PROGRAMS = {
    ("01-modal-state-units-offsets", 4): [
        (lambda: _edit("01-modal-state-units-offsets", 4, " G80", ""), "missing before the first move: G80"),
        (lambda: _edit("01-modal-state-units-offsets", 4, "S8000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F200\n",
                       "G0 X10 Y10 Z5\nG1 Z-1 F200\nS8000 M3\n"), "line 3 feeds with the spindle stopped"),
        (lambda: _edit("01-modal-state-units-offsets", 4, "G1 Z-1 F200\nG1 X30", "G0 Z-1\nG1 X30 F200"),
         "moves at rapid speed down to Z-1"),
    ],
    ("02-arcs-planes-helices", 2): [
        (lambda: _edit("02-arcs-planes-helices", 2, "I15 J0", "R15"), "the controller would stop at an error"),
        (lambda: _edit("02-arcs-planes-helices", 2, "I15 J0", "I-15 J0"), "the cut at Z-1 leaves the circle"),
        (lambda: _edit("02-arcs-planes-helices", 2, "G2 X25", "G3 X25"), "degrees counter-clockwise"),
    ],
    ("02-arcs-planes-helices", 3): [
        (lambda: _edit("02-arcs-planes-helices", 3, " Z-3 P3", " P3"), "no arc goes down"),
        (lambda: _edit("02-arcs-planes-helices", 3, "G3 X5", "G2 X5"), "it turns the other way"),
        (lambda: _edit("02-arcs-planes-helices", 3, "P3", "P2"), "it makes 2 turns"),
    ],
    ("03-tools-and-length-offsets", 2): [
        (lambda: _edit("03-tools-and-length-offsets", 2, "G43 H2", "G43 H1"), "tool 2's tip goes deeper than Z-2"),
        (lambda: _edit("03-tools-and-length-offsets", 2, "G43 H2", "G49"), "tool 2's tip goes deeper than Z-2"),
        (lambda: _edit("03-tools-and-length-offsets", 2, "G43 H1", "G43 H2"), "tool 1's tip goes not as deep as Z-2"),
    ],
    ("04-canned-cycles", 2): [
        (lambda: _edit("04-canned-cycles", 2, "G98 X30", "X30"), "the tool passes over it at Z1"),
        (lambda: _edit("04-canned-cycles", 2, "Z-5 R1", "Z-4 R1"), "goes down to Z-4"),
        (lambda: _edit("04-canned-cycles", 2, "X10\nG80", "G80"), "no hole at X10 Y30"),
        # G98 left in force after the clamp: up to Z15 after the third hole too (13.18 s against 13.74 s)
        (lambda: _edit("04-canned-cycles", 2, "G99 X30 Y30", "X30 Y30"), "it takes 13.74 s"),
    ],
    ("05-feeds-and-speeds", 2): [
        (lambda: _edit("05-feeds-and-speeds", 2, "S7960", "S796"), "rpm: too slow for this cutter"),
        (lambda: _edit("05-feeds-and-speeds", 2, "F637", "F318"), "the chip load is too thin"),  # one flute
        (lambda: _edit("05-feeds-and-speeds", 2, "F637", "F1274"), "the chip load is too thick"),  # four flutes
    ],
    ("06-cutter-compensation-and-stages", 2): [
        (lambda: _edit("06-cutter-compensation-and-stages", 2, "G41 D1", "G42 D1"),
         "the tool centre leaves the box on line 8"),  # the entry move: G42 keeps the tool outside the wall
        (lambda: _edit("06-cutter-compensation-and-stages", 2, "G40 G1 X30 Y10", "G40 G1 X-10 Y-10"),
         "the tool centre leaves the box on line 14"),  # the exit move runs out through the wall
        (lambda: _edit("06-cutter-compensation-and-stages", 2, "G0 X30 Y10 Z5", "G0 X-10 Y-10 Z5"),
         "the tool centre leaves the box on line 7"),  # the plunge outside
        # the program printed above the exercise, which plunges at X20 Y10
        (lambda: (WORKSHEETS / "programs" / "pocket_wall.ngc").read_text(), "the tool goes down to Z-1 at X30 Y10"),
    ],
    ("07-planned-against-naive-time", 4): [
        (lambda: _program("07-planned-against-naive-time", 4).replace("F9000", "F6000"), "it takes"),
        (lambda: _program("07-planned-against-naive-time", 4).replace("F9000", "F20000"), "asks for F20000"),
        (lambda: re.sub(r"G1 X10[0-3](\.5)? Y4(\.5)?\n", "", _program("07-planned-against-naive-time", 4)),
         "the path no longer passes X100.5 Y4.5"),
    ],
    ("08-extrusion-retraction-temperatures", 2): [
        (lambda: _edit("08-extrusion-retraction-temperatures", 2, "M83", "M82\nG92 E0"),
         "M83 does not come before the first E word"),
        (lambda: _edit("08-extrusion-retraction-temperatures", 2, "G1 E-0.8 F2400\n", ""), "pulled back 0 mm"),
        # E from the filament's diameter taken as its radius: a quarter of the plastic
        (lambda: _program("08-extrusion-retraction-temperatures", 2).replace("E1.8709", "E0.4677"), "too little"),
    ],
    ("08-extrusion-retraction-temperatures", 5): [
        (lambda: _edit("08-extrusion-retraction-temperatures", 5, "M190 S80\nM109 S240", "M109 S240\nM190 S80"),
         "waits for the nozzle before"),
        # each heater waited for in turn, neither set beforehand: 110 s for the bed, then 86 s for the nozzle
        (lambda: _edit("08-extrusion-retraction-temperatures", 5, "M140 S80\nM104 S240\n", ""), "it waits 196 s"),
        (lambda: _edit("08-extrusion-retraction-temperatures", 5, "M107", "M106 S255"),
         "layer 0 prints (line 10) with the fan at S255"),
    ],
    ("09-beads-layers-heat-and-5-axis", 2): [
        (lambda: _program("09-beads-layers-heat-and-5-axis", 2).replace("G4 S18\n", ""), "layer 0 takes"),
        (lambda: _program("09-beads-layers-heat-and-5-axis", 2).replace("G4 S18\n", "").replace("F3000", "F300"),
         "prints at F300"),
        (lambda: _program("09-beads-layers-heat-and-5-axis", 2).replace("G4 S18", "G4 S8"), "layer 0 takes"),
    ],
}

#: Stated facts: (worksheet, program file, line number, text that line holds).
STATED_LINES = [
    ("01", "controller.ngc", 3, "G10 L2 P1 X100 Y50 Z0"), ("01", "controller.ngc", 6, "G43 H1"),
    ("01", "controller.ngc", 9, "G1 Z-1"), ("01", "controller.ngc", 10, "G1 X10"), ("01", "controller.ngc", 11, "G91"),
    ("01", "controller.ngc", 16, "G1 X1"),
    ("03", "two_tools.ngc", 11, "G43 H1"), ("03", "two_tools.ngc", 14, "G1 Z-2"),
    ("04", "drill.ngc", 5, "G99 G83 X0 Y0 Z-10 R2 Q3"),
    *[("07", "zigzag.gcode", n, "G1 X10") for n in range(10, 16)],
]


# -- running a worksheet's code in this process ------------------------------------------------------------------

_NAMESPACES: dict[str, dict] = {}


def _cells(name: str):
    return nbformat.read(WORKSHEETS / f"{name}.ipynb", as_version=4).cells


def _namespace(name: str) -> dict:
    """The worksheet's code cells run once in order (widget cells left out), with the teacher's answers."""
    if name not in _NAMESPACES:
        namespace: dict = {}
        with _in(WORKSHEETS), contextlib.redirect_stderr(io.StringIO()):
            for cell in _cells(name):
                if cell.cell_type == "code":
                    body = ast.parse(cell.source).body
                    if body and isinstance(body[-1], ast.Expr) and _WIDGET_CELL.search(ast.unparse(body[-1])):
                        body = body[:-1]  # a widget shown: its picture costs time and holds nothing checked here
                    exec(compile(ast.Module(body, []), f"{name}.ipynb", "exec"), namespace)
        _NAMESPACES[name] = namespace
    return _NAMESPACES[name]


@contextlib.contextmanager
def _in(folder: Path):
    here = os.getcwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(here)


def _check(name: str, k: int, **answers):
    """What the check cell of exercise ``k`` says for these answers (its last expression)."""
    namespace = dict(_namespace(name), **answers)
    source = next(c.source for c in _cells(name) if f"check-{k}" in c.metadata.get("tags", []))
    body = ast.parse(source).body
    with _in(WORKSHEETS):
        exec(compile(ast.Module(body[:-1], []), "check", "exec"), namespace)
        return eval(compile(ast.Expression(body[-1].value), "check", "eval"), namespace)


def _forms(value) -> list[str]:
    """How an expected number could be written in a message."""
    values = value if isinstance(value, (tuple, list)) else [value]
    forms = []
    for v in values:
        if isinstance(v, str):
            forms.append(v)
            continue
        forms += {f"{v:g}", f"{v:.6g}", f"{v:.4g}", f"{v:.3g}", f"{v:.2f}", f"{v:.1f}"} - {"0", "0.0", "1", "1.0"}
    return forms


def _holds(message: str, value) -> bool:
    """Whether ``message`` says ``value`` (the count in "1 of 4 requirements not met" is no answer)."""
    message = re.sub(r"\d+ of \d+ requirements", "", message)
    return any(re.search(rf"(?<![\d.]){re.escape(form)}(?![\d])", message) for form in _forms(value))


# -- the tests ---------------------------------------------------------------------------------------------------


def test_curriculum_is_complete():
    assert len(NAMES) >= 8
    assert set(HAND) | {name for name, _ in WRONG_PROGRAMS} == set(NAMES)
    exercises = {(name, int(t.split("-")[1])) for name in NAMES for c in _cells(name)
                 for t in c.metadata.get("tags", []) if t.startswith("check-")}
    numeric = {(name, k) for name, answers in HAND.items() for k in answers}
    assert exercises == numeric | set(WRONG_PROGRAMS)  # every exercise is tested here
    assert 3 * len(WRONG_PROGRAMS) >= len(exercises)  # at least a third write or edit G-code
    readme = (WORKSHEETS / "README.md").read_text()
    assert all(name in readme for name in NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_hand_answers_are_right_and_wrong_ones_say_what_is_wrong(name):
    for k, value in HAND[name].items():
        value = _value(value)
        right = _check(name, k, **{f"answer_{k}": value})
        assert right.ok, (name, k, right.message)
        assert _check(name, k, **{f"answer_{k}": None}).ok is None
        wrong = _check(name, k, **{f"answer_{k}": WRONG[name][k]})
        assert wrong.ok is False and wrong.message.startswith("Not quite"), (name, k, wrong.message)
        assert not _holds(wrong.message, value), (name, k, wrong.message)


@pytest.mark.parametrize("exercise", sorted(WRONG_PROGRAMS), ids=lambda e: f"{e[0][:2]}-{e[1]}")
def test_program_exercises_pass_the_right_program_and_name_what_is_wrong(exercise):
    name, k = exercise
    assert _check(name, k).ok, _check(name, k).message  # the teacher's program
    assert _check(name, k, **{f"program_{k}": None}).ok is None
    starting = _released_answer(name, k)
    assert _check(name, k, **{f"program_{k}": starting}).ok is False  # the program as handed out
    for make, said in WRONG_PROGRAMS[exercise]:
        program = make()
        assert program != _program(name, k)
        result = _check(name, k, **{f"program_{k}": program})
        assert result.ok is False and said in result.message, (name, k, program, result.message)


def _released_answer(name: str, k: int):
    """The value of ``program_k`` in the worksheet as released (the starting program)."""
    source = next(c.source for c in _cells(name) if f"answer-{k}" in c.metadata.get("tags", []))
    namespace = dict(_namespace(name))
    with _in(WORKSHEETS):
        exec(source.split("### BEGIN SOLUTION")[0], namespace)
    return namespace[f"program_{k}"]


@pytest.mark.parametrize("fact", STATED_LINES, ids=lambda f: f"{f[0]}-{f[1]}-{f[2]}")
def test_line_numbers_the_worksheets_state(fact):
    number, program, line, text = fact
    lines = (WORKSHEETS / "programs" / program).read_text().splitlines()
    assert lines[line - 1].startswith(text), (program, line, lines[line - 1])
    worksheet = next(n for n in NAMES if n.startswith(number))
    text = " ".join(c.source for c in _cells(worksheet))
    said = {int(n) for n in re.findall(r"\bline (\d+)\b", text, re.I)}
    said |= {n for a, b in re.findall(r"\blines (\d+)-(\d+)\b", text, re.I) for n in range(int(a), int(b) + 1)}
    assert line in said, (worksheet, line)


def test_zigzag_length_stated_in_worksheet_7():
    import gcodekit

    op = gcodekit.gcode_to_operation(str(WORKSHEETS / "programs" / "zigzag.gcode"), "grbl", plan=False)
    assert float(op.waypoints["distance"].sum()) == pytest.approx(437.2426, abs=1e-4)
    assert "437.24 mm" in " ".join(c.source for c in _cells("07-planned-against-naive-time"))


def test_layer_times_stated_in_worksheet_9():
    import gcodekit

    op = gcodekit.gcode_to_operation(str(WORKSHEETS / "programs" / "cube20_prusaslicer_marlin.gcode"))
    times = gcodekit.AdditivePart(op).layer_times().time
    assert times.idxmax() == 0 and round(times.max()) == 65
    assert 0 < times.idxmin() < 99 and round(times.min()) == 11  # a middle layer, not the first or the top


def _text(name: str) -> str:
    return " ".join(c.source for c in _cells(name))


def test_corner_facts_stated_in_worksheet_7():
    """Klipper's junction deviation from square_corner_velocity, the corner speeds it gives, and pressure advance
    leaving the planned time alone, as worksheet 7 states them."""
    import gcodekit

    text = _text("07-planned-against-naive-time")
    for scv, said in ((5, "0.0035 mm"), (20, "0.055 mm")):
        deviation = scv**2 * (math.sqrt(2) - 1) / 3000
        assert f"{deviation:.2g} mm" == said and said in text
        assert _corner_speed(3000, deviation, 90) == pytest.approx(scv)  # a square corner at exactly scv
        corner = gcodekit.gcode_to_operation(f"SET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY={scv}\nG21\nG90\n"
                                             "G1 X100 F6000\nG1 Y100\n", "klipper").to_dataframe()
        assert corner.query("line == 4").end_v.iloc[-1] == pytest.approx(scv)
    # the 45-degree turn of exercise 6 is X100 -> X170.7107 Y70.7107: both moves long, the second at 45 degrees
    assert math.degrees(math.atan2(70.7107, 70.7107)) == pytest.approx(45)
    assert math.hypot(70.7107, 70.7107) == pytest.approx(100, abs=1e-4)
    assert "3.7418" in text and 100 * _E_PER_MM == pytest.approx(3.7418, abs=1e-4)  # exercise 7's E: 0.45 x 0.2
    line = "G21\nG90\nM83\nG1 X100 E3.7418 F6000\nG1 Y100 E3.7418\n"
    plain = gcodekit.gcode_to_operation(line, "klipper")
    advanced = gcodekit.gcode_to_operation("SET_PRESSURE_ADVANCE ADVANCE=0.04\n" + line, "klipper")
    assert not advanced.diagnostics.errors
    assert advanced.get_statistics()["time_s"] == plain.get_statistics()["time_s"]
    row = plain.to_dataframe().query("line == 4").iloc[-1]
    assert (row.cruise_v, row.end_v) == pytest.approx((100, 5))  # "cruises at 100 mm/s", the corner at scv


def test_heating_facts_stated_in_worksheet_8():
    """On Marlin the moves before M109 slow to a stop, and a wait takes no time in the statistics, the waypoints'
    elapsed time and the event series."""
    import gcodekit

    assert "the moves before an `M109` slow down to a stop" in _text("08-extrusion-retraction-temperatures")
    moves = "G21\nG90\nM83\nG1 X50 E2 F3000\n{}G1 X100 E2\n"
    waits = gcodekit.gcode_to_operation(moves.format("M109 S210\n"), "marlin")
    goes_on = gcodekit.gcode_to_operation(moves.format(""), "marlin")
    df = waits.to_dataframe()
    assert df.query("line == 4").end_v.iloc[-1] == pytest.approx(0.05)  # Marlin's MINIMUM_PLANNER_SPEED: a stop
    assert goes_on.to_dataframe().query("line == 4").end_v.iloc[-1] > 1
    assert df.query("line == 5").elapsed_time.iloc[-1] == df.query("line == 4").elapsed_time.iloc[-1]
    events = [gcodekit.gcode_dataframe_to_event_series(op.to_dataframe()).time.max() for op in (waits, goes_on)]
    assert waits.get_statistics()["time_s"] > goes_on.get_statistics()["time_s"] and events[0] > events[1]
    # the extra time is the stop and the restart, not a heat-up: far below one second
    assert waits.get_statistics()["time_s"] - goes_on.get_statistics()["time_s"] < 0.1


def test_heater_model_by_hand():
    """heater_waits against waits worked out by hand (constant rates from 25 °C)."""
    import gcodekit
    from gcodekit.widgets.tasks import heater_waits

    rates = {"nozzle": 2.5, "bed": 0.5}

    def waits(program):
        return [(line, heater, round(s, 6)) for line, heater, s in
                heater_waits(gcodekit.gcode_to_operation(program + "G1 X10 F600\n", "marlin"), rates)]

    assert waits("M190 S60\nM109 S210\n") == [(1, "bed", 70.0), (2, "nozzle", 74.0)]
    # both set first: the nozzle heats during the bed's 110 s and is ready before it
    assert waits("M140 S80\nM104 S240\nM190 S80\nM109 S240\n") == [(3, "bed", 110.0), (4, "nozzle", 0.0)]
    # the nozzle set 20 s into the bed's wait: 86 s from then, 110 - 20 of them already gone
    assert waits("M140 S80\nG4 S20\nM104 S240\nM190 S80\nM109 S240\n") == [(4, "bed", 90.0), (5, "nozzle", 0.0)]
    assert waits("M109 S210\nM109 S200\n") == [(1, "nozzle", 74.0), (2, "nozzle", 0.0)]  # cooling is not waited for
    assert waits("M104 S210\nM109\n") == [(2, "nozzle", 74.0)]  # M109 without S waits for the target in force


def test_fan_requirement_reads_m106_and_m107():
    from gcodekit.widgets.tasks import check_program, fan_from_layer

    two_layers = "G21\nG90\nM83\n{}G1 X50 E1 F1800 Z0.2\n{}G1 Z0.4\nG1 X0 E1\n"
    assert check_program(two_layers.format("M107\n", "M106\n"), [fan_from_layer(1)], "marlin").ok  # no S: full
    half = check_program(two_layers.format("", "M106 S128\n"), [fan_from_layer(1)], "marlin")
    assert not half.ok and "layer 1 prints (line 7) with the fan at S128" in half.message
    off = check_program(two_layers.format("M106\n", "M107\n"), [fan_from_layer(1)], "marlin")
    assert "layer 0 prints (line 5) with the fan at S255" in off.message


# -- nbgrader ------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """A course directory with the worksheets as one assignment, released and autograded for three students.

    ``right`` hands in the teacher's answers, ``empty`` the released worksheets as they are, ``wrong`` a wrong
    answer (the first wrong program) in every exercise.
    """
    import sys

    from nbgrader.apps import NbGraderAPI
    from traitlets.config import Config

    # nbgrader runs its `alembic` command by name: this environment's scripts first on the path
    path = os.environ["PATH"]
    os.environ["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{path}"
    try:
        yield _graded_course(tmp_path_factory.mktemp("course"), NbGraderAPI, Config)
    finally:
        os.environ["PATH"] = path


STUDENTS = ("right", "empty", "wrong")


def _config(root: Path, Config):
    """nbgrader's configuration for the course in ``root``: the worksheets' nbgrader_config.py and the course."""
    config = Config()
    exec((WORKSHEETS / "nbgrader_config.py").read_text(), {"get_config": lambda: config})
    config.CourseDirectory.root = str(root)
    config.CourseDirectory.db_url = f"sqlite:///{root / 'gradebook.db'}"
    config.ExecutePreprocessor.timeout = 600
    return config


#: What nbgrader logs when a kernel could not bind the ports picked for it
KERNEL_LOST_PORT_RACE = "Kernel died before replying to kernel_info"


def _grade(root: Path, student: str, NbGraderAPI, Config) -> None:
    """In a process of its own: nbgrader's autograde and feedback for one student of the course in ``root``."""
    import sys

    api = NbGraderAPI(config=_config(root, Config))
    os.chdir(root)
    for step in (api.autograde, api.generate_feedback):
        result = step("worksheets", student)
        if not result["success"]:
            (root / "grading.log").write_text(result["log"])
            sys.exit(1)


def _graded_course(root: Path, NbGraderAPI, Config):
    """The course of the fixture above, graded: (root, scores)."""
    source = root / "source" / "worksheets"
    shutil.copytree(WORKSHEETS, source, ignore=shutil.ignore_patterns("*.md", "nbgrader_config.py", "*.html"))
    shutil.copy(WORKSHEETS / "nbgrader_config.py", root / "nbgrader_config.py")
    api = NbGraderAPI(config=_config(root, Config))
    with _in(root):
        generated = api.generate_assignment("worksheets")
    assert generated["success"], generated["log"]
    released = root / "release" / "worksheets"
    for student in STUDENTS:
        folder = root / "submitted" / student / "worksheets"
        shutil.copytree(released, folder)
        (folder / "timestamp.txt").write_text("2026-12-03 12:00:00.000000 UTC")
    for name in NAMES:
        src = nbformat.read(WORKSHEETS / f"{name}.ipynb", as_version=4)
        for student, answer in (("right", _teacher), ("wrong", _wrong)):
            path = root / "submitted" / student / "worksheets" / f"{name}.ipynb"
            nb = nbformat.read(path, as_version=4)
            for cell, original in zip(nb.cells, src.cells):
                tags = original.metadata.get("tags", [])
                if any(t.startswith("answer-") for t in tags):
                    cell.source = answer(name, int(tags[0].split("-")[1]), original.source)
            nbformat.write(nb, path)
    # each student graded in a copy of the course (its own gradebook), the three side by side in fresh processes:
    # each autograde runs nine kernels one after the other.  Spawned, not forked: a fork of this process inherits
    # the ZeroMQ contexts of the notebook tests run before it, and libzmq aborts in the child
    # ("Assertion failed: pfd.revents & POLLIN", then "Kernel didn't respond in 60 seconds")
    import multiprocessing

    from nbgrader.api import Gradebook

    spawn = multiprocessing.get_context("spawn")

    def start(student: str):
        copy = root.parent / f"{root.name}-{student}"
        shutil.rmtree(copy, ignore_errors=True)
        shutil.copytree(root, copy, ignore=shutil.ignore_patterns(*[s for s in STUDENTS if s != student]))
        process = spawn.Process(target=_grade, args=(copy, student, NbGraderAPI, Config))
        process.start()
        return copy, process

    running = {student: start(student) for student in STUDENTS}
    scores = {}
    for student in STUDENTS:
        copy, process = running[student]
        process.join()
        log = copy / "grading.log"
        if process.exitcode != 0 and log.exists() and KERNEL_LOST_PORT_RACE in log.read_text():
            # jupyter_client picks a kernel's free ports before the kernel binds them: a kernel of another
            # student's process, started in between, may take one ("Address already in use"); grade again, alone
            copy, process = start(student)
            process.join()
        assert process.exitcode == 0, log.read_text()[-3000:] if log.exists() else "see the captured stderr"
        for folder in ("autograded", "feedback"):
            shutil.copytree(copy / folder / student, root / folder / student)
        with Gradebook(f"sqlite:///{copy / 'gradebook.db'}") as gradebook:
            scores.update({(student, name): (gradebook.find_submission_notebook(name, "worksheets", student).score,
                                             gradebook.find_notebook(name, "worksheets").max_score)
                           for name in NAMES})
    return root, scores


def _teacher(name: str, k: int, source: str) -> str:
    """The answer cell with the teacher's answer, as a student would write it (no solution markers)."""
    return re.sub(r"### (BEGIN|END) SOLUTION\n?", "", source)


def _wrong(name: str, k: int, source: str) -> str:
    if (name, k) in WRONG_PROGRAMS:
        return f"program_{k} = {WRONG_PROGRAMS[(name, k)][0][0]()!r}"
    return f"answer_{k} = {WRONG[name][k]!r}"


def test_nbgrader_releases_without_the_answers(course):
    root, _ = course
    for name in NAMES:
        released = (root / "release" / "worksheets" / f"{name}.ipynb").read_text()
        assert "BEGIN SOLUTION" not in released and "answer_1 = None" in released or "program_" in released
        for k, value in HAND.get(name, {}).items():
            line = next(c.source for c in _cells(name) if f"answer-{k}" in c.metadata.get("tags", []))
            solution = line.split("### BEGIN SOLUTION\n")[1].split("\n### END SOLUTION")[0]
            assert solution not in released, (name, k)
    assert (root / "release" / "worksheets" / "programs" / "tools.tbl").exists()


def test_nbgrader_autograde_scores(course):
    root, scores = course
    for name in NAMES:
        score, most = scores[("right", name)]
        assert most > 0 and score == most, (name, scores[("right", name)])
        assert scores[("empty", name)][0] == 0, (name, scores[("empty", name)])
        assert scores[("wrong", name)][0] == 0, (name, scores[("wrong", name)])


def test_autograded_notebooks_run_to_the_end_and_feedback_keeps_answers_hidden(course):
    root, _ = course
    for student in ("right", "empty", "wrong"):
        for name in NAMES:
            nb = nbformat.read(root / "autograded" / student / "worksheets" / f"{name}.ipynb", as_version=4)
            outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
            assert not [o for o in outputs if o.output_type == "error"], (student, name)
            if student != "wrong":
                continue
            said = " ".join(o.get("text", "") for c in nb.cells if any(t.startswith("check-") for t in
                                                                         c.metadata.get("tags", []))
                            for o in c.outputs)
            for k, value in HAND.get(name, {}).items():
                assert not _holds(said, _value(value)), (name, k, said)
            page = (root / "feedback" / student / "worksheets" / f"{name}.html").read_text()
            assert "Not quite" in page or "Not yet" in page


# -- handing in as HTML ------------------------------------------------------------------------------------------

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
_REMOTE_SCRIPT = re.compile(r"<script[^>]*\ssrc=[\"']?(https?:)?//", re.I)


@pytest.fixture(scope="module")
def handed_in(course, tmp_path_factory):
    """The right hand-ins as nbgrader executed them, converted by plain ``jupyter nbconvert --to html``."""
    import subprocess
    import sys

    root, _ = course
    folder = tmp_path_factory.mktemp("hand-in")
    for name in NAMES:
        shutil.copy(root / "autograded" / "right" / "worksheets" / f"{name}.ipynb", folder)
    jupyter = Path(sys.executable).parent / "jupyter"
    done = subprocess.run([str(jupyter), "nbconvert", "--to", "html", *[f"{n}.ipynb" for n in NAMES]], cwd=folder,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return folder


def _widget_outputs(nb) -> int:
    return sum(WIDGET_VIEW in o.get("data", {}) for c in nb.cells if c.cell_type == "code" for o in c.outputs)


def test_plain_nbconvert_shows_one_picture_per_widget_and_no_remote_script(handed_in):
    for name in NAMES:
        nb = nbformat.read(handed_in / f"{name}.ipynb", as_version=4)
        page = (handed_in / f"{name}.html").read_text()
        widgets = _widget_outputs(nb)
        assert widgets > 0, name
        pictures = len(re.findall(r'<img[^>]+src="data:image/png;base64,', page))
        assert pictures == widgets, (name, pictures, widgets)
        assert not _REMOTE_SCRIPT.search(page), (name, _REMOTE_SCRIPT.search(page))
        assert WIDGET_VIEW not in page and "html-manager" not in page


def test_handed_in_pages_show_their_pictures_offline_in_chromium(handed_in):
    from jupyter_browser import browser_page, chromium_path

    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    import numpy as np
    from PIL import Image

    with browser_page() as page:
        page.context.set_offline(True)
        for name in NAMES:
            page.goto((handed_in / f"{name}.html").as_uri())
            page.wait_for_load_state("load")
            sizes = page.evaluate("[...document.images].map(i => [i.naturalWidth, i.naturalHeight])")
            assert sizes and all(w > 100 and h > 100 for w, h in sizes), (name, sizes)
            # looked at as a picture: the first widget's picture as the page shows it holds a drawing below its
            # title and legend (the top eighth: alone they darken about 0.5 % of the pixels; one cut at one feed
            # is a few lines, 0.4 % more), not a blank
            shot = page.locator("img").first.screenshot()
            pixels = np.asarray(Image.open(io.BytesIO(shot)).convert("L"), float)
            drawing = pixels[pixels.shape[0] // 8:]
            assert pixels.std() > 10 and (drawing < 250).mean() > 0.002, (name, (drawing < 250).mean())
        assert page.console_errors == []


def test_jupyterlab_export_shows_the_pictures_offline(handed_in, tmp_path):
    """JupyterLab's File > Save and Export Notebook As > HTML asks the server's /nbconvert/html handler."""
    from jupyter_browser import browser_page, chromium_path, jupyter_lab

    if chromium_path() is None:
        pytest.skip("chromium not found: apt-get install chromium (scripts/setup.sh does as root)")
    name = "06-cutter-compensation-and-stages"
    shutil.copy(handed_in / f"{name}.ipynb", tmp_path)
    with jupyter_lab(tmp_path) as url, browser_page() as page:
        page.goto(f"{url}/lab")
        # what the menu item opens: the server's exporter, asked from the JupyterLab page
        response = page.request.get(f"{url}/nbconvert/html/{name}.ipynb?download=true", headers={"Referer": f"{url}/lab"})
        assert response.ok, response.status
        page_html = response.text()
    nb = nbformat.read(tmp_path / f"{name}.ipynb", as_version=4)
    assert len(re.findall(r'<img[^>]+src="data:image/png;base64,', page_html)) == _widget_outputs(nb) == 2
    assert not _REMOTE_SCRIPT.search(page_html) and WIDGET_VIEW not in page_html
