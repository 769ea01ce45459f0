"""Benchmark: how fast the stand-up simulates, and where the time goes (issue 5).

    drake-standup bench [--scenario PATH|NAME] [--duration S] [--plant-duration S]
                                  [--repeat N] [--plant-steps N] [--out FILE]
                                  [--profile [PATH]]

In one process, --repeat times each:
  (a) plant_seat_hold: the seated hold under Drake's built-in joint PD, no controller,
      --plant-duration simulated seconds (a stationary hold: a few are enough);
  (b) closed_loop_recording: the scenario under the whole-body controller with the
      Meshcat recording on, --duration simulated seconds (default: the scenario's);
  (c) closed_loop: the same without the recording;
  (d) run_diagram: `drake-standup run` (what `python run_diagram.py` runs) as a user
      runs it, once, in a fresh process: imports, both simulations (the psi = t one
      beside the main one), the recording and every output; --no-run-diagram skips it;
  (e) with --against NAME: (c) of another scenario, as long, interleaved with (c) run by
      run (the machine's load shared alike), and the ratio of their speeds (e.g. the
      person's body against the scripted helper: --scenario body --against assisted).
Then the controller's tick split (WholeBodyController.timing_s()) and its share of
the closed loop's wall time, the plant step timed one step at a time, the model
build with a cold and a warm mesh cache, peak memory and the machine. One JSON
summary goes to stdout (and to --out); progress goes to stderr. sim_s_per_wall_s is
simulate()'s realtime_factor: simulated time over the wall time of the simulation
loop only. (b) and (c) both write their outputs into a temporary directory, so
call_wall_s (the whole simulate() call: build, loop, metrics, figures, diagram, and
for (b) the recording's HTML) differs between them by the recording alone.

A benchmark, not a test: the machine is shared and noisy, so read medians and
ratios, and compare figures from one run of this script only.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from drake_standup.config import DEFAULT_SCENARIO, Scenario, ScenarioError, load_scenario
from drake_standup.config.arguments import OneLineErrorParser, positive_float, positive_int
from drake_standup.config.inputs import check_output_dir
from drake_standup.control.controller import TIMING
from drake_standup.sim.simulate import RunResult
from drake_standup.studies.bench_measurements import (
    git_state,
    log,
    machine,
    profile_closed_loop,
    time_model_build,
    time_plant_step,
    time_run_diagram,
    timed_runs,
    us_stats,
)

DEFAULT_PROFILE = Path("out") / "bench_profile.prof"


def _stats(values: list[float]) -> dict:
    return {
        "median": statistics.median(values),
        "min": min(values),
        "max": max(values),
        "values": values,
    }


def _summary(results: list[RunResult], closed_loop: bool) -> dict:
    metrics = [r.metrics for r in results]
    summary = {
        "sim_s_per_wall_s": _stats([m["realtime_factor"] for m in metrics]),
        "sim_time_s": [m["sim_time_s"] for m in metrics],
        "loop_wall_s": [m["wall_time_s"] for m in metrics],
        "call_wall_s": [m["call_wall_s"] for m in metrics],
        "build_time_s_median": statistics.median(m["build_time_s"] for m in metrics),
        "repetitions": len(results),
    }
    if closed_loop:
        summary["stood_up"] = [
            {
                "success": m["success"],
                "failure_reason": m["failure_reason"],
                "standup_time_s": m.get("standup_time_s"),
                "qp_failures": m.get("qp_failures"),
            }
            for m in metrics
        ]
    recording = [m["recording_bytes"] for m in metrics if "recording_bytes" in m]
    if recording:
        summary["recording_bytes"] = recording
    return summary


def _tick_split(results: list[RunResult]) -> dict:
    """Median, p95 and mean per column of WholeBodyController.timing_s(), in us,
    over every tick of every run."""
    timing = np.concatenate([r.controller_timing_s for r in results])
    columns = [name.removesuffix("_s") + "_us" for name in TIMING]
    us = 1e6 * timing
    split = {name: us_stats(us[:, k]) for k, name in enumerate(columns)}
    # The parts are disjoint intervals inside the tick: what they leave of the
    # total is the rest of the update (posture, state writes).
    parts = us[:, :-1].sum(axis=1)
    split["unaccounted_us"] = {
        "median": float(np.median(us[:, -1] - parts)),
        "mean": float((us[:, -1] - parts).mean()),
    }
    split["ticks"] = len(us)
    return split


def _tick_share(results: list[RunResult], scenario: Scenario) -> dict:
    """The controller's share of the closed loop's wall time: its ticks' total
    compute time over the loop's wall time, per run (median over runs)."""
    shares = [float(r.controller_timing_s[:, -1].sum()) / r.metrics["wall_time_s"] for r in results]
    per_step = [
        r.metrics["wall_time_s"] / (r.metrics["sim_time_s"] / scenario.plant.time_step)
        for r in results
    ]
    return {
        "controller_share_of_loop_wall": statistics.median(shares),
        "loop_wall_per_plant_step_us": 1e6 * statistics.median(per_step),
        "plant_time_step_s": scenario.plant.time_step,
        "controller_period_s": scenario.controller_period_s,
    }


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = OneLineErrorParser(
        prog=prog,
        description=__doc__,
        epilog="example: drake-standup bench --scenario unassisted --repeat 1 --no-run-diagram",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--scenario",
        default=str(DEFAULT_SCENARIO),
        help="a scenario YAML file, or a shipped scenario's name (default: assisted)",
    )
    parser.add_argument(
        "--duration",
        type=positive_float,
        default=None,
        help="simulated s per closed-loop run (b, c); default: the scenario's duration_s",
    )
    parser.add_argument(
        "--plant-duration",
        type=positive_float,
        default=3.0,
        help="simulated s per plant-only seated hold (a); default 3",
    )
    parser.add_argument("--repeat", type=positive_int, default=3, help="runs of each; default 3")
    parser.add_argument(
        "--plant-steps",
        type=positive_int,
        default=300,
        help="single steps timed for the plant step; default 300",
    )
    parser.add_argument(
        "--no-run-diagram", action="store_true", help="skip (d), the whole run_diagram.py"
    )
    parser.add_argument(
        "--against",
        help="(e): a scenario to time (c) against, as --scenario names one (default: none)",
    )
    parser.add_argument("--out", type=Path, help="also write the JSON summary to this file")
    parser.add_argument(
        "--profile",
        type=Path,
        nargs="?",
        const=DEFAULT_PROFILE,
        help=f"cProfile one closed-loop run (c) into PATH (default {DEFAULT_PROFILE}) "
        "and a text top-40 into PATH with suffix .txt",
    )
    return parser


def _check_output_files(args: argparse.Namespace) -> None:
    """--out and --profile are files: their folders are checked before any simulation."""
    for flag, path in (("--out", args.out), ("--profile", args.profile)):
        if path is not None:
            if path.is_dir():
                raise ScenarioError(f"{flag}: '{path}' is a folder; accepted: a file path")
            check_output_dir(path.parent, flag)


def _measure(args: argparse.Namespace, scenario: Scenario, plant_scenario: Scenario) -> dict:
    """Every measurement, in the module docstring's order: the model build, the plant
    step, the runs (a), (b), (c) by those letters, the profile and (d) if asked."""
    log("model build, cold and warm mesh cache")
    build = time_model_build(scenario)
    log("plant step, one step at a time")
    plant_step = time_plant_step(plant_scenario, args.plant_steps)
    a = timed_runs(
        plant_scenario,
        "(a) plant_seat_hold",
        args.repeat,
        controller="seat_hold",
        record=False,
        outputs=False,
    )
    b = timed_runs(
        scenario,
        "(b) closed_loop_recording",
        args.repeat,
        controller="whole_body",
        record=True,
        outputs=True,
    )
    c, e = [], []
    against = _against(args, scenario)
    for k in range(args.repeat):  # (c) and (e) alternate, so both see the same load
        c += timed_runs(
            scenario,
            f"(c) closed_loop {k + 1}",
            1,
            controller="whole_body",
            record=False,
            outputs=True,
        )
        if against is not None:
            e += timed_runs(
                against,
                f"(e) against {k + 1}",
                1,
                controller="whole_body",
                record=False,
                outputs=True,
            )
    profile = profile_closed_loop(scenario, args.profile) if args.profile is not None else None
    run_diagram = None if args.no_run_diagram else time_run_diagram(args.scenario)
    return {
        "model_build": build,
        "plant_step": plant_step,
        "a": a,
        "b": b,
        "c": c,
        "e": e,
        "profile": profile,
        "run_diagram": run_diagram,
    }


def _against(args: argparse.Namespace, scenario: Scenario) -> Scenario | None:
    """--against's scenario, as long as the benchmarked one; None without it."""
    if args.against is None:
        return None
    against = load_scenario(args.against)
    against.duration_s = scenario.duration_s
    return against


def _against_report(args: argparse.Namespace, e: list[RunResult], closed_loop: float) -> dict:
    """(e)'s runs and how much slower (c) simulates than they do (1.3: 30 % slower)."""
    if not e:
        return {}
    against = _summary(e, closed_loop=True)
    return {
        "against": {"scenario": str(args.against), "closed_loop": against},
        "ratio_against_to_closed_loop": against["sim_s_per_wall_s"]["median"] / closed_loop,
    }


def _report(
    args: argparse.Namespace,
    scenario: Scenario,
    measured: dict,
    load_start: list[float],
    git_start: dict,
    t_bench: float,
) -> dict:
    """The JSON summary of the measurements (its git entry's changed_during_bench aside)."""
    a, b, c = measured["a"], measured["b"], measured["c"]
    runs = {
        "plant_seat_hold": _summary(a, closed_loop=False),
        "closed_loop_recording": _summary(b, closed_loop=True),
        "closed_loop": _summary(c, closed_loop=True),
    }
    median = {name: run["sim_s_per_wall_s"]["median"] for name, run in runs.items()}
    return {
        "scenario": str(args.scenario),
        "duration_s": {"closed_loop": scenario.duration_s, "plant_seat_hold": args.plant_duration},
        **runs,
        "ratio_closed_loop_recording_to_plant_seat_hold": (
            median["closed_loop_recording"] / median["plant_seat_hold"]
        ),
        "ratio_closed_loop_to_plant_seat_hold": median["closed_loop"] / median["plant_seat_hold"],
        "ratio_closed_loop_recording_to_closed_loop": (
            median["closed_loop_recording"] / median["closed_loop"]
        ),
        **_against_report(args, measured["e"], median["closed_loop"]),
        "controller_tick": {"closed_loop": _tick_split(c), "closed_loop_recording": _tick_split(b)},
        "controller_share": {
            "closed_loop": _tick_share(c, scenario),
            "closed_loop_recording": _tick_share(b, scenario),
        },
        "run_diagram": measured["run_diagram"],
        "plant_step": measured["plant_step"],
        "model_build": measured["model_build"],
        "profile": measured["profile"],
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "machine": machine(),
        "load_average_1_5_15": {"start": load_start, "end": list(os.getloadavg())},
        "git": git_start,
        "bench_wall_s": time.perf_counter() - t_bench,
    }


def main(argv: list[str] | None = None, prog: str = "python -m drake_standup.studies.bench") -> int:
    args = _parser(prog).parse_args(argv)
    t_bench = time.perf_counter()
    git_start, load_start = git_state(), list(os.getloadavg())
    try:
        _check_output_files(args)
        scenario = load_scenario(args.scenario)
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    plant_scenario = load_scenario(args.scenario)
    plant_scenario.duration_s = args.plant_duration
    if args.duration is not None:
        scenario.duration_s = args.duration

    # Anything a run prints (graphviz notices) must not reach the JSON on stdout.
    with contextlib.redirect_stdout(sys.stderr):
        measured = _measure(args, scenario, plant_scenario)

    summary = _report(args, scenario, measured, load_start, git_start, t_bench)
    summary["git"]["changed_during_bench"] = changed = git_state() != git_start
    if changed:
        log("warning: the working tree changed during the bench; its figures mix versions")
    text = json.dumps(summary, indent=2, allow_nan=False)
    print(text)
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
