"""Sweep throughput: the same sweep on 1 worker, then on 2, in one run.

python -m drake_standup.studies.sweep_bench [--spec assistance] [--workers 1 2]
                                    [--limit N] [--out DIR]

A benchmark, not a test. Each worker count gets a fresh LocalCluster and a
fresh output directory (nothing resumed), and is timed from starting the
cluster to the last run's record. Prints one JSON summary: runs per wall
minute for each count, their ratio to the first, and whether every table
holds the same simulation results (timing columns aside).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import sys
import time
from pathlib import Path

from drake_standup.config.arguments import OneLineErrorParser
from drake_standup.studies.bench_measurements import git_state
from drake_standup.studies.sweep import run_sweep
from drake_standup.studies.sweep_file import load_sweep
from drake_standup.studies.sweep_table import simulation_rows


def _git() -> dict:
    """The commit (short) and whether the tree had uncommitted changes."""
    state = git_state()
    return {"commit": (state["commit"] or "")[:7], "dirty": bool(state["uncommitted"])}


def main(argv: list[str] | None = None) -> int:
    parser = OneLineErrorParser(
        prog="python -m drake_standup.studies.sweep_bench",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--spec", default="assistance", help="sweep file or shipped name")
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--limit", type=int, default=None, help="first N runs only")
    parser.add_argument("--out", type=Path, default=Path("out") / "sweep_bench")
    args = parser.parse_args(argv)

    spec = load_sweep(args.spec)
    results = {}
    tables = {}
    load_before = os.getloadavg()
    for n in args.workers:
        out = args.out / f"workers_{n}"
        shutil.rmtree(out, ignore_errors=True)  # a benchmark never resumes
        t0 = time.perf_counter()
        result = run_sweep(spec, out, workers=n, limit=args.limit)
        wall_s = time.perf_counter() - t0
        records = [result.records[r.run_id] for r in result.runs]
        run_walls = [r["metrics"].get("run_wall_s", 0.0) for r in records]
        results[n] = {
            "runs": len(records),
            "wall_s": round(wall_s, 2),
            "runs_per_min": round(60.0 * len(records) / wall_s, 3),
            "sum_of_run_wall_s": round(sum(run_walls), 2),
            "stood_up": sum(bool(r["metrics"].get("success")) for r in records),
            "out": str(out),
        }
        tables[n] = simulation_rows(result.table)
    first = args.workers[0]
    for n in args.workers:
        results[n]["throughput_vs_first"] = round(
            results[n]["runs_per_min"] / results[first]["runs_per_min"], 3
        )
    summary = {
        "sweep": str(args.spec),
        "workers": results,
        "same_results_for_every_worker_count": all(t == tables[first] for t in tables.values()),
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "load_average_before": [round(x, 2) for x in load_before],
            "load_average_after": [round(x, 2) for x in os.getloadavg()],
        },
        "git": _git(),
    }
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
