"""The sweep file and its expansion into runs.

A sweep file names a base scenario, the parameters to vary by their scenario key paths (a
grid, and seeded random draws), fixed overrides and perturbations (pushes on the torso,
mass and friction errors, noise on the measured hand wrench); see sweeps/*.yaml and the
README. Every run is expanded here, so what a run simulates depends only on the sweep file
and its index, never on which worker ran it or in what order. A run is the base scenario's
text and its overrides [(key path, value)], applied through config.apply_overrides: the
same loader, and the same checks, as a scenario file and `--set`.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import reprlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from drake_standup.config import (
    Push,
    ScenarioError,
    apply_overrides,
    expand_key_path,
    parse_scenario,
    read_text_file,
)
from drake_standup.config.resources import find, shipped
from drake_standup.sim.progress import ProgressBar


class SweepError(ValueError):
    """A sweep file that cannot run; the message is one line naming the key."""


@dataclass
class Parameter:
    """One column of the table: its name, the key paths it sets, its values."""

    name: str
    paths: list[str]
    values: list | None = None  # grid
    draw: dict | None = None  # random: {'uniform': [a, b]} | {'normal': [m, s]} | {'choice': [...]}
    # grid: key paths set along with this column, their k-th value with values[k]
    # (e.g. the stand-up's trigger that goes with a pull); a column each in the table.
    with_: dict[str, list] = field(default_factory=dict)


@dataclass
class Figure:
    # 'line': mean of y per x (per group); 'rate': mean of y per x bin; 'scatter': y of
    # each run against its x (per group), for random draws.
    kind: str = "line"
    x: str = ""
    y: str = ""
    group: str | None = None
    bins: int = 6
    range: list[float] | None = None  # rate: the bins' span (default: the data's)
    title: str | None = None
    # Reference lines: [{x: value, label: text}] vertical, e.g. a bound from theory, or
    # [{y: value, label: text}] horizontal, e.g. the time without help.
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
    # Its runs, checked once when the file is loaded (load_sweep), so that running it
    # does not check them again.
    runs: list[RunSpec] | None = None


@dataclass
class RunSpec:
    index: int
    run_id: str
    params: dict  # column -> value (grid, random and perturbation draws)
    overrides: list  # [(concrete key path, value)], in order


TOP_KEYS = tuple("name base seed samples overrides grid random perturbations figures".split())
PERTURBATION_KEYS = ("push", "mass_scale", "friction_scale", "hand_wrench_noise_N")
# A push's keys and what one left out of a sweep file means (config.Push's defaults).
PUSH_DEFAULTS = {"body": Push.body, "start_s": Push.start_s, "duration_s": Push.duration_s}
PUSH_DEFAULTS.update(magnitude_N=0.0, azimuth_deg=0.0, elevation_deg=0.0)
DRAWS = "{uniform: [low, high]}, {normal: [mean, std]} or {choice: [a, b, ...]}"
# Runs a sweep file may expand to: a run costs ~10 s, so 10,000 are ~28 CPU-hours (14 h on
# two workers); past that a count is a slip, and expanding it (~0.1 s a run) would hang.
MAX_RUNS = 10_000


def load_sweep(path: str | Path) -> SweepSpec:
    """Reads and checks a sweep file (a path, or the name of a shipped sweep); raises
    SweepError (one line)."""
    found = find("sweeps", path)
    accepted = f"a YAML file or a shipped sweep: {', '.join(shipped('sweeps'))}"
    text = _checked(None, read_text_file, found or path, "sweep", accepted)
    try:
        raw = yaml.safe_load(text) or {}
    except yaml.YAMLError as err:
        raise SweepError(f"sweep {found}: not valid YAML ({' '.join(str(err).split())})") from None
    if not isinstance(raw, dict):
        raise SweepError(
            f"sweep {found}: {reprlib.repr(raw)}; accepted: a mapping of {', '.join(TOP_KEYS)}"
        )
    _known("sweep", raw, TOP_KEYS)
    if "base" not in raw:
        raise SweepError("base: missing; accepted: the path of a scenario YAML file")
    base_path = find("scenarios", raw["base"], found.parent)
    if base_path is None:
        raise SweepError(
            f"base: '{raw['base']}' not found; accepted: a scenario YAML path (relative to the "
            "current directory or the sweep file), or a shipped scenario's name"
        )
    overrides = raw.get("overrides") or {}
    if not isinstance(overrides, dict):
        raise SweepError("overrides: accepted: a mapping of key path -> value")
    perturbations = _known("perturbations", raw.get("perturbations") or {}, PERTURBATION_KEYS)
    push = _known("perturbations.push", perturbations.get("push", {}), tuple(PUSH_DEFAULTS))
    if not isinstance(push.get("body", ""), str):
        raise SweepError("perturbations.push.body: accepted: the name of a robot body")
    draws = {f"perturbations.push.{k}": v for k, v in push.items() if k != "body"}
    draws.update({f"perturbations.{k}": v for k, v in perturbations.items() if k != "push"})
    for where, draw in draws.items():
        _check_draw(where, draw)
    figures = raw.get("figures") or []
    if not isinstance(figures, list):
        raise SweepError(f"figures: {figures!r}; accepted: a list of {{kind, x, y, ...}}")
    spec = SweepSpec(
        name=str(raw.get("name", found.stem)),
        base_path=base_path,
        base_text=_checked(None, read_text_file, base_path, "base", "a scenario YAML file"),
        seed=_integer("seed", raw.get("seed", 0), 0),
        samples=_integer("samples", raw.get("samples", 1), 1),
        overrides=overrides,
        grid=_parameters(raw, "grid"),
        random=_parameters(raw, "random"),
        perturbations=perturbations,
        figures=[_figure(f"figures[{i}]", f) for i, f in enumerate(figures)],
    )
    names = columns(spec)
    if len(set(names)) != len(names):
        raise SweepError(f"grid/random: a column name is used twice in {names}")
    spec.runs = expand(spec)  # every key path and value checked against the base now
    return spec


def _known(where: str, mapping, accepted: tuple[str, ...]) -> dict:
    """mapping, checked: a mapping of accepted keys only."""
    if not isinstance(mapping, dict):
        raise SweepError(f"{where}: accepted: a mapping of {', '.join(accepted)}")
    for key in mapping:
        if key not in accepted:
            raise SweepError(f"{where}.{key}: unknown key; accepted: {', '.join(accepted)}")
    return mapping


def _integer(where: str, value, low: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value < low:
        raise SweepError(f"{where}: {value!r}; accepted: an integer >= {low}")
    return value


def columns(spec) -> list[str]:
    """The parameter columns of the sweep's table: each grid and random parameter's name,
    each grid entry's companions (with) after it."""
    names = []
    for p in spec.grid:
        names += [p.name, *p.with_]
    return names + [p.name for p in spec.random]


def _number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _parameters(raw: dict, key: str) -> list[Parameter]:
    """grid or random: a list of {name, path or paths, values or draw}; a mapping
    {path: values or draw} is a shorthand."""
    kind = "values" if key == "grid" else "draw"
    entries = raw.get(key) or []
    if isinstance(entries, dict):
        entries = [{"path": path, kind: value} for path, value in entries.items()]
    if not isinstance(entries, list):
        raise SweepError(f"{key}: accepted: a list of {{name, path(s), {kind}}} or path: {kind}")
    params = []
    for i, entry in enumerate(entries):
        where = f"{key}[{i}]"
        _known(
            where, entry, ("name", "path", "paths", kind) + (("with",) if kind == "values" else ())
        )
        paths = entry.get("paths", entry.get("path"))
        paths = [paths] if isinstance(paths, str) else paths
        if not paths or not isinstance(paths, list) or not all(isinstance(p, str) for p in paths):
            raise SweepError(
                f"{where}.path: missing; accepted: a scenario key path or a list of them"
            )
        value = entry.get(kind)
        if kind == "values" and not (isinstance(value, list) and value):
            raise SweepError(f"{where}.values: {value!r}; accepted: a non-empty list")
        if kind == "draw":
            _check_draw(f"{where}.draw", value, constant_ok=False)
        companions = entry.get("with") or {}
        if not isinstance(companions, dict) or not all(
            isinstance(path, str) and isinstance(v, list) and len(v) == len(value)
            for path, v in companions.items()
        ):
            raise SweepError(
                f"{where}.with: {companions!r}; accepted: key path: a list of "
                f"{len(value)} values (one per entry of values)"
            )
        params.append(
            Parameter(entry.get("name", paths[0]), paths, **{kind: value}, with_=companions)
        )
    return params


def _check_draw(where: str, draw, constant_ok: bool = True) -> None:
    """A distribution (DRAWS) or, where constant_ok, a number or a name."""
    one = isinstance(draw, dict) and len(draw) == 1
    kind, args = next(iter(draw.items())) if one else (None, None)
    two_numbers = isinstance(args, list) and len(args) == 2 and all(map(_number, args))
    ok = {
        "uniform": two_numbers and args[0] <= args[1],
        "normal": two_numbers and args[1] >= 0,
        "choice": isinstance(args, list) and len(args) > 0,
    }.get(kind, constant_ok and (_number(draw) or isinstance(draw, str)))
    if not ok:
        accepted = "a number, " if constant_ok else ""
        raise SweepError(f"{where}: {draw!r}; accepted: {accepted}{DRAWS}")


def _figure(where: str, entry) -> Figure:
    figure = Figure(**_known(where, entry, tuple(Figure.__dataclass_fields__)))
    lines, span = figure.lines, figure.range
    if not isinstance(lines, list) or not all(
        isinstance(line, dict)
        and set(line) in ({"x", "label"}, {"y", "label"})
        and _number(line.get("x", line.get("y")))
        and isinstance(line["label"], str)
        for line in lines
    ):
        raise SweepError(
            f"{where}.lines: {lines!r}; accepted: a list of {{x or y: number, label: text}}"
        )
    if span is not None and not (
        isinstance(span, list) and len(span) == 2 and all(map(_number, span)) and span[0] < span[1]
    ):
        raise SweepError(f"{where}.range: {span!r}; accepted: [low, high] with low < high")
    _integer(f"{where}.bins", figure.bins, 1)
    if figure.kind not in ("line", "rate", "scatter"):
        raise SweepError(f"{where}.kind: {figure.kind!r}; accepted: line | rate | scatter")
    for key in ("x", "y"):
        if not isinstance(entry.get(key), str):
            raise SweepError(f"{where}.{key}: missing; accepted: a column of the results table")
    return figure


# --- Expansion: the sweep file -> one RunSpec per run -----------------------------------


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


def run_key(base_text: str, overrides: list) -> str:
    """Names a run by what it simulates: base scenario and overrides."""
    payload = json.dumps({"base": base_text, "overrides": overrides}, sort_keys=True)
    return hashlib.sha1(payload.encode()).hexdigest()[:12]


def check_run_count(spec: SweepSpec) -> int:
    """The number of runs spec expands to (grid combinations x samples), from the sizes
    alone; raises SweepError past MAX_RUNS."""
    sizes = [len(p.values) for p in spec.grid]
    total = math.prod(sizes) * spec.samples
    if spec.samples > MAX_RUNS:
        raise SweepError(
            f"samples: {spec.samples}; accepted: an integer from 1 to {MAX_RUNS} "
            f"(runs in one sweep)"
        )
    if total > MAX_RUNS:
        factors = " x ".join(f"{n} {p.name}" for n, p in zip(sizes, spec.grid, strict=True))
        raise SweepError(
            f"grid x samples: {factors} x {spec.samples} samples = {total} runs; accepted: "
            f"at most {MAX_RUNS} runs in one sweep"
        )
    return total


def expand(spec: SweepSpec) -> list[RunSpec]:
    """Grid x samples runs; run k's draws come from the generator seeded by
    (seed, k), so a run's parameters don't depend on the others. Checks every
    key path and value against the base scenario (raises SweepError); the runs
    load_sweep already checked are returned as they are."""
    if spec.runs is not None:
        return spec.runs
    total = check_run_count(spec)  # first: nothing expanded or allocated yet
    # Checking a run takes ~0.1 s: a large sweep says how far its check has come.
    progress = ProgressBar(total, f"checking {spec.name}", unit="runs") if total >= 200 else None
    base = _checked("base", parse_scenario, spec.base_text, str(spec.base_path))
    fixed = [
        (concrete, value)
        for path, value in spec.overrides.items()
        for concrete in _paths(base, path, f"overrides.{path}")
    ]
    base = _checked("overrides", apply_overrides, base, fixed)
    # Column name -> the concrete key paths it sets, in the order the overrides are applied.
    paths = {
        p.name: [c for path in p.paths for c in _paths(base, path, p.name)]
        for p in spec.grid + spec.random
    }
    for p in spec.grid:
        for path in p.with_:
            paths[path] = _paths(base, path, f"{p.name}.with.{path}")
    combos = []
    for picks in itertools.product(*(range(len(p.values)) for p in spec.grid)):
        combo = {}
        for p, k in zip(spec.grid, picks, strict=True):
            combo[p.name] = p.values[k]
            combo.update({path: values[k] for path, values in p.with_.items()})
        combos.append(combo)
    runs = []
    for index, combo in enumerate([c for c in combos for _ in range(spec.samples)]):
        rng = np.random.default_rng([spec.seed, index])
        params = {**combo, **{param.name: _draw(rng, param.draw) for param in spec.random}}
        overrides = fixed + [
            (c, params[name]) for name, concrete in paths.items() for c in concrete
        ]
        overrides += _perturbations(rng, spec.perturbations, params)
        _checked(f"run {index} ({params})", apply_overrides, base, overrides)
        runs.append(RunSpec(index, run_key(spec.base_text, overrides), params, overrides))
        if progress is not None:
            progress.update(index + 1)
    if progress is not None:
        progress.close()
    return runs


def _perturbations(rng: np.random.Generator, pert: dict, params: dict) -> list:
    """One run's draws of the perturbations: overrides, and their columns in params."""
    overrides = []
    if "push" in pert:
        push = {**PUSH_DEFAULTS, **pert["push"]}
        start, duration, magnitude, azimuth, elevation = (
            _draw(rng, push[k]) for k in list(PUSH_DEFAULTS)[1:]
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
        pushed = {"body": push["body"], "start_s": start, "duration_s": duration, "force_N": force}
        overrides.append(("perturbation.pushes", [] if magnitude == 0 else [pushed]))
    for key in PERTURBATION_KEYS[1:]:
        if key in pert:
            params[key] = _draw(rng, pert[key])
            overrides.append((f"perturbation.{key}", params[key]))
    if "hand_wrench_noise_N" in pert:
        overrides.append(("perturbation.noise_seed", int(rng.integers(0, 2**31 - 1))))
    return overrides


def _paths(base, path: str, where: str) -> list[str]:
    """The concrete key paths of path ([*]: every entry) in the base scenario."""
    paths = expand_key_path(base, path)
    if not paths:
        raise SweepError(f"{where}: key path '{path}' names no key of the base scenario")
    return paths


def _checked(where: str | None, function, *args):
    """function(*args); a ScenarioError becomes a SweepError naming where (None: its
    message names the key already)."""
    try:
        return function(*args)
    except ScenarioError as err:
        raise SweepError(str(err) if where is None else f"{where}: {err}") from None
