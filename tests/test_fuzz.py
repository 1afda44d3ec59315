"""The fuzz suite on a fixed seed: bad, broken and hostile inputs through every command.

Each case runs in a process of its own with a time limit (a hang detector,
far above what any case needs) and its peak memory measured: no case may
crash, hang, pass 2 GB or be rejected without naming where.  The same cases
come back on every run; ``./scripts/fuzz.sh`` runs fresh seeds and larger
counts, and what it finds becomes a regression example here or beside the
behaviour it breaks (see ``test_limits.py``, ``test_program_files.py``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from fuzz.cases import make_cases
from fuzz.runner import FAILURES

TESTS = Path(__file__).parent
SEED, COUNT = 14, 120


def test_cases_cover_every_kind_and_command():
    cases = make_cases(COUNT, SEED)
    assert {c.kind for c in cases} == {"bytes", "container", "mutated", "hostile"}
    assert {c.args[0] for c in cases} >= {"info", "export", "translate", "api"}
    assert [c.files for c in make_cases(8, SEED)] == [c.files for c in cases[:8]]  # the seed fixes them


def test_fixed_seed_fuzz_cases(tmp_path):
    out = tmp_path / "figures.json"
    env = {**os.environ, "PYTHONPATH": str(TESTS)}
    done = subprocess.run([sys.executable, "-m", "fuzz", "--count", str(COUNT), "--seed", str(SEED),
                           "--timeout", "180", "--memory-mb", "2048", "--keep", str(tmp_path / "failed"),
                           "--json", str(out)], env=env, cwd=TESTS, capture_output=True, text=True)
    figures = json.loads(out.read_text())
    failures = [f"{f['name']}: {f['verdict']} ({f['command']}): {f['stderr'][-400:]}" for f in figures["failures"]]
    assert not failures, "\n".join(failures)
    assert done.returncode == 0, done.stderr[-2000:]
    assert figures["cases"] == COUNT
    assert not set(figures["verdicts"]) & set(FAILURES)
    assert figures["peak_memory"]["mb"] < 2048
    # the hostile and broken inputs are noticed, not read as if nothing were wrong
    noticed = sum(n for kind in ("container", "hostile") for v, n in figures["by_kind"][kind].items()
                  if v in ("diagnosed", "rejected"))
    assert noticed >= 0.6 * sum(sum(figures["by_kind"][k].values()) for k in ("container", "hostile"))
