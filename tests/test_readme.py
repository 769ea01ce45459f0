"""The README stays short and its table from the paper's equations to the code stays true:
every file it names exists and defines every function or class named beside it."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README_LINE_LIMIT = 300


def _table() -> list[str]:
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Where the paper is in the code") :]
    return [line for line in section.split("\n\n")[1].splitlines() if line.startswith("| ")][1:]


def _named(cell: str) -> list[tuple[str, list[str]]]:
    """(file, names) for each `DIR/FILE.py` in cell and the `names` after it (up to the next
    file)."""
    found, current = [], None
    for token in re.findall(r"`([^`]+)`", cell):
        if token.endswith(".py"):
            current = (token, [])
            found.append(current)
        elif current is not None:
            current[1].append(token)
    return found


def _defined(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    return {
        node.name
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef | ast.ClassDef | ast.AsyncFunctionDef)
    }


def test_the_readme_is_short():
    assert len((ROOT / "README.md").read_text().splitlines()) <= README_LINE_LIMIT


def test_the_equation_table_names_code_that_exists():
    rows = _table()
    assert len(rows) == 5  # reference, update law, helpful interaction, objective, QP
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        named = _named(cells[-1])
        assert named, row
        for file, names in named:
            path = ROOT / "drake_standup" / file
            assert path.is_file(), file
            missing = set(names) - _defined(path)
            assert not missing, (file, missing)


def test_the_table_check_sees_a_missing_name(tmp_path):
    module = tmp_path / "m.py"
    module.write_text("def law():\n    pass\n")
    assert _named("`m.py`: `law`, `gone`") == [("m.py", ["law", "gone"])]
    assert {"law", "gone"} - _defined(module) == {"gone"}
