"""The Meshcat recording as a standalone HTML, and the system diagram as DOT and SVG."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from pydrake.geometry import Meshcat
from pydrake.systems.framework import Diagram


def write_recording(meshcat: Meshcat, path: Path) -> int:
    """Saves Meshcat's self-contained HTML (scene + recording); returns bytes."""
    html = meshcat.StaticHtml()
    path.write_text(html)
    return len(html.encode())


def export_diagram(diagram: Diagram, directory: Path, stem: str = "standup") -> list[Path]:
    """Writes <stem>.dot and, where graphviz's dot exists, <stem>.svg."""
    directory.mkdir(parents=True, exist_ok=True)
    dot_path = directory / f"{stem}.dot"
    # Two levels: the station's and the stand-up controller's systems inside their boxes.
    dot_path.write_text(diagram.GetGraphvizString(max_depth=2))
    written = [dot_path]
    dot = shutil.which("dot")
    if dot is None:
        print(
            f"notice: graphviz 'dot' not found; wrote {dot_path} only "
            "(apt-get install graphviz, then: dot -Tsvg -O " + str(dot_path) + ")"
        )
        return written
    svg_path = directory / f"{stem}.svg"
    subprocess.run([dot, "-Tsvg", str(dot_path), "-o", str(svg_path)], check=True)
    written.append(svg_path)
    return written
