"""The shape of the code: data flows one way (config -> problem -> transcription -> solution -> solve ->
tables/plots -> experiments -> CLI), no import cycle anywhere, and the verifier depends on nothing of designopt."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# Lower layers never import higher ones. Within a layer, modules may import each other (acyclically).
LAYERS = [
    ("designopt.errors", "designopt.kinematics", "designopt.toolpaths", "designopt.design_space",
     "designopt.costs", "designopt.modular", "designopt.verify", "designopt.forces", "designopt.gcode",
     "designopt.clearance"),
    ("designopt.config",),
    ("designopt.problem",),
    ("designopt.transcriptions", "designopt.initial_guess"),
    ("designopt.evaluation", "designopt.solution", "designopt.results_io"),
    ("designopt.solve",),
    ("designopt.tables", "designopt.style", "designopt.plots", "designopt.plots_experiments", "designopt.export",
     "designopt.view"),
    ("designopt.experiments",),
    ("cli",),
]


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def layer(module: str) -> int:
    for i, prefixes in enumerate(LAYERS):
        if any(module == p or module.startswith(p + ".") for p in prefixes):
            return i
    raise AssertionError(f"{module} has no layer: add it to LAYERS")


def imports() -> dict[str, set[str]]:
    """Every project module -> the project modules it imports (top level or inside functions)."""
    graph = {}
    for path in sorted([*ROOT.glob("designopt/**/*.py"), *ROOT.glob("cli/*.py")]):
        name, found = module_name(path), set()
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + [base]).strip(".")
                found.add(base)
                found |= {f"{base}.{a.name}" for a in node.names}
        graph[name] = found
    roots = {"designopt", "cli"}  # the package __init__s hold no code (a version string)
    modules = set(graph) - roots
    return {m: {i for i in deps if i in modules and i != m} for m, deps in graph.items() if m not in roots}


def test_every_import_points_down_the_flow():
    wrong = [f"{m} (layer {layer(m)}) imports {d} (layer {layer(d)})"
             for m, deps in imports().items() for d in deps if layer(d) > layer(m)]
    assert not wrong, "\n".join(wrong)


def test_no_import_cycle():
    graph = imports()
    state: dict[str, int] = {}

    def visit(node, stack):
        state[node] = 1
        for dep in graph[node]:
            if state.get(dep) == 1:
                raise AssertionError("import cycle: " + " -> ".join([*stack, node, dep]))
            if dep not in state:
                visit(dep, [*stack, node])
        state[node] = 2

    for node in graph:
        if node not in state:
            visit(node, [])


def test_the_verifier_stands_alone():
    tree = ast.parse((ROOT / "designopt" / "verify.py").read_text())
    used = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    used |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
    # numpy for kinematics and costs; coal (an independent collision library) for the cell's clearance
    assert used <= {"__future__", "json", "math", "sys", "dataclasses", "pathlib", "numpy", "coal"}, used
