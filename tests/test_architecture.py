"""The package's imports run one way, down the pipeline, and never in a circle.

Every ``import`` in gcodekit, at module level, inside a function or under
``if TYPE_CHECKING:``, is read from the source.  A module may import its own
folder and the stages before it (docs/architecture.md), for types too: a
stage that needs a later stage's object names what it uses in a protocol of
its own.  The one exception is the Operation's convenience methods
(``op.plot()``, ``op.to_vtk()``, ...), which import an output inside the
call.  Type-only imports never run, so they make no import circle.  No
module imports another package's private (``_``) names.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "gcodekit"

#: The stages in order; a module's stage is the longest prefix that names it.
STAGES: list[tuple[str, ...]] = [
    ("gcodekit.errors", "gcodekit.limits", "gcodekit.units", "gcodekit.schema", "gcodekit.memory", "gcodekit.jit",
     "gcodekit.growing", "gcodekit.columns", "gcodekit.lathe_profile", "gcodekit.tool_shapes"),
    ("gcodekit.syntax",),
    ("gcodekit.preprocess",),
    ("gcodekit.read",),
    ("gcodekit.parse",),
    ("gcodekit.emulate",),
    ("gcodekit.plan",),
    ("gcodekit.model",),
    ("gcodekit.analysis", "gcodekit.additive", "gcodekit.export", "gcodekit.view", "gcodekit.visualize",
     "gcodekit.transpile", "gcodekit.cut"),
    ("gcodekit.pipeline",),
    ("gcodekit.report", "gcodekit.widgets", "gcodekit.cli", "gcodekit.testing", "gcodekit.path", "gcodekit"),
]
#: Where an import may reach a later stage: the Operation's convenience methods, lazily, into the outputs.
CONVENIENCE = (("gcodekit.model.operation", "gcodekit.model.processes"), 8)


def modules() -> dict[str, Path]:
    found = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found[name] = path
    return found


def stage_of(module: str) -> int:
    best, rank = -1, -1
    for k, names in enumerate(STAGES):
        for name in names:
            if (module == name or module.startswith(name + ".")) and len(name) > best:
                best, rank = len(name), k
    assert rank >= 0, f"{module} belongs to no stage: add it to STAGES and docs/architecture.md"
    return rank


def _type_checking_only(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def imports(name: str, path: Path, known: dict[str, Path]) -> list[tuple[str, int, bool, bool, str]]:
    """(imported module, line, inside a function, only for type checkers, name imported) of every import."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []

    def visit(node: ast.AST, in_function: bool, typing_only: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking_only(child):
                for other in child.body:
                    visit_one(other, in_function, True)
                for other in child.orelse:
                    visit_one(other, in_function, typing_only)
                continue
            visit_one(child, in_function, typing_only)

    def visit_one(child: ast.AST, in_function: bool, typing_only: bool) -> None:
        inside = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
        if isinstance(child, ast.Import):
            found.extend((a.name, child.lineno, inside, typing_only, "") for a in child.names
                         if a.name.startswith("gcodekit"))
        elif isinstance(child, ast.ImportFrom):
            base = child.module or ""
            if child.level:
                anchor = package.split(".")[: len(package.split(".")) - (child.level - 1)]
                base = ".".join(anchor + ([child.module] if child.module else []))
            if base.startswith("gcodekit"):
                for alias in child.names:
                    target = f"{base}.{alias.name}"
                    found.append((target if target in known else base, child.lineno, inside, typing_only,
                                  "" if target in known else alias.name))
        visit(child, inside, typing_only)

    visit(tree, False, False)
    return found


def edges(*, typing: bool = False) -> list[tuple[str, str, int, bool]]:
    """(importer, imported module, line, inside a function); with ``typing``, type-only imports too."""
    return [(s, t, line, inside) for s, t, line, inside, typing_only, _ in all_imports() if typing or not typing_only]


def all_imports() -> list[tuple[str, str, int, bool, bool, str]]:
    known = modules()
    out = []
    for name, path in sorted(known.items()):
        for target, line, inside, typing_only, imported in imports(name, path, known):
            while target not in known and "." in target:
                target = target.rpartition(".")[0]
            if target != name:
                out.append((name, target, line, inside, typing_only, imported))
    return out


def allowed_upward(source: str, target: str, inside: bool) -> bool:
    return inside and source in CONVENIENCE[0] and stage_of(target) == CONVENIENCE[1]


def test_imports_run_down_the_pipeline():
    wrong = [f"{s}:{line} imports {t} ({'inside a function' if inside else 'module level'}): stage "
             f"{stage_of(s)} reaches stage {stage_of(t)}"
             for s, t, line, inside in edges(typing=True)
             if stage_of(t) > stage_of(s) and not allowed_upward(s, t, inside)]
    assert not wrong, "\n".join(wrong)


def _package(module: str) -> str:
    """The top-level part of gcodekit a module belongs to (``gcodekit.plan``, ``gcodekit.cli``)."""
    return ".".join(module.split(".")[:2])


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_no_private_name_crosses_packages():
    wrong = [f"{s}:{line} imports {t}.{name}"
             for s, t, line, _, _, name in all_imports()
             if (_private(name) or _private(t.rpartition(".")[2]))
             and _package(s) != _package(t)]
    assert not wrong, "private names used from another package:\n" + "\n".join(wrong)


def test_no_import_circles():
    graph: dict[str, set[str]] = {}
    for s, t, _, inside in edges():
        if not allowed_upward(s, t, inside):
            graph.setdefault(s, set()).add(t)
    # a package's __init__ re-exporting its own modules is not a circle of ideas: leave those edges out
    for s in list(graph):
        graph[s] = {t for t in graph[s] if not (t.startswith(s + ".") and (PACKAGE / Path(*s.split(".")[1:]) / "__init__.py").exists())}
    cycles = _cycles(graph)
    assert not cycles, "import circles:\n" + "\n".join(" -> ".join(c) for c in cycles)


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def connect(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in list(graph):
        if v not in index:
            connect(v)
    return found


def test_the_check_sees_function_level_imports():
    """The walker must not miss an import hidden in a function (the kind that once made circles)."""
    found = {(s, t) for s, t, _, inside in edges() if inside}
    assert ("gcodekit.cli", "gcodekit.pipeline") in found


#: Exceptions that are signals between gcodekit's own parts, always caught inside gcodekit and turned into a
#: diagnostic or a GcodeError before a user sees them -- not errors of their own.
SIGNALS = {
    "gcodekit.limits.TooManyMotions": "the stage that made the motions reports it at its line",
    "gcodekit.preprocess.flow.run.Stop": "ends the program counter's run (a program end or a limit)",
    "gcodekit.preprocess.wizards.arguments.BadCall": "becomes a diagnostic at the call's column",
    "gcodekit.pipeline.feedback.MachineStop": "carries the machine's GcodeError through the parameter stage",
    "gcodekit.path.rules._Problem": "becomes a FreeCADFormatError or a diagnostic at its column",
}


def test_every_error_is_rooted_in_gcode_error():
    import importlib
    import inspect

    from gcodekit.errors import GcodeError

    found, wrong = set(), []
    for name in modules():
        module = importlib.import_module(name)
        for cls_name, cls in inspect.getmembers(module, inspect.isclass):
            if cls.__module__ != name or not issubclass(cls, BaseException) or issubclass(cls, Warning):
                continue
            qualified = f"{name}.{cls_name}"
            found.add(qualified)
            if qualified not in SIGNALS and not issubclass(cls, GcodeError):
                wrong.append(f"{qualified} derives from {', '.join(b.__name__ for b in cls.__bases__)}")
    assert not wrong, "errors users can meet must derive from GcodeError:\n" + "\n".join(wrong)
    assert set(SIGNALS) <= found, f"signals that no longer exist: {set(SIGNALS) - found}"


def test_one_import_style_relative_inside_the_package():
    absolute = []
    for name, path in modules().items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "gcodekit":
                absolute.append(f"{name}:{node.lineno} from {node.module} import ...")
            elif isinstance(node, ast.Import):
                absolute += [f"{name}:{node.lineno} import {a.name}" for a in node.names
                             if a.name.split(".")[0] == "gcodekit"]
    assert not absolute, "gcodekit's modules import each other relatively:\n" + "\n".join(absolute)
