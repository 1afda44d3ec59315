"""Post-processing a FreeCAD-style job for LinuxCNC, GRBL, Fanuc, Marlin and GER; pre-processing real programs.

A post-processed job, read back by gcodekit with the target's own machine,
must move like the job itself (the same end points in the same order); the
LinuxCNC output must also move so under LinuxCNC's own rs274 (skipped where
it is not installed).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path as FilePath

import numpy as np
import pytest

import gcodekit
import gcodekit.path as Path
from gcodekit.errors import ConfigError

sys.path.insert(0, str(FilePath(__file__).parent / "golden" / "linuxcnc"))
from differential import rs274  # noqa: E402

sys.path.pop(0)


def _job() -> Path.Job:
    table = Path.Tooltable()
    table.addTools(Path.Tool("3 mm end mill", tooltype="EndMill", diameter=3))
    table.addTools(Path.Tool("6 mm drill", tooltype="Drill", diameter=6, cuttingEdgeAngle=118))
    job = Path.Job(tooltable=table)
    slot = Path.Path("G0 Z5 G0 X1 Y1 M3 S10000 G1 Z-1 F100 G1 X20 G2 X30 Y1 I5 J0 G3 X20 Y1 I-5 J0 G0 Z5")
    job.add(slot, tool=1, name="slot")
    job.add(Path.Path("G0 X40 Y10 G81 X40 Y10 Z-3 R2 F50 G81 X50 Y10 Z-3 R2 G80 G0 Z5"), tool=2, name="holes")
    job.add(Path.Path("G0 X0 Y0 G1 Z-0.5 F80 G1 X5 G0 Z5"), tool=1, placement=Path.Placement(Path.Vector(60, 20, 0)))
    job.UsePlacements = True
    return job


def _points(op) -> np.ndarray:
    """End points of the motions, consecutive repeats dropped."""
    w = op.waypoints
    rows = w["motion"] > 0
    pts = np.column_stack([w["x"][rows], w["y"][rows], w["z"][rows]])
    keep = np.ones(len(pts), bool)
    keep[1:] = np.any(np.abs(np.diff(pts, axis=0)) > 1e-9, axis=1)
    return pts[keep]


@pytest.fixture(scope="module")
def reference():
    return _points(Path.to_operation(_job(), plan=False))


def test_the_reference_moves_are_the_jobs(reference):
    # the placed third path runs from (60, 20) to (65, 20); the drilling goes down to Z-3 twice
    assert reference[-2].tolist() == [65.0, 20.0, -0.5]
    assert (np.isclose(reference[:, 2], -3.0)).sum() == 2
    assert reference[:, 0].max() == 65.0


@pytest.mark.parametrize("target", list(Path.TARGETS))
def test_post_processed_job_moves_alike_when_read_back(target, reference):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # GRBL has no M6 code: the exporter says so in the text
        text = Path.post_process(_job(), target)
    spec = Path.TARGETS[target]
    op = gcodekit.gcode_to_operation(text, machine=spec.machine, plan=False)
    assert not op.diagnostics.errors, [str(d) for d in op.diagnostics.errors]
    ours = _points(op)
    assert ours.shape == reference.shape, (target, ours.shape, reference.shape)
    np.testing.assert_allclose(ours, reference, atol=1e-4)


def test_targets_get_their_headers_tool_changes_and_line_numbers():
    job = _job()
    linuxcnc = Path.post_process(job, "linuxcnc")
    assert linuxcnc.splitlines()[0] == "(program: post-processed by gcodekit for linuxcnc)"
    assert "(T2: 6 mm drill, Drill, D6 mm)" in linuxcnc and "G21 G90 G17 G40 G80" in linuxcnc
    assert "M6 T2" in linuxcnc and linuxcnc.rstrip().endswith("M2")
    fanuc = Path.post_process(job, "fanuc", program_number=42)
    lines = fanuc.splitlines()
    assert lines[:2] == ["%", "O0042"] and lines[-2:] == ["M30", "%"]
    numbered = [ln for ln in lines if ln.startswith("N")]
    assert [int(ln.split()[0][1:]) for ln in numbered] == list(range(1, len(numbered) + 1))
    assert "G81" in fanuc  # Fanuc has drilling cycles
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        grbl = Path.post_process(job, "grbl")
        marlin = Path.post_process(job, "marlin")
    assert not any(ln.startswith("G81") for ln in grbl.splitlines()) and "(change to tool 2)" in grbl and "\nM0\n" in grbl  # no tool changer: a pause
    assert marlin.startswith(";program: post-processed") and "(" not in marlin.replace("(from", "")
    ger = Path.post_process(job, "ger")
    assert "G21" in ger.split("(slot)")[0]  # GER starts in inches


def test_unknown_target_lists_the_known_ones():
    with pytest.raises(ConfigError, match="did you mean 'linuxcnc'"):
        Path.post_process(_job(), "linuxcn")


@pytest.mark.skipif(not rs274.available(), reason="LinuxCNC's rs274 is not installed")
def test_linuxcnc_output_moves_alike_under_rs274(reference):
    text = Path.post_process(_job(), "linuxcnc")
    ref = rs274.run_rs274(text)
    assert ref.error is None, ref.error
    assert all(m["units"] == "mm" and m["tlo_z"] == 0 for m in ref.motions)
    pts = np.array([[m["x"], m["y"], m["z"]] for m in ref.motions])
    keep = np.ones(len(pts), bool)
    keep[1:] = np.any(np.abs(np.diff(pts, axis=0)) > 1e-9, axis=1)
    np.testing.assert_allclose(pts[keep], reference, atol=1e-4)  # rs274 prints 4 decimals


def test_preprocessor_turns_a_program_into_freecads_form():
    program = "G20 (inches)\n#1 = 0.5\nG0 X#1 Y0\nG1 Z-0.1 F10\nG2 X1.5 Y0 I0.5 J0\nM2\n"
    path = Path.read(program, machine="linuxcnc")
    assert [c.Name for c in path.Commands] == ["G0", "G1", "G2"]
    arc = path.Commands[2].Parameters
    assert arc["X"] == pytest.approx(38.1) and arc["I"] == pytest.approx(12.7) and arc["F"] == pytest.approx(254)
    assert path.Length == pytest.approx(12.7 + 2.54 + np.pi * 12.7)  # from the origin, down, half a circle
    assert not path.diagnostics.errors


def test_preprocessor_keeps_going_past_what_it_cannot_read():
    path = Path.read("G0 X1\nG1 X2 Y\nG1 X3 F100\n", machine="linuxcnc")
    assert {d.line for d in path.diagnostics.errors} == {2}
    assert path.Commands[-1].Parameters["X"] == 3.0


@pytest.mark.parametrize("program, machine", [
    ("bracket_mill.ngc", "linuxcnc"), ("cube20_prusaslicer_marlin.gcode", None),
])
def test_preprocessed_example_measures_what_the_pipeline_measured(program, machine):
    """read() turns every motion into a command; the path's own length (gcodekit.path.measure, arcs
    from the written I/J/K) equals the pipeline's distance, so the arcs' centres came across right."""
    file = FilePath(__file__).resolve().parents[1] / "examples" / program
    op = gcodekit.gcode_to_operation(file, machine, plan=False)
    path = Path.read(file, machine=machine)
    moves = [c for c in path.Commands if c.Name in ("G0", "G1", "G2", "G3")]
    assert len(moves) == int((op.waypoints["motion"] > 0).sum())
    assert path.Length == pytest.approx(float(op.waypoints["distance"].sum()), rel=1e-9)
