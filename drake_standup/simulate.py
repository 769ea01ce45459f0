"""Run one scenario: build, simulate, collect metrics and outputs.

The one function that run_diagram.py, the benchmark and the sweeps call.
"""

from __future__ import annotations

import copy
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from pydrake.common.yaml import yaml_dump_typed
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import EventStatus

from drake_standup import outputs
from drake_standup.config import Scenario
from drake_standup.controller import WholeBodyController
from drake_standup.diagram import StandupDiagram, build_diagram
from drake_standup.perturbations import apply_model_errors
from drake_standup.progress import ProgressBar
from drake_standup.scene import erect_com_height_m, set_seated_state

if TYPE_CHECKING:
    from drake_standup.live import LiveSession


@dataclass
class RunResult:
    metrics: dict
    files: dict[str, Path] = field(default_factory=dict)
    # The run's time series on one time grid, as signals.npz holds them
    # (make_signals; README, "signals.npz").
    signals: dict[str, np.ndarray] = field(default_factory=dict)
    # WholeBodyController.timing_s(): per-tick compute times, (ticks, 5) in the
    # columns of WholeBodyController.TIMING; None without that controller.
    controller_timing_s: np.ndarray | None = None

    @property
    def times_s(self) -> np.ndarray:
        return self.signals["time_s"]

    @property
    def com_W(self) -> np.ndarray:
        """(N, 3)."""
        return self.signals["com_W"]

    @property
    def pad_forces_W(self) -> np.ndarray:
        """(N, n_pads, 3) world force on each pad."""
        return self.signals["pad_forces_W"]

    @property
    def pad_names(self) -> list[str]:
        return [str(n) for n in self.signals["pad_names"]]


def make_meshcat() -> Meshcat:
    """Meshcat on localhost only, on a free port (parallel runs don't clash)."""
    return Meshcat(MeshcatParams(host="localhost", port=0, show_stats_plot=False))


def simulate(
    scenario: Scenario,
    out_dir: Path | None = None,
    *,
    record: bool = True,
    progress: bool = True,
    baseline: bool = False,
    controller: str = "whole_body",
    chunk_s: float = 0.05,
    live: LiveSession | None = None,
) -> RunResult:
    """Simulates scenario; writes recording, metrics, figures and diagram into out_dir.

    baseline: also simulate the same scenario with advancement disabled (psi = t),
    for the faded reference of figure_advancement.png and the metric
    standup_time_s_without_advancement. Where nothing could advance psi (no
    human, or advancement already off) the run is its own baseline.
    controller: 'whole_body', or 'seat_hold' (the plant-only benchmark).
    live: a live.LiveSession (its Meshcat, its human, called after each chunk).
    """
    pending = None
    if baseline and scenario.advancement.enabled and _human_acts(scenario):
        base_scenario = copy.deepcopy(scenario)
        base_scenario.advancement.enabled = False
        pending = _Baseline(base_scenario, controller, chunk_s)
    try:
        return _simulate_one(
            scenario,
            out_dir,
            record=record,
            progress=progress,
            chunk_s=chunk_s,
            label="simulating",
            baseline=pending,
            controller=controller,
            live=live,
        )
    except BaseException:
        if pending is not None:
            pending.cancel()
        raise


class _Baseline:
    """The psi = t run, simulated beside the main run in a Python process of
    its own (on two cores it then costs no wall time). The scenario goes to
    it as YAML, signals.npz and metrics.json come back through a temporary
    folder. Where that process fails (a notice gives its last error line),
    the run is simulated here instead."""

    def __init__(self, scenario: Scenario, controller: str, chunk_s: float):
        self._scenario = scenario
        self._controller = controller
        self._chunk_s = chunk_s
        self._dir = Path(tempfile.mkdtemp(prefix="drake_standup_baseline_"))
        (self._dir / "scenario.yaml").write_text(yaml_dump_typed(scenario))
        command = [sys.executable, "-m", "drake_standup.simulate", "--baseline-dir"]
        command += [str(self._dir), "--controller", controller, "--chunk", repr(chunk_s)]
        self._stderr = open(self._dir / "stderr.txt", "w")  # noqa: SIM115 - closed in result()
        # The child imports this very package, installed or not.
        env = dict(os.environ)
        package_root = str(Path(__file__).resolve().parent.parent)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [package_root, env.get("PYTHONPATH")]))
        self._process = subprocess.Popen(
            command,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=self._stderr,
            env=env,
        )

    def result(self) -> RunResult:
        try:
            returncode = self._process.wait()
            self._stderr.close()
            if returncode == 0:
                return RunResult(
                    json.loads((self._dir / "metrics.json").read_text()),
                    signals=outputs.load_signals(self._dir / "signals.npz"),
                )
            lines = (self._dir / "stderr.txt").read_text().strip().splitlines()
            print(
                f"notice: the psi = t run's process failed ({lines[-1] if lines else returncode});"
                " simulating it here",
                file=sys.stderr,
            )
            return _simulate_baseline(self._scenario, self._controller, self._chunk_s)
        finally:
            shutil.rmtree(self._dir, ignore_errors=True)

    def cancel(self) -> None:
        self._process.kill()
        self._process.wait()
        self._stderr.close()
        shutil.rmtree(self._dir, ignore_errors=True)


def _simulate_baseline(scenario: Scenario, controller: str, chunk_s: float) -> RunResult:
    """The psi = t run itself: no recording, no progress bar, no outputs."""
    return _simulate_one(
        scenario,
        None,
        record=False,
        progress=False,
        chunk_s=chunk_s,
        label="baseline (psi = t)",
        controller=controller,
    )


def _baseline_main(argv: list[str]) -> int:
    """Entry of the psi = t run's process (see _Baseline)."""
    import argparse

    from drake_standup.config import parse_scenario

    parser = argparse.ArgumentParser()
    parser.add_argument("--baseline-dir", type=Path, required=True)
    parser.add_argument("--controller", required=True)
    parser.add_argument("--chunk", type=float, required=True)
    args = parser.parse_args(argv)
    scenario = parse_scenario((args.baseline_dir / "scenario.yaml").read_text(), "baseline")
    result = _simulate_baseline(scenario, args.controller, args.chunk)
    outputs.write_signals(args.baseline_dir / "signals.npz", result.signals)
    outputs.write_metrics(args.baseline_dir / "metrics.json", result.metrics)
    return 0


def _human_acts(scenario: Scenario) -> bool:
    return scenario.human.mode == "reactive" or bool(scenario.human.pulls)


def _simulate_one(
    scenario: Scenario,
    out_dir: Path | None,
    *,
    record: bool,
    progress: bool,
    chunk_s: float,
    label: str,
    controller: str,
    baseline: _Baseline | None = None,
    live: LiveSession | None = None,
) -> RunResult:
    if live is not None:
        meshcat, make_human = live.meshcat, live.make_human
    else:
        meshcat, make_human = (make_meshcat() if record else None), None
    t_build = time.perf_counter()
    built = build_diagram(scenario, meshcat, controller, make_human)
    build_time_s = time.perf_counter() - t_build

    simulator = Simulator(built.diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    root_context = simulator.get_mutable_context()
    plant = built.scene.plant
    plant_context = plant.GetMyMutableContextFromRoot(root_context)
    set_seated_state(built.scene, plant_context, scenario)
    # The simulated robot only: every other system keeps its own nominal context.
    apply_model_errors(built.scene, plant_context, scenario)

    fall = _FallMonitor(built, scenario)
    simulator.set_monitor(fall)
    if meshcat is not None:
        vis = scenario.visualization
        meshcat.SetCameraPose(np.array(vis.camera_xyz_m), np.array(vis.target_xyz_m))
        built.visualizer.StartRecording(set_transforms_while_recording=live is not None)

    failure_reason = None
    bar = ProgressBar(scenario.duration_s, label) if progress else None
    t_wall = time.perf_counter()
    # Chunk ends on the plant's step grid: an end a rounding error off an
    # event time makes the integrator take a ~1e-17 s step (measured: 8% more
    # integrator steps at 5 ms).
    step_s = scenario.plant.time_step
    if step_s > 0.0:
        chunk_s = step_s * max(1, round(chunk_s / step_s))
    try:
        simulator.Initialize()
        if live is not None:
            live.started(simulator, built, fall)
        chunk = 0
        while root_context.get_time() < scenario.duration_s - 1e-9:
            chunk += 1
            target = min(chunk * chunk_s, scenario.duration_s)
            status = simulator.AdvanceTo(target)
            elapsed = time.perf_counter() - t_wall
            if bar is not None:
                rate = root_context.get_time() / max(elapsed, 1e-9)
                bar.update(root_context.get_time(), f"{rate:.2f}x real time")
            if status.reason() == status.ReturnReason.kReachedTerminationCondition:
                failure_reason = fall.reason
                break
            if live is not None and live.after_chunk(simulator, built):
                break
    except RuntimeError as err:
        failure_reason = "simulation error: " + " ".join(str(err).split())[:300]
    wall_time_s = time.perf_counter() - t_wall
    if live is not None and failure_reason is None:
        failure_reason = live.fell  # a fall that no Reset undid
    if bar is not None:
        bar.close()

    result = _collect(built, root_context, scenario)
    if built.controller is not None:
        result.controller_timing_s = built.controller.timing_s()
    sim_time_s = root_context.get_time()
    # Success: standing at the end, having stood (standup_time_s: standing held 0.2 s).
    standing = result.metrics.get("standing_at_end", False) and (
        result.metrics.get("standup_time_s") is not None
    )
    if failure_reason is None and built.controller is not None and not standing:
        if (
            result.metrics.get("held_back_s", 0.0) > 0.0
            and result.metrics.get("standup_time_s") is None
        ):
            failure_reason = "held back: hindering pull"
        else:
            failure_reason = (
                "did not stand up"
                if result.metrics.get("standup_time_s") is None
                else "stood up but was not standing at the end"
            )
    result.metrics.update(
        success=failure_reason is None,
        failure_reason=failure_reason,
        sim_time_s=sim_time_s,
        wall_time_s=wall_time_s,
        realtime_factor=sim_time_s / wall_time_s if wall_time_s > 0 else None,
        build_time_s=build_time_s,
        robot_model=scenario.robot.model,
    )
    result.metrics = {k: result.metrics[k] for k in _ordered(result.metrics)}

    base = None
    if baseline is not None:
        base = baseline.result()
        result.metrics["standup_time_s_without_advancement"] = base.metrics.get("standup_time_s")
    if out_dir is not None:
        out_dir = Path(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        if meshcat is not None:
            built.visualizer.StopRecording()
            built.visualizer.PublishRecording()
            path = out_dir / "recording.html"
            result.metrics["recording_bytes"] = outputs.write_recording(meshcat, path)
            result.files["recording"] = path
        for p in outputs.export_diagram(built.diagram, out_dir / "diagrams"):
            result.files[p.suffix.lstrip(".")] = p
        path = out_dir / "signals.npz"
        outputs.write_signals(path, result.signals)
        result.files["signals"] = path
        # Every value simulated, as a scenario file (--scenario reruns it).
        path = out_dir / "scenario.yaml"
        path.write_text(yaml_dump_typed(scenario))
        result.files["scenario"] = path
        # The figures draw the arrays signals.npz holds (the round trip is tested).
        entries = result.metrics.get("state_entry_times_s", [])
        path = out_dir / "figure_advancement.png"
        outputs.figure_advancement(result.signals, base.signals if base else None, entries, path)
        result.files["figure_advancement"] = path
        path = out_dir / "figure_tracking.png"
        outputs.figure_tracking(result.signals, entries, path)
        result.files["figure_tracking"] = path
        path = out_dir / "metrics.json"
        outputs.write_metrics(path, result.metrics)
        result.files["metrics"] = path
    return result


def _ordered(metrics: dict) -> list[str]:
    head = ["success", "failure_reason", "sim_time_s", "wall_time_s", "realtime_factor"]
    return [k for k in head if k in metrics] + [k for k in metrics if k not in head]


class _FallMonitor:
    """Simulator monitor: stops the run when the robot has fallen or the
    controller's QP has stayed infeasible for max_qp_failure_streak_s.

    Checks the floating base only (cheap each step): its height, and its
    horizontal distance from where it started.
    """

    def __init__(self, built: StandupDiagram, scenario: Scenario):
        self._plant = built.scene.plant
        self._instance = built.scene.robot.model_instance
        self._min_z = scenario.fall.min_root_height_m
        self._max_xy = scenario.fall.max_com_horizontal_m
        self._xy0 = np.array(scenario.initial.base_xyz_m[:2])
        self._controller = built.controller
        self._diagnostics = (
            None if built.controller is None else built.controller.GetOutputPort("diagnostics")
        )
        self._max_streak_s = scenario.fall.max_qp_failure_streak_s
        self._failing_since: float | None = None
        self.reason: str | None = None

    def reset(self) -> None:
        """Forgets a fall and a run of QP failures (the live mode's Reset)."""
        self._failing_since = None
        self.reason = None

    def __call__(self, root_context) -> EventStatus:
        context = self._plant.GetMyContextFromRoot(root_context)
        q = self._plant.GetPositions(context, self._instance)
        p_WB = q[4:7]  # floating base: quaternion (4), then position (3)
        if p_WB[2] < self._min_z:
            self.reason = (
                f"fall: root_link height {p_WB[2]:.3f} m < {self._min_z} m "
                f"at t = {root_context.get_time():.3f} s"
            )
        elif (moved := math.hypot(p_WB[0] - self._xy0[0], p_WB[1] - self._xy0[1])) > self._max_xy:
            self.reason = (
                f"fall: root_link moved {moved:.3f} m "
                f"horizontally at t = {root_context.get_time():.3f} s"
            )
        elif self._controller is not None:
            self._check_qp(root_context)
        if self.reason is not None:
            return EventStatus.ReachedTermination(None, self.reason)
        return EventStatus.DidNothing()

    def _check_qp(self, root_context) -> None:
        t = root_context.get_time()
        context = self._controller.GetMyContextFromRoot(root_context)
        qp_ok = self._diagnostics.Eval(context)[0]
        if qp_ok:
            self._failing_since = None
        elif self._failing_since is None:
            self._failing_since = t
        elif t - self._failing_since >= self._max_streak_s:
            self.reason = (
                f"controller: QP infeasible since t = {self._failing_since:.3f} s "
                f"({t - self._failing_since:.2f} s)"
            )


def make_signals(built: StandupDiagram, root_context) -> dict[str, np.ndarray]:
    """Every logger's series as named arrays on one time grid (rows = samples):
    what signals.npz holds, and what the metrics and figures are computed from."""
    logs = {}
    for name, logger in built.logs.items():
        log = logger.FindLog(root_context)
        logs[name] = (log.sample_times(), log.data())
    t = logs["com_W"][0].copy()
    for name, (times, _) in logs.items():
        if not np.array_equal(times, t):
            raise RuntimeError(f"logger {name} is not on the common time grid")

    def rows(name: str) -> np.ndarray:
        return logs[name][1].T.copy()

    state = rows("robot_state")
    nq = built.scene.plant.num_positions(built.scene.robot.model_instance)
    joints = built.joints
    pad_forces = rows("pad_forces_W").reshape(len(t), len(built.pad_groups), 3)
    segment = rows("segment")
    reference = rows("com_reference")
    signals = {
        "time_s": t,
        "com_W": rows("com_W"),
        "com_reference_W": reference[:, 0:3],
        "com_reference_velocity_W": reference[:, 3:6],
        "com_reference_acceleration_W": reference[:, 6:9],
        "psi": rows("psi")[:, 0],
        "psi_dot": rows("psi_dot")[:, 0],
        "alpha": rows("alpha")[:, 0],
        "state": np.rint(rows("standup_state")[:, 0]).astype(np.int8),
        "segment_psi_entry": segment[:, 0],
        "segment_psi_length": segment[:, 1],
        "hand_wrenches_W": rows("hand_wrenches_W"),
        "pad_names": np.array(list(built.pad_groups), dtype=str),
        "pad_groups": np.array(list(built.pad_groups.values()), dtype=str),
        "pad_forces_W": pad_forces,
        "pad_normal_force_N": pad_forces[:, :, 2].copy(),
        "base_quaternion_wxyz": state[:, 0:4],
        "base_position_W": state[:, 4:7],
        "joint_names": np.array(joints.names, dtype=str),
        "joint_positions_rad": state[:, joints.q_index],
        "joint_velocities_rad_per_s": state[:, nq + joints.v_index],
        "joint_torques_Nm": rows("net_actuation"),
    }
    if "controller_diagnostics" in logs:
        diagnostics = rows("controller_diagnostics")
        signals["qp_ok"] = diagnostics[:, 0] > 0.5
        signals["qp_failures"] = diagnostics[:, 1].astype(np.int64)
        signals["joint_limit_slack"] = diagnostics[:, 10]
        signals["qp_relaxed"] = diagnostics[:, 13].astype(np.int64)
        signals["com_lean_W"] = np.c_[diagnostics[:, 11:13], np.zeros(len(t))]
        # The controller's model mass over the nominal, as it weighed the robot seated.
        signals["model_mass_scale"] = diagnostics[:, 14]
        # What the QP asked of each of its contacts (NaN where it failed): against
        # pad_normal_force_N it shows where the controller's contact model is wrong.
        signals["commanded_contacts"] = np.array(WholeBodyController.CONTACTS, dtype=str)
        signals["commanded_normal_force_N"] = diagnostics[:, 4:9]
    if "push_force_W" in logs:
        signals["push_force_W"] = rows("push_force_W")
    if "held_back" in logs:
        held = rows("held_back")
        signals["hindered"] = held[:, 0] > 0.5
        signals["held_back_s"] = held[:, 1]
    return signals


def _collect(built: StandupDiagram, root_context, scenario: Scenario) -> RunResult:
    """Reads every logger and turns the signals into metrics."""
    plant = built.scene.plant
    instance = built.scene.robot.model_instance
    signals = make_signals(built, root_context)
    result = RunResult({}, signals=signals)
    # The model's (nominal) mass, which the controller knows, and the simulated
    # one (perturbation.mass_scale), whose weight the contacts carry.
    mass_kg = plant.CalcTotalMass(plant.CreateDefaultContext(), [instance])
    simulated_mass_kg = plant.CalcTotalMass(plant.GetMyContextFromRoot(root_context), [instance])
    g = -plant.gravity_field().gravity_vector()[2]
    metrics = outputs.seated_metrics(signals, weight_N=simulated_mass_kg * g)
    metrics["robot_mass_kg"] = mass_kg
    metrics["simulated_mass_kg"] = simulated_mass_kg
    entry_times = built.state_machine.mode(
        built.state_machine.GetMyContextFromRoot(root_context)
    ).entry_times_s
    psi_now = built.advancement.GetOutputPort("psi").Eval(
        built.advancement.GetMyContextFromRoot(root_context)
    )[0]
    metrics.update(outputs.advancement_metrics(psi_now, signals["psi_dot"], entry_times))
    metrics.update(
        outputs.standup_metrics(
            signals,
            metrics["state_entry_times_s"],
            standing_height_m=erect_com_height_m(
                built.scene, scenario, scenario.phases.rise.posture_rad
            ),
        )
    )
    if "qp_failures" in signals:
        metrics["qp_failures"] = int(signals["qp_failures"][-1]) if len(signals["time_s"]) else 0
    if "joint_limit_slack" in signals and len(signals["time_s"]):
        slack = signals["joint_limit_slack"]
        metrics["joint_limit_slack_peak"] = float(slack.max())
        metrics["joint_limit_slack_integral"] = float(
            np.sum(slack) * (signals["time_s"][1] - signals["time_s"][0]) if len(slack) > 1 else 0.0
        )
    if "qp_relaxed" in signals and len(signals["time_s"]):
        # Ticks the QP was solved only with its contacts relaxed (control/qp.py).
        metrics["qp_relaxed_ticks"] = int(signals["qp_relaxed"][-1])
    if "model_mass_scale" in signals and len(signals["time_s"]):
        # The robot's mass as the controller estimated it (weighing itself seated).
        metrics["model_mass_kg"] = float(signals["model_mass_scale"][-1] * mass_kg)
    if "held_back_s" in signals and len(signals["time_s"]):
        # How long the stand-up waited for a pull against it to stop (state machine).
        metrics["held_back_s"] = float(signals["held_back_s"][-1])
    torques = signals["joint_torques_Nm"]
    metrics["max_abs_torque_Nm"] = float(np.abs(torques).max()) if torques.size else None
    result.metrics = metrics
    return result


if __name__ == "__main__":
    sys.exit(_baseline_main(sys.argv[1:]))
