"""A sweep's results table: its run records (OUT/runs/<run_id>.json) as one tidy CSV,
OUT/results.csv (a row per run, every parameter and metric), and back as numbers,
booleans and strings."""

from __future__ import annotations

import csv
import math
from pathlib import Path

HEAD_METRICS = (
    "success",
    "failure_reason",
    "standup_time_s",
    "psi_final",
    "psi_dot_max",
    "com_tracking_rms_m",
    "max_abs_torque_Nm",
    "qp_failures",
    "sim_time_s",
    "wall_time_s",
    "run_wall_s",
)


def flatten(prefix: str, value, out: dict) -> None:
    """Nested metrics -> columns: 'a.b' for mappings, 'a[i]' for lists."""
    if isinstance(value, dict):
        for key, item in value.items():
            flatten(f"{prefix}.{key}" if prefix else key, item, out)
    elif isinstance(value, (list, tuple)):
        for i, item in enumerate(value):
            flatten(f"{prefix}[{i}]", item, out)
    else:
        out[prefix] = value


def table_rows(records: list[dict]) -> list[dict]:
    rows = []
    for record in records:
        row = {"index": record["index"], "run_id": record["run_id"]}
        flatten("", record["params"], row)
        metrics: dict = {}
        flatten("", record["metrics"], metrics)
        row.update(metrics)
        rows.append(row)
    return rows


def write_table(path: Path, records: list[dict], param_names: list[str]) -> None:
    """One tidy CSV: a row per run; index, run_id, the parameters, the metrics."""
    rows = table_rows(records)
    params: list[str] = []
    for record in records:
        flat: dict = {}
        flatten("", record["params"], flat)
        params += [k for k in flat if k not in params]
    params.sort(key=lambda k: param_names.index(k) if k in param_names else len(param_names))
    metrics = [m for m in HEAD_METRICS if any(m in row for row in rows)]
    for row in rows:
        metrics += [
            k for k in row if k not in metrics and k not in params and k not in ("index", "run_id")
        ]
    columns = ["index", "run_id"] + params + metrics
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({c: _cell(row.get(c)) for c in columns})


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, float) and not math.isfinite(value):
        return ""
    return value


# Columns that measure the machine, not the simulation.
TIMING_COLUMNS = ("wall_time_s", "run_wall_s", "realtime_factor", "build_time_s")


def simulation_rows(path: Path) -> list[dict]:
    """results.csv without its timing columns: what two sweeps of the same
    file must agree on, whatever ran them."""
    return [{k: v for k, v in row.items() if k not in TIMING_COLUMNS} for row in read_table(path)]


def read_table(path: Path) -> list[dict]:
    """results.csv back as dicts of numbers, booleans and strings."""

    def parse(text: str):
        if text == "":
            return None
        if text in ("True", "False"):
            return text == "True"
        try:
            return int(text)
        except ValueError:
            pass
        try:
            return float(text)
        except ValueError:
            return text

    with Path(path).open(newline="") as f:
        return [{k: parse(v) for k, v in row.items()} for row in csv.DictReader(f)]
