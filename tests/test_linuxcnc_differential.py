"""Differential check: random RS274NGC programs run as LinuxCNC's rs274 2.9 runs them.

Each seed's program (``tests/golden/linuxcnc/differential``, README there)
is run by rs274 and emulated by gcodekit; they must give the same motions
in machine coordinates, or both refuse the program on the same line.  The
tests skip where rs274 is not installed (``./scripts/run-tests.sh`` installs
it with apt-get); ``differential/run.py`` runs larger counts on demand.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent / "golden" / "linuxcnc"))

from differential import rs274  # noqa: E402
from differential.compare import judge  # noqa: E402
from differential.generate import generate  # noqa: E402
from differential.shrink import ddmin  # noqa: E402

pytestmark = pytest.mark.skipif(not rs274.available(), reason=f"{rs274.RS274} not installed "
                                "(apt-get install -y --no-install-recommends linuxcnc-uspace)")

#: Fixed seeds: about 12 s of rs274 and gcodekit together (run.py --count 1000 for the full figure).
SEEDS = range(100)


@pytest.mark.parametrize("seed", SEEDS)
def test_random_program_agrees_with_rs274(seed: int) -> None:
    verdict = judge(generate(seed).text)
    if not verdict.agree:
        pytest.fail(f"seed {seed}: {verdict.kind}: {verdict.cluster}\n{verdict.detail}\n"
                    f"(show it: tests/golden/linuxcnc/differential/run.py --show {seed})", pytrace=False)


def test_a_moved_reference_motion_is_a_difference() -> None:
    """The judge compares what it is given: rs274's motions with one end point moved must disagree."""
    text = "G21 G90\nG0 X1 Y2 Z3\nG1 X4 F100\nM2\n"
    reference = rs274.run_rs274(text)
    assert judge(text, reference).kind == "agree"
    moved = [dict(m) for m in reference.motions]
    moved[1]["x"] += 0.01  # 10 um: more than the judge's tolerance
    verdict = judge(text, dataclasses.replace(reference, motions=moved))
    assert (verdict.agree, verdict.kind, verdict.line) == (False, "motions", 3)


def test_shrinking_keeps_rs274_refusal_and_drops_the_rest() -> None:
    """ddmin reduces a generated program with a deliberate error to the few lines rs274 still refuses."""
    seed = next(s for s in range(200) if "deliberate error" in generate(s).features
                and rs274.run_rs274(generate(s).text).error is not None)
    lines = generate(seed).text.rstrip("\n").split("\n")
    message = rs274.run_rs274("\n".join(lines) + "\n").error[0]

    def still_refused(candidate: list[str]) -> bool:
        refused = rs274.run_rs274("\n".join(candidate) + "\n", timeout=3.0).error
        return refused is not None and refused[0] == message

    small = ddmin(lines, still_refused)
    assert still_refused(small) and len(small) <= 6 < len(lines)
