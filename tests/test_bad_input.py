"""Bad input: random bytes and mutated real programs through the whole pipeline.

Lenient mode must never raise; strict mode may raise only gcodekit's own
errors.  Hangs and memory are the fuzz suite's to catch (tests/test_fuzz.py
runs each case in a process of its own, with limits): no clock here.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gcodekit
from gcodekit.errors import GcodeError

EXAMPLES = Path(__file__).parents[1] / "examples"
SAMPLES = {
    "marlin": (EXAMPLES / "cube20_prusaslicer_marlin.gcode").read_text().splitlines()[:400],
    "rs274ngc": (EXAMPLES / "bracket_mill.ngc").read_text().splitlines(),
    "beckhoff_ded": (EXAMPLES / "dome_ded_beckhoff.nc").read_text().splitlines()[:200],
}
MACHINES = {"marlin": "marlin", "rs274ngc": "linuxcnc", "beckhoff_ded": "beckhoff_ded"}
SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@st.composite
def mutated_program(draw):
    flavor = draw(st.sampled_from(sorted(SAMPLES)))
    lines = list(SAMPLES[flavor])
    for _ in range(draw(st.integers(1, 8))):
        i = draw(st.integers(0, len(lines) - 1))
        line = lines[i]
        j = draw(st.integers(0, len(line)))
        edit = draw(st.sampled_from(["insert", "delete", "replace", "duplicate", "drop"]))
        junk = draw(st.text(alphabet=st.sampled_from(list("GXYZEFIJKRPM0123456789.-+;()#[]*=\"/% \t\x00é")),
                            min_size=1, max_size=4))
        if edit == "insert":
            lines[i] = line[:j] + junk + line[j:]
        elif edit == "delete":
            lines[i] = line[:j] + line[j + len(junk):]
        elif edit == "replace":
            lines[i] = line[:j] + junk + line[j + len(junk):]
        elif edit == "duplicate":
            lines.insert(i, line)
        elif len(lines) > 1:
            del lines[i]
    return flavor, "\n".join(lines) + "\n"


def run_both_modes(text: str, flavor: str, machine: str) -> None:
    op = gcodekit.gcode_to_operation(text, machine, flavor=flavor)
    assert len(op.process_data) == len(op.commands)
    op.get_statistics()
    try:
        gcodekit.gcode_to_operation(text, machine, flavor=flavor, mode="strict")
    except GcodeError as exc:
        assert exc.diagnostic is not None and exc.diagnostic.line >= 1


@SETTINGS
@given(mutated_program())
def test_mutated_real_programs(case):
    flavor, text = case
    run_both_modes(text, flavor, MACHINES[flavor])


@SETTINGS
@given(st.binary(max_size=2000), st.sampled_from(sorted(SAMPLES)))
def test_random_bytes(data, flavor):
    run_both_modes(data.decode("latin-1") + "\n", flavor, MACHINES[flavor])


@pytest.mark.parametrize("text", ["", "\n", ";", "G1", "G2 X1", "G1 X1e400", "X" * 100000, "G1 X" + "9" * 400])
def test_edge_cases(text):
    run_both_modes(text + "\n", "rs274ngc", "linuxcnc")


@pytest.mark.parametrize("as_path", [str, Path])
def test_a_missing_program_file_is_named(tmp_path, as_path):
    missing = tmp_path / "missing.ngc"
    with pytest.raises(FileNotFoundError, match=r"no such program file: .*missing\.ngc"):
        gcodekit.gcode_to_operation(as_path(missing), "linuxcnc")
