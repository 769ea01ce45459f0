"""JSON files: metrics.json, the sweeps' run records, the convergence study's."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np


def json_safe(x):
    """x with numpy scalars and arrays as Python values and non-finite floats
    as None (JSON has no NaN)."""
    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, np.ndarray)):
        return [json_safe(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def write_metrics(path: Path, metrics: dict) -> None:
    """JSON with non-finite numbers written as null."""
    path.write_text(json.dumps(json_safe(metrics), indent=2) + "\n")


def write_json(path: Path, data) -> None:
    """data as JSON (json_safe), written whole or not at all (a temporary file
    renamed over path), its folder made if needed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(json_safe(data), indent=1) + "\n")
    tmp.replace(path)
