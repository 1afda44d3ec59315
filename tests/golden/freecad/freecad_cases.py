"""Scripted FreeCAD Path API sequences: run on FreeCAD 0.20.2 by regenerate_freecad.py, on gcodekit.path by the tests.

Each case is a snippet that sets ``result``.  It sees ``Path`` (FreeCAD's
module or ``gcodekit.path``), ``App`` (``FreeCAD`` or ``gcodekit.path``, for
``Vector``/``Placement``/``Rotation``) and two measuring helpers:
``length(p)`` and ``box(p)`` are FreeCAD's ``p.Length`` and
``p.BoundBox`` under FreeCAD and ``p.freecad_length()`` and
``p.freecad_bound_box()`` under gcodekit (whose own ``Length`` and
``BoundBox`` are exact and checked by hand in the tests).  ``same(p)`` is
for paths whose exact measures equal FreeCAD's (no arcs): it is the pair
``(p.Length, box list)`` on both sides.
"""

import math


def plain(value):
    """A JSON-able form of an answer: FreeCAD objects by repr, floats as floats."""
    if isinstance(value, bool) or value is None or isinstance(value, (int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else repr(value)
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return repr(value)


CASES: dict[str, str] = {
    # -- commands: the seed's three ways, names and keys in either case --------------------------
    "command_empty": "result = repr(Path.Command())",
    "command_name_then_params": (
        "c = Path.Command(); c.Name = 'G1'; c.Parameters = {'X': 1, 'Y': 0}\n"
        "result = [repr(c), c.Parameters, c.toGCode()]"),
    "command_params_half": "c = Path.Command('G1'); c.Parameters = {'X': 1, 'Y': 0.5}; result = [repr(c), c.toGCode()]",
    "command_from_dict": "c = Path.Command('G1', {'X': 34, 'Y': 1.2}); result = [repr(c), c.toGCode(), repr(c.Placement)]",
    "command_lower_keys": "c = Path.Command('g1', {'x': 1, 'y': 0}); result = [c.Name, c.Parameters]",
    "command_from_text": "result = [repr(Path.Command(t)) for t in ('G1X4Y5', 'g1x1', 'g1 x2 y2', 'G01 X1', 'M3 S1000', 'T1 M6', 'G38.2 Z-5 F10')]",
    "command_set_from_gcode": "c = Path.Command('G1', {'X': 34, 'Y': 1.2}); c.setFromGCode('G1X1Y0'); result = repr(c)",
    "command_from_placement": (
        "p1 = App.Placement(); p1.Base = App.Vector(3, 2, 1)\n"
        "c5 = Path.Command('g1', p1); r1 = repr(c5)\n"
        "p2 = App.Placement(); p2.Base = App.Vector(5, 0, 0); c5.Placement = p2; r2 = repr(c5)\n"
        "x0 = c5.x; c5.x = 10; r3 = repr(c5); c5.y = 2\n"
        "result = [r1, r2, x0, r3, repr(c5), repr(p1)]"),
    "command_attributes": "c = Path.Command('G1 X5 F3'); result = [c.X, c.x, c.f, c.F, c.q]",
    "command_placement_drops_feed": (
        "c = Path.Command('G0 X3 Y2 Z1 F100'); c.Placement = App.Placement(App.Vector(5, 0, 0), App.Rotation())\n"
        "result = repr(c)"),
    "command_repr_digits": "result = repr(Path.Command('G1 X1.123456789 Y-1234567.5 Z0.000012345'))",
    "command_sorted_words": "result = Path.Command('G2 X1 Y2 I3 J4 K5 F100 N7').toGCode()",
    "command_rounding": (
        "result = [Path.Command('G1 X' + v).toGCode() for v in "
        "('0.0000005', '0.0000015', '-1.0000005', '0.1234567891', '-0.0000001', '123456789.123', '922337203685', '2.675')]"),
    "command_odd_numbers": "result = [Path.Command(t).Parameters for t in ('G1 X--1', 'G1 X1.2.3', 'G1 X1e5', 'G1 X1 X2', 'G1 X1 N5')]",
    "command_letter_without_number": "result = Path.Command('G1 X1 Y').Parameters",
    "command_comment": "c = Path.Command('(hello world)'); result = [c.Name, c.toGCode(), c.Parameters]",
    "command_bad_param_type": "result = Path.Command('G1', {'X': 'a'})",
    "command_bad_key_type": "result = Path.Command('G1', {1: 2})",
    "command_parameters_copy": "c = Path.Command('G1 X3'); c.Parameters.update({'Y': 4}); result = repr(c)",
    "command_transform": (
        "c = Path.Command('G1 X3 Y1 I2 F5')\n"
        "result = repr(c.transform(App.Placement(App.Vector(1, 2, 3), App.Rotation())))"),
    # -- paths ----------------------------------------------------------------------------------
    "path_from_commands": (
        "c1 = Path.Command('g1', {'x': 1, 'y': 0}); c2 = Path.Command('g1', {'x': 0, 'y': 2})\n"
        "p = Path.Path([c1, c2]); r = [repr(p), repr(p.Commands), p.Length]\n"
        "p.addCommands(c1); result = r + [repr(p), p.toGCode(), p.Size]"),
    "path_seed_first": (
        "p = Path.Path([Path.Command('g1x1'), Path.Command('g1y4'), Path.Command('g1 x2 y2')])\n"
        "result = [p.toGCode(), same(p)]"),
    "path_from_text": "p = Path.Path('G0 X2 Y2 G1 X0 Y2'); result = [repr(p), p.Size, p.toGCode(), same(p)]",
    "path_multiline": (
        "p = Path.Path('(start)\\nG0 X1 Y1 Z5\\ng1 z-1 f100\\nG1 X10\\n  x12 y3\\nM5\\nM2\\n')\n"
        "result = [repr(p.Commands), p.toGCode(), same(p)]"),
    "path_set_from_gcode": "p = Path.Path('G1 X1'); p.setFromGCode('G0 X7 G1 Y3'); result = [repr(p), same(p)]",
    "path_add_list": (
        "p = Path.Path('G1 X1'); p.addCommands(Path.Command('G1 X3'))\n"
        "p.addCommands([Path.Command('G1 X4'), Path.Command('G1 X5')]); result = [repr(p), p.toGCode()]"),
    "path_insert": (
        "out = []\n"
        "for args in ((0,), (), (2,), (-1,)):\n"
        "    p = Path.Path('G1 X1 G1 X2'); p.insertCommand(Path.Command('G1 X9'), *args); out.append(repr(p.Commands))\n"
        "result = out"),
    "path_insert_beyond": "p = Path.Path('G1 X1 G1 X2'); result = p.insertCommand(Path.Command('G1 X9'), 3)",
    "path_insert_below": "p = Path.Path('G1 X1 G1 X2'); result = p.insertCommand(Path.Command('G1 X9'), -2)",
    "path_delete": (
        "out = []\n"
        "for args in ((), (0,), (-1,), (1,)):\n"
        "    p = Path.Path('G1 X1 G1 X2 G1 X3'); p.deleteCommand(*args); out.append(repr(p.Commands))\n"
        "result = out"),
    "path_delete_size": "p = Path.Path('G1 X1 G1 X2 G1 X3'); result = p.deleteCommand(3)",
    "path_delete_far": "p = Path.Path('G1 X1 G1 X2 G1 X3'); result = p.deleteCommand(7)",
    "path_delete_type": "result = Path.Path('G1 X1').deleteCommand('a')",
    "path_commands_are_copies": (
        "p = Path.Path('G1 X1'); p.Commands.append(Path.Command('G0 X5')); c = p.Commands[0]; c.Name = 'G0'\n"
        "result = [repr(p), repr(p.Commands)]"),
    "path_commands_assign": "p = Path.Path('G1 X1'); p.Commands = [Path.Command('G0 X5')]; result = repr(p)",
    "path_bad_list": "result = Path.Path([Path.Command('G1 X1'), 5])",
    "path_bad_arg": "result = Path.Path(5)",
    "path_copy": "p = Path.Path('G1 X1 G0 Y2'); q = p.copy(); q.deleteCommand(); result = [repr(p), repr(q)]",
    "path_empty": "p = Path.Path(); result = [repr(p), p.Length, box(p)]",
    "path_only_m": "p = Path.Path('M3 S100'); result = [p.Length, box(p)]",
    "path_omitted_axes": "p = Path.Path('G0 X1 Y1 G1 X2'); result = [same(p), length(p)]",
    "path_splitting": (
        "result = [repr(Path.Path(t).Commands) for t in "
        "('G1X1G1X2', 'G1 X1 M3 S100', 'N10 G1 X1\\nN20 X2', '(a(b)c) G1 X1', '(unterminated G1 X1', "
        "'G1 X1 (c1) Y2', 'G1 X1 %', '%\\nG1 X1\\n%', 'O100 sub\\nG1 X1', 'G1 X1 ;\\nG1 X2')]"),
    "path_inches": (
        "p = Path.Path('G20 G0 X1 Y1 Z1 I1 J1 R1 F1 Q1 P1 S1 A1 N1 T1 U1 G21 G1 X1')\n"
        "result = [c.Parameters for c in p.Commands]"),
    "path_g91": "p = Path.Path('G91 G0 X1 G0 X1 G0 Y2'); result = [length(p), box(p)]",
    "path_drill": "p = Path.Path('G0 Z5 G81 X1 Y1 Z-1 R1 G80'); result = [length(p), box(p)]",
    "path_peck": "p = Path.Path('G0 Z5 G83 X1 Y1 Z-1 R2 Q0.7 G80'); result = [length(p), box(p)]",
    "path_probe": "p = Path.Path('G0 Z5 G38.2 Z-5 F10 G1 X1'); result = [length(p), box(p)]",
    # -- arcs crossing quadrants and helices: FreeCAD's own (wrong) measures ------------------------
    "arc_half_cw": "p = Path.Path('G0 X1 Y1 G2 X3 Y1 I1 J0'); result = [length(p), box(p)]",
    "arc_full_circle": "p = Path.Path('G2 X0 Y0 I1 J0'); result = [length(p), box(p)]",
    "arc_quarter_ccw": "p = Path.Path('G0 X1 G3 X0 Y1 I-1 J0'); result = [length(p), box(p)]",
    "arc_three_quarters_cw": "p = Path.Path('G0 X1 G2 X0 Y1 I-1 J0'); result = [length(p), box(p)]",
    "arc_crossing_four_quadrants": "p = Path.Path('G0 X10 Y5 G3 X9 Y3 I-5 J0'); result = [length(p), box(p)]",
    "arc_far_from_origin": "p = Path.Path('G0 X100 Y50 G3 X90 Y60 I-10 J0 G2 X80 Y50 I0 J-10'); result = [length(p), box(p)]",
    "arc_xz_plane": "p = Path.Path('G0 X1 Y1 G18 G2 X3 Z0 I1 K0'); result = [length(p), box(p)]",
    "arc_yz_plane": "p = Path.Path('G0 X1 Y1 G19 G3 Y3 Z0 J1 K0'); result = [length(p), box(p)]",
    "helix": "p = Path.Path('G0 X1 Y1 Z1 G2 X3 Y1 Z3 I1 J0'); result = [length(p), box(p)]",
    "helix_full_turns": "p = Path.Path('G0 X5 Y0 Z0 G3 X5 Y0 Z-2 I-5 J0 G3 X5 Y0 Z-4 I-5 J0'); result = [length(p), box(p)]",
    "helix_g91": "p = Path.Path('G0 X1 Y1 Z1 G91 G2 X2 Z2 I1 J0'); result = [length(p), box(p)]",
    "arc_absolute_centre": "p = Path.Path('G0 X1 G90.1 G2 X-1 Y0 I0 J0'); result = [length(p), box(p)]",
    # -- tools and tool tables ----------------------------------------------------------------------
    "tool_default": (
        "t = Path.Tool()\n"
        "result = [repr(t), t.Name, t.ToolType, t.Material, t.Diameter, t.LengthOffset, t.FlatRadius, "
        "t.CornerRadius, t.CuttingEdgeAngle, t.CuttingEdgeHeight]"),
    "tool_seed": (
        "t1 = Path.Tool(); t1.Name = '12.7mm Drill Bit'; r = repr(t1); t1.ToolType = 'Drill'\n"
        "t1.Diameter = 12.7; t1.LengthOffset = 127; t1.CuttingEdgeAngle = 59; t1.CuttingEdgeHeight = 50.8\n"
        "t2 = Path.Tool('my other tool', tooltype='EndMill', diameter=10)\n"
        "result = [r, t1.templateAttrs(), repr(t2), t2.Diameter, t2.ToolType]"),
    "tool_types": "result = [Path.Tool().getToolTypes(), Path.Tool().getToolMaterials()]",
    "tool_content": "result = Path.Tool('a', tooltype='Drill').Content",
    "tool_keywords": "t = Path.Tool(name='x', material='Carbide', cornerRadius=1.5); result = t.templateAttrs()",
    "tool_bad_name": "result = Path.Tool(5)",
    "tooltable_seed": (
        "t1 = Path.Tool('12.7mm Drill Bit', tooltype='Drill', diameter=12.7)\n"
        "t2 = Path.Tool('my other tool', tooltype='EndMill', diameter=10)\n"
        "table = Path.Tooltable(); r0 = repr(table); table.addTools(t1); r1 = repr(table); table.addTools(t2)\n"
        "result = [r0, r1, repr(table), repr(table.Tools)]"),
    "tooltable_numbering": (
        "t = Path.Tooltable(); t.setTool(5, Path.Tool('a')); t.setTool(2, Path.Tool('b')); t.addTools(Path.Tool('c'))\n"
        "t.addTools([Path.Tool('d'), Path.Tool('e')]); result = repr(t.Tools)"),
    "tooltable_get_delete": (
        "t = Path.Tooltable(); t.addTools([Path.Tool('a'), Path.Tool('b')]); g = [repr(t.getTool(1)), t.getTool(9)]\n"
        "t.deleteTool(1); result = g + [repr(t.Tools)]"),
    "tooltable_delete_missing": "t = Path.Tooltable(); t.addTools(Path.Tool('a')); result = t.deleteTool(7)",
    "tooltable_copies": (
        "t = Path.Tooltable(); t.addTools(Path.Tool('a')); t.getTool(1).Name = 'zz'; t.Tools[1].Name = 'zz'\n"
        "result = repr(t.Tools)"),
    "tooltable_template": "t = Path.Tooltable(); t.addTools(Path.Tool('a', diameter=3)); result = t.templateAttrs()",
    "tooltable_content": "t = Path.Tooltable(); t.addTools(Path.Tool('a', diameter=3)); result = t.Content",
}

#: Cases where gcodekit answers differently from FreeCAD 0.20 on purpose, and why (docs/freecad.md).
DIFFERENT: dict[str, str] = {
    "path_insert_below": "FreeCAD 0.20 crashes (a position below -1); gcodekit raises IndexError",
    "path_delete_size": "FreeCAD 0.20 erases past the end (undefined: a double-free abort or corrupted memory); "
                        "gcodekit raises IndexError",
    "command_rounding": "922337203685 overflows FreeCAD's 64-bit arithmetic; gcodekit writes the number",
    "path_inches": "after G20 FreeCAD leaves K unscaled; gcodekit scales it like I and J (here: no K, so the same)",
    "path_splitting": "'G1 X1 ;' keeps FreeCAD's reading; a ';' comment with text is a comment here",
}
