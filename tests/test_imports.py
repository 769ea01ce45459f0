"""Imports run one way: no cycle among the package's modules, counting every import
statement anywhere in a file (in functions and under `if TYPE_CHECKING:` too) and every
importlib.import_module("drake_standup...") of a literal name."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "drake_standup"


def _modules() -> dict[str, Path]:
    """Module name -> file, for every module of the package."""
    modules = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    return modules


def _imports(path: Path, name: str, modules: dict[str, Path]) -> set[str]:
    """The package's modules that path's module imports: the module an import names, or
    for `from package import name` the submodule package.name where there is one. A
    module's own package is not counted (Python imports it first, whatever the file
    says)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        targets = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from its package
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1])
                base = f"{base}.{node.module}" if node.module else base
            targets = [f"{base}.{alias.name}" for alias in node.names] + [base]
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "import_module":
            targets = [arg.value for arg in node.args if isinstance(arg, ast.Constant)]
        for target in targets:
            # The deepest module of the package that the dotted name starts with.
            while target and target not in modules:
                target = target.rpartition(".")[0]
            if target and not name.startswith(target + ".") and target != name:
                found.add(target)
    return found


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: _imports(path, name, modules) for name, path in modules.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
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

    for v in graph:
        if v not in index:
            visit(v)
    return found


def test_the_package_has_no_import_cycle():
    assert _cycles(_graph()) == []


def test_the_check_sees_every_kind_of_import(tmp_path, monkeypatch):
    """A cycle made only of a function-level import, a TYPE_CHECKING import or an
    import_module call is found (the test above cannot pass by missing them)."""
    package = tmp_path / "drake_standup"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "sub" / "__init__.py").write_text("")
    (package / "a.py").write_text("def f():\n    from drake_standup import b\n")
    (package / "b.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n"
        "    from drake_standup.sub.c import x\n"
    )
    (package / "sub" / "c.py").write_text(
        "import importlib\nimportlib.import_module('drake_standup.a')\n"
    )
    monkeypatch.setattr(__import__(__name__), "PACKAGE", package)
    assert _cycles(_graph()) == [["drake_standup.a", "drake_standup.b", "drake_standup.sub.c"]]


@pytest.mark.parametrize(
    "low, high",
    [
        ("drake_standup.config", "drake_standup.sim.diagram"),
        ("drake_standup.config.phases", "drake_standup.standup.state_machine"),
        ("drake_standup.control.controller", "drake_standup.sim.runner"),
        ("drake_standup.sim.runner", "drake_standup.sim.live"),
        ("drake_standup.config.arguments", "drake_standup.cli"),
    ],
)
def test_layers_import_downward_only(low, high):
    """Data flows config -> model -> systems -> diagram -> runner -> entry points: a lower
    layer reaches no higher one, directly or through others."""
    graph = _graph()
    reached, todo = set(), [low]
    while todo:
        for module in graph[todo.pop()]:
            if module not in reached:
                reached.add(module)
                todo.append(module)
    assert high not in reached
