"""One run of a scenario in three steps: prepare, advance, collect.

    run = prepare(scenario, meshcat)      build the diagram, seat the robot, Initialize
    advance(run, t)                       simulate to t; a fall or failure ends the run
    result = collect(run)                 signals, metrics and how the run ended

simulate.py (a run to its end, with its files), live.py (paced, with a person at the
page), bench.py and the sweeps compose these; none copies the loop.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import EventStatus

from drake_standup.config import Scenario
from drake_standup.control.controller import DIAGNOSTICS
from drake_standup.outputs.metrics import run_metrics
from drake_standup.outputs.signals import make_signals
from drake_standup.robot.icub import reflects_motor_inertia
from drake_standup.sim.diagram import StandupDiagram, build_diagram
from drake_standup.sim.visuals import camera_pose
from drake_standup.world.perturbations import apply_model_errors
from drake_standup.world.scene import set_seated_state

_QP_OK = DIAGNOSTICS.index("qp_ok")


@dataclass
class RunResult:
    metrics: dict
    files: dict = field(default_factory=dict)
    # The run's time series on one time grid, as signals.npz holds them (signals.py).
    signals: dict[str, np.ndarray] = field(default_factory=dict)
    # WholeBodyController.timing_s(): per-tick compute times, (ticks, 5) in the columns
    # of control/controller.py's TIMING; None without that controller.
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


class FallMonitor:
    """Simulator monitor: the robot has fallen (its base below fall.min_root_height_m or
    fall.max_com_horizontal_m from where it started) or the controller's QP has stayed
    infeasible for fall.max_qp_failure_streak_s. Reads the diagram's outputs
    robot_state and controller_diagnostics."""

    def __init__(self, built: StandupDiagram, scenario: Scenario):
        self._state = built.diagram.GetOutputPort("robot_state")
        self._diagnostics = (
            built.diagram.GetOutputPort("controller_diagnostics")
            if built.diagram.HasOutputPort("controller_diagnostics")
            else None
        )
        self._min_z = scenario.fall.min_root_height_m
        self._max_xy = scenario.fall.max_com_horizontal_m
        self._xy0 = built.station.scene.seated.base.translation()[:2].copy()
        self._max_streak_s = scenario.fall.max_qp_failure_streak_s
        self._failing_since: float | None = None
        self.reason: str | None = None

    def reset(self) -> None:
        """Forgets a fall and a run of QP failures (the live mode's Reset)."""
        self._failing_since = None
        self.reason = None

    def __call__(self, root_context) -> EventStatus:
        t = root_context.get_time()
        p_WB = self._state.Eval(root_context)[4:7]  # quaternion (4), then position (3)
        moved = math.hypot(p_WB[0] - self._xy0[0], p_WB[1] - self._xy0[1])
        if p_WB[2] < self._min_z:
            self.reason = (
                f"fall: root_link height {p_WB[2]:.3f} m < {self._min_z} m at t = {t:.3f} s"
            )
        elif moved > self._max_xy:
            self.reason = f"fall: root_link moved {moved:.3f} m horizontally at t = {t:.3f} s"
        elif self._diagnostics is not None:
            self._check_qp(t, self._diagnostics.Eval(root_context)[_QP_OK])
        if self.reason is not None:
            return EventStatus.ReachedTermination(None, self.reason)
        return EventStatus.DidNothing()

    def _check_qp(self, t: float, qp_ok: float) -> None:
        if qp_ok:
            self._failing_since = None
        elif self._failing_since is None:
            self._failing_since = t
        elif t - self._failing_since >= self._max_streak_s:
            self.reason = (
                f"controller: QP infeasible since t = {self._failing_since:.3f} s "
                f"({t - self._failing_since:.2f} s)"
            )


@dataclass
class Run:
    """A prepared run: its diagram, simulator and fall monitor, and how it is going."""

    scenario: Scenario
    built: StandupDiagram
    simulator: Simulator
    fall: FallMonitor
    meshcat: Meshcat | None
    build_time_s: float
    # perf_counter() at Initialize: the run's wall time counts from there to the end of
    # its last advance (what happens between the chunks, e.g. the live page, included).
    started_s: float = 0.0
    failure_reason: str | None = None
    wall_time_s: float = 0.0

    @property
    def root_context(self):
        return self.simulator.get_context()

    @property
    def time_s(self) -> float:
        return self.root_context.get_time()


def prepare(
    scenario: Scenario,
    meshcat: Meshcat | None = None,
    *,
    controller: str = "whole_body",
    make_human: Callable | None = None,
    live_transforms: bool = False,
) -> Run:
    """Builds the run's diagram (diagram.build_diagram), seats the robot in the
    scenario's pose with its model errors (on the simulated robot only), starts the
    recording when there is a Meshcat (live_transforms: also drawn as it goes) and
    initializes the simulator."""
    t_build = time.perf_counter()
    built = build_diagram(scenario, meshcat, controller, make_human)
    build_time_s = time.perf_counter() - t_build
    simulator = Simulator(built.diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    station = built.station
    plant_context = station.plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    set_seated_state(station.scene, plant_context)
    apply_model_errors(station.scene, plant_context, scenario)
    fall = FallMonitor(built, scenario)
    simulator.set_monitor(fall)
    if meshcat is not None:
        vis = scenario.visualization
        helper = station.scene.helper
        meshcat.SetCameraPose(*camera_pose(vis, None if helper is None else helper.X_WP))
        built.visualizer.StartRecording(set_transforms_while_recording=live_transforms)
    started_s = time.perf_counter()
    simulator.Initialize()
    return Run(scenario, built, simulator, fall, meshcat, build_time_s, started_s)


def advance(run: Run, t: float) -> bool:
    """Simulates to t (at most the scenario's duration); False once the run has ended: a
    fall, the QP failing for too long (the fall monitor) or the simulator throwing, the
    reason in run.failure_reason."""
    try:
        status = run.simulator.AdvanceTo(min(t, run.scenario.duration_s))
        if status.reason() == status.ReturnReason.kReachedTerminationCondition:
            run.failure_reason = run.fall.reason
    except RuntimeError as err:
        run.failure_reason = "simulation error: " + " ".join(str(err).split())[:300]
    run.wall_time_s = time.perf_counter() - run.started_s
    return run.failure_reason is None


def finished(run: Run) -> bool:
    return run.failure_reason is not None or run.time_s >= run.scenario.duration_s - 1e-9


def responses_used(signals: dict, default: str) -> str:
    """The robot's responses to the pull over the run, in the order first used, joined by
    '+' (one name but where the live page's switch moved; default: no controller)."""
    if "response" not in signals:
        return default
    codes = dict.fromkeys(int(code) for code in signals["response"])
    return "+".join(str(signals["responses"][code]) for code in codes)


def collect(run: Run) -> RunResult:
    """The run's signals and metrics (metrics.py), success and the failure reason: a fall
    or failure, else whether it stood up and stayed standing."""
    built, scenario = run.built, run.scenario
    root = run.root_context
    signals = make_signals(built, root)
    metrics = run_metrics(
        signals,
        built.station,
        station_context=built.station.plant.GetMyContextFromRoot(root),
        scenario=scenario,
        psi_final=float(built.output("psi", root)[0]) if "psi" in built.logs else None,
        entry_times_s=tuple(built.output("entry_times_s", root)) if built.controller else (),
        standing_height_m=built.plan.erect_com_height_m,
    )
    reason = run.failure_reason
    if reason is None and built.controller is not None:
        stood = metrics.get("standup_time_s") is not None
        # A cycle may end seated: its last sit-down landed and the robot sits at the end.
        sat = bool(metrics.get("sit_downs")) and metrics["sit_downs"][-1]["seated_s"] is not None
        sat = sat and int(signals["state"][-1]) == 1
        if stood and (metrics.get("standing_at_end", False) or sat):
            reason = None
        elif not stood and metrics.get("held_back_s", 0.0) > 0.0:
            beyond = metrics.get("held_back_beyond_feet_s", 0.0)
            reason = (
                "held back: a pull beyond what the standing feet can hold"
                if beyond > 0.5 * metrics["held_back_s"]
                else "held back: hindering pull"
            )
        else:
            reason = "stood up but was not standing at the end" if stood else "did not stand up"
    sim_time_s = root.get_time()
    head = {
        "success": reason is None,
        "failure_reason": reason,
        "sim_time_s": sim_time_s,
        "wall_time_s": run.wall_time_s,
        "realtime_factor": sim_time_s / run.wall_time_s if run.wall_time_s > 0 else None,
    }
    model = scenario.robot.model
    metrics = (
        head
        | metrics
        | {
            "build_time_s": run.build_time_s,
            "robot_model": model,
            "reflected_inertia": reflects_motor_inertia(scenario.robot.reflected_inertia, model),
            "response": responses_used(signals, scenario.response),
        }
    )
    return RunResult(
        metrics,
        signals=signals,
        controller_timing_s=None if built.controller is None else built.controller.timing_s(),
    )
