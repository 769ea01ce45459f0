"""A sweep's results table: its run records (OUT/runs/<run_id>.json) as one tidy CSV,
OUT/results.csv (a row per run, every parameter and metric), and back as numbers,
booleans and strings."""

from __future__ import annotations

import csv
import math
from pathlib import Path

# The metrics a reader looks at first, right after the parameters.
HEAD_METRICS = tuple(
    "success failure_reason standup_time_s psi_final psi_dot_max com_tracking_rms_m "
    "max_abs_torque_Nm qp_failures sim_time_s wall_time_s run_wall_s".split()
)
# Columns that measure the machine, not the simulation.
TIMING_COLUMNS = ("wall_time_s", "run_wall_s", "realtime_factor", "build_time_s")


def flatten(value, prefix: str = "") -> dict:
    """Nested metrics -> columns: 'a.b' for mappings, 'a[i]' for lists."""
    if isinstance(value, dict):
        items = [(f"{prefix}.{key}" if prefix else key, item) for key, item in value.items()]
    elif isinstance(value, list | tuple):
        items = [(f"{prefix}[{i}]", item) for i, item in enumerate(value)]
    else:
        return {prefix: value}
    return {column: leaf for key, item in items for column, leaf in flatten(item, key).items()}


def table_rows(records: list[dict]) -> list[dict]:
    """A row per run: index, run_id, its parameters and its metrics, flattened."""
    return [
        {
            "index": r["index"],
            "run_id": r["run_id"],
            **flatten(r["params"]),
            **flatten(r["metrics"]),
        }
        for r in records
    ]


def write_table(path: Path, records: list[dict], param_names: list[str]) -> None:
    """One tidy CSV: a row per run; index, run_id, the parameters, the metrics."""
    rows = table_rows(records)
    params = list(dict.fromkeys(key for r in records for key in flatten(r["params"])))
    params.sort(key=lambda k: param_names.index(k) if k in param_names else len(param_names))
    metrics = [m for m in HEAD_METRICS if any(m in row for row in rows)]
    seen = {"index", "run_id", *params, *metrics}
    metrics += [k for k in dict.fromkeys(k for row in rows for k in row) if k not in seen]
    columns = ["index", "run_id"] + params + metrics
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({c: _cell(row.get(c)) for c in columns})


def finite_number(value) -> float | None:
    """value as a float if it is a finite number (not a boolean), else None: a metric
    a table or figure can show."""
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    return float(value) if ok and math.isfinite(value) else None


def _cell(value):
    """None and non-finite numbers as empty cells."""
    finite = not isinstance(value, float) or math.isfinite(value)
    return value if value is not None and finite else ""


def simulation_rows(path: Path) -> list[dict]:
    """results.csv without its timing columns: what two sweeps of the same
    file must agree on, whatever ran them."""
    return [{k: v for k, v in row.items() if k not in TIMING_COLUMNS} for row in read_table(path)]


def read_table(path: Path) -> list[dict]:
    """results.csv back as dicts of numbers, booleans and strings."""

    def parse(text: str):
        for number in (int, float):
            try:
                return number(text)
            except ValueError:
                pass
        return {"": None, "True": True, "False": False}.get(text, text)

    with Path(path).open(newline="") as f:
        return [{k: parse(v) for k, v in row.items()} for row in csv.DictReader(f)]
