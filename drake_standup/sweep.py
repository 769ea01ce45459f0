"""Sweeps and robustness campaigns: many independent stand-ups on Dask.

python -m drake_standup.sweep SPEC.yaml [--workers N] [--address ADDR] [--out DIR]

A sweep file names a base scenario, the parameters to vary by their scenario
key paths (a grid, and seeded random draws), and perturbations (pushes on the
torso, mass and friction errors, noise on the measured hand wrench); see
sweeps/*.yaml and the README. Every run is expanded in this process, so what a
run simulates depends only on the sweep file and its index, never on which
worker ran it or in what order. Runs go to a Dask cluster: by default a
LocalCluster of single-threaded worker processes on this machine, or the
scheduler at --address. Each finished run is saved at once under
OUT/runs/<run_id>.json; a sweep started again skips the runs it finds there.
At the end: OUT/results.csv (one row per run, every parameter and metric) and
the figures the sweep file asks for.
"""

from __future__ import annotations

import argparse
import copy
import csv
import hashlib
import json
import logging
import math
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from drake_standup.cli import OneLineErrorParser
from drake_standup.config import (
    REPO_ROOT,
    ScenarioError,
    expand_key_path,
    parse_scenario,
    set_key_path,
    validate,
)

SWEEP_DIR = REPO_ROOT / "sweeps"


class SweepError(ValueError):
    """A sweep file that cannot run; the message is one line naming the key."""


# --- The sweep file -----------------------------------------------------------

DISTRIBUTIONS = ("uniform", "normal", "choice")


@dataclass
class Parameter:
    """One column of the table: its name, the key paths it sets, its values."""

    name: str
    paths: list[str]
    values: list | None = None  # grid
    draw: dict | None = None  # random: {'uniform': [a, b]} | {'normal': [m, s]} | {'choice': [...]}


@dataclass
class Figure:
    kind: str  # 'line': mean of y per x (per group); 'rate': mean of y per x bin
    x: str
    y: str
    group: str | None = None
    bins: int = 6
    range: list[float] | None = None  # rate: the bins' span (default: the data's)
    title: str | None = None
    # Vertical reference lines: [{x: value, label: text}], e.g. a bound from theory.
    lines: list[dict] = field(default_factory=list)


@dataclass
class SweepSpec:
    name: str
    base_path: Path
    base_text: str
    seed: int
    samples: int
    overrides: dict
    grid: list[Parameter]
    random: list[Parameter]
    perturbations: dict
    figures: list[Figure]


@dataclass
class RunSpec:
    index: int
    run_id: str
    params: dict  # column -> value (grid, random and perturbation draws)
    overrides: list  # [(concrete key path, value)], in order


TOP_KEYS = (
    "name",
    "base",
    "seed",
    "samples",
    "overrides",
    "grid",
    "random",
    "perturbations",
    "figures",
)
PERTURBATION_KEYS = ("push", "mass_scale", "friction_scale", "hand_wrench_noise_N")
PUSH_KEYS = ("body", "start_s", "duration_s", "magnitude_N", "azimuth_deg", "elevation_deg")
# What a push key left out of a sweep file means (config.Push's defaults).
PUSH_DEFAULTS = {
    "start_s": 5.0,
    "duration_s": 0.2,
    "magnitude_N": 0.0,
    "azimuth_deg": 0.0,
    "elevation_deg": 0.0,
}


def load_sweep(path: str | Path) -> SweepSpec:
    """Reads and checks a sweep file; raises SweepError (one line)."""
    path = Path(path)
    if not path.is_file():
        shipped = ", ".join(sorted(str(p.relative_to(REPO_ROOT)) for p in SWEEP_DIR.glob("*.yaml")))
        raise SweepError(f"sweep: file '{path}' not found; accepted: a YAML file, e.g. {shipped}")
    try:
        raw = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError as err:
        raise SweepError(f"sweep {path}: not valid YAML ({' '.join(str(err).split())})") from None
    if not isinstance(raw, dict):
        raise SweepError(f"sweep {path}: a mapping of {', '.join(TOP_KEYS)} expected")
    _known("sweep", raw, TOP_KEYS)
    if "base" not in raw:
        raise SweepError("base: missing; accepted: the path of a scenario YAML file")
    base_path = _find_file(str(raw["base"]), path.parent)
    if base_path is None:
        raise SweepError(
            f"base: '{raw['base']}' not found; accepted: a scenario YAML path (relative to the "
            "current directory, the sweep file or the repository)"
        )
    seed = raw.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise SweepError(f"seed: {seed!r}; accepted: an integer >= 0")
    overrides = raw.get("overrides") or {}
    if not isinstance(overrides, dict):
        raise SweepError("overrides: accepted: a mapping of key path -> value")
    grid = [_parameter(f"grid[{i}]", p, "values") for i, p in enumerate(_entries(raw, "grid"))]
    random = [_parameter(f"random[{i}]", p, "draw") for i, p in enumerate(_entries(raw, "random"))]
    perturbations = raw.get("perturbations") or {}
    if not isinstance(perturbations, dict):
        raise SweepError(f"perturbations: accepted: a mapping of {', '.join(PERTURBATION_KEYS)}")
    _known("perturbations", perturbations, PERTURBATION_KEYS)
    if "push" in perturbations:
        if not isinstance(perturbations["push"], dict):
            raise SweepError(f"perturbations.push: accepted: a mapping of {', '.join(PUSH_KEYS)}")
        _known("perturbations.push", perturbations["push"], PUSH_KEYS)
        for key in PUSH_KEYS[1:]:
            _check_draw(f"perturbations.push.{key}", perturbations["push"].get(key, 0.0))
        if not isinstance(perturbations["push"].get("body", "chest"), str):
            raise SweepError("perturbations.push.body: accepted: the name of a robot body")
    for key in PERTURBATION_KEYS[1:]:
        if key in perturbations:
            _check_draw(f"perturbations.{key}", perturbations[key])
    samples = raw.get("samples", 1)
    if not isinstance(samples, int) or isinstance(samples, bool) or samples < 1:
        raise SweepError(f"samples: {samples!r}; accepted: an integer >= 1")
    names = [p.name for p in grid + random]
    if len(set(names)) != len(names):
        raise SweepError(f"grid/random: a column name is used twice in {names}")
    figures = [_figure(i, f) for i, f in enumerate(raw.get("figures") or [])]
    spec = SweepSpec(
        name=str(raw.get("name", path.stem)),
        base_path=base_path,
        base_text=base_path.read_text(),
        seed=seed,
        samples=samples,
        overrides=overrides,
        grid=grid,
        random=random,
        perturbations=perturbations,
        figures=figures,
    )
    expand(spec)  # every key path and value checked against the base scenario now
    return spec


def _find_file(name: str, sweep_dir: Path) -> Path | None:
    for candidate in (Path(name), sweep_dir / name, REPO_ROOT / name):
        if candidate.is_file():
            return candidate
    return None


def _known(where: str, mapping: dict, accepted: tuple[str, ...]) -> None:
    for key in mapping:
        if key not in accepted:
            raise SweepError(f"{where}.{key}: unknown key; accepted: {', '.join(accepted)}")


def _entries(raw: dict, key: str) -> list[dict]:
    """grid/random as a list of entries; a mapping {path: values} is a shorthand."""
    value = raw.get(key) or []
    if isinstance(value, dict):
        return [
            {"path": path, ("values" if key == "grid" else "draw"): v} for path, v in value.items()
        ]
    if not isinstance(value, list) or not all(isinstance(e, dict) for e in value):
        raise SweepError(f"{key}: accepted: a list of {{name, path(s), values}} or path: values")
    return value


def _parameter(where: str, entry: dict, kind: str) -> Parameter:
    accepted = ("name", "path", "paths", kind)
    _known(where, entry, accepted)
    paths = entry.get("paths", entry.get("path"))
    if isinstance(paths, str):
        paths = [paths]
    if not paths or not all(isinstance(p, str) for p in paths):
        raise SweepError(f"{where}.path: missing; accepted: a scenario key path or a list of them")
    name = entry.get("name", paths[0])
    if kind == "values":
        values = entry.get("values")
        if not isinstance(values, list) or not values:
            raise SweepError(f"{where}.values: {values!r}; accepted: a non-empty list")
        return Parameter(name, paths, values=values)
    _check_draw(f"{where}.draw", entry.get("draw"), constant_ok=False)
    return Parameter(name, paths, draw=entry["draw"])


def _check_draw(where: str, draw, constant_ok: bool = True) -> None:
    if constant_ok and isinstance(draw, (int, float, str)) and not isinstance(draw, bool):
        return
    ok = isinstance(draw, dict) and len(draw) == 1 and next(iter(draw)) in DISTRIBUTIONS
    if ok:
        ((kind, args),) = draw.items()
        if kind == "choice":
            ok = isinstance(args, list) and len(args) > 0
        else:
            ok = (
                isinstance(args, list)
                and len(args) == 2
                and all(isinstance(a, (int, float)) and not isinstance(a, bool) for a in args)
                and (args[0] <= args[1] if kind == "uniform" else args[1] >= 0)
            )
    if not ok:
        accepted = "a number, " if constant_ok else ""
        raise SweepError(
            f"{where}: {draw!r}; accepted: {accepted}{{uniform: [low, high]}}, "
            "{normal: [mean, std]} or {choice: [a, b, ...]}"
        )


def _figure(i: int, entry) -> Figure:
    where = f"figures[{i}]"
    if not isinstance(entry, dict):
        raise SweepError(f"{where}: accepted: a mapping of kind, x, y, group, bins, title")
    _known(where, entry, ("kind", "x", "y", "group", "bins", "range", "title", "lines"))
    lines = entry.get("lines", [])
    if not isinstance(lines, list) or not all(
        isinstance(line, dict)
        and set(line) == {"x", "label"}
        and isinstance(line["x"], (int, float))
        and not isinstance(line["x"], bool)
        and isinstance(line["label"], str)
        for line in lines
    ):
        raise SweepError(
            f"{where}.lines: {lines!r}; accepted: a list of {{x: number, label: text}}"
        )
    span = entry.get("range")
    if span is not None and not (
        isinstance(span, list)
        and len(span) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in span)
        and span[0] < span[1]
    ):
        raise SweepError(f"{where}.range: {span!r}; accepted: [low, high] with low < high")
    bins = entry.get("bins", 6)
    if not isinstance(bins, int) or isinstance(bins, bool) or bins < 1:
        raise SweepError(f"{where}.bins: {bins!r}; accepted: an integer >= 1")
    if entry.get("kind", "line") not in ("line", "rate"):
        raise SweepError(f"{where}.kind: {entry.get('kind')!r}; accepted: line | rate")
    for key in ("x", "y"):
        if not isinstance(entry.get(key), str):
            raise SweepError(f"{where}.{key}: missing; accepted: a column of the results table")
    return Figure(
        kind=entry.get("kind", "line"),
        x=entry["x"],
        y=entry["y"],
        group=entry.get("group"),
        bins=bins,
        range=span,
        title=entry.get("title"),
        lines=lines,
    )


# --- Expansion: the sweep file -> one RunSpec per run -------------------------


def _draw(rng: np.random.Generator, draw):
    """One value of a distribution (a constant is itself; one rng call per draw
    either way, so the stream does not shift when a constant becomes random)."""
    u = rng.random()
    if not isinstance(draw, dict):
        return draw
    ((kind, args),) = draw.items()
    if kind == "uniform":
        return float(args[0] + u * (args[1] - args[0]))
    if kind == "normal":
        # Inverse-CDF free: a second variate for the Gaussian.
        return float(args[0] + args[1] * rng.standard_normal())
    return args[min(int(u * len(args)), len(args) - 1)]


def _run_id(base_text: str, overrides: list) -> str:
    """Names a run by what it simulates: base scenario and overrides."""
    payload = json.dumps({"base": base_text, "overrides": overrides}, sort_keys=True)
    return hashlib.sha1(payload.encode()).hexdigest()[:12]


def expand(spec: SweepSpec) -> list[RunSpec]:
    """Grid x samples runs; run k's draws come from the generator seeded by
    (seed, k), so a run's parameters don't depend on the others. Checks every
    key path and value against the base scenario (raises SweepError)."""
    try:
        base = parse_scenario(spec.base_text, str(spec.base_path))
    except ScenarioError as err:
        raise SweepError(f"base: {err}") from None
    fixed = []
    for path, value in spec.overrides.items():
        fixed += [(p, value) for p in _expand_path(base, path, f"overrides.{path}")]
    for p, value in fixed:
        _set(base, p, value, f"overrides: {p}")
    grid_paths = {
        param.name: [p for path in param.paths for p in _expand_path(base, path, param.name)]
        for param in spec.grid + spec.random
    }
    combos = [{}]
    for param in spec.grid:
        combos = [{**c, param.name: v} for c in combos for v in param.values]
    pert = spec.perturbations
    runs = []
    for combo in combos:
        for _ in range(spec.samples):
            index = len(runs)
            rng = np.random.default_rng([spec.seed, index])
            params = dict(combo)
            for param in spec.random:
                params[param.name] = _draw(rng, param.draw)
            overrides = list(fixed)
            for param in spec.grid + spec.random:
                overrides += [(p, params[param.name]) for p in grid_paths[param.name]]
            if "push" in pert:
                push = pert["push"]
                start, duration, magnitude, azimuth, elevation = (
                    _draw(rng, push.get(k, PUSH_DEFAULTS[k])) for k in PUSH_KEYS[1:]
                )
                az, el = math.radians(azimuth), math.radians(elevation)
                force = [
                    magnitude * math.cos(el) * math.cos(az),
                    magnitude * math.cos(el) * math.sin(az),
                    magnitude * math.sin(el),
                ]
                params.update(
                    push_start_s=start,
                    push_duration_s=duration,
                    push_magnitude_N=magnitude,
                    push_impulse_Ns=magnitude * duration,
                    push_azimuth_deg=azimuth,
                    push_elevation_deg=elevation,
                )
                pushes = (
                    []
                    if magnitude == 0
                    else [
                        {
                            "body": push.get("body", "chest"),
                            "start_s": start,
                            "duration_s": duration,
                            "force_N": force,
                        }
                    ]
                )
                overrides.append(("perturbation.pushes", pushes))
            for key in PERTURBATION_KEYS[1:]:
                if key in pert:
                    params[key] = _draw(rng, pert[key])
                    overrides.append((f"perturbation.{key}", params[key]))
            if "hand_wrench_noise_N" in pert:
                seed = int(rng.integers(0, 2**31 - 1))
                overrides.append(("perturbation.noise_seed", seed))
            check = copy.deepcopy(base)
            for p, value in overrides[len(fixed) :]:
                _set(check, p, value, f"run {index}: {p}")
            try:
                validate(check)
            except ScenarioError as err:
                raise SweepError(f"run {index} ({params}): {err}") from None
            runs.append(RunSpec(index, _run_id(spec.base_text, overrides), params, overrides))
    return runs


def _expand_path(base, path: str, where: str) -> list[str]:
    try:
        paths = expand_key_path(base, path)
    except ScenarioError as err:
        raise SweepError(f"{where}: {err}") from None
    if not paths:
        raise SweepError(f"{where}: key path '{path}' names no key of the base scenario")
    return paths


def _set(scenario, path: str, value, where: str) -> None:
    try:
        set_key_path(scenario, path, value)
    except ScenarioError as err:
        raise SweepError(f"{where}: {err}") from None


# --- One run, in a worker -----------------------------------------------------


def run_one(base_text: str, overrides: list) -> dict:
    """Simulates one run; never raises: a failure is success false + reason.

    Runs in a Dask worker: its own diagram, simulator and plant contexts.
    """
    from drake_standup.outputs import json_safe
    from drake_standup.simulate import simulate

    t0 = time.perf_counter()
    try:
        scenario = parse_scenario(base_text, "base")
        for path, value in overrides:
            set_key_path(scenario, path, value)
        validate(scenario)
        result = simulate(scenario, None, record=False, progress=False, baseline=False)
        metrics = json_safe(result.metrics)
    except ScenarioError as err:
        metrics = {"success": False, "failure_reason": f"invalid scenario: {err}"}
    except Exception as err:  # noqa: BLE001 - a run's failure is its result
        tail = traceback.format_exc().strip().splitlines()[-3:]
        reason = f"error: {type(err).__name__}: {' '.join(str(err).split())[:300]}"
        metrics = {"success": False, "failure_reason": reason, "traceback": " | ".join(tail)}
    metrics["run_wall_s"] = time.perf_counter() - t0
    return metrics


# --- The sweep: submit, collect, resume ---------------------------------------


@dataclass
class SweepResult:
    runs: list[RunSpec]
    records: dict[str, dict]  # run_id -> record
    table: Path
    figures: list[Path] = field(default_factory=list)
    computed: int = 0  # runs simulated by this call (the rest were resumed)
    wall_s: float = 0.0  # of the computing part only


def open_client(workers: int, address: str | None):
    """A Dask client: on the scheduler at address, or on a new LocalCluster of
    `workers` single-threaded worker processes listening on localhost only."""
    from distributed import Client, LocalCluster

    if address:
        client = Client(address, timeout="30s")
        try:
            client.wait_for_workers(1, timeout=60)
        except TimeoutError:
            client.close()
            raise OSError(f"no Dask worker joined the scheduler at {address} in 60 s") from None
        return client, None
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    return Client(cluster), cluster


def run_on_cluster(
    tasks: list,
    on_result,
    *,
    workers: int,
    address: str | None,
    label: str,
    progress: bool = True,
) -> None:
    """Runs tasks [(item, key, fn, args), ...] on a Dask cluster (open_client)
    and, as each finishes, calls on_result(item, metrics, lost): metrics is
    fn's return value (a metrics dict) or None with lost the exception of a
    task the cluster lost (a dead worker: not the run's fault); on_result
    returns the metrics to count. A progress bar counts the runs, those not
    stood up and the rate; the cluster is closed however this ends."""
    from distributed import as_completed

    from drake_standup.progress import ProgressBar

    client, cluster = open_client(workers, address)
    try:
        futures = {
            client.submit(fn, *args, key=key, pure=False): item for item, key, fn, args in tasks
        }
        bar = ProgressBar(len(tasks), label, unit="runs") if progress else None
        t0 = time.perf_counter()
        done = failed = 0
        for future in as_completed(futures):
            item = futures[future]
            if future.status == "finished":
                metrics = on_result(item, future.result(), None)
            else:
                metrics = on_result(item, None, future.exception())
            done += 1
            failed += not metrics.get("success", False)
            future.release()
            if bar is not None:
                rate = 60.0 * done / (time.perf_counter() - t0)
                bar.update(done, f"{failed} not stood up; {rate:.1f} runs/min")
        if bar is not None:
            bar.close()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_sweep(
    spec: SweepSpec,
    out_dir: Path,
    *,
    workers: int = 2,
    address: str | None = None,
    progress: bool = True,
    limit: int | None = None,
) -> SweepResult:
    """Runs what out_dir/runs/ does not hold yet; writes the table and figures."""

    runs = expand(spec)[:limit]
    out_dir = Path(out_dir)
    runs_dir = out_dir / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    write_json(
        out_dir / "sweep.json",
        {
            "name": spec.name,
            "base": str(spec.base_path),
            "seed": spec.seed,
            "runs": [{"index": r.index, "run_id": r.run_id, "params": r.params} for r in runs],
        },
    )
    records = {}
    for run in runs:
        path = runs_dir / f"{run.run_id}.json"
        if path.is_file():
            record = json.loads(path.read_text())
            if not record.get("retry"):
                records[run.run_id] = record
    todo = [r for r in runs if r.run_id not in records]
    if progress and records:
        print(f"resuming: {len(records)} of {len(runs)} runs already in {runs_dir}", flush=True)

    def on_result(run: RunSpec, metrics: dict | None, lost: BaseException | None) -> dict:
        if lost is not None:
            text = " ".join(str(lost).split())
            metrics = {
                "success": False,
                "failure_reason": f"cluster: {type(lost).__name__}: {text}"[:300],
            }
        record = {
            "index": run.index,
            "run_id": run.run_id,
            "params": run.params,
            "overrides": run.overrides,
            "metrics": metrics,
            "retry": lost is not None,
        }
        write_json(runs_dir / f"{run.run_id}.json", record)
        records[run.run_id] = record
        return metrics

    t0 = time.perf_counter()
    if todo:
        run_on_cluster(
            [(r, f"standup-{r.run_id}", run_one, (spec.base_text, r.overrides)) for r in todo],
            on_result,
            workers=workers,
            address=address,
            label=f"sweep {spec.name}",
            progress=progress,
        )
    wall_s = time.perf_counter() - t0

    ordered = [records[r.run_id] for r in runs]
    table = out_dir / "results.csv"
    write_table(table, ordered, [p.name for p in spec.grid + spec.random])
    figures = [draw_figure(fig, ordered, out_dir) for fig in spec.figures]
    return SweepResult(runs, records, table, [f for f in figures if f], len(todo), wall_s)


def write_json(path: Path, data) -> None:
    """data as JSON (json_safe), written whole or not at all (a temporary file
    renamed over path), its folder made if needed."""
    from drake_standup.outputs import json_safe

    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(json_safe(data), indent=1) + "\n")
    tmp.replace(path)


# --- The table and the figures ------------------------------------------------

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


def _order(value):
    """Sorts numbers numerically and before anything else."""
    return (0, value, "") if isinstance(value, (int, float)) else (1, 0, str(value))


def _number(value) -> float | None:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    return float(value) if ok and math.isfinite(value) else None


def draw_figure(fig: Figure, records: list[dict], out_dir: Path) -> Path | None:
    """line: mean y per x value (one line per group; runs that did not stand
    up drawn as crosses on the x axis); rate: mean of y (e.g. success) per x bin,
    with the number of runs per bin."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = table_rows(records)
    if not rows or fig.x not in rows[0]:
        return None
    fig_obj, ax = plt.subplots(figsize=(6.4, 4.2))
    if fig.kind == "line":
        groups = sorted({row.get(fig.group) for row in rows}, key=_order) if fig.group else [None]
        markers = "osD^v<>p"
        for k, g in enumerate(groups):
            sel = [r for r in rows if fig.group is None or r.get(fig.group) == g]
            xs = sorted({r[fig.x] for r in sel}, key=_order)
            mean = []
            for x in xs:
                ys = [_number(r.get(fig.y)) for r in sel if r[fig.x] == x and r.get("success")]
                ys = [y for y in ys if y is not None]
                mean.append(float(np.mean(ys)) if ys else np.nan)
            label = f"{fig.group} = {g}" if fig.group else None
            (line,) = ax.plot(xs, mean, marker=markers[k % len(markers)], label=label)
            # Failed runs: a cross at their value, or on the x axis without one.
            failed = [r for r in sel if not r.get("success")]
            if failed:
                ax.plot(
                    [r[fig.x] for r in failed],
                    [_number(r.get(fig.y)) or 0.0 for r in failed],
                    "x",
                    color=line.get_color(),
                    ms=10,
                    mew=2,
                )
        if fig.group:
            ax.legend(fontsize=8)
        ax.set_ylabel(fig.y)
        ax.text(
            0.01,
            0.01,
            "lines: mean over runs that stood up; x: a run that failed (reason in results.csv)",
            transform=ax.transAxes,
            fontsize=7,
        )
    else:
        xs = np.array([r[fig.x] for r in rows], dtype=float)
        ys = np.array([float(bool(r.get(fig.y))) for r in rows])
        low, high = fig.range or (xs.min(), xs.max())
        edges = np.linspace(low, high, fig.bins + 1)
        which = np.clip(np.digitize(xs, edges[1:-1]), 0, fig.bins - 1)
        centres, rates, counts = [], [], []
        for b in range(fig.bins):
            sel = which == b
            if sel.any():
                centres.append(0.5 * (edges[b] + edges[b + 1]))
                rates.append(ys[sel].mean())
                counts.append(int(sel.sum()))
        width = (edges[1] - edges[0]) * 0.9 if len(edges) > 1 else 1.0
        ax.bar(centres, rates, width=width, color="tab:blue", alpha=0.7, edgecolor="tab:blue")
        for c, r, n in zip(centres, rates, counts):
            ax.text(c, r + 0.02, f"n={n}", ha="center", fontsize=8)
        ax.set_ylim(0, 1.15)
        ax.set_ylabel(f"{fig.y} rate")
    for k, line in enumerate(fig.lines):
        ax.axvline(line["x"], color="tab:red", ls="--", lw=1.2)
        ax.text(
            line["x"],
            0.98 - 0.07 * k,
            f" {line['label']}",
            transform=ax.get_xaxis_transform(),
            color="tab:red",
            fontsize=8,
            va="top",
        )
    ax.set_xlabel(fig.x)
    ax.set_title(fig.title or f"{fig.y} vs {fig.x}", fontsize=10)
    ax.grid(alpha=0.3)
    fig_obj.tight_layout()
    path = out_dir / f"{fig.y}_vs_{fig.x}.png".replace("/", "_")
    fig_obj.savefig(path, dpi=110)
    plt.close(fig_obj)
    return path


# --- Command line -------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    parser = OneLineErrorParser(
        prog="python -m drake_standup.sweep",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", type=Path, help="sweep YAML, e.g. sweeps/assistance.yaml")
    parser.add_argument(
        "--workers", type=int, default=2, help="LocalCluster worker processes (default 2)"
    )
    parser.add_argument(
        "--address",
        default=None,
        help="Dask scheduler address, e.g. tcp://127.0.0.1:8786 "
        "(default: a LocalCluster of --workers processes)",
    )
    parser.add_argument(
        "--out", type=Path, default=None, help="output directory (default: out/sweeps/NAME)"
    )
    parser.add_argument(
        "--limit", type=int, default=None, help="run only the first N runs of the sweep"
    )
    args = parser.parse_args(argv)
    if args.workers < 1:
        print(f"error: --workers: {args.workers}; accepted: an integer >= 1", file=sys.stderr)
        return 2
    if args.limit is not None and args.limit < 1:
        print(f"error: --limit: {args.limit}; accepted: an integer >= 1", file=sys.stderr)
        return 2
    try:
        spec = load_sweep(args.spec)
    except (SweepError, ScenarioError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    out = args.out or Path("out") / "sweeps" / spec.name
    try:
        result = run_sweep(spec, out, workers=args.workers, address=args.address, limit=args.limit)
    except OSError as err:  # e.g. no scheduler at --address
        print(f"error: --address {args.address}: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        saved = len(list((out / "runs").glob("*.json")))
        print(
            f"\ninterrupted: {saved} run records in {out / 'runs'}; "
            "the same command resumes from there",
            file=sys.stderr,
        )
        return 130
    records = [result.records[r.run_id] for r in result.runs]
    stood = sum(bool(r["metrics"].get("success")) for r in records)
    print(f"wrote table: {result.table}")
    for path in result.figures:
        print(f"wrote figure: {path}")
    resumed = len(records) - result.computed
    if result.computed:
        rate = 60.0 * result.computed / result.wall_s
        work = f"{result.computed} simulated in {result.wall_s:.0f} s ({rate:.1f} runs/min)"
        work += f", {resumed} resumed" if resumed else ""
    else:
        work = f"all {resumed} resumed from {out / 'runs'}"
    lost = [r for r in records if r.get("retry")]
    if lost:
        print(
            f"warning: {len(lost)} runs lost to the cluster, not simulated (first: "
            f"{lost[0]['metrics']['failure_reason'][:160]}); the same command retries them",
            file=sys.stderr,
        )
    print(
        f"sweep {spec.name}: {len(records)} runs, {stood} stood up, "
        f"{len(records) - stood} did not; {work}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
