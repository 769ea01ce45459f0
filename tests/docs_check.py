"""What the tests check the docs against (imported by the tests, not collected)."""

from __future__ import annotations

import re
from pathlib import Path

OUTPUTS_MD = Path(__file__).resolve().parent.parent / "docs" / "outputs.md"


def metrics_section(text: str | None = None) -> str:
    """docs/outputs.md's "## metrics.json" section."""
    text = OUTPUTS_MD.read_text() if text is None else text
    start = text.index("\n## metrics.json")
    end = text.find("\n## ", start + 1)
    return text[start : end if end >= 0 else len(text)]


def undocumented_metrics(metrics: dict, section: str | None = None) -> list[str]:
    """The keys of a run's metrics.json that the section does not name as `key`."""
    section = metrics_section() if section is None else section
    return sorted(key for key in metrics if f"`{key}`" not in section)


REPO = Path(__file__).resolve().parent.parent
PACKAGE = REPO / "drake_standup"
# Markdown documents: the README, CHANGELOG and docs/ (the generated campaign tables under
# docs/*/ included).
DOCUMENTS = [REPO / "README.md", REPO / "CHANGELOG.md", *sorted((REPO / "docs").rglob("*.md"))]

_FENCE = re.compile(r"```.*?```", re.S)
_LINK = re.compile(r"\]\(([^)\s]+)\)")
# A repository path as a doc or docstring writes it: folders, a name, a known suffix.
_PATH = re.compile(
    r"(?<![\w./-])((?:[\w.-]+/)+[\w.-]+\.(?:py|md|yaml|json|npz|png|html|csv|toml|dot|svg))\b"
)
_HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*$", re.M)


def slug(heading: str) -> str:
    """GitHub's anchor of a Markdown heading."""
    text = re.sub(r"[`*_]|\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The anchors of a Markdown file's headings (repeated ones get -1, -2, ...)."""
    seen: dict[str, int] = {}
    found = set()
    for heading in _HEADING.findall(_FENCE.sub("", path.read_text())):
        base = slug(heading)
        n = seen.get(base, 0)
        seen[base] = n + 1
        found.add(base if n == 0 else f"{base}-{n}")
    return found


def broken_links(doc: Path, text: str | None = None) -> list[str]:
    """Relative links of doc (file and #anchor) that lead nowhere."""
    text = _FENCE.sub("", doc.read_text() if text is None else text)
    broken = []
    for target in _LINK.findall(text):
        if re.match(r"[a-z]+:", target):  # http:, mailto:
            continue
        file, _, anchor = target.partition("#")
        path = (doc.parent / file).resolve() if file else doc
        if not path.exists():
            broken.append(target)
        elif anchor and path.suffix == ".md" and anchor not in anchors(path):
            broken.append(target)
    return broken


def _exists(name: str, near: Path) -> bool:
    """Whether a path a text names exists: from the repository, the package, or the
    naming file's folder (and, for a package-relative name, any layer of it)."""
    for base in (REPO, PACKAGE, near.parent, REPO / "docs"):
        if (base / name).exists():
            return True
    return False


def prose(path: Path) -> str:
    """What a file says to its reader: a Python file's docstrings and comments (its string
    literals are data: a test may name a file that must not exist), any other's text."""
    import ast
    import io
    import tokenize

    text = path.read_text()
    if path.suffix == ".toml":  # its [sections] are syntax: the comments only
        return "\n".join(line for line in text.splitlines() if line.lstrip().startswith("#"))
    if path.suffix != ".py":
        return text
    parts = [
        ast.get_docstring(node, clean=False) or ""
        for node in ast.walk(ast.parse(text))
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
    ]
    parts += [
        tok.string
        for tok in tokenize.generate_tokens(io.StringIO(text).readline)
        if tok.type == tokenize.COMMENT
    ]
    return "\n".join(parts)


def missing_paths(path: Path, text: str | None = None) -> list[str]:
    """Repository paths a doc or a source file names (a/b.py, docs/x.md, ...) that do not
    exist. Paths under out/, a run's folder, or a user's DIR are outputs, not files of
    the repository."""
    text = prose(path) if text is None else text
    missing = []
    for name in _PATH.findall(text):
        parts = name.split("/")
        # Outputs (out/, a user's DIR) and placeholders (scenarios/NAME.yaml).
        if (
            parts[0] in ("out", "tmp")
            or "*" in name
            or any(p.split(".")[0].isupper() for p in parts)
        ):
            continue
        if not _exists(name, path):
            missing.append(name)
    return sorted(set(missing))


_BARE_FILE = re.compile(r"(?<![\w./-])([A-Za-z_]\w*\.py)\b")
# `module.name` or `module.Class.name` in backticks (docs), or a module-qualified name in
# a docstring or comment: module is one of the package's modules, by its file's name.
_QUALIFIED = re.compile(r"(?<![\w.])([a-z_][a-z0-9_]*)\.([A-Za-z_]\w*)(?:\.([A-Za-z_]\w*))?")
_SUFFIXES = {
    "py",
    "md",
    "yaml",
    "json",
    "npz",
    "png",
    "html",
    "csv",
    "sdf",
    "obj",
    "stl",
    "dot",
    "svg",
}
# The scenario's sections (config.Scenario's fields): `section.key` is a key.
_SECTIONS = {
    "robot",
    "plant",
    "simulator",
    "human",
    "compliance",
    "advancement",
    "standup",
    "phases",
    "controller",
    "initial",
    "chair",
    "fall",
    "perturbation",
    "visualization",
    "seat_hold",
    "hardware",
}
_PLACEHOLDERS = {"NAME", "nope", "a/b.py", "dir/file.py", "docs/x.md"}


def _files_by_name() -> dict[str, list[Path]]:
    found: dict[str, list[Path]] = {}
    for path in REPO.rglob("*.py"):
        if not {".git", ".venv", "venv", "build"} & set(path.parts):
            found.setdefault(path.name, []).append(path)
    return found


def _defined(path: Path) -> dict[str, set[str]]:
    """A module's top-level names, and each class's own names (key: the class)."""
    import ast

    tree = ast.parse(path.read_text())
    names: dict[str, set[str]] = {"": set()}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names[""].add(node.name)
            if isinstance(node, ast.ClassDef):
                names[node.name] = {
                    n.name
                    for n in ast.walk(node)
                    if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)
                } | {
                    t.id
                    for n in node.body
                    if isinstance(n, ast.Assign | ast.AnnAssign)
                    for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
                    if isinstance(t, ast.Name)
                }
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                for name in ast.walk(target):
                    if isinstance(name, ast.Name):
                        names[""].add(name.id)
        elif isinstance(node, ast.ImportFrom | ast.Import):
            names[""].update((a.asname or a.name).split(".")[0] for a in node.names)
    return names


# Module names more than one file of the package has, and __init__: not resolvable by name.
_AMBIGUOUS = {"__init__", "__main__", "cli", "controller", "body", "chair", "figures", "hardware"}


def missing_names(
    path: Path, text: str | None = None, backticked_only: bool = False, qualified: bool = True
) -> list[str]:
    """Files named bare (reference.py) that exist nowhere in the repository, and
    module.name references to one of the package's modules that name nothing in it."""
    text = prose(path) if text is None else text
    if backticked_only:
        text = " ".join(re.findall(r"`([^`\n]+)`", _FENCE.sub("", text)))
    files = _files_by_name()
    modules = {p.stem: p for p in PACKAGE.rglob("*.py") if p.stem not in _AMBIGUOUS}
    missing = [f for f in _BARE_FILE.findall(text) if f not in files and f not in _PLACEHOLDERS]
    for module, name, member in _QUALIFIED.findall(text) if qualified else ():
        # A scenario key (chair.seat_height_m) or an output file (metrics.json) is no
        # module's name.
        if module not in modules or module in _SECTIONS or name in _SUFFIXES:
            continue
        defined = _defined(modules[module])
        if name in modules and modules[name].parent.name == module:  # package.module
            continue
        if name not in defined[""]:
            missing.append(f"{module}.{name}")
        elif member and name in defined and member not in defined[name]:
            missing.append(f"{module}.{name}.{member}")
    if backticked_only and qualified:  # a doc's code spans: every dotted name resolves
        missing += _unresolved_dotted(text, modules)
    return sorted(set(missing))


# Heads of dotted names in a doc that are not the package's: libraries, the scenario's
# subsections (human.reactive, phases.*.exit).
_FOREIGN = {"numpy", "np", "json", "icub_models", "importlib", "pyproject", "pydrake"}
# A user's own package in docs/extending.md's walk-through, and a plug-in class's self.
_FOREIGN |= {"mylab", "self"}
# The plug-ins' entry point groups (config/plugins.py ENTRY_POINT_GROUP): names, no modules.
_ENTRY_POINT_GROUPS = {
    "drake_standup.laws",
    "drake_standup.helpers",
    "drake_standup.chairs",
    "drake_standup.responses",
}
_SUBSECTIONS = {"reactive", "exit", "body", "pulls", "advance", "seated", "forward"}
_DOTTED = re.compile(r"(?<![\w.])([a-z_][a-z0-9_]*(?:\.[A-Za-z_]\w*)+)")


def _unresolved_dotted(text: str, modules: dict[str, Path]) -> list[str]:
    """Dotted names whose head is neither one of the package's modules (by file name) nor
    a layer, a scenario section or a library: a module that moved or went
    (references.static_lean); and drake_standup.a.b[.name] that leads to no module or
    name."""
    layers = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    missing = []
    for dotted in _DOTTED.findall(text):
        head, *rest = dotted.split(".")
        if rest and rest[0] in _SUFFIXES:
            continue
        if dotted in _ENTRY_POINT_GROUPS:
            continue
        if head == "drake_standup":
            path = PACKAGE
            while rest and ((path / rest[0]).is_dir() or (path / f"{rest[0]}.py").exists()):
                path = path / rest.pop(0)
            module = path / "__init__.py" if path.is_dir() else path.with_suffix(".py")
            if rest and rest[0] not in _defined(module)[""] and module.exists():
                missing.append(dotted)
            continue
        known = modules.keys() | layers | _SECTIONS | _FOREIGN | _SUBSECTIONS | _AMBIGUOUS
        if head not in known:
            missing.append(dotted)
    return missing


# A section cited by its heading: docs/design.md, "The sole's heel landing" (also across a
# line break and a comment's #).
_SECTION = re.compile(r"((?:[\w.-]+/)*[\w.-]+\.md),?\s*(?:section\s+)?\"([A-Za-z`][^\"]{2,80})\"")


def missing_sections(path: Path, text: str | None = None) -> list[str]:
    """Sections a text cites by their heading ("file.md, "Heading"") that its file does
    not have: the heading, or one that begins with it."""
    text = prose(path) if text is None else text
    text = re.sub(r"\n\s*#\s*", " ", text)  # a citation folded over comment lines
    missing = []
    for name, heading in _SECTION.findall(re.sub(r"\s+", " ", text)):
        doc = next(
            (b / name for b in (REPO, REPO / "docs", path.parent) if (b / name).exists()), None
        )
        if doc is None:
            missing.append(f"{name}: the file")
            continue
        headings = [h.strip().lower() for h in _HEADING.findall(_FENCE.sub("", doc.read_text()))]
        wanted = heading.strip().lower().rstrip(".")
        if not any(h == wanted or h.startswith(wanted) for h in headings):
            missing.append(f'{name}, "{heading}"')
    return sorted(set(missing))


_COMMIT = re.compile(r"(?<![\w/.#-])([0-9a-f]{7,12})(?![\w/-])")


def named_commits(text: str) -> set[str]:
    """Abbreviated commit hashes a doc names (hex words of 7-12 characters with a letter
    and a digit)."""
    return {h for h in _COMMIT.findall(text) if re.search(r"[a-f]", h) and re.search(r"\d", h)}


def missing_commits(hashes: set[str]) -> list[str]:
    """The hashes that name no commit of the repository's history."""
    import subprocess

    if not hashes:
        return []
    done = subprocess.run(
        ["git", "-C", str(REPO), "cat-file", "--batch-check"],
        input="".join(f"{h}^{{commit}}\n" for h in sorted(hashes)),
        capture_output=True,
        text=True,
        check=True,
    )
    return sorted(
        line.split()[0].removesuffix("^{commit}")
        for line in done.stdout.splitlines()
        if line.endswith("missing") or "ambiguous" in line
    )


REFERENCES_MD = REPO / "docs" / "references.md"
# A citation of an entry of docs/references.md: [authors-code], [nava2016].
_CITATION = re.compile(r"\[([a-z][a-z0-9]*(?:-[a-z0-9]+)+|[a-z]+\d{4})\](?!\()")


def reference_keys(text: str | None = None) -> set[str]:
    """The entries of docs/references.md (each opens with **[key]**)."""
    text = REFERENCES_MD.read_text() if text is None else text
    return set(re.findall(r"^\*\*\[([^\]]+)\]\*\*", text, re.M))


def unknown_citations(path: Path, text: str | None = None) -> list[str]:
    """[key] citations in a file's prose that docs/references.md has no entry for."""
    text = prose(path) if text is None else text
    return sorted(set(_CITATION.findall(text)) - reference_keys())


def outside_citations(path: Path, text: str | None = None) -> list[str]:
    """Citations of the team's brief outside the repository (SPEC 3, SPEC section 9,
    "SPEC:", ../shared/): a reader cannot follow them. SPEC as a word in capitals is the
    brief whatever follows it."""
    text = prose(path) if text is None else text
    return re.findall(r"\bSPEC\b(?:\s+section)?(?:\s+\d+)?|\.\./shared/\S*", text)


def scenario_block(document: Path, section: str) -> str:
    """The first ```yaml block after a document's section heading."""
    text = document.read_text()
    return text[text.index(section) :].split("```yaml\n", 1)[1].split("```", 1)[0]


def not_defaults(block: str, defaults) -> list[str]:
    """The block's values that are not the defaults' (a Scenario): key path, the block's
    value, the default. Entries of a list (pulls, pushes) are examples and not compared."""
    import dataclasses

    import yaml

    found = []

    def walk(node, default, path: str) -> None:
        if isinstance(node, dict):
            for key, value in node.items():
                sub = default.get(key) if isinstance(default, dict) else getattr(default, key)
                walk(value, sub, f"{path}.{key}" if path else key)
        elif isinstance(node, list) and any(isinstance(v, dict) for v in node):
            return
        else:
            value = list(default) if isinstance(default, tuple) else default
            assert not dataclasses.is_dataclass(value), path
            if node != value:
                found.append(f"{path}: {node!r}, default {value!r}")

    walk(yaml.safe_load(block), defaults, "")
    return found
