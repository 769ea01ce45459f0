"""Sweeps and robustness campaigns: many independent stand-ups on Dask.

    drake-standup sweep SWEEP [--workers N] [--address ADDR] [--out DIR] [--limit N]

SWEEP is a sweep file (sweep_file.py: the base scenario, what to vary, the perturbations
and the figures) or the name of a shipped one (drake-standup scenarios lists them). Runs
go to a Dask cluster (cluster.py): by default a LocalCluster of single-threaded worker
processes on this machine, or the scheduler at --address. Each finished run is saved at
once under OUT/runs/<run_id>.json; a sweep started again skips the runs it finds there. At
the end: OUT/results.csv (sweep_table.py: one row per run, every parameter and metric) and
the figures the sweep file asks for (sweep_figures.py).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from dataclasses import asdict, dataclass, field
from pathlib import Path

from drake_standup.config import ScenarioError, check_output_dir, parse_scenario
from drake_standup.config.arguments import OneLineErrorParser
from drake_standup.outputs.json_files import write_json
from drake_standup.studies.cluster import run_on_cluster
from drake_standup.studies.sweep_figures import draw_figure
from drake_standup.studies.sweep_file import (
    RunSpec,
    SweepError,
    SweepSpec,
    columns,
    expand,
    load_sweep,
)
from drake_standup.studies.sweep_table import write_table

EXAMPLE = "example: drake-standup sweep assistance --limit 2 --out out/sweeps/try"


def run_one(base_text: str, overrides: list) -> dict:
    """Simulates one run; never raises: a failure is success false + reason.

    Runs in a Dask worker: its own diagram, simulator and plant contexts.
    """
    from drake_standup.outputs.json_files import json_safe
    from drake_standup.sim.simulate import simulate

    t0 = time.perf_counter()
    try:
        scenario = parse_scenario(base_text, "base", overrides)
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


def run_resumable(
    runs: list,
    runs_dir: Path,
    *,
    run_id,
    record_of,
    task,
    label: str,
    workers: int,
    address: str | None,
    progress: bool,
) -> tuple[dict[str, dict], int]:
    """Simulates on the cluster the runs runs_dir does not hold yet (those the cluster
    lost before are retried) and saves each as runs_dir/<run_id>.json as it finishes:
    record_of(run) and its metrics. run_id(run) names a run, task(run) is (fn, args).
    Returns run_id -> record, and how many runs this call simulated."""
    runs_dir.mkdir(parents=True, exist_ok=True)
    saved = [runs_dir / f"{run_id(run)}.json" for run in runs]
    records = {path.stem: json.loads(path.read_text()) for path in saved if path.is_file()}
    records = {key: r for key, r in records.items() if not r.get("retry")}
    todo = [run for run in runs if run_id(run) not in records]
    if progress and records:
        print(f"resuming: {len(records)} of {len(runs)} runs already in {runs_dir}", flush=True)

    def on_result(run, metrics: dict | None, lost: BaseException | None) -> dict:
        if lost is not None:
            reason = f"cluster: {type(lost).__name__}: {' '.join(str(lost).split())}"
            metrics = {"success": False, "failure_reason": reason[:300]}
        record = {**record_of(run), "metrics": metrics, "retry": lost is not None}
        write_json(runs_dir / f"{run_id(run)}.json", record)
        records[run_id(run)] = record
        return metrics

    if todo:
        run_on_cluster(
            [(run, f"standup-{run_id(run)}", *task(run)) for run in todo],
            on_result,
            workers=workers,
            address=address,
            label=label,
            progress=progress,
        )
    return records, len(todo)


@dataclass
class SweepResult:
    runs: list[RunSpec]
    records: dict[str, dict]  # run_id -> record
    table: Path
    figures: list[Path] = field(default_factory=list)
    computed: int = 0  # runs simulated by this call (the rest were resumed)
    wall_s: float = 0.0  # of the computing part only


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
    summary = {"name": spec.name, "base": str(spec.base_path), "seed": spec.seed}
    summary["runs"] = [{"index": r.index, "run_id": r.run_id, "params": r.params} for r in runs]
    write_json(out_dir / "sweep.json", summary)
    t0 = time.perf_counter()
    records, computed = run_resumable(
        runs,
        runs_dir,
        run_id=lambda run: run.run_id,
        record_of=asdict,
        task=lambda run: (run_one, (spec.base_text, run.overrides)),
        label=f"sweep {spec.name}",
        workers=workers,
        address=address,
        progress=progress,
    )
    wall_s = time.perf_counter() - t0

    ordered = [records[r.run_id] for r in runs]
    table = out_dir / "results.csv"
    write_table(table, ordered, columns(spec))
    figures = [draw_figure(fig, ordered, out_dir) for fig in spec.figures]
    return SweepResult(runs, records, table, [f for f in figures if f], computed, wall_s)


# --- Command line ---------------------------------------------------------------------


def main(argv: list[str] | None = None, prog: str = "python -m drake_standup.studies.sweep") -> int:
    parser = OneLineErrorParser(
        prog=prog,
        description=__doc__,
        epilog=EXAMPLE,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("spec", help="a sweep YAML file, or a shipped sweep's name, e.g. pushes")
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
    for flag, count in (("--workers", args.workers), ("--limit", args.limit)):
        if count is not None and count < 1:
            print(f"error: {flag}: {count}; accepted: an integer >= 1", file=sys.stderr)
            return 2
    try:
        spec = load_sweep(args.spec)
        out = check_output_dir(args.out or Path("out") / "sweeps" / spec.name, "--out")
    except (SweepError, ScenarioError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
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
