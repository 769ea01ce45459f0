"""Imports run one way, and the package stays readable: no cycle among the package's
modules, counting every import statement anywhere in a file (in functions and under
`if TYPE_CHECKING:` too) and every importlib.import_module("drake_standup...") of a
literal name; the sub-packages are layers that import only downward; modules and
functions stay short."""

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


# The package's layers, lowest first: a module imports only from its own layer or lower
# ones (docs/design.md, "Layout"). The top-level modules (cli, __main__) sit above all.
LAYERS = (
    "ports",
    "config",
    "robot",
    "helper",
    "world",
    "senses",
    "control",
    "standup",
    "outputs",
    "sim",
    "studies",
)
TOP_LEVEL_LIMIT = 12  # modules at the package's top, __init__ included
MODULE_LINE_LIMIT = 450
FUNCTION_LINE_LIMIT = 80
POSITIONAL_LIMIT = 6  # a function's positional parameters (self aside); more go by keyword


def _layer(module: str) -> int:
    """module's layer index; the package's own top-level modules are above every layer."""
    parts = module.split(".")
    if len(parts) > 1 and parts[1] in LAYERS:
        return LAYERS.index(parts[1])
    if len(parts) > 2 or (len(parts) == 2 and (PACKAGE / parts[1]).is_dir()):
        raise AssertionError(f"{module}: in no layer of LAYERS")
    return len(LAYERS)


def _upward_imports(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    return sorted(
        (module, target)
        for module, targets in graph.items()
        for target in targets
        if _layer(target) > _layer(module)
    )


def test_every_sub_package_is_a_layer():
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    assert packages == set(LAYERS)


def test_layers_import_downward_only():
    """For every pair of layers, the lower one reaches nothing of the higher one."""
    assert _upward_imports(_graph()) == []


@pytest.mark.parametrize(
    "low, high",
    [(low, high) for i, low in enumerate(LAYERS) for high in LAYERS[i + 1 :]],
)
def test_no_layer_reaches_a_higher_one_through_others(low, high):
    """Transitively too: nothing in low reaches high through a chain of imports."""
    graph = _graph()
    todo = [m for m in graph if _layer(m) == LAYERS.index(low)]
    reached = set(todo)
    while todo:
        for module in graph[todo.pop()]:
            if module not in reached:
                reached.add(module)
                todo.append(module)
    assert not [m for m in reached if _layer(m) == LAYERS.index(high)]


def test_the_layer_check_finds_an_upward_import():
    graph = {
        "drake_standup.config.a": {"drake_standup.sim.b"},
        "drake_standup.sim.b": {"drake_standup.config.a"},
    }
    assert _upward_imports(graph) == [("drake_standup.config.a", "drake_standup.sim.b")]


def test_the_package_top_holds_few_modules():
    assert len(list(PACKAGE.glob("*.py"))) <= TOP_LEVEL_LIMIT


def _long_functions(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            lines = node.end_lineno - node.lineno + 1
            if lines > FUNCTION_LINE_LIMIT:
                found.append(f"{path.name}:{node.name} {lines}")
    return found


def test_no_module_or_function_is_too_long():
    modules = _modules().values()
    long_modules = [
        f"{p.relative_to(PACKAGE)} {n}"
        for p in modules
        if (n := len(p.read_text().splitlines())) > MODULE_LINE_LIMIT
    ]
    long_functions = [f for p in modules for f in _long_functions(p)]
    assert (long_modules, long_functions) == ([], [])


def test_the_length_check_counts_a_long_function(tmp_path):
    path = tmp_path / "m.py"
    body = "\n".join(f"    x{i} = {i}" for i in range(FUNCTION_LINE_LIMIT))
    path.write_text(f"def f():\n{body}\n")
    assert _long_functions(path) == [f"m.py:f {FUNCTION_LINE_LIMIT + 1}"]


def _wide_functions(path: Path) -> list[str]:
    """Functions taking more than POSITIONAL_LIMIT positional parameters (self and cls
    aside; keyword-only ones are named at every call)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            positional = [a.arg for a in node.args.posonlyargs + node.args.args]
            if positional[:1] in (["self"], ["cls"]):
                positional = positional[1:]
            if len(positional) > POSITIONAL_LIMIT:
                found.append(f"{path.name}:{node.name} {len(positional)}")
    return found


def test_no_function_takes_more_than_six_positional_parameters():
    assert [f for p in sorted(PACKAGE.rglob("*.py")) for f in _wide_functions(p)] == []


def test_the_width_check_finds_a_wide_function(tmp_path):
    wide = tmp_path / "wide.py"
    wide.write_text(
        "def f(a, b, c, d, e, f, g):\n    pass\n\n\n"
        "def h(self, a, b, c, d, e, f, *, g):\n    pass\n"
    )
    assert _wide_functions(wide) == ["wide.py:f 7"]
