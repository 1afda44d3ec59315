"""Emulate stage: the registry of modal handlers, and handlers run on a machine's parts without a machine."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import gcodekit
from gcodekit.emulate.handlers import HANDLERS, Block, Context, handles
from gcodekit.emulate.modal import route
from gcodekit.emulate.presets import load_machine
from gcodekit.emulate.state import MachineState
from gcodekit.emulate.tooltable import ToolTable
from gcodekit.errors import Diagnostics
from gcodekit.limits import MotionBudget

EMULATE = Path(gcodekit.__file__).parent / "emulate"


def _context(warned: list[str]) -> Context:
    """The parts of a LinuxCNC machine, with no Machine around them."""
    return Context(MachineState(), load_machine("linuxcnc"), Diagnostics(), ToolTable(), MotionBudget(),
                   lambda key, line, message: warned.append(key))


def _run(ctx: Context, text: str) -> list:
    """Run every block of ``text`` through its handler; the outcomes of those that moved."""
    table = gcodekit.gcode_to_operation(text, "linuxcnc", plan=False).table
    outcomes = []
    for row in range(len(table)):
        block = Block(table, row, table.command(row))
        handler = HANDLERS.get(route(block, ctx))
        if handler is not None:
            outcomes.append(handler(ctx, block))
    return [o for o in outcomes if o is not None]


def test_handlers_need_only_the_machine_parts():
    warned: list[str] = []
    ctx = _context(warned)
    ctx.state.position[:3] = (10.0, 4.0, 0.0)
    # G20 then G92 X0: the point X10 mm reads 0, so the G92 offset is 10 mm in X; Y keeps no offset
    assert _run(ctx, "G20\nG92 X0\n") == []
    assert ctx.state.units == 25.4
    assert ctx.state.g92[:3].tolist() == [10.0, 0.0, 0.0]
    # G28 X0.5 (inches) passes X 0.5 in = 12.7 mm in program coordinates, machine 22.7, then X goes
    # to the stored home (machine 0); Y, without a word, stays
    (home,) = _run(ctx, "G20\nG28 X0.5\n")
    assert home.passed[0].values["x"] == pytest.approx(22.7)
    assert ctx.state.position[:2].tolist() == pytest.approx([0.0, 4.0])
    # T5, T6 with no tool table: the handler asks for the warning (the context's warn_once says it once)
    _run(ctx, "T5\nT6\n")
    assert ctx.state.selected_tool == 6 and set(warned) == {"no tool table"}


def test_a_key_has_one_handler():
    units = HANDLERS["units_inch"]
    assert "linear" not in HANDLERS  # plain moves run in runs, not one at a time
    with pytest.raises(ValueError, match="'units_inch' already has a handler"):
        handles("linear", "units_inch")(lambda ctx, block: None)
    with pytest.raises(ValueError, match="'units_imch' is neither a command name nor a mode key"):
        handles("linear", "units_imch")(lambda ctx, block: None)
    # refused registrations leave the registry as it was
    assert HANDLERS["units_inch"] is units and "linear" not in HANDLERS and "units_imch" not in HANDLERS


def _imports(path: Path) -> set[str]:
    """Modules ``path`` imports, anywhere in it (functions and TYPE_CHECKING blocks too), resolved."""
    package = "gcodekit." + ".".join(path.relative_to(EMULATE.parent).with_suffix("").parts[:-1])
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package.rsplit(".", node.level - 1)[0] if node.level else ""
            module = ".".join(part for part in (base, node.module) if part)
            found |= {module} | {f"{module}.{alias.name}" for alias in node.names}
    return found


def test_the_dispatcher_and_handlers_never_import_the_machine():
    paths = [EMULATE / "modal.py", *sorted((EMULATE / "handlers").glob("*.py"))]
    assert len(paths) > 5
    for path in paths:
        assert "gcodekit.emulate.machine" not in _imports(path), path
