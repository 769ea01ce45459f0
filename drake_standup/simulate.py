"""Run one scenario: build, simulate, collect metrics and outputs.

The one function that run_diagram.py, the benchmark and the sweeps call.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import EventStatus

from drake_standup import outputs
from drake_standup.config import Scenario
from drake_standup.diagram import StandupDiagram, build_diagram
from drake_standup.perturbations import apply_model_errors
from drake_standup.progress import ProgressBar
from drake_standup.scene import set_seated_state

GRAVITY_MPS2 = 9.81


@dataclass
class RunResult:
    metrics: dict
    files: dict[str, Path] = field(default_factory=dict)
    # Logged signal name -> (sample times (N,), data (size, N)).
    signals: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    pad_groups: dict[str, str] = field(default_factory=dict)  # pad -> group, log order
    # WholeBodyController.timing_s(): per-tick compute times, (ticks, 5) in the
    # columns of WholeBodyController.TIMING; None without that controller.
    controller_timing_s: np.ndarray | None = None

    @property
    def times_s(self) -> np.ndarray:
        return self.signals["com_W"][0]

    @property
    def com_W(self) -> np.ndarray:
        return self.signals["com_W"][1]

    @property
    def pad_forces_W(self) -> np.ndarray:
        """(n_pads, 3, N) world force on each pad."""
        return self.signals["pad_forces_W"][1].reshape(len(self.pad_groups), 3, -1)

    @property
    def pad_names(self) -> list[str]:
        return list(self.pad_groups)


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
) -> RunResult:
    """Simulates scenario; writes recording, metrics, figures and diagram into out_dir.

    baseline: also simulate the same scenario with advancement disabled (psi = t),
    for the faded reference of figure_advancement.png and the metric
    standup_time_s_without_advancement. Where nothing could advance psi (no
    human, or advancement already off) the run is its own baseline.
    controller: 'whole_body', or 'seat_hold' (the plant-only benchmark).
    """
    base = None
    if baseline and scenario.advancement.enabled and _human_acts(scenario):
        base_scenario = copy.deepcopy(scenario)
        base_scenario.advancement.enabled = False
        base = _simulate_one(
            base_scenario,
            None,
            record=False,
            progress=progress,
            chunk_s=chunk_s,
            label="baseline (psi = t)",
            controller=controller,
        )
    result = _simulate_one(
        scenario,
        out_dir,
        record=record,
        progress=progress,
        chunk_s=chunk_s,
        label="simulating",
        baseline=base,
        controller=controller,
    )
    return result


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
    baseline: RunResult | None = None,
) -> RunResult:
    meshcat = make_meshcat() if record else None
    t_build = time.perf_counter()
    built = build_diagram(scenario, meshcat, controller)
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
        built.visualizer.StartRecording(set_transforms_while_recording=False)

    failure_reason = None
    bar = ProgressBar(scenario.duration_s, label) if progress else None
    t_wall = time.perf_counter()
    try:
        simulator.Initialize()
        while root_context.get_time() < scenario.duration_s - 1e-9:
            target = min(root_context.get_time() + chunk_s, scenario.duration_s)
            status = simulator.AdvanceTo(target)
            elapsed = time.perf_counter() - t_wall
            if bar is not None:
                rate = root_context.get_time() / max(elapsed, 1e-9)
                bar.update(root_context.get_time(), f"{rate:.2f}x real time")
            if status.reason() == status.ReturnReason.kReachedTerminationCondition:
                failure_reason = fall.reason
                break
    except RuntimeError as err:
        failure_reason = "simulation error: " + " ".join(str(err).split())[:300]
    wall_time_s = time.perf_counter() - t_wall
    if bar is not None:
        bar.close()

    result = _collect(built, root_context, scenario)
    if built.controller is not None:
        result.controller_timing_s = built.controller.timing_s()
    sim_time_s = root_context.get_time()
    standing = result.metrics.get("standing_at_end", False)
    if failure_reason is None and built.controller is not None and not standing:
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

    if baseline is not None:
        result.metrics["standup_time_s_without_advancement"] = baseline.metrics.get(
            "standup_time_s"
        )
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
        entries = result.metrics.get("state_entry_times_s", [])
        path = out_dir / "figure_advancement.png"
        outputs.figure_advancement(
            result.signals, baseline.signals if baseline else None, entries, path
        )
        result.files["figure_advancement"] = path
        path = out_dir / "figure_tracking.png"
        outputs.figure_tracking(result.signals, built.pad_groups, entries, path)
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
        self._max_streak_s = scenario.fall.max_qp_failure_streak_s
        self._failing_since: float | None = None
        self.reason: str | None = None

    def __call__(self, root_context) -> EventStatus:
        context = self._plant.GetMyContextFromRoot(root_context)
        q = self._plant.GetPositions(context, self._instance)
        p_WB = q[4:7]  # floating base: quaternion (4), then position (3)
        if p_WB[2] < self._min_z:
            self.reason = (
                f"fall: root_link height {p_WB[2]:.3f} m < {self._min_z} m "
                f"at t = {root_context.get_time():.3f} s"
            )
        elif np.linalg.norm(p_WB[:2] - self._xy0) > self._max_xy:
            self.reason = (
                f"fall: root_link moved {np.linalg.norm(p_WB[:2] - self._xy0):.3f} m "
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
        qp_ok = self._controller.GetOutputPort("diagnostics").Eval(context)[0]
        if qp_ok:
            self._failing_since = None
        elif self._failing_since is None:
            self._failing_since = t
        elif t - self._failing_since >= self._max_streak_s:
            self.reason = (
                f"controller: QP infeasible since t = {self._failing_since:.3f} s "
                f"({t - self._failing_since:.2f} s)"
            )


def _collect(built: StandupDiagram, root_context, scenario: Scenario) -> RunResult:
    """Reads every logger and turns the signals into metrics."""
    plant = built.scene.plant
    instance = built.scene.robot.model_instance
    signals = {}
    for name, logger in built.logs.items():
        log = logger.FindLog(root_context)
        signals[name] = (log.sample_times().copy(), log.data().copy())
    result = RunResult({}, signals=signals, pad_groups=dict(built.pad_groups))
    # The model's (nominal) mass, which the controller knows, and the simulated
    # one (perturbation.mass_scale), whose weight the contacts carry.
    mass_kg = plant.CalcTotalMass(plant.CreateDefaultContext(), [instance])
    simulated_mass_kg = plant.CalcTotalMass(plant.GetMyContextFromRoot(root_context), [instance])
    metrics = outputs.seated_metrics(
        result.times_s,
        result.com_W,
        result.pad_forces_W,
        built.pad_groups,
        weight_N=simulated_mass_kg * GRAVITY_MPS2,
    )
    metrics["robot_mass_kg"] = mass_kg
    metrics["simulated_mass_kg"] = simulated_mass_kg
    entry_times = built.state_machine.mode(
        built.state_machine.GetMyContextFromRoot(root_context)
    ).entry_times_s
    psi_now = built.advancement.GetOutputPort("psi").Eval(
        built.advancement.GetMyContextFromRoot(root_context)
    )[0]
    metrics.update(outputs.advancement_metrics(psi_now, signals["psi_dot"][1][0], entry_times))
    metrics.update(
        outputs.standup_metrics(signals, built.pad_groups, metrics["state_entry_times_s"])
    )
    if "controller_diagnostics" in signals:
        diagnostics = signals["controller_diagnostics"][1]
        metrics["qp_failures"] = int(diagnostics[1, -1]) if diagnostics.size else 0
    torques = signals["net_actuation"][1]
    metrics["max_abs_torque_Nm"] = float(np.abs(torques).max()) if torques.size else None
    result.metrics = metrics
    return result
