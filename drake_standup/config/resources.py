"""The files the package ships: the robot's contact pads, chair and floor (models/), the
scenarios (scenarios/), the sweeps (sweeps/) and the recorded helpers' files (recordings/).

In the repository they are top-level folders; a wheel carries them inside the package as
drake_standup/data/<folder> (setup.py). Both are read here, through importlib.resources,
so no module assumes the current directory or a checkout.
"""

from __future__ import annotations

import importlib.resources
import re
from pathlib import Path

FOLDERS = ("models", "scenarios", "sweeps", "recordings")


def data_root() -> Path:
    """The folder holding models/, scenarios/, sweeps/ and recordings/: the installed
    package's data/, or, run from a checkout (editable install or PYTHONPATH), the
    repository's root."""
    package = Path(str(importlib.resources.files("drake_standup")))
    installed = package / "data"
    return installed if installed.is_dir() else package.parent


def shipped(folder: str) -> dict[str, Path]:
    """The shipped YAML files of one folder (scenarios or sweeps), by name (file stem)."""
    return {p.stem: p for p in sorted((data_root() / folder).glob("*.yaml"))}


def own_or_shipped(name: str) -> Path:
    """A file a scenario names (chair.file, human.recorded.file): the user's own (absolute,
    or relative to the current folder), else the shipped one of that path under the data
    root (models/chair.sdf, recordings/default_pull.csv), else the name as given (its
    check then says it is missing)."""
    own, shipped = Path(name), data_root() / name
    return shipped if not own.is_absolute() and not own.exists() and shipped.is_file() else own


def model_file(name: str) -> Path:
    """A shipped model file, e.g. model_file('chair.sdf')."""
    return data_root() / "models" / name


def find(folder: str, name: str | Path, *also: Path) -> Path | None:
    """A file a user names: a path (as given, else in one of the folders `also`, else
    relative to the data root, e.g. scenarios/assisted.yaml) or the name of a shipped file
    of folder (e.g. 'assisted'); None if none of these is a file."""
    name = str(name)
    candidates = [Path(name), *(d / name for d in also), data_root() / name]
    candidates.append(data_root() / folder / f"{name}.yaml")
    return next((p for p in candidates if p.is_file()), None)


def description(path: Path) -> str:
    """A shipped file's one-line description: the first sentence of its leading comment."""
    comment = []
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            break
        comment.append(line.lstrip("#").strip())
    text = " ".join(part for part in comment if part)
    match = re.match(r"(.+?[.?])(\s|$)", text)
    return match.group(1) if match else text
