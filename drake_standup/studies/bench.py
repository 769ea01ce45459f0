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
      beside the main one), the recording and every output; --no-run-diagram skips it.
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
import cProfile
import hashlib
import importlib.metadata
import json
import os
import platform
import pstats
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import DEFAULT_SCENARIO, Scenario, ScenarioError, load_scenario
from drake_standup.config.arguments import OneLineErrorParser, positive_float, positive_int
from drake_standup.config.inputs import check_output_dir
from drake_standup.control.controller import TIMING
from drake_standup.sim.diagram import add_seat_hold, build_diagram
from drake_standup.sim.simulate import RunResult, simulate
from drake_standup.world.scene import add_scene, set_seated_state

DEFAULT_PROFILE = Path("out") / "bench_profile.prof"
PROFILE_TOP = 40  # functions listed in the profile's text summary


def _log(message: str) -> None:
    print(f"bench: {message}", file=sys.stderr, flush=True)


def _stats(values: list[float]) -> dict:
    return {
        "median": statistics.median(values),
        "min": min(values),
        "max": max(values),
        "values": values,
    }


def _run(
    scenario: Scenario, label: str, *, controller: str, record: bool, out_dir: Path | None
) -> RunResult:
    t0 = time.perf_counter()
    result = simulate(scenario, out_dir, record=record, progress=False, controller=controller)
    result.metrics["call_wall_s"] = time.perf_counter() - t0
    _log(
        f"{label}: {result.metrics['realtime_factor']:.3f} sim s / wall s "
        f"({result.metrics['sim_time_s']:.2f} s simulated in {result.metrics['wall_time_s']:.1f} s)"
    )
    return result


def _runs(
    scenario: Scenario, name: str, repeat: int, *, controller: str, record: bool, outputs: bool
) -> list[RunResult]:
    results = []
    for i in range(repeat):
        with tempfile.TemporaryDirectory(prefix="bench_") as tmp:
            out_dir = Path(tmp) if outputs else None
            label = f"{name} {i + 1}/{repeat}"
            results.append(
                _run(scenario, label, controller=controller, record=record, out_dir=out_dir)
            )
    return results


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
    split = {name: _us_stats(us[:, k]) for k, name in enumerate(columns)}
    # The parts are disjoint intervals inside the tick: what they leave of the
    # total is the rest of the update (posture, state writes).
    parts = us[:, :-1].sum(axis=1)
    split["unaccounted_us"] = {
        "median": float(np.median(us[:, -1] - parts)),
        "mean": float((us[:, -1] - parts).mean()),
    }
    split["ticks"] = len(us)
    return split


def _step_times_s(simulator: Simulator, step_s: float, steps: int) -> list[float]:
    """Advances one step at a time; wall time of each AdvanceTo."""
    context = simulator.get_context()
    simulator.Initialize()
    times = []
    for _ in range(steps):
        target = context.get_time() + step_s
        t0 = time.perf_counter()
        simulator.AdvanceTo(target)
        times.append(time.perf_counter() - t0)
    return times


def _us_stats(us: np.ndarray) -> dict:
    return {
        "median": float(np.median(us)),
        "p95": float(np.percentile(us, 95)),
        "mean": float(us.mean()),
    }


def _step_stats(times_s: list[float]) -> dict:
    return _us_stats(1e6 * np.asarray(times_s)) | {"steps": len(times_s)}


def _plant_step(scenario: Scenario, steps: int) -> dict:
    """Wall time per plant step (plant.time_step) of the seated hold, one
    AdvanceTo per step:
    the bare plant and scene graph under the joint PD (fixed set point and gravity
    feed-forward), and the whole seat-hold diagram of (a)."""
    step_s = scenario.plant.time_step
    builder = DiagramBuilder()
    hold = scenario.seat_hold
    scene = add_scene(builder, scenario, pd_gains=(hold.kp_Nm_per_rad, hold.kd_Nms_per_rad))
    instance = scene.robot.model_instance
    add_seat_hold(
        builder,
        scene,
        scenario,
        scene.plant.get_desired_state_input_port(instance),
        scene.plant.get_actuation_input_port(instance),
    )
    simulator = Simulator(builder.Build())
    ApplySimulatorConfig(scenario.simulator, simulator)
    set_seated_state(
        scene, scene.plant.GetMyMutableContextFromRoot(simulator.get_mutable_context()), scenario
    )
    plant_only = _step_times_s(simulator, step_s, steps)

    built = build_diagram(scenario, None, "seat_hold")
    simulator = Simulator(built.diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    station = built.station
    set_seated_state(
        station.scene,
        station.plant.GetMyMutableContextFromRoot(simulator.get_mutable_context()),
        scenario,
    )
    diagram = _step_times_s(simulator, step_s, steps)
    return {
        "step_s": step_s,
        "plant_and_scene_graph_us": _step_stats(plant_only),
        "seat_hold_diagram_us": _step_stats(diagram),
    }


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


def _run_diagram(scenario_path: str) -> dict:
    """`drake-standup run --scenario PATH --out TMP` in a fresh process: the
    wall time a user waits for the whole job, and its summary line."""
    with tempfile.TemporaryDirectory(prefix="bench_run_diagram_") as tmp:
        t0 = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-m", "drake_standup", "run", "--scenario", str(scenario_path)]
            + ["--out", tmp],
            capture_output=True,
            text=True,
            check=False,
            stdin=subprocess.DEVNULL,
        )
        wall_s = time.perf_counter() - t0
    lines = done.stdout.strip().splitlines()
    _log(f"(d) run_diagram: {wall_s:.1f} s wall, exit {done.returncode}")
    return {
        "wall_s": wall_s,
        "returncode": done.returncode,
        "summary_line": lines[-1] if lines else done.stderr.strip()[-300:],
    }


def _model_build(scenario: Scenario) -> dict:
    """build_diagram() with a cold mesh cache (a fresh $DRAKE_STANDUP_CACHE: every
    STL converted and decimated) and then warm (same cache). A first build with the
    usual cache warms the process (imports, first parses) so the two differ by the
    cache alone."""
    t0 = time.perf_counter()
    build_diagram(scenario, None)
    first_s = time.perf_counter() - t0
    saved = os.environ.get("DRAKE_STANDUP_CACHE")
    cache = Path(tempfile.mkdtemp(prefix="bench_cache_"))
    os.environ["DRAKE_STANDUP_CACHE"] = str(cache)
    try:
        t0 = time.perf_counter()
        build_diagram(scenario, None)
        cold_s = time.perf_counter() - t0
        converted = len(list((cache / "meshes").glob("*.obj")))
        t0 = time.perf_counter()
        build_diagram(scenario, None)
        warm_s = time.perf_counter() - t0
    finally:
        if saved is None:
            del os.environ["DRAKE_STANDUP_CACHE"]
        else:
            os.environ["DRAKE_STANDUP_CACHE"] = saved
        shutil.rmtree(cache, ignore_errors=True)
    return {
        "cold_cache_s": cold_s,
        "warm_cache_s": warm_s,
        "meshes_converted_cold": converted,
        "first_build_in_process_s": first_s,
    }


def _profile(scenario: Scenario, path: Path) -> dict:
    """cProfile of one closed-loop run (c); .prof and a text summary beside it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    profiler = cProfile.Profile()
    with tempfile.TemporaryDirectory(prefix="bench_") as tmp:
        profiler.enable()
        result = simulate(
            scenario, Path(tmp), record=False, progress=False, controller="whole_body"
        )
        profiler.disable()
    profiler.dump_stats(path)
    text_path = path.with_suffix(".txt")
    with text_path.open("w") as f:
        for key in ("cumulative", "tottime"):
            f.write(f"Top {PROFILE_TOP} by {key} time\n")
            pstats.Stats(str(path), stream=f).sort_stats(key).print_stats(PROFILE_TOP)
    _log(f"profile written to {path} and {text_path}")
    return {
        "prof": str(path),
        "text": str(text_path),
        "sim_s_per_wall_s_under_profiler": result.metrics["realtime_factor"],
    }


def _machine() -> dict:
    cpu_model = None
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu_model = line.split(":", 1)[1].strip()
                break
    return {
        "nproc": len(os.sched_getaffinity(0)),
        "cpu_count": os.cpu_count(),
        "cpu_model": cpu_model,
        "drake": importlib.metadata.version("drake"),
        "python": platform.python_version(),
        "platform": platform.platform(),
    }


def _git() -> dict:
    """Commit, uncommitted files and a digest of their changes, so the figures can be
    tied to the code (models and scenarios are read at every build, so a tree that
    changes during the bench mixes versions)."""

    def git(*args: str) -> str:
        try:
            done = subprocess.run(
                ["git", *args],
                cwd=Path(__file__).parent,
                capture_output=True,
                text=True,
                check=False,
            )
        except OSError:
            return ""
        return done.stdout if done.returncode == 0 else ""

    # Porcelain lines are "XY path": two status letters, a space, the path.
    status = git("status", "--porcelain").splitlines()
    return {
        "commit": git("rev-parse", "HEAD").strip() or None,
        "uncommitted": [line[3:] for line in status],
        "diff_sha1": hashlib.sha1(git("diff", "HEAD", "--binary").encode()).hexdigest(),
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


def main(argv: list[str] | None = None, prog: str = "python -m drake_standup.studies.bench") -> int:
    args = _parser(prog).parse_args(argv)
    t_bench = time.perf_counter()
    git_start, load_start = _git(), list(os.getloadavg())
    try:
        # --out and --profile are files: their folders are checked before any simulation.
        for flag, path in (("--out", args.out), ("--profile", args.profile)):
            if path is not None:
                if path.is_dir():
                    raise ScenarioError(f"{flag}: '{path}' is a folder; accepted: a file path")
                check_output_dir(path.parent, flag)
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
        _log("model build, cold and warm mesh cache")
        build = _model_build(scenario)
        _log("plant step, one step at a time")
        plant_step = _plant_step(plant_scenario, args.plant_steps)
        a = _runs(
            plant_scenario,
            "(a) plant_seat_hold",
            args.repeat,
            controller="seat_hold",
            record=False,
            outputs=False,
        )
        b = _runs(
            scenario,
            "(b) closed_loop_recording",
            args.repeat,
            controller="whole_body",
            record=True,
            outputs=True,
        )
        c = _runs(
            scenario,
            "(c) closed_loop",
            args.repeat,
            controller="whole_body",
            record=False,
            outputs=True,
        )
        profile = _profile(scenario, args.profile) if args.profile is not None else None
        run_diagram = None if args.no_run_diagram else _run_diagram(args.scenario)

    runs = {
        "plant_seat_hold": _summary(a, closed_loop=False),
        "closed_loop_recording": _summary(b, closed_loop=True),
        "closed_loop": _summary(c, closed_loop=True),
    }
    median = {name: run["sim_s_per_wall_s"]["median"] for name, run in runs.items()}
    summary = {
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
        "controller_tick": {"closed_loop": _tick_split(c), "closed_loop_recording": _tick_split(b)},
        "controller_share": {
            "closed_loop": _tick_share(c, scenario),
            "closed_loop_recording": _tick_share(b, scenario),
        },
        "run_diagram": run_diagram,
        "plant_step": plant_step,
        "model_build": build,
        "profile": profile,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "machine": _machine(),
        "load_average_1_5_15": {"start": load_start, "end": list(os.getloadavg())},
        "git": git_start,
        "bench_wall_s": time.perf_counter() - t_bench,
    }
    summary["git"]["changed_during_bench"] = changed = _git() != git_start
    if changed:
        _log("warning: the working tree changed during the bench; its figures mix versions")
    text = json.dumps(summary, indent=2, allow_nan=False)
    print(text)
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
