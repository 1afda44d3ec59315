"""Corpus programs rs274 runs cleanly without a single motion (subroutine
libraries, parameter and I/O demos): gcodekit must run them alike, with no
error and no motion.  They stay in the shared corpus (many call each other
along its folders), so the test skips where the corpus is absent."""

from __future__ import annotations

import csv

import gcodekit


def test_programs_without_motions_run_without_errors(shared_dir):
    root = shared_dir / "corpus" / "linuxcnc"
    with (root / "RESULTS.tsv").open(newline="") as f:
        silent = [r["file"] for r in csv.DictReader(f, delimiter="\t") if r["status"] == "ok" and r["motions"] == "0"]
    assert len(silent) > 50
    problems = []
    for name in silent:
        op = gcodekit.gcode_to_operation(root / name, machine="linuxcnc")
        errors = [str(d) for d in op.diagnostics if d.severity == "error"]
        moves = int((op.waypoints["motion"] > 0).sum())
        if errors or moves:
            problems.append((name, moves, errors[:1]))
    assert problems == []
