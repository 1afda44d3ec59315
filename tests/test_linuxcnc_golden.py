"""Golden tests: motions of LinuxCNC example programs against rs274's canon.

Cases and their reference tables sit in ``tests/golden/linuxcnc/cases`` (see
the README there; ``make_slicer_files.py`` selects and refreshes them).  The canon
gives program coordinates plus the offsets in force, so each reference row is
moved to machine coordinates first: rotate(program + G92, XY rotation) + G5x
+ tool offset, all in the program units of that move.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import gcodekit
from gcodekit.parse.table import NAME_ID

CASES = Path(__file__).parent / "golden" / "linuxcnc" / "cases"
# a case has its reference table; other .ngc files are subroutines a case calls (x-trim.ngc's touchoff.ngc)
PROGRAMS = sorted(p.name for p in CASES.glob("*.ngc") if p.with_name(p.name + ".canon.csv").exists())
ATOL, RTOL = 1e-4, 1e-9
AXES = ["x", "y", "z", "a", "b", "c"]
CENTRE = ["cx", "cy", "cz"]
# rs274 standalone has no probe input: a probe move runs to its target, a feed for us.
# A spline is one NURBS_FEED in the canon; gcodekit follows it with chords (see ours_like_canon).
CANON_MOTION = {"STRAIGHT_TRAVERSE": "rapid", "STRAIGHT_FEED": "feed", "STRAIGHT_PROBE": "feed",
                "NURBS_FEED": "spline"}
SPLINES = [NAME_ID[n] for n in ("spline_cubic", "spline_quadratic", "nurbs_end")]
#: gcodekit's LinuxCNC machine as rs274 run standalone behaves: it reads tool tables in inches,
#: and its canon hands back the F number and the tool offset's numbers when G20/G21 change the
#: units (``F30 G20`` is 30 in/min there, 30 mm/min in LinuxCNC's task) and the last move's
#: program point after M6 (see MachineConfig.standalone_canon)
RS274_STANDALONE = {"machine": "linuxcnc", "tool_table_units": "inch", "units_keep_feed": True,
                    "standalone_canon": True}


def to_machine(x: np.ndarray, y: np.ndarray, z: np.ndarray,
               ref: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Program coordinates of canon rows -> machine coordinates."""
    px, py = x + ref["g92_x"], y + ref["g92_y"]
    angle = np.radians(ref["xy_rot"])
    cos, sin = np.cos(angle), np.sin(angle)
    mx = px * cos - py * sin + ref["g5x_x"] + ref["tlo_x"]
    my = px * sin + py * cos + ref["g5x_y"] + (ref["tlo_y"] if "tlo_y" in ref else 0.0)  # G43.1 Y
    mz = z + ref["g92_z"] + ref["g5x_z"] + ref["tlo_z"]
    return mx.to_numpy(), my.to_numpy(), mz.to_numpy()


def reference_motions(csv_path: Path) -> pd.DataFrame:
    """A ``.canon.csv`` as a table shaped like :meth:`Operation.motions`."""
    return reference_table(pd.read_csv(csv_path, keep_default_na=False, na_values=[""]))


def reference_table(ref: pd.DataFrame) -> pd.DataFrame:
    """Canon rows (the ``.canon.csv`` columns, blanks as NaN) as a table shaped like :meth:`Operation.motions`."""
    motion = ref["type"].map(CANON_MOTION)
    arc = ref["type"] == "ARC_FEED"
    motion[arc] = np.where(ref.loc[arc, "arc_rotation"] < 0, "arc_cw", "arc_ccw")
    out = pd.DataFrame({"src_line": ref["src_line"], "line_match": ref["line_match"],
                        "motion": motion.fillna(ref["type"])})
    out["x"], out["y"], out["z"] = to_machine(ref["x"], ref["y"], ref["z"], ref)
    for key in "abc":
        out[key] = ref[key]
    # The helix-axis coordinate of a centre is empty: transform with the end
    # point's coordinate there, then blank it again.
    centre = [ref[f"arc_{k}"].fillna(ref[k[1]]) for k in CENTRE]
    for key, value in zip(CENTRE, to_machine(*centre, ref)):
        out[key] = np.where(ref[f"arc_{key}"].isna(), np.nan, value)
    out["feed"] = ref["feed"]
    out["feed_mode"] = ref["feed_mode"]
    out["plane"], out["units"] = ref["plane"], ref["units"]
    return out


def first_difference(ours: pd.DataFrame, ref: pd.DataFrame, exact: list[str],
                     close: list[str], atol: "float | np.ndarray" = ATOL) -> str | None:
    """Describe the first row where the tables differ, or None.

    ``exact`` columns must be equal; ``close`` columns must agree within
    ``atol`` (a number, or one per row) + RTOL * |reference| wherever the reference has a value.
    """
    n = min(len(ours), len(ref))
    a, b = ours.iloc[:n].reset_index(drop=True), ref.iloc[:n].reset_index(drop=True)
    bad = pd.DataFrame(index=range(n))
    for key in exact:
        bad[key] = a[key].to_numpy() != b[key].to_numpy()
    for key in close:
        want, got = b[key].to_numpy(float), a[key].to_numpy(float)
        ok = np.abs(got - want) <= atol + RTOL * np.abs(want)
        bad[key] = ~np.isnan(want) & ~ok
    rows = np.flatnonzero(bad.to_numpy().any(axis=1))
    if len(rows) == 0:
        return None if len(ours) == len(ref) else (
            f"motion count differs: ours {len(ours)}, rs274 {len(ref)}; "
            f"first extra row (ours line {ours['line'].iloc[n] if n < len(ours) else '-'}, "
            f"rs274 source line {ref['src_line'].iloc[n] if n < len(ref) else '-'})")
    i = rows[0]
    cols = [k for k in exact + close if bad.at[i, k]]
    shown = list(dict.fromkeys(["motion"] + cols + AXES + CENTRE))
    table = pd.DataFrame({"ours": a.loc[i, shown], "rs274": b.loc[i, shown]})
    return (f"{len(rows)} of {n} motions differ (counts: ours {len(ours)}, rs274 {len(ref)}); "
            f"first at motion {i}, rs274 source line {b.at[i, 'src_line']}, ours line "
            f"{a.at[i, 'line']}, in {cols}:\n{table.to_string()}")


def tool_table(name: str) -> Path:
    """The tool table rs274 ran the case with (its own ``.tbl`` beside it, TOOLTABLE_OVERRIDES.tsv, else tool.tbl)."""
    own = (CASES / name).with_suffix(".tbl")
    if own.exists():
        return own
    tables = CASES.parent / "tooltables"
    for line in (tables / "overrides.tsv").read_text().splitlines():
        program, _, table = line.partition("\t")
        flat = program.removeprefix("nc_files/").replace("/", "__")  # case files are named flat
        if not line.startswith("#") and name in (flat, Path(program).name):
            return tables / Path(table).name
    return tables / "tool.tbl"


def ours_like_canon(op) -> pd.DataFrame:
    """Our motions with each spline's chords folded into one ``spline`` motion to its end, as rs274 prints it."""
    ours = op.motions()
    w = op.waypoints
    moved = np.flatnonzero(w["motion"] > 0)
    rows = w["command"][moved] if "command" in w else moved
    spline = np.isin(op.table.name[rows], SPLINES)
    last_of_command = np.r_[rows[1:] != rows[:-1], True]
    keep = ~spline | last_of_command
    # G33 and G76's threading feeds move at a pitch per spindle revolution; the canon keeps printing the modal F
    ours["synced"] = np.isin(op.table.name[rows], [NAME_ID["thread"], NAME_ID["cycle_thread"], NAME_ID["rigid_tap"]]) \
        & (ours["motion"] == "feed")
    # a rigid tap (G33.1) is one RIGID_TAP to the bottom in the canon; gcodekit also moves back out
    tapping = op.table.name[rows] == NAME_ID["rigid_tap"]
    ours.loc[tapping & ~last_of_command, "motion"] = "RIGID_TAP"
    keep &= ~(tapping & last_of_command)
    ours = ours[keep].reset_index(drop=True)
    ours.loc[spline[keep], "motion"] = "spline"
    return ours


@cache
def motions(name: str) -> tuple[pd.DataFrame, pd.DataFrame, list]:
    """(our motions, reference motions, diagnostics) of one case."""
    op = gcodekit.gcode_to_operation(CASES / name, plan=False, tool_table=tool_table(name), **RS274_STANDALONE)
    return ours_like_canon(op), reference_motions(CASES / (name + ".canon.csv")), op.diagnostics.items


def test_cases_present() -> None:
    assert PROGRAMS, f"no golden cases in {CASES}; run tests/golden/linuxcnc/regenerate.py"


@pytest.mark.parametrize("name", PROGRAMS)
def test_motions_match_rs274(name: str) -> None:
    """Type, end point and arc centre of every motion, in order, and the count."""
    ours, ref, diagnostics = motions(name)
    problem = first_difference(ours, ref, ["motion", "units", "plane"], AXES + CENTRE)
    if problem is not None:
        pytest.fail(f"{name}: {problem}\ndiagnostics: {diagnostics[:5]}", pytrace=False)


@pytest.mark.parametrize("name", PROGRAMS)
def test_feeds_match_rs274(name: str) -> None:
    """Feed of every motion in units per minute mode (G94)."""
    ours, ref, _ = motions(name)
    if len(ours) != len(ref):
        pytest.skip("motion counts differ (see test_motions_match_rs274)")
    keep = (ref["feed_mode"] == 0).to_numpy() & ~ours["synced"].to_numpy()
    ours, ref = ours[keep].copy(), ref[keep].copy()
    ours["feed"] = ours["feed"].fillna(-1.0)  # rapids: NaN on both sides
    ref["feed"] = ref["feed"].fillna(-1.0)
    problem = first_difference(ours, ref, [], ["feed"])
    if problem is not None:
        pytest.fail(f"{name}: {problem}", pytrace=False)


@pytest.mark.parametrize("name", PROGRAMS)
def test_source_lines_match_rs274(name: str) -> None:
    """Every motion names the source line LinuxCNC's gcode module reports."""
    ours, ref, _ = motions(name)
    if len(ours) != len(ref):
        pytest.skip("motion counts differ (see test_motions_match_rs274)")
    # "order": emitted late, line not comparable; rs274's gcode module gives no
    # line (-1) to the moves of a lathe cycle after its first
    matched = (ref["line_match"].isin(["ok", "nurbs"]) & (ref["src_line"] >= 0)).to_numpy()
    ours = ours[matched].reset_index(drop=True).assign(src=lambda f: f["line"].astype("int64"))
    ref = ref[matched].reset_index(drop=True).assign(src=lambda f: f["src_line"].astype("int64"))
    problem = first_difference(ours, ref, ["src"], [])
    if problem is not None:
        pytest.fail(f"{name}: {problem}", pytrace=False)


def test_reference_offsets_applied(tmp_path: Path) -> None:
    """G92, XY rotation, G5x and tool offsets move canon rows to machine coordinates."""
    header = ("idx,src_line,line_match,type,x,y,z,a,b,c,feed,feed_mode,units,plane,arc_rotation,"
              "arc_cx,arc_cy,arc_cz,g5x_x,g5x_y,g5x_z,g92_x,g92_y,g92_z,xy_rot,tlo_x,tlo_z")
    row = "0,7,ok,ARC_FEED,1,0,0,0,0,0,100,0,mm,XY,-1,1,1,,10,20,3,1,0,0,90,0,0.5"
    path = tmp_path / "t.canon.csv"
    path.write_text(header + "\n" + row + "\n")
    ref = reference_motions(path).iloc[0]
    assert ref["motion"] == "arc_cw"
    assert np.allclose(ref[["x", "y", "z"]].to_numpy(float), [10.0, 22.0, 3.5])
    assert np.allclose(ref[["cx", "cy"]].to_numpy(float), [9.0, 22.0])
    assert np.isnan(ref["cz"])
