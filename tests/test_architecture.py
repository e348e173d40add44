"""The package's layers, read from its source (AST): nothing imports upwards, model packages import only the
contract and the foundation beneath it, and no modules import each other in a circle.

Imports inside functions count as much as those at the top of a module: an import deferred into a function
still ties the two modules together (docs/architecture.md, "Layers").
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import clutchlab

ROOT = Path(clutchlab.__file__).parent

#: the layers from the ground up; a module may import its own layer and those below it.  A top-level module
#: or sub-package of clutchlab is named by its first name after ``clutchlab`` (``"clutchlab"``: the package's
#: face, ``clutchlab/__init__.py``)
LAYERS = (
    ("foundation", {"errors", "_limits", "_compile_notice", "_process", "_cache", "units", "numerics", "result", "curves", "plotting"}),
    ("contract", {"clutchlab", "system", "component", "trim", "io", "params", "hysteresis", "friction"}),
    ("models", {"eclutch", "wet", "emtc"}),
    ("composition", {"driveline"}),
    ("built on the contract", {"fmu", "sweep", "control"}),
    ("presentation", {"report"}),
    ("applications", {"cli", "demo", "warmup", "__main__"}),
)
#: layers whose packages stand side by side: none of them imports another
PEERS = ("models", "built on the contract")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def package_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "clutchlab"


def read_imports():
    """``{module: {imported module: first line}}`` of every clutchlab module, imports in functions included."""
    modules = {module_name(p): p for p in ROOT.rglob("*.py")}
    graph: dict[str, dict[str, int]] = {}
    for name, path in modules.items():
        is_package = path.name == "__init__.py"
        edges = graph.setdefault(name, {})
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".") if is_package else name.split(".")[:-1]
                    base = base[:len(base) - (node.level - 1)]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                # ``from clutchlab.x import y`` imports the module x.y where y is one, else x
                subs = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in modules]
                targets = subs if len(subs) == len(node.names) else subs + [target]
            for target in targets:
                while target and target not in modules and "." in target:
                    target = target.rsplit(".", 1)[0]  # ``import clutchlab.wet.system`` -> the module
                if target in modules and target != name and target.split(".")[0] == "clutchlab":
                    edges.setdefault(target, node.lineno)
    return modules, graph


MODULES, GRAPH = read_imports()
LAYER_OF = {pkg: i for i, (_, pkgs) in enumerate(LAYERS) for pkg in pkgs}


def test_every_package_has_a_layer():
    """A new top-level module or package must be given its place (LAYERS above, docs/architecture.md)."""
    missing = sorted({package_of(m) for m in MODULES} - set(LAYER_OF))
    assert not missing, f"no layer for {missing}: add them to LAYERS and to docs/architecture.md"


def _where(module, target):
    return f"{MODULES[module].relative_to(ROOT.parent)}:{GRAPH[module][target]} imports {target}"


def test_nothing_imports_upwards():
    upward = []
    for module, edges in GRAPH.items():
        here = LAYER_OF.get(package_of(module))
        for target in edges:
            there = LAYER_OF.get(package_of(target))
            if here is not None and there is not None and there > here:
                upward.append(f"{_where(module, target)} ({LAYERS[here][0]} -> {LAYERS[there][0]})")
    assert not upward, "imports that run back up:\n" + "\n".join(sorted(upward))


def test_peer_packages_do_not_import_each_other():
    crossing = []
    for module, edges in GRAPH.items():
        a = package_of(module)
        for target in edges:
            b = package_of(target)
            if a != b and LAYER_OF.get(a) == LAYER_OF.get(b) and LAYERS[LAYER_OF[a]][0] in PEERS:
                crossing.append(_where(module, target))
    assert not crossing, "peer packages importing each other:\n" + "\n".join(sorted(crossing))


@pytest.mark.parametrize("package", sorted(LAYERS[2][1]))
def test_a_model_package_imports_only_the_contract_and_the_foundation(package):
    """The issue's rule: numerics, system, friction, params, io, units, curves, hysteresis (and the foundation's
    errors, limits, result type and the contract's operating points) -- never drivelines, FMUs, sweeps, control,
    reports or the command line."""
    allowed = LAYERS[0][1] | LAYERS[1][1] | {package}
    bad = [_where(m, t) for m, edges in GRAPH.items() if package_of(m) == package
           for t in edges if package_of(t) not in allowed]
    assert not bad, "\n".join(sorted(bad))


def _circles(graph):
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(graph.get(w, ()))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_circles():
    circles = _circles(GRAPH)
    lines = []
    for comp in circles:
        ties = [_where(m, t) for m in comp for t in GRAPH[m] if t in comp]
        lines.append(" <-> ".join(comp) + "\n    " + "\n    ".join(ties))
    assert not circles, "modules importing each other:\n" + "\n".join(lines)


def test_the_checks_see_a_circle_and_an_upward_import():
    """The walk itself: a circle and an upward import written into a copy of the graph are found."""
    graph = {m: dict(e) for m, e in GRAPH.items()}
    graph["clutchlab.system"]["clutchlab.wet.system"] = 1
    graph["clutchlab.wet.system"]["clutchlab.system"] = 1
    assert any({"clutchlab.system", "clutchlab.wet.system"} <= set(c) for c in _circles(graph))
    assert LAYER_OF[package_of("clutchlab.wet.system")] > LAYER_OF[package_of("clutchlab.system")]
    # the parser resolves relative imports inside functions
    assert "clutchlab.system" in GRAPH["clutchlab.wet.engagement"]
