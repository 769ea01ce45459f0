"""Time-step convergence study (issue 11): how coarse may the plant and controller step?

drake-standup convergence [--out DIR] [--workers N] [--scenarios NAME ...]
    [--steps-ms H ...] [--controller-ms P] [--set KEY=VALUE ...] [--fresh] [--docs DIR]

A study, not a test. It simulates scenarios/NAME.yaml (assisted, unassisted,
lateral and seated by default) with the plant stepped at each of 0.5, 1, 2, 4, 5, 8
and 10 ms and the controller at the same period, plus, at 2, 4 and 5 ms, the
controller at twice the plant step ("does a slower controller over a finer plant
pay?"). Every run is compared with the same scenario's run at 1 ms against issue 11's
bounds (comparison.py's constants). A 0.5 ms run of each scenario says how converged
that reference is itself: a bound that the 1 ms run fails against the 0.5 ms
run measures the scenario's sensitivity (a guard or gate that a tiny change
flips), not the step's error. So a run passes a bound when it is within the
bound of the 1 ms run, or no further from the 0.5 ms run than the 1 ms run is;
the strict verdict (against 1 ms only) is reported beside it. The default step
is chosen: the largest plant step at which every scenario passes.

Runs go to a Dask LocalCluster of single-threaded worker processes (or the
scheduler at --address; the workers must then share OUT's file system). Each run
writes OUT/runs/<scenario>_<step ms>_<controller period / step>/ (metrics.json,
signals.npz, inputs.json) and is reused by the next start when its inputs (the
scenario's text, duration, plant step and controller period) are unchanged;
--fresh simulates every run again. A change of the code is not an input: after
one, use --fresh. At the end: OUT/convergence.json (every run's numbers, errors,
pass or fail per bound, and the choice), OUT/convergence.md (the tables for the
README) and OUT/convergence.png (the errors over their bounds and the speed
against the step). --set changes every run's scenario alike (e.g.
robot.reflected_inertia=all: does the motors' inertia let a larger step converge?).

--controller-ms P keeps the controller at P at every plant step instead (no slower
variants; each step a whole divisor of P) and compares each run with the 1 ms step at
P: which plant step a controller at a robot's own rate needs. Under
--set robot.hardware=icub the steps go to hardware.plant_time_step_s and P to
hardware.rate_hz, e.g. --controller-ms 10 --steps-ms 1 2.5 5 (issue 49).
"""

from __future__ import annotations

import argparse
import math
import shutil
import sys
from pathlib import Path

from drake_standup.config import SCENARIO_DIR, ScenarioError, parse_scenario
from drake_standup.config.arguments import OneLineErrorParser, parse_set
from drake_standup.config.inputs import check_output_dir
from drake_standup.studies.convergence.cases import SCENARIOS, STEPS_MS, steps_divide
from drake_standup.studies.convergence.report import fmt
from drake_standup.studies.convergence.study import StudyResult, run_study


def main(
    argv: list[str] | None = None, prog: str = "python -m drake_standup.studies.convergence"
) -> int:
    """Parses argv, runs the study, prints what it wrote; 2 on a bad option."""
    args = _parser(prog).parse_args(argv)
    error = _options_error(args)
    if error is not None:
        print(f"error: {error}", file=sys.stderr)
        return 2
    scenarios = list(dict.fromkeys(args.scenarios))
    steps = sorted(set(args.steps_ms))
    try:  # a bad --set fails now, on every scenario, not in the workers
        overrides = _checked_overrides(args.set, scenarios)
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    try:
        result = run_study(
            scenarios,
            steps,
            args.out,
            workers=args.workers,
            address=args.address,
            fresh=args.fresh,
            overrides=overrides,
            controller_ms=args.controller_ms,
        )
    except OSError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: finished runs are kept in {args.out / 'runs'}; "
            "the same command reuses them",
            file=sys.stderr,
        )
        return 130
    _print_result(result, args.docs)
    return 0


def _parser(prog: str) -> argparse.ArgumentParser:
    """The command's options (the module docstring)."""
    parser = OneLineErrorParser(
        prog=prog,
        description=__doc__,
        epilog="example: drake-standup convergence --scenarios seated --steps-ms 1 4 --out out/c",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--out", type=Path, default=Path("out/convergence"), help="default out/convergence"
    )
    parser.add_argument(
        "--workers", type=int, default=2, help="LocalCluster worker processes (default 2)"
    )
    parser.add_argument(
        "--address", default=None, help="a Dask scheduler instead (workers must share OUT)"
    )
    parser.add_argument(
        "--scenarios",
        nargs="+",
        default=list(SCENARIOS),
        help="names in scenarios/ (default: %(default)s)",
    )
    parser.add_argument(
        "--steps-ms",
        nargs="+",
        type=float,
        default=list(STEPS_MS),
        help="plant steps, ms; 1 ms is the reference, a smaller one checks it "
        "(default: %(default)s)",
    )
    parser.add_argument(
        "--controller-ms",
        type=float,
        default=None,
        help="the controller at this period at every plant step (each a whole divisor of "
        "it), compared with the 1 ms step at the same period: a robot's own rate, e.g. 10 "
        "with --set robot.hardware=icub (default: the controller at the step)",
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a scenario key set in every run (YAML value; repeatable)",
    )
    parser.add_argument("--fresh", action="store_true", help="simulate every run again")
    parser.add_argument(
        "--docs", type=Path, default=None, help="also copy convergence.md and .png into DIR"
    )
    return parser


def _options_error(args: argparse.Namespace) -> str | None:
    """What is wrong with the options but --set (None: nothing), before any run."""
    if args.workers < 1:
        return f"--workers: {args.workers}; accepted: an integer >= 1"
    bad = [s for s in args.steps_ms if not (math.isfinite(s) and s > 0)]
    if bad:
        return f"--steps-ms: {bad[0]}; accepted: steps > 0 (ms)"
    if args.controller_ms is not None:
        step = steps_divide(args.steps_ms, args.controller_ms)
        if step is not None:
            return (
                f"--steps-ms: {step:g}; accepted: whole divisors of --controller-ms "
                f"({args.controller_ms:g}), e.g. {args.controller_ms / 2:g} or "
                f"{args.controller_ms / 4:g}"
            )
    shipped = sorted(p.stem for p in SCENARIO_DIR.glob("*.yaml"))
    unknown = [s for s in args.scenarios if s not in shipped]
    if unknown:
        return f"--scenarios: '{unknown[0]}' unknown; accepted: {', '.join(shipped)}"
    try:  # a folder that cannot be written fails now, not after the runs
        check_output_dir(args.out, "--out")
        if args.docs is not None:
            check_output_dir(args.docs, "--docs")
    except ScenarioError as err:
        return str(err)
    return None


def _checked_overrides(settings: list[str], scenarios: list[str]) -> list:
    """The --set pairs, each scenario parsed with them (ScenarioError on a bad one)."""
    overrides = [parse_set(text) for text in settings]
    for name in scenarios:
        path = SCENARIO_DIR / f"{name}.yaml"
        parse_scenario(path.read_text(), f"scenarios/{name}.yaml", overrides)
    return overrides


def _print_result(result: StudyResult, docs: Path | None) -> None:
    """The files written (copied into docs if given) and the study's summary line."""
    for path in result.files:
        print(f"wrote {path}")
    if docs is not None:
        docs.mkdir(parents=True, exist_ok=True)
        for path in result.files[1:]:
            shutil.copy2(path, docs / path.name)
            print(f"copied {path.name} to {docs}")
    n = len(result.records)
    work = (
        f"{result.computed} simulated in {result.wall_s / 60:.1f} min, {result.reused} reused"
        if result.computed
        else f"all {n} reused"
    )
    passed = sum(r["pass"] for r in result.records)
    choice = result.choice
    chosen = (
        f"chosen step: plant {choice['step_ms']:g} ms, controller "
        f"{choice['controller_period_ms']:g} ms ({fmt(choice['median_realtime_factor'])}x real "
        "time median)"
        if choice
        else "no step passes for every scenario"
    )
    print(f"convergence: {n} runs ({work}), {passed} within issue 11's bounds; {chosen}")
