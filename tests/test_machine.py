"""Emulate stage: modal machine behaviour against values worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gcodekit


def run(text: str, machine: str = "linuxcnc", **kw):
    """Emulate without the motion planner: times here are length over feed."""
    op = gcodekit.gcode_to_operation(text, machine, plan=False, **kw)
    return op, op.to_dataframe()


def end(op, i=-1):
    return op.process_data[i].location[:3]


def test_units_switch_mid_program():
    op, df = run("G21 G1 X10 F100\nG20 X1\nG21 Y5\n")
    assert end(op, 1) == (10.0, 0.0, 0.0)
    assert end(op, 3) == pytest.approx((25.4, 0.0, 0.0))
    assert end(op, 5) == pytest.approx((25.4, 5.0, 0.0))
    assert df["distance"].iloc[3] == pytest.approx(15.4)
    # the feed in force keeps its speed across G20 (LinuxCNC converts it to 3.937 in/min)
    assert df["time"].iloc[3] == pytest.approx(15.4 / (100 / 60))
    assert op.motions()["feed"].iloc[1] == pytest.approx(100 / 25.4)


def test_units_keep_feed_keeps_the_f_number():
    # rs274 standalone: "F30 G20" and a later G21 leave the F number alone (30 in/min, then 30 mm/min)
    text = "G21 F30 G18 G20\nG1 X1\nG21\nG1 X30\n"
    op, df = run(text, units_keep_feed=True)
    assert op.motions()["feed"].tolist() == [30.0, 30.0]
    assert df["time"].iloc[-1] == pytest.approx((30 - 25.4) / (30 / 60))
    # by default the speed stays: 30 mm/min is 1.1811 in/min after G20
    assert run(text)[0].motions()["feed"].tolist() == pytest.approx([30 / 25.4, 30.0])


def test_incremental_and_absolute_mixed():
    op, _ = run("G21 G90 G0 X10 Y10\nG91 G1 X5 Y-2 F60\nX5\nG90 X0\n")
    assert op.process_data[-1].location[:2] == (0.0, 8.0)
    frame = op.motions()
    assert frame[["x", "y"]].values.tolist() == [[10, 10], [15, 8], [20, 8], [0, 8]]


def test_work_offsets_and_g92_family():
    text = "\n".join([
        "G21 G90",
        "G55 G0 X0 Y0",       # G55 = (100, 50, 0) from the preset override
        "G92 X10 Y10",        # the current point (100, 50) is now (10, 10)
        "G0 X20 Y10",         # machine (110, 50)
        "G92.2",              # suspend: program coordinates are G55 again
        "G0 X0 Y0",           # machine (100, 50)
        "G92.3",              # restore the offset (-> program (0,0) is machine (90, 40))
        "G0 X0 Y0",
        "G92.1",
        "G54 G0 X1 Y2",
    ]) + "\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", work_offsets={"G55": (100.0, 50.0, 0.0)})
    m = op.motions()[["x", "y"]].values.tolist()
    assert m == [[100, 50], [110, 50], [100, 50], [90, 40], [1, 2]]


def test_g28_goes_through_the_given_point_to_the_stored_position():
    op, _ = run("G21 G0 X10 Y10 Z5\nG28.1\nG0 X0 Y0 Z0\nG28 Z8\n")
    m = op.motions()
    # via the intermediate point (0, 0, 8), then only Z to the stored 5
    assert m[["x", "y", "z"]].values.tolist()[-2:] == [[0, 0, 8], [0, 0, 5]]
    assert (m["line"].iloc[-2], m["line"].iloc[-1]) == (4, 4)
    assert len(op.process_data) == len(op.commands)


def test_marlin_g28_homes_named_axes():
    op, _ = run("G1 X10 Y20 Z5 F600\nG28 X\nG28\n", "marlin")
    assert end(op, 1) == (0.0, 20.0, 5.0)
    assert end(op, 2) == (0.0, 0.0, 0.0)


def test_g53_moves_in_machine_coordinates_once():
    op = gcodekit.gcode_to_operation("G21 G55 G0 X1\nG53 G0 X5\nX2\n", "linuxcnc", work_offsets={"G55": (100.0, 0, 0)})
    assert op.motions()["x"].tolist() == [101.0, 5.0, 102.0]


@pytest.mark.parametrize("plane, words, center, endpoint", [
    ("G17", "X10 Y10 I0 J10", (0, 10, None), (10, 10, 0)),
    ("G18", "X10 Z10 I10 K0", (10, None, 0), (10, 0, 10)),
    ("G19", "Y10 Z10 J0 K10", (None, 0, 10), (0, 10, 10)),
])
def test_arc_planes(plane, words, center, endpoint):
    op, df = run(f"G21 {plane} G2 {words} F100\n")
    row = op.motions().iloc[0]
    assert (row.x, row.y, row.z) == pytest.approx(endpoint)
    got = (row.cx, row.cy, row.cz)
    for g, c in zip(got, center):
        assert (math.isnan(g) if c is None else g == pytest.approx(c))
    # clockwise seen with the plane's first axis right and second up: three quarters
    assert df["distance"].iloc[-1] == pytest.approx(0.75 * 2 * math.pi * 10)


def test_arc_lengths_quarter_half_full_and_helix():
    # CW from (10,0) about the origin to (0,-10): a quarter turn of radius 10
    _, df = run("G21 G0 X10 Y0\nG2 X0 Y-10 I-10 J0 F600\n")
    assert df["distance"].iloc[-1] == pytest.approx(math.pi * 5)
    # CCW the same way round is three quarters
    _, df = run("G21 G0 X10 Y0\nG3 X0 Y-10 I-10 J0 F600\n")
    assert df["distance"].iloc[-1] == pytest.approx(math.pi * 15)
    # a full circle with a 4 mm rise, two turns (P2)
    _, df = run("G21 G0 X10 Y0\nG2 X10 Y0 Z4 I-10 J0 P2 F600\n")
    assert df["distance"].iloc[-1] == pytest.approx(math.hypot(2 * 2 * math.pi * 10, 4))


def test_radius_form_short_and_long_arcs():
    op, _ = run("G21 G0 X0 Y0\nG2 X10 Y0 R5 F100\nG0 X0 Y0\nG2 X10 Y0 R-7.0710678118654755\nG0 X0 Y0\nG3 X10 Y0 R7.0710678118654755\n")
    m = op.motions()
    # R5 over a 10 mm chord is a half circle centred on the chord
    assert (m.cx.iloc[1], m.cy.iloc[1]) == pytest.approx((5, 0))
    # negative R: the long way round, centre to the left of travel for G2
    assert (m.cx.iloc[3], m.cy.iloc[3]) == pytest.approx((5, 5))
    # G3 with positive R: the short arc, centre to the left as well
    assert (m.cx.iloc[5], m.cy.iloc[5]) == pytest.approx((5, 5))


def test_absolute_arc_centres_g90_1():
    op, _ = run("G21 G0 X10 Y0\nG90.1 G3 X-10 Y0 I0 J0 F100\n")
    assert (op.motions().cx.iloc[-1], op.motions().cy.iloc[-1]) == (0.0, 0.0)


def test_arc_radius_mismatch_is_reported():
    op, _ = run("G21 G0 X10 Y0\nG2 X0 Y-12 I-10 J0 F100\n")
    assert any("radius" in d.message and d.line == 2 for d in op.diagnostics)


def test_inverse_time_feed():
    _, df = run("G21 G93 G1 X30 F2\n")  # each move takes 1/F minutes
    assert df["time"].iloc[-1] == pytest.approx(30.0)


def test_dwell_units_follow_the_machine():
    _, lin = run("G4 P1.5\n", "linuxcnc")
    _, mar = run("G4 P1500\nG4 S2\n", "marlin")
    assert lin["time"].sum() == pytest.approx(1.5)
    assert mar["time"].tolist() == pytest.approx([1.5, 2.0])


def test_extrusion_absolute_relative_and_g92_e():
    op, df = run("M82\nG1 X10 E1 F600\nG1 X20 E3\nG92 E0\nG1 X30 E0.5\nM83\nG1 X40 E0.25\nG1 E-0.8\n", "marlin")
    assert df["de"].tolist() == pytest.approx([0, 1, 2, 0, 0.5, 0, 0.25, -0.8])
    assert op.get_statistics()["filament_mm"] == pytest.approx(2.95)
    assert [c.kind.name for c in op.commands[6:8]] == ["MOVE_EXTRUDE", "EXTRUDE"]


def test_rapid_speed_depends_on_firmware():
    _, lin = run("G21 G0 X50\n", "linuxcnc")  # 3000 mm/min preset rapid rate
    _, mar = run("G1 F600\nG0 X50\n", "marlin")  # Marlin's G0 uses the modal feed
    assert lin["time"].iloc[-1] == pytest.approx(1.0)
    assert mar["time"].iloc[-1] == pytest.approx(5.0)


def test_tools_spindle_coolant():
    op, df = run("T2 M6\nS1000 M3\nM8\nG1 X1 F100\nM4\nM9\nM5\n")
    row = df.iloc[3]
    assert (row.tool, row.spindle, row.coolant) == (2, 1000.0, 2)
    assert df["spindle"].iloc[4] == -1000.0
    assert df["coolant"].iloc[-1] == 0 and df["spindle"].iloc[-1] == 0


def test_program_end_stops_the_machine():
    op, df = run("G21 G1 X1 F100\nM2\nG1 X50\n")
    assert end(op) == (1.0, 0.0, 0.0)
    assert any("program end" in d.message for d in op.diagnostics)


def test_statistics_and_bounds_warn_before_emulation():
    op = gcodekit.parse_program("G1 X1\n", flavor="rs274ngc")
    with pytest.warns(UserWarning):
        assert op.get_bounds() is None
    with pytest.warns(UserWarning):
        assert op.get_statistics() is None
    assert len(op.process_data) == 0
    gcodekit.emulate_operation(op)
    assert op.get_bounds()["max"][0] == 1.0


def test_bounds_include_arc_bulge():
    op, _ = run("G21 G0 X10 Y0\nG3 X-10 Y0 I-10 J0 F100\n")
    assert op.get_bounds("feed")["max"][1] == pytest.approx(10.0)


# -- the vectorized runs against a plain per-move reference -----------------------

def reference_positions(lines):
    """Absolute/incremental linear moves with G20/G21 and G92, one at a time."""
    pos = np.zeros(3)
    offset = np.zeros(3)
    units, incremental = 1.0, False
    out = []
    for kind, values in lines:
        if kind == "G20":
            units = 25.4
        elif kind == "G21":
            units = 1.0
        elif kind == "G90":
            incremental = False
        elif kind == "G91":
            incremental = True
        elif kind == "G92":
            for ax, v in values.items():
                offset[ax] = pos[ax] - v * units
        else:
            for ax, v in values.items():
                pos[ax] = (pos[ax] + v * units) if incremental else v * units + offset[ax]
            out.append(pos.copy())
    return out


axis_values = st.dictionaries(st.sampled_from([0, 1, 2]), st.integers(-500, 500).map(lambda v: v / 8),
                              min_size=1, max_size=3)
program_lines = st.lists(st.one_of(
    st.tuples(st.just("G1"), axis_values),
    st.tuples(st.just("G1"), axis_values),
    st.tuples(st.sampled_from(["G20", "G21", "G90", "G91"]), st.just({})),
    st.tuples(st.just("G92"), axis_values),
), max_size=40)


@settings(max_examples=200, deadline=None)
@given(program_lines)
def test_vectorized_runs_match_reference(lines):
    text = "G21 G90 F1000\n" + "".join(
        f"{kind} " + " ".join(f"{'XYZ'[a]}{v}" for a, v in values.items()) + "\n" for kind, values in lines)
    op = gcodekit.gcode_to_operation(text, "linuxcnc")
    moved = op.to_dataframe()
    moved = moved[moved["kind"].isin(["move"])]
    expected = reference_positions(lines)
    got = moved[["x", "y", "z"]].to_numpy()
    assert got.shape == (len(expected), 3)
    np.testing.assert_allclose(got, np.array(expected).reshape(-1, 3), atol=1e-9)


def test_g90_g91_set_the_extrusion_mode_in_marlin_not_klipper():
    text = "M83\nG90\nG1 X1 E1 F600\nG1 X2 E2\nG91\nG1 E-1\nG90\nG1 X3 E1.5\n"
    _, marlin = run(text, "marlin")
    _, klipper = run(text, "klipper")
    # Marlin: G90 made E absolute again (1, then +1), G91 relative (-1), G90 absolute (1.5 - 1)
    assert marlin["de"].tolist() == pytest.approx([0, 0, 1, 1, 0, -1, 0, 0.5])
    # Klipper keeps M83 through G90; G91 is relative anyway
    assert klipper["de"].tolist() == pytest.approx([0, 0, 1, 2, 0, -1, 0, 1.5])


def test_feed_per_revolution():
    # 0.1 mm per revolution at 600 rpm is 60 mm/min: 30 mm take 30 s
    _, df = run("G21 S600 M3\nG95 G1 X30 F0.1\n")
    assert df["time"].iloc[-1] == pytest.approx(30.0)
    assert df["feed"].iloc[-1] == pytest.approx(60.0)


def test_ger_relaxed_statements():
    """GER manual, section 2: several statements per line, ';' separates them."""
    text = "(a comment\nover two lines) G21\nG01 X1.0 G20 G01 Y1.0 F10\nG01 X2.0; Y2.0\nX3 Y3\n"
    op = gcodekit.gcode_to_operation(text, "ger")
    m = op.motions()
    # lengths are given in the units in force at each move: X1 mm is 1/25.4 in after G20
    expected = [[1.0, 0.0], [1 / 25.4, 1.0], [2.0, 1.0], [2.0, 2.0], [3.0, 3.0]]
    np.testing.assert_allclose(m[["x", "y"]].to_numpy(), expected)
    assert m["units"].tolist() == ["mm", "in", "in", "in", "in"]
    assert op.commands[0].comment == "a comment over two lines"
    # the program starts in rapid mode: axis words alone move at once
    assert gcodekit.gcode_to_operation("X1 Y1\n", "ger").motions()["motion"].tolist() == ["rapid"]


def test_tool_length_offsets_g10_and_g52(tmp_path):
    table = tmp_path / "tools.tbl"
    table.write_text("T1 P1 Z0.5 D0.25 ;end mill\nT2 P2 Z1.0\n")
    text = "\n".join([
        "G20 T1 M6",
        "G43 H1",            # tool 1: +0.5 mm; the machine stays, program Z becomes -0.5 mm
        "G0 X1",             # ... so Z does not move (rs274, gmoccapy golden case)
        "G43.2 H2",          # add tool 2: 1.5 in in all
        "G0 Z0",
        "G49 G0 Z0",
        "G10 L2 P2 X2",      # G55 is at X 2 in
        "G55 G0 X0",
        "G10 L20 P1 X1",     # the current point becomes X 1 in G54
        "G54 G0 X1",
        "G52 X0.5",          # LinuxCNC: a local offset kept in the G92 slot
        "G0 X1",
        "G43.1 Z-0.25",
        "G0 Z0",
    ]) + "\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, tool_table=table, tool_table_units="mm")
    m = op.motions()
    np.testing.assert_allclose(m[["x", "z"]].to_numpy(), [
        [1, 0], [1, 1.5 / 25.4], [1, 0], [2, 0], [2, 0], [2.5, 0], [2.5, -0.25]], atol=1e-12)


def test_tool_length_offset_in_the_tool_change_block_keeps_program_position(tmp_path):
    """rs274 re-reads its position after M6, so G43 in that block moves Z on the next move (skeleton.ngc)."""
    table = tmp_path / "tools.tbl"
    table.write_text("T1 P1 Z0.5\n")
    op = gcodekit.gcode_to_operation("G21 T1 M6 G43 H1\nG0 X1\n", "linuxcnc", plan=False,
                                     tool_table=table, tool_table_units="mm")
    np.testing.assert_allclose(op.motions()[["x", "z"]].to_numpy(), [[1, 0.5]], atol=1e-12)


def test_xy_rotation_turns_the_program_frame_about_the_work_origin():
    """G10 L2 R: machine = rotate(program + G92) + G5x (values worked out by hand)."""
    text = "\n".join([
        "G21 G90 G0 X10 Y0",
        "G10 L2 P1 X10 Y0 R90",  # G54's origin at (10, 0), its X axis along machine +Y
        "G1 X1 F100",            # program (1, 0) -> machine (10, 1)
        "G91 Y2",                # an increment along program Y runs along machine -X: (8, 1)
        "G90",
        "G2 X-1 Y2 I-1 J0",      # centre program (0, 2) -> machine (8, 0), end (-1, 2) -> (8, -1)
        "G92 X0 Y0",             # the G92 offset sits before the rotation: program (-1, 2) is now (0, 0)
        "G1 X1",                 # program (1, 0) + G92 (-1, 2) = (0, 2) -> machine (8, 0)
        "G92.1",
        "G55 G1 X3 Y4",          # G55 is not turned
        "G54 G1 X0 Y0",
        "G10 L2 P1 R0",          # back to square: rs274 turns its idea of the point with it
        "G1 X5",
        "M2",
    ]) + "\n"
    op, df = run(text)
    assert not op.diagnostics.items
    m = op.motions()
    np.testing.assert_allclose(m[["x", "y"]].to_numpy(), [
        [10, 0], [10, 1], [8, 1], [8, -1], [8, 0], [3, 4], [10, 0], [15, 0]], atol=1e-12)
    np.testing.assert_allclose(m[["cx", "cy"]].to_numpy()[3], [8, 0], atol=1e-12)
    assert df.loc[df["line"] == 3, "rotation"].tolist() == [90.0]
    assert df.loc[df["line"] == 13, "rotation"].tolist() == [0.0]


def test_g10_l20_under_a_rotation_moves_the_origin_along_both_axes():
    # in G54 turned 90 degrees at (0, 0), the point machine (0, 5) is program (5, 0); X0 alone keeps
    # program Y 0, so the origin moves to machine (0, 5) and the next X1 goes to machine (0, 6)
    op, _ = run("G21 G0 X0 Y5\nG10 L2 P1 R90\nG10 L20 P1 X0\nG1 X1 F100\nM2\n")
    np.testing.assert_allclose(op.motions()[["x", "y"]].to_numpy()[-1], [0, 6], atol=1e-12)
    op, _ = run("G21\nG10 L20 P1 X0 R30\nM2\n")
    assert [(d.line, d.message) for d in op.diagnostics.items] == [(2, "R not allowed in G10 L20")]


def test_tool_table_lines_rs274_cannot_read_are_skipped(tmp_path):
    # rs274 2.9 skips a line without T, or with a word it lacks (a newer table's WX wear offset, K):
    # selecting such a tool is then "Requested tool 2 not found in the tool table"
    table = tmp_path / "tools.tbl"
    table.write_text("T1 P1 Z1.0\nT2 P2 X3.0 Z4.0 WX0.05 WZ-0.03\nP3 Z1\nT4 P4 Z1 K5 ;note\nT5 P5 Z2 Q9 ;lathe\n")
    op, _ = run("G20\nT2 M6\nT5 M6\nM2\n", tool_table=table, tool_table_units="inch")
    found = [(d.file.endswith("tools.tbl"), d.line, d.severity) for d in op.diagnostics.items]
    assert found == [(True, 2, "warning"), (True, 3, "warning"), (True, 4, "warning"), (False, 2, "error")]
    assert "Requested tool 2 not found" in op.diagnostics.items[-1].message


def test_g92_leaves_the_tool_length_offset_out_of_its_offset(tmp_path):
    # program Z 10 with a 12.7 mm tool is machine Z 22.7; G92 Z0 makes the offset 10, so Z-1 is machine 21.7
    table = tmp_path / "tools.tbl"
    table.write_text("T1 P1 Z12.7\n")
    op, _ = run("G21 T1 M6\nG43 H1\nG0 Z10\nG92 Z0\nG1 Z-1 F100\nM2\n", tool_table=table,
                tool_table_units="mm")
    np.testing.assert_allclose(op.motions()["z"].to_numpy(), [22.7, 21.7], atol=1e-12)


def test_canned_cycles_follow_linuxcnc():
    text = "G21 G90 G17 G0 X0 Y0 Z10\nG98 G81 X10 Y5 Z-3 R2 F100\nX20\nG99 G83 X30 Z-5 R1 Q2\nG80\nG0 Z10\n"
    m = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False).motions()
    expected = [  # (line, motion, x, z): worked out from the LinuxCNC manual's cycle descriptions
        (1, "rapid", 0, 10),
        (2, "rapid", 10, 10), (2, "rapid", 10, 2), (2, "feed", 10, -3), (2, "rapid", 10, 10),  # G98: back to 10
        (3, "rapid", 20, 10), (3, "rapid", 20, 2), (3, "feed", 20, -3), (3, "rapid", 20, 10),  # modal repeat
        (4, "rapid", 30, 10), (4, "rapid", 30, 1),
        (4, "feed", 30, -1), (4, "rapid", 30, 1), (4, "rapid", 30, -1 + 0.254),   # peck 2 mm, out, back in
        (4, "feed", 30, -3), (4, "rapid", 30, 1), (4, "rapid", 30, -3 + 0.254),
        (4, "feed", 30, -5), (4, "rapid", 30, 1),                                   # G99: retract to R
        (6, "rapid", 30, 10),
    ]
    got = list(zip(m["line"], m["motion"], m["x"], m["z"]))
    assert [g[:2] for g in got] == [e[:2] for e in expected]
    np.testing.assert_allclose([g[2:] for g in got], [e[2:] for e in expected], atol=1e-12)


def test_incremental_canned_cycle_repeats():
    # G91: R from the start Z, Z from R; X increments repeated L times
    m = gcodekit.gcode_to_operation("G21 G0 X0 Y0 Z5\nG91 G81 X10 R-3 Z-4 L3 F60\n", "linuxcnc", plan=False).motions()
    holes = m[m["motion"] == "feed"]
    assert holes["x"].tolist() == [10.0, 20.0, 30.0]
    assert holes["z"].tolist() == [-2.0, -2.0, -2.0]
    assert m["z"].iloc[-1] == 2.0  # rs274 starts in G99: back to R (checked in rs274 2.9)


def test_inverse_time_feed_is_not_scaled_by_inches():
    _, df = run("G20 G93 G1 X1 F2\n")  # 1 inch in 1/2 minute, whatever the units
    assert df["time"].iloc[-1] == pytest.approx(30.0)
    assert df["feed"].iloc[-1] == pytest.approx(2 * 25.4)  # mm/min actually travelled


def test_g16_polar_fanuc_absolute_pole_at_origin():
    # G90: X radius, Y angle about the program origin; a missing word keeps its last value
    text = "G21 G90 G17 G54 G0 X0 Y0\nG16\nG1 X10 Y30 F100\nY90\nX5\nG15\nG1 X1 Y1\n"
    m = gcodekit.gcode_to_operation(text, "fanuc", plan=False).motions()
    np.testing.assert_allclose(m[["x", "y"]].to_numpy(), [
        [0, 0], [10 * math.cos(math.radians(30)), 5], [0, 10], [0, 5], [1, 1]], atol=1e-12)


def test_g16_polar_ger_incremental_pole_at_tool():
    # GER: polar only in G91, each move X long at angle Y from where the tool is
    text = "G21 G91\nG16\nG01 X10 Y90 F100\nX10 Y0\nX2 Y180\nG15\nG01 X1 Y1\n"
    op = gcodekit.gcode_to_operation(text, "ger", plan=False)
    np.testing.assert_allclose(op.motions()[["x", "y"]].to_numpy(), [[0, 10], [10, 10], [8, 10], [9, 11]],
                               atol=1e-12)
    assert not op.diagnostics.items


def test_g16_refuses_arcs():
    op = gcodekit.gcode_to_operation("G21 G91 G16\nG02 X10 Y10 I5 J0\n", "ger", plan=False)
    assert [(d.line, d.severity) for d in op.diagnostics] == [(2, "error")]
    assert "G16" in op.diagnostics.items[0].message


def test_tapping_and_boring_cycles_by_hand():
    # G84 feeds out to the clear height; G88 stays at the bottom (manual retract); both need the spindle on
    text = "G21 G90 G0 X0 Y0 Z10 M3 S500\nG98 G84 X5 Y0 Z-4 R2 F100\nG80\nG0 Z10\nG88 X8 Z-3 R1 P2\nG80\n"
    m = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False).motions()
    assert m[["motion", "x", "z"]].values.tolist() == [
        ["rapid", 0, 10], ["rapid", 5, 10], ["rapid", 5, 2], ["feed", 5, -4], ["feed", 5, 10],
        ["rapid", 5, 10], ["rapid", 8, 10], ["rapid", 8, 1], ["feed", 8, -3]]


def test_g16_under_ger_rules():
    # GER: polar moves only in G91, and the program zero stays put while G16 is on
    op = gcodekit.gcode_to_operation("G21 G90 G16\nG01 X10 Y90 F100\nG91 G92 X5\nG15\n", "ger", plan=False)
    errors = [(d.line, d.message) for d in op.diagnostics if d.severity == "error"]
    assert [line for line, _ in errors] == [2, 3]
    assert "G91" in errors[0][1] and "program zero" in errors[1][1]


def test_probe_moves_run_to_their_target():
    # no probe input: G38.2 feeds all the way, like rs274 standalone, and the tool then stands
    # 0.254 mm back towards the start (Z-1.746); G38.5 may go nowhere, G38.4 may not (rs274 2.9)
    text = "G21 G0 Z5\nG38.2 Z-2 F50\nG38.5 Z-1.746\nG38.4 Z-1.746\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    m = op.motions()
    assert m[["line", "motion", "z"]].values.tolist()[:3] == [[1, "rapid", 5], [2, "feed", -2], [3, "feed", -1.746]]
    assert op.to_dataframe()["distance"].iloc[3] == pytest.approx(0.0, abs=1e-12)  # the G38.5 goes nowhere
    assert m["feed"].iloc[1] == 50
    assert [(d.line, d.message) for d in op.diagnostics if d.severity == "error"] == [
        (4, "Start point too close to probe point")]


def test_probe_results_are_the_targets_as_rs274_standalone_sets_them():
    # #5061-#5063: the target in program coordinates (G92 in force: X105, the machine's X5);
    # #5070 (tripped) is 0, so the smartprobe.ngc-style loop runs once; values checked with rs274 2.9
    text = "\n".join([
        "G21 G90 F100", "G0 X0 Y0 Z10",
        "G38.2 Z0",                      # tool stands at Z0.254 after it
        "G0 X[#5063 + 7] Y[#5070 + 1]",  # X7 Y1
        "G92 X100",                      # X7 is now X100
        "#5070 = 1",
        "o1 while [#5070 NE 0]",
        "  G38.3 X105",                  # machine X12
        "o1 endwhile",
        "G1 X[#5061 - 50] Y#5062",       # X55 in the G92 frame: machine X-38
        "G91 G1 Z1",                     # from the backed-off Z0.254
        "M2"])
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    m = op.motions()
    expected = [(0, 0, 10), (0, 0, 0), (7, 1, 0.254), (12, 1, 0.254), (-38, 1, 0.254), (-38, 1, 1.254)]
    np.testing.assert_allclose(m[["x", "y", "z"]].to_numpy(float), expected, atol=1e-12)
    assert [d for d in op.diagnostics if d.severity == "error"] == []


def test_axis_words_after_a_probe_probe_again():
    # G38.x is a motion mode: "Z-2" after "G38.3 Z-1" is a second probe (its results, its backoff);
    # rs274 2.9 gives X8 Y-1 Z-1.746 for the rapid
    text = "G21 F50\nG38.3 Z-1\n#1 = #5063\nZ-2\nG0 X[#5063 + 10] Y#1\nG91 G1 X1\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
    assert op.table.number[op.table.line == 4].tolist() == [383]
    np.testing.assert_allclose(op.motions()[["x", "y", "z"]].to_numpy(float),
                               [(0, 0, -1), (0, 0, -2), (8, -1, -1.746), (9, -1, -1.746)], atol=1e-12)


@pytest.mark.parametrize("move, message", [("G1 X2", "Cannot do g1 with zero feed rate"),
                                           ("G2 X3 I1", "Cannot make arc with zero feed rate")])
def test_feed_moves_without_feed_are_refused_as_rs274_does(move, message):
    # messages as rs274 2.9 prints them for these programs
    op = gcodekit.gcode_to_operation(f"G21 G0 X1\n{move}\nM2\n", "linuxcnc", plan=False)
    assert [(d.line, d.severity, d.message) for d in op.diagnostics] == [(2, "error", message)]


def test_probe_results_from_a_subroutine_file(tmp_path):
    # the probe sits in myprobe.ngc beside the program; rs274 2.9 rapids to X7 Z-2.746
    (tmp_path / "myprobe.ngc").write_text("o<myprobe> sub\nG38.2 Z#1\no<myprobe> endsub\nM2\n")
    main = tmp_path / "main.ngc"
    main.write_text("G21 F50\no<myprobe> call [-3]\nG0 X[#5063 + 10]\nM2\n")
    op = gcodekit.gcode_to_operation(main, "linuxcnc", plan=False)
    np.testing.assert_allclose(op.motions()[["x", "z"]].to_numpy(float), [(0, -3), (7, -2.746)], atol=1e-12)


def test_tapping_and_boring_cycles_need_the_spindle_turning():
    """rs274 (run_rs274.sh): G74, G84, G86 and G88 with the spindle stopped are errors; G81 is not."""
    for cycle, code in [("G74", "G74"), ("G84", "G84"), ("G86", "g86"), ("G88", "g88")]:
        text = f"G21 G17 F100\nG0 X0 Y0 Z5\n{cycle} X1 Y1 Z-1 R1 P1\nG80\nM2\n"
        op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False)
        assert [(d.line, d.message) for d in op.diagnostics.errors] == [(3, f"Spindle not turning in {code}")]
    drilled = gcodekit.gcode_to_operation("G21 G17 F100\nG0 X0 Y0 Z5\nG81 X1 Y1 Z-1 R1\nG80\nM2\n", "linuxcnc")
    assert not drilled.diagnostics.errors


def test_arc_radius_tolerance_is_rs274s():
    """interp_arc.cc: 2*sqrt(2)*0.01 mm and 0.1 % of the larger radius (both exceeded), or 100 times
    that tolerance; the end radius 1000.5 against 999.5 passes, 0.03 on a radius of 10 does not."""
    def errors(c: float, d: float) -> list:
        text = f"G21 G17 F100\nG0 X0 Y0\nG2 X{2 * c + d} I{c}\nM2\n"
        return [d.line for d in gcodekit.gcode_to_operation(text, "linuxcnc", plan=False).diagnostics.errors]

    assert errors(999.5, 1.0) == [] and errors(999.5, 1.2) == [3]
    assert errors(10, 0.02) == [] and errors(10, 0.03) == [3]


@pytest.mark.parametrize("block, group", [("G90 G91", "distance mode"), ("G20 G21", "units"), ("G17 G18", "plane"),
                                          ("G54 G55", "coordinate system"), ("G41 G40", "cutter compensation"),
                                          ("G98 G99 G81 X0 Z-1 R1 F10", "canned cycle return"),
                                          ("G4 P1 G92 X0", "non-modal"), ("M3 M5", "spindle"),
                                          ("M7 M8", "coolant"), ("M0 M2", "stopping"),
                                          ("G92.1 G92.2", "G92 offset switch"), ("G28.1 G4 P1", "non-modal")])
def test_two_codes_of_one_modal_group_are_refused_as_rs274_does(block, group):
    # rs274 2.9: "Two g codes used from same modal group" (and m codes, M7 M8 included)
    op, _ = run(f"G21\n{block}\nM2\n")
    assert any(d.line == 2 and f"same modal group ({group})" in d.message for d in op.diagnostics.items)


def test_codes_of_different_groups_share_a_block():
    # rs274 2.9 lets G92.1-G92.3 share a block with another non-modal code
    op, _ = run("G21 G90 G17 G54 G94 M3 S100 M8\nG53 G0 X1\nG10 L2 P1 X1 G54\nG0 X0\nG92.1 G52 X0\nM2\n")
    assert not op.diagnostics.items
    # Fanuc takes the last code of a group without an alarm
    assert not gcodekit.gcode_to_operation("G90 G91 G0 X1\nM30\n", "fanuc", plan=False).diagnostics.items


@pytest.mark.parametrize("block, letter", [("G1 X1 R5 F10", "R"), ("G64 P1 R0.5", "R"), ("G0 X1 P1", "P"),
                                           ("G1 X1 Q1 F1", "Q"), ("G1 X1 L2 F1", "L"), ("G0 X1 H1", "H"),
                                           ("G0 X1 D1", "D"), ("G0 X1 K1", "K"), ("M3 P1 S100", "P"),
                                           ("G33 Z-1 K0.1 D90", "D")])
def test_a_word_no_code_of_the_block_uses_is_refused_as_rs274_does(block, letter):
    # each block run in rs274 2.9: "R word with no g code that uses it", "P word with no G2 G3 G4 ..."
    op, _ = run(f"G21 G0 X0 Y0 Z0\nS100 M3\n{block}\nM2\n")
    assert [d.message.split()[0] for d in op.diagnostics.items if d.line == 3] == [letter]


def test_words_their_code_or_motion_mode_uses_pass():
    text = ("G21 S100 M3\nG43 H1\nG41 D1 G1 X1 F10\nG40 G0 X5\nG2 X10 Y0 R3\nX15 R3\nG81 X0 Y0 Z-1 R1\nX2\n"
            "G82 X1 Y1 Z-1 R1 P2\nG80 G4 P1\nG10 L2 P1 R30\nG64 P0.1 Q0.1\nM2\n")
    op, _ = run(text)
    assert not [d for d in op.diagnostics.items if "word with no" in d.message]


@pytest.mark.parametrize("program, message", [
    ("T99999999 M6\nG1 X1 F100\n", "no tool table: tool 99999999"),
    ("G43 H99999999\nG1 X1 F100\n", "no tool table: tool 99999999"),
    ("T2147483648 M6\n", "Tool number 2147483648 out of range"),
    ("M6 T-5\n", "Negative tool id used"),
    ("G43 H-1\n", "H word -1 out of range"),
])
def test_tools_a_mill_cannot_have_are_said(program, message):
    """Issue 14: tools with no table, or numbers no tool table holds, were accepted silently."""
    op = gcodekit.gcode_to_operation(program + "M2\n", "linuxcnc", plan=False)
    (diagnostic,) = op.diagnostics.items
    assert diagnostic.line == 1 and message in diagnostic.message


def test_one_warning_for_every_tool_without_a_table():
    op = gcodekit.gcode_to_operation("T1 M6\nG43 H1\nT2 M6\nG43 H2\nM2\n", "linuxcnc", plan=False)
    assert [d.severity for d in op.diagnostics] == ["warning"]
    printer = gcodekit.gcode_to_operation("T1\nG1 X1 E1 F100\nT0\n", "marlin", plan=False)
    assert not printer.diagnostics.items  # extruders need no table


def test_standalone_canon_aims_g28_and_g53_with_the_stale_tool_offset(tmp_path):
    """rs274 alone keeps a tool offset's number across G20/G21: G43 H2 in mm holds 2.54, read as
    2.54 in after G20, so G28 aims at home less 2.54 in and the machine's real 0.1 in offset
    puts the tool at -2.44 in (worked out by hand; rs274 2.9 prints the same)."""
    table = tmp_path / "tools.tbl"
    table.write_text("T2 P2 Z0.1\n")
    text = "G21\nG43 H2\nG20\nG28\nG53 G0 Z0.5\nM2\n"
    standalone = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, tool_table=table, tool_table_units="inch",
                                             standalone_canon=True)
    np.testing.assert_allclose(standalone.motions()["z"].to_numpy(), [0.0, -2.44, 0.5 - 2.44], atol=1e-9)
    machine = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, tool_table=table, tool_table_units="inch")
    np.testing.assert_allclose(machine.motions()["z"].to_numpy(), [0.0, 0.0, 0.5], atol=1e-9)


def test_standalone_canon_stores_g28_home_with_the_held_tool_offset():
    """G28.1 stores the machine point rs274 works out (program point plus offsets plus the tool offset it
    holds, stale after G20/G21), so a G28 right after it goes nowhere (rs274 2.9 prints the same)."""
    text = "G20\nG43.1 X0.06487 Z-0.30651\nG21\nG28.1\nG28\nM2\n"
    op = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False, standalone_canon=True)
    np.testing.assert_allclose(op.motions()[["x", "y", "z"]].to_numpy(), np.zeros((2, 3)), atol=1e-9)


@pytest.mark.parametrize("machine, names_linuxcnc", [("linuxcnc", True), ("fanuc", False)])
def test_the_no_tool_table_warning_names_linuxcnc_only_on_linuxcnc(machine, names_linuxcnc):
    """A Fanuc control takes lengths from its own offset registers: its warning must not speak of LinuxCNC."""
    op = gcodekit.gcode_to_operation("T1 M6\nG43 H1\nG1 X1 F100\nM30\n", machine, plan=False)
    (warning,) = [d for d in op.diagnostics.items if "no tool table" in d.message]
    assert ("LinuxCNC" in warning.message) == names_linuxcnc


@pytest.mark.parametrize("flavor", ["marlin", "prusa_mk3s", "bambu"])
def test_f_at_or_below_zero_leaves_a_printer_firmware_s_feed(flavor):
    """Marlin's gcode.cpp sets the feed only when ``parser.floatval('F') > 0`` (in
    ``get_destination_from_command``; Prusa's and Bambu's firmware likewise): a move after ``G1 F0`` or
    ``F-5`` runs at the feed before, on moves and on the blocks the modal handler runs (G92, G28).  Said once,
    at the first such F."""
    text = "G1 F800 X10\nG1 F0\nG0 Z3\nG92 E0 F0\nG28 X F-5\nG1 X20 F-5\nG1 X30\n"
    op = gcodekit.gcode_to_operation(text, flavor, plan=False)
    assert op.waypoints["feed"].tolist() == [800.0] * len(op.waypoints["feed"])
    assert np.isfinite(op.waypoints["time"]).all()
    said = [d for d in op.diagnostics if d.message.startswith("F at or below 0")]
    assert [(d.line, d.severity) for d in said] == [(2, "warning")]


@pytest.mark.parametrize("flavor, said, line", [
    ("linuxcnc", "Cannot do g1 with zero feed rate", 2),  # rs274 refuses the G1 F0 block itself
    ("grbl", "Cannot do g1 with zero feed rate", 3),
    ("makerbot", "feed move with no feed rate (F) in force: the controller refuses it", 3),
])
def test_f0_sets_a_zero_feed_elsewhere(flavor, said, line):
    op = gcodekit.gcode_to_operation("G1 F800 X10\nG1 F0\nG1 X20\n", flavor, plan=False)
    assert op.waypoints["feed"].tolist()[-1] == 0.0 and np.isnan(op.waypoints["time"][-1])
    assert [d.line for d in op.diagnostics if d.message.startswith(said)] == [line]


def test_reprapfirmware_moves_at_f0_at_its_minimum_movement_speed():
    """RepRapFirmware takes F0 as written (``GCodeBuffer::GetSpeed`` checks nothing) and moves at its
    minimum movement speed (``DDA::InitStandardMove``: ``max(feedRate, MinMovementSpeed)``): the preset's
    M203 I30, 0.5 mm/s, until the program's M203 I120, 2 mm/s.  The feed column keeps the F as written;
    it is not said to refuse the move, as GRBL and LinuxCNC do."""
    op = gcodekit.gcode_to_operation("G1 F800 X10\nG1 F0\nG1 X13\nG0 Z3\nM203 I120\nG1 X19\nG1 X20 F6\n",
                                     "reprapfirmware", plan=False)
    w = op.waypoints
    assert w["feed"].tolist() == [800.0, 0.0, 0.0, 0.0, 0.0, 0.0, 6.0]
    np.testing.assert_allclose(w["time"], [10 / (800 / 60), 0.0, 3 / 0.5, 3 / 0.5, 0.0, 6 / 2.0, 1 / 2.0])
    (said,) = [d for d in op.diagnostics if d.message.startswith("feed move at F0")]
    assert said.line == 3 and said.message.endswith("(RepRapFirmware's M203 I), 30 mm/min here")


def test_a_minimum_movement_speed_the_machine_does_not_give_leaves_f0_moves_untimed():
    # RepRapFirmware's flavor on Klipper's preset, whose planner has no minimum movement speed
    op = gcodekit.gcode_to_operation("G1 F800 X10\nG1 F0\nG1 X13\n", "klipper", flavor="reprapfirmware",
                                     plan=False)
    assert np.isnan(op.waypoints["time"][-1])
    (said,) = [d for d in op.diagnostics if d.message.startswith("feed move at F0")]
    assert said.line == 3 and said.message.endswith("which this machine does not give: its time is unknown")


def test_klipper_refuses_a_move_at_f0_or_below():
    """Klipper's gcode_move.py ``cmd_G1`` raises "Invalid speed" for F <= 0 after reading the axis words;
    the ``gcode:command_error`` event resets ``last_position`` to the toolhead's, which never moved.  So the
    block makes no move and drops its words (an absolute X20 and a relative X5 alike), the feed stays 800,
    and the next move starts where the tool is; an arc passes its F to its first segment (gcode_arcs.py).
    G92 and G28 read no F: only the warning that the F sets nothing."""
    text = ("G1 F800 X10\nG1 X20 Y5 E1 F0\nG1 Y3\nG92 E0 F0\nG91\nG1 X5 F-5\nG1 X1\nG90\n"
            "G2 X14 Y7 I2 J2 F0\nG1 F0\nG1 Y0\n")
    op = gcodekit.gcode_to_operation(text, "klipper", plan=False)
    w = op.waypoints
    moved = np.flatnonzero(w["motion"] > 0)
    assert op.table.line[w["command"][moved]].tolist() == [1, 3, 7, 11]
    assert list(zip(w["x"][moved], w["y"][moved])) == [(10, 0), (10, 3), (11, 3), (11, 0)]
    assert (w["feed"] == 800.0).all() and w["de"].sum() == 0.0
    np.testing.assert_allclose(w["time"][moved], np.array([10, 3, 1, 3]) / (800 / 60))
    errors = [d for d in op.diagnostics if d.severity == "error"]
    assert [d.line for d in errors] == [2, 6, 9, 10]
    assert errors[0].message.startswith("Invalid speed: Klipper refuses a move with F at or below 0")
    assert errors[0].message.endswith("a print from its virtual SD card stops here")
    assert [(d.line, d.severity) for d in op.diagnostics if d.message.startswith("F at or below 0")] == \
        [(4, "warning")]
    with pytest.raises(gcodekit.errors.GcodeMachineError, match="<string>:2:1: error: Invalid speed"):
        gcodekit.gcode_to_operation(text, "klipper", mode="strict", plan=False)
