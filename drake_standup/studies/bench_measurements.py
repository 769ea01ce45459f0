"""The benchmark's measurements (bench.py): timed runs of simulate(), the plant step timed
one step at a time, the model build with a cold and a warm mesh cache, a profiled run,
`drake-standup run` in a fresh process, the machine and the git state. Each returns what
bench.py's JSON summary reports of it; progress goes to stderr (log).
"""

from __future__ import annotations

import contextlib
import cProfile
import hashlib
import importlib.metadata
import os
import platform
import pstats
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import Scenario
from drake_standup.senses.wiring import joint_damping
from drake_standup.sim.diagram import add_seat_hold, build_diagram
from drake_standup.sim.simulate import RunResult, simulate
from drake_standup.world.scene import add_scene, set_seated_state, without_body

PROFILE_TOP = 40  # functions listed in the profile's text summary


def log(message: str) -> None:
    """message on stderr, as the bench's progress."""
    print(f"bench: {message}", file=sys.stderr, flush=True)


def _run(
    scenario: Scenario, label: str, *, controller: str, record: bool, out_dir: Path | None
) -> RunResult:
    t0 = time.perf_counter()
    result = simulate(scenario, out_dir, record=record, progress=False, controller=controller)
    result.metrics["call_wall_s"] = time.perf_counter() - t0
    log(
        f"{label}: {result.metrics['realtime_factor']:.3f} sim s / wall s "
        f"({result.metrics['sim_time_s']:.2f} s simulated in {result.metrics['wall_time_s']:.1f} s)"
    )
    return result


def timed_runs(
    scenario: Scenario, name: str, repeat: int, *, controller: str, record: bool, outputs: bool
) -> list[RunResult]:
    """repeat runs of scenario, each in a fresh temporary output folder if outputs."""
    results = []
    for i in range(repeat):
        with tempfile.TemporaryDirectory(prefix="bench_") as tmp:
            out_dir = Path(tmp) if outputs else None
            label = f"{name} {i + 1}/{repeat}"
            results.append(
                _run(scenario, label, controller=controller, record=record, out_dir=out_dir)
            )
    return results


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


def us_stats(us: np.ndarray) -> dict:
    """Median, p95 and mean of us."""
    return {
        "median": float(np.median(us)),
        "p95": float(np.percentile(us, 95)),
        "mean": float(us.mean()),
    }


def _step_stats(times_s: list[float]) -> dict:
    return us_stats(1e6 * np.asarray(times_s)) | {"steps": len(times_s)}


def time_plant_step(scenario: Scenario, steps: int) -> dict:
    """Wall time per plant step (plant.time_step) of the seated hold, one
    AdvanceTo per step:
    the bare plant and scene graph under the joint PD (fixed set point and gravity
    feed-forward), and the whole seat-hold diagram of (a)."""
    step_s = scenario.plant.time_step
    builder = DiagramBuilder()
    hold = scenario.seat_hold
    # The bare plant is the robot's scene: a helper's body needs its controller wired.
    pd_gains = (hold.kp_Nm_per_rad, hold.kd_Nms_per_rad)
    scene = add_scene(
        builder, without_body(scenario), pd_gains=pd_gains, joint_damping=joint_damping(scenario)
    )
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
        scene, scene.plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    )
    plant_only = _step_times_s(simulator, step_s, steps)

    built = build_diagram(scenario, None, "seat_hold")
    simulator = Simulator(built.diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    station = built.station
    set_seated_state(
        station.scene, station.plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    )
    diagram = _step_times_s(simulator, step_s, steps)
    return {
        "step_s": step_s,
        "plant_and_scene_graph_us": _step_stats(plant_only),
        "seat_hold_diagram_us": _step_stats(diagram),
    }


def time_run_diagram(scenario_path: str) -> dict:
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
    log(f"(d) run_diagram: {wall_s:.1f} s wall, exit {done.returncode}")
    return {
        "wall_s": wall_s,
        "returncode": done.returncode,
        "summary_line": lines[-1] if lines else done.stderr.strip()[-300:],
    }


def time_model_build(scenario: Scenario) -> dict:
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


def profile_closed_loop(scenario: Scenario, path: Path) -> dict:
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
    log(f"profile written to {path} and {text_path}")
    return {
        "prof": str(path),
        "text": str(text_path),
        "sim_s_per_wall_s_under_profiler": result.metrics["realtime_factor"],
    }


def machine() -> dict:
    """The CPUs, the Drake and Python versions and the platform."""
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


def git_state() -> dict:
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
