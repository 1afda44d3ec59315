"""gcodekit.path's tools, tool tables, jobs and from_shape, checked against hand-worked values,
FreeCAD 0.20.2's own XML (tests/golden/freecad/api.json), LinuxCNC's tool table reader and shapely."""

from __future__ import annotations

import json
import math
from pathlib import Path as FilePath

import pytest

import gcodekit.path as Path
from gcodekit.emulate.tooltable import ToolTable
from gcodekit.errors import ConfigError
from gcodekit.path.tooltable_files import tooltable_from_text, tooltable_to_json, tooltable_to_tbl
from gcodekit.tool_shapes import ToolShape

shapely = pytest.importorskip("shapely")
from shapely.geometry import LineString, Polygon, box  # noqa: E402

API = json.loads((FilePath(__file__).parent / "golden" / "freecad" / "api.json").read_text())["cases"]


def _table() -> Path.Tooltable:
    table = Path.Tooltable(name="shop")
    table.addTools(Path.Tool("3 mm end mill", tooltype="EndMill", material="Carbide", diameter=3, lengthOffset=40.5,
                             cuttingEdgeHeight=12))
    table.setTool(7, Path.Tool("6 mm ball", tooltype="BallEndMill", diameter=6, lengthOffset=55))
    table.addTools(Path.Tool("90 deg V", tooltype="Engraver", diameter=10, cuttingEdgeAngle=90, lengthOffset=30))
    return table


# -- tool tables: FreeCAD's XML and JSON, LinuxCNC's .tbl -----------------------------------------

def test_xml_is_freecads_byte_for_byte():
    table = Path.Tooltable()
    table.addTools(Path.Tool("a", diameter=3))
    assert table.Content == API["tooltable_content"]["result"]
    assert Path.Tool("a", tooltype="Drill").Content == API["tool_content"]["result"]


@pytest.mark.parametrize("suffix", [".json", ".xml", ".tbl"])
def test_tool_table_files_round_trip(tmp_path, suffix):
    table = _table()
    Path.write_tooltable(table, tmp_path / f"t{suffix}")
    back = Path.read_tooltable(tmp_path / f"t{suffix}")
    assert sorted(back.Tools) == [1, 7, 8]
    fields = ("Name", "Diameter", "LengthOffset") if suffix == ".tbl" else (
        "Name", "ToolType", "Material", "Diameter", "LengthOffset", "CuttingEdgeAngle", "CuttingEdgeHeight")
    for n, tool in table.Tools.items():
        assert [getattr(back.getTool(n), f) for f in fields] == [getattr(tool, f) for f in fields]


def test_tbl_is_what_linuxcncs_reader_reads():
    text = tooltable_to_tbl(_table())
    linuxcnc = ToolTable.parse(text, units="mm")
    assert not linuxcnc.skipped
    assert linuxcnc[7].diameter == 6.0 and float(linuxcnc[7].offset[2]) == 55.0 and linuxcnc[1].comment == "3 mm end mill"


def test_tbl_in_inches_is_converted():
    table = tooltable_from_text("T3 P3 D0.25 Z1.5 ;quarter inch\n", "tbl", units="inch")
    tool = table.getTool(3)
    assert (tool.Name, tool.Diameter, tool.LengthOffset) == ("quarter inch", pytest.approx(6.35), pytest.approx(38.1))


def test_freecad_018_json_and_bare_json_are_read():
    entry = {"name": "q", "diameter": 2, "tooltype": "Drill", "cuttingEdgeAngle": 118}
    for data in ([{"TableName": "t", "Version": 1, "Tools": {"3": entry}}], {"3": entry}):
        tool = tooltable_from_text(json.dumps(data), "json").getTool(3)
        assert (tool.Name, tool.Diameter, tool.ToolType) == ("q", 2.0, "Drill")
    assert json.loads(tooltable_to_json(_table()))["Tools"]["7"]["tooltype"] == "BallEndMill"


@pytest.mark.parametrize("text, fmt, message", [
    ("{not json", "json", "not JSON"), ("<Tools/>", "xml", "root element is <Tools>"),
    ('{"1": {"diameter": "wide"}}', "json", "not a FreeCAD tool"), ("<Tooltable", "xml", "not XML"),
])
def test_bad_tool_table_text_is_a_clear_error(text, fmt, message):
    with pytest.raises(ConfigError, match=message):
        tooltable_from_text(text, fmt, source="shop.x")


def test_unknown_tool_type_is_an_error_not_undefined():
    """FreeCAD 0.20 silently stores 'Undefined' for a type it does not know; gcodekit says so."""
    with pytest.raises(ConfigError, match="did you mean 'BallEndMill'"):
        Path.Tool("x", tooltype="BallEndMil")
    assert Path.Tool("x", tooltype="ballendmill").ToolType == "BallEndMill"


# -- tools as gcodekit's shapes -----------------------------------------------------------------------

@pytest.mark.parametrize("tool, shape", [
    (Path.Tool(tooltype="EndMill", diameter=6, cuttingEdgeHeight=20), ToolShape("endmill", 6, 20)),
    (Path.Tool(tooltype="EndMill", diameter=6, cornerRadius=1), ToolShape("bullnose", 6, 30, corner_radius=1)),
    (Path.Tool(tooltype="BallEndMill", diameter=6), ToolShape("ballend", 6, 30)),
    (Path.Tool(tooltype="Drill", diameter=5, cuttingEdgeAngle=118), ToolShape("drill", 5, 30, angle=118)),
    (Path.Tool(tooltype="Engraver", diameter=10, cuttingEdgeAngle=60), ToolShape("vbit", 10, 30, angle=60)),
    (Path.Tool(tooltype="ChamferMill", diameter=10, cuttingEdgeAngle=90, flatRadius=1),
     ToolShape("chamfer", 10, 30, angle=90, tip_diameter=2)),
])
def test_legacy_tools_become_tool_shapes_and_back(tool, shape):
    assert tool.shape() == shape
    assert Path.Tool.from_shape(shape).shape() == shape


@pytest.mark.parametrize("shape", [
    ToolShape("endmill", 6, 20), ToolShape("ballend", 3, 10), ToolShape("bullnose", 8, 25, corner_radius=1.5),
    ToolShape("vbit", 10, 12, angle=60), ToolShape("drill", 5, 40), ToolShape("chamfer", 12, 10, angle=90, tip_diameter=1),
])
def test_toolbits_round_trip_through_fctb(shape):
    bit = Path.ToolBit.from_shape(shape)
    again = Path.ToolBit.from_dict(json.loads(json.dumps(bit.as_dict())))
    assert again.to_shape() == shape


def test_toolbit_reads_freecads_quantities():
    bit = Path.ToolBit.from_dict({"version": 2, "name": "5mm Endmill", "shape": "endmill.fcstd",
                                  "parameter": {"CuttingEdgeHeight": "30.0000 mm", "Diameter": "5.0000 mm",
                                                "Length": "50.0000 mm", "ShankDiameter": "3.0000 mm"}})
    assert bit.to_shape() == ToolShape("endmill", 5, 30)
    v = Path.ToolBit("v", "v-bit.fcstd", {"Diameter": "10 mm", "CuttingEdgeAngle": "60.0000 °", "TipDiameter": "0 mm"})
    assert v.to_shape().height_at(5.0).item() == pytest.approx(5 / math.tan(math.radians(30)))
    with pytest.raises(ConfigError, match="unknown ToolBit shape"):
        Path.ToolBit("x", "spoon.fcstd", {"Diameter": 1}).to_shape()


# -- jobs ---------------------------------------------------------------------------------------

def test_compound_joins_in_order_and_applies_placements_only_when_asked():
    p1, p2 = Path.Path("G1X1"), Path.Path("G1Y1")  # the seed's compound
    comp = Path.Compound([p1, p2])
    assert comp.Path.toGCode() == "G1 X1.000000\nG1 Y1.000000\n"
    job = Path.Job(tooltable=_table())
    job.add(Path.Path("G0 X0 Y0 G2 X2 Y0 I1 J0 M3 S100"), placement=Path.Placement(Path.Vector(10, 5, 1)), tool=7)
    assert [c.toGCode() for c in job.Path.Commands][-2] == "G2 I1.000000 J0.000000 X2.000000 Y0.000000"
    job.UsePlacements = True
    moved = job.Path.Commands
    assert moved[-2].toGCode() == "G2 I1.000000 J0.000000 X12.000000 Y5.000000"  # I/J stay relative
    assert moved[-1].toGCode() == "M3 S100.000000"  # no position: not moved
    assert [c.toGCode() for c in moved[:2]] == ["(T7: 6 mm ball)", "M6 T7.000000"]


def test_a_job_changes_tools_only_when_the_tool_changes():
    job = Path.Job(tooltable=_table())
    for tool in (1, 1, 7, 1):
        job.add(Path.Path("G1 X1"), tool=tool)
    assert [c.Parameters["T"] for c in job.Path.Commands if c.Name == "M6"] == [1.0, 7.0, 1.0]
    with pytest.raises(ConfigError, match="tool 4 is not in the job's tool table"):
        job.add(Path.Path("G1 X1"), tool=4)


# -- from_shape ---------------------------------------------------------------------------------

def test_from_shape_follows_the_seeds_polygon_and_fixes_freecads_zero_coordinates():
    closed = Path.from_shape([(0, 0, 1), (0, 2, 1), (2, 2, 1), (0, 0, 1)])
    # FreeCAD 0.20 writes the last move as 'G1 Z1.000000' (X0 and Y0 left out), which goes nowhere
    assert closed.Commands[-1].toGCode() == "G1 X0.000000 Y0.000000"
    assert closed.Length == pytest.approx(2 + 2 + math.hypot(2, 2) + 1)


@pytest.mark.parametrize("geometry", [
    box(0, 0, 10, 5), Polygon([(0, 0), (20, 0), (20, 10)], [[(12, 2), (17, 2), (17, 4)]]),
    LineString([(0, 0), (3, 4), (10, 4)]),
])
def test_contours_have_shapelys_length(geometry):
    path = Path.from_shape(geometry, feed=500)
    cut = sum(s.length for s in path.segments() if s.kind == "feed")
    assert cut == pytest.approx(geometry.length, rel=1e-12)


def test_offset_contour_is_shapelys_buffer():
    square = box(0, 0, 10, 10)
    outside = Path.from_shape(square, offset=2, final_depth=-1, safe_height=5, feed=300)
    cut = [s for s in outside.segments() if s.kind == "feed" and s.start[2] == s.end[2]]
    assert sum(s.length for s in cut) == pytest.approx(square.buffer(2).exterior.length, rel=1e-12)
    inside = Path.from_shape(square, offset=-1.5, final_depth=-1)
    corners = [p for s in inside.segments() if s.kind == "feed" for p in (s.start, s.end)]
    xs, ys = [p[0] for p in corners], [p[1] for p in corners]
    assert (min(xs), min(ys), max(xs), max(ys)) == pytest.approx((1.5, 1.5, 8.5, 8.5))


def test_depth_steps_reach_the_final_depth_and_retract():
    path = Path.from_shape(box(0, 0, 4, 4), safe_height=5, start_depth=0, final_depth=-2.5, step_down=1,
                           feed=400, vertical_feed=100)
    plunges = [c.Parameters for c in path.Commands if c.Name == "G1" and set(c.Parameters) <= {"Z", "F"}]
    assert [p["Z"] for p in plunges] == [-1, -2, -2.5]
    assert all(p["F"] == 100 for p in plunges)
    assert path.Commands[-1].toGCode() == "G0 Z5.000000"
    assert path.BoundBox.as_list() == pytest.approx([0, 0, -2.5, 4, 4, 5])


def test_from_shape_rejects_what_it_cannot_follow():
    with pytest.raises(ConfigError, match="at least two"):
        Path.from_shape([(0, 0)])
    with pytest.raises(TypeError, match="shapely geometry"):
        Path.from_shape("square")


def test_readme_freecad_example_runs(tmp_path, monkeypatch, capsys):
    """The README's FreeCAD section is the seed page's examples; they run as written."""
    readme = (FilePath(__file__).resolve().parents[1] / "README.md").read_text()
    section = readme.split("## FreeCAD users", 1)[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    (tmp_path / "program.ngc").write_text("G21\nG0 X1 Y1\nG1 X5 F100\nM2\n")
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)
    out = capsys.readouterr().out
    assert out.startswith("G1 X1.000000\nG1 Y4.000000\nG1 X2.000000 Y2.000000\n")
    assert "M6 T2" in out and "M6 T1" in out
    assert repr(scope["c5"]) == "Command G1 [ X:3 Y:2 Z:1 ]"
    assert repr(scope["table"].Tools) == "{1: Tool 12.7mm Drill Bit, 2: Tool my other tool}"
    assert [c.Name for c in scope["imported"].Commands] == ["G0", "G1"]
    assert scope["op"].emulated
