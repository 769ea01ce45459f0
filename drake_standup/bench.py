"""Benchmark: simulated seconds per wall second, from one run of this script.

    python -m drake_standup.bench [--scenario PATH] [--duration S] [--repeat N]

Prints a JSON summary. A benchmark, not a test: the machine is shared and
noisy, so read ratios and medians, and compare figures from one run only.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

from drake_standup.config import SCENARIO_DIR, ScenarioError, load_scenario
from drake_standup.simulate import simulate


def _rates(scenario, repeat: int, record: bool, controller: str) -> dict:
    rates, build = [], []
    for _ in range(repeat):
        result = simulate(scenario, None, record=record, progress=False, controller=controller)
        rates.append(result.metrics["realtime_factor"])
        build.append(result.metrics["build_time_s"])
    return {
        "sim_s_per_wall_s": {
            "median": statistics.median(rates),
            "min": min(rates),
            "max": max(rates),
        },
        "build_time_s_median": statistics.median(build),
        "repetitions": repeat,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scenario", type=Path, default=SCENARIO_DIR / "seated.yaml")
    parser.add_argument("--duration", type=float, default=3.0, help="simulated s per repetition")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    try:
        scenario = load_scenario(args.scenario)
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    scenario.duration_s = args.duration

    t0 = time.perf_counter()
    plant_only = _rates(scenario, args.repeat, record=False, controller="seat_hold")
    closed_loop = _rates(scenario, args.repeat, record=False, controller="whole_body")
    summary = {
        "scenario": str(args.scenario),
        "duration_s": args.duration,
        "seat_hold_plant_pd": plant_only,
        "seat_hold_plant_pd_recording": _rates(
            scenario, args.repeat, record=True, controller="seat_hold"
        ),
        "whole_body_controller": closed_loop,
        "ratio_closed_loop_to_plant_only": (
            closed_loop["sim_s_per_wall_s"]["median"] / plant_only["sim_s_per_wall_s"]["median"]
        ),
        "bench_wall_s": None,
    }
    summary["bench_wall_s"] = time.perf_counter() - t0
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
