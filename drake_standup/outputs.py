"""What a run leaves behind: metrics, the Meshcat HTML, the system diagram."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.framework import Diagram


def write_metrics(path: Path, metrics: dict) -> None:
    """JSON with non-finite numbers written as null (JSON has no NaN)."""

    def clean(x):
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple, np.ndarray)):
            return [clean(v) for v in x]
        if isinstance(x, (float, np.floating)):
            return float(x) if math.isfinite(x) else None
        if isinstance(x, np.integer):
            return int(x)
        if isinstance(x, np.bool_):
            return bool(x)
        return x

    path.write_text(json.dumps(clean(metrics), indent=2) + "\n")


def write_recording(meshcat: Meshcat, path: Path) -> int:
    """Saves Meshcat's self-contained HTML (scene + recording); returns bytes."""
    html = meshcat.StaticHtml()
    path.write_text(html)
    return len(html.encode())


def export_diagram(diagram: Diagram, directory: Path, stem: str = "standup") -> list[Path]:
    """Writes <stem>.dot and, where graphviz's dot exists, <stem>.svg."""
    directory.mkdir(parents=True, exist_ok=True)
    dot_path = directory / f"{stem}.dot"
    dot_path.write_text(diagram.GetGraphvizString(max_depth=1))
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


def seated_metrics(
    times_s: np.ndarray,
    com_W: np.ndarray,
    pad_forces_W: np.ndarray,
    pad_groups: dict[str, str],
    weight_N: float,
    settle_s: float = 0.5,
) -> dict:
    """CoM drift after settling and the contact forces at the end of the run.

    pad_forces_W is (n_pads, 3, N): the world force on each robot pad, rows in
    the order of pad_groups (pad name -> group name, e.g. "soles").
    """
    pad_names = list(pad_groups)
    metrics: dict = {"weight_N": weight_N}
    if len(times_s) == 0:
        return metrics
    after = times_s >= settle_s
    if after.any():
        ref = com_W[:, np.argmax(after)]
        drift = np.linalg.norm(com_W[:, after] - ref[:, None], axis=0)
        metrics["com_drift_after_settle_m"] = float(drift.max())
    metrics["com_final_m"] = com_W[:, -1]
    if pad_forces_W.shape[-1] > 0:
        final = pad_forces_W[:, :, -1]
        metrics["contact_force_N"] = {n: final[i] for i, n in enumerate(pad_names)}
        by_group: dict[str, float] = {}
        for i, name in enumerate(pad_names):
            group = pad_groups[name]
            by_group[group] = by_group.get(group, 0.0) + float(final[i, 2])
        metrics["contact_normal_force_N"] = by_group
        metrics["contact_force_total_N"] = final.sum(axis=0)
    return metrics


def advancement_metrics(
    psi_final: float, psi_dot: np.ndarray, entry_times_s: tuple[float, ...]
) -> dict:
    """psi at the end, the range of psi_dot, when each state was entered."""
    if len(psi_dot) == 0:
        return {"psi_final": float(psi_final)}
    return {
        "psi_final": float(psi_final),
        "psi_dot_min": float(np.min(psi_dot)),
        "psi_dot_max": float(np.max(psi_dot)),
        "state_entry_times_s": [None if np.isnan(t) else float(t) for t in entry_times_s],
    }
