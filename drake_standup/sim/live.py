"""Be the helper: the stand-up live in the browser, paced at real time (issue 15).

    python run_diagram.py --live [--scenario PATH] [--duration S] [--out DIR]

The scenario's human is replaced by LiveHumanSource: the pull on each hand comes from
Meshcat sliders (forward and up, N, within +-human.reactive.force_cap_N, the helper's
cap per hand), one switch pulls both hands together (the left hand's sliders drive
both), and a standard gamepad, once the page has seen it, drives the pull from its
sticks. A slider switches the robot's response to the pull (advancement, stiff,
compliant: config.RESPONSES) while the run goes on, so that the same pull can be felt
answered each way. "Stand up" starts the stand-up where standup.trigger waits for the hands,
"Reset" puts the robot back on the chair (also after a fall, which in a live run is
reported on the console instead of ending it), "Stop" (or Escape, or Ctrl-C) ends the
run.
The rest of the diagram is the normal run's, and so are the outputs (metrics.json,
signals.npz, figures, recording.html); there is no psi = t run beside it (nobody
knows the pull in advance).

Pacing: Drake's Simulator.set_target_realtime_rate(1). When the machine cannot keep
up, the simulation slows down (the sliders are read at every plant step of simulated
time, so no input is lost), the achieved rate is printed once a second, and the
pacing restarts from where it is rather than catching up in a burst.
"""

from __future__ import annotations

import copy
import logging
import signal
import time
from pathlib import Path

import numpy as np
from pydrake.common.value import Value
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import (
    BasicVector,
    Context,
    DiscreteValues,
    EventStatus,
    LeafSystem,
)

from drake_standup.config import RESPONSES, HumanConfig, Scenario
from drake_standup.config.responses import response_names
from drake_standup.helper.hands import hand_forces, spatial_forces
from drake_standup.robot.icub import Robot
from drake_standup.sim.diagram import on_step_grid
from drake_standup.sim.run_folder import write_run
from drake_standup.sim.runner import Run, RunResult, advance, collect, finished, prepare

# The page's controls, in the order they appear.
HANDS = ("left", "right")
AXES = ("fwd", "up")  # world x (the robot faces +x) and z
# Short labels: Meshcat's control panel cuts a label at ~15 characters.
SLIDERS = {(hand, axis): f"{hand} {axis} (N)" for hand in HANDS for axis in AXES}
TOGETHER = "both hands"
# The response switch: 0, 1, 2 in the order of config.RESPONSES (15 characters).
RESPONSE = "adv/stiff/compl"
STAND_UP = "Stand up"
SIT_DOWN = "Sit down"
RESET = "Reset"
STOP = "Stop"
# Slider resolution. N.
SLIDER_STEP_N = 0.5
# Sticks of a standard gamepad (https://w3c.github.io/gamepad/#remapping): left stick
# axes 0 (right +) and 1 (down +) pull the left hand, the right stick (2, 3) the
# right hand; right = forward, up = up, as the default camera shows the robot (facing
# to the right). Deflections below the dead zone read as 0 (a resting stick drifts by
# a few percent).
GAMEPAD_DEAD_ZONE = 0.1
GAMEPAD_START_BUTTON = 9  # "Stand up"
# Without --duration: five minutes of play (the recording grows ~0.15 MB per
# simulated second). s.
DEFAULT_DURATION_S = 300.0
# Report the achieved rate when it is below this fraction of the target.
SLOW_FRACTION = 0.95
# How far the simulation may fall behind the wall clock before the pacing restarts
# from where it is (Drake's pacing otherwise catches up at full speed). s.
MAX_LAG_S = 0.1


def gamepad_pull(axes: list[float], cap_N: float) -> np.ndarray:
    """(2, 2) [forward, up] pull on the left and right hand from a standard gamepad's
    sticks, N: full deflection is cap_N, the dead zone 0."""
    a = np.zeros(4)
    n = min(4, len(axes))
    a[:n] = axes[:n]
    a[np.abs(a) < GAMEPAD_DEAD_ZONE] = 0.0
    return cap_N * np.clip(np.array([[a[0], -a[1]], [a[2], -a[3]]]), -1.0, 1.0)


class LiveHumanSource(LeafSystem):
    """The helper at the Meshcat page: HumanWrenchSource's ports (input robot_state,
    unused; outputs hand_wrenches_W and spatial_forces) plus stand_up (1: how often the
    "Stand up" button was pressed since the last reset, at least 1 once the gamepad's start
    button was), response (1: the response switch's code, RESPONSES' index; starts at
    response) and sit_down (1: how often the "Sit down" button was pressed since then).

    Every period_s (the plant's step) a discrete update reads the page (sliders, the
    switches, the gamepad, the buttons) into the state [f_left (3), f_right (3),
    stand_up, response, sit_down], world frame, N: so the pull reaches the plant within a
    step, and the run's signals hold what the helper did.
    """

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: Robot,
        config: HumanConfig,
        meshcat: Meshcat,
        period_s: float,
        stand_up_button: bool = True,
        *,
        sit_down_button: bool = False,
        response: int = 0,
        responses: tuple[str, ...] = RESPONSES,
    ):
        super().__init__()
        self._responses = responses
        self._meshcat = meshcat
        self._cap = config.reactive.force_cap_N
        self._stand_up_button = stand_up_button
        self._sit_down_button = sit_down_button
        self._clicks_seen = 0
        self._sit_clicks_seen = 0
        self._applied = hand_forces(plant, robot)
        self.DeclareVectorInputPort("robot_state", plant.num_multibody_states(robot.model_instance))
        self._response = response
        self._index = self.DeclareDiscreteState(np.r_[np.zeros(7), float(response), 0.0])
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._Update)
        state = {self.discrete_state_ticket(self._index)}
        self.DeclareVectorOutputPort(
            "hand_wrenches_W", 12, self._CalcWrenches, prerequisites_of_calc=state
        )
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
            self._CalcSpatialForces,
            prerequisites_of_calc=state,
        )
        self.DeclareVectorOutputPort("stand_up", 1, self._CalcStandUp, prerequisites_of_calc=state)
        self.DeclareVectorOutputPort("response", 1, self._CalcResponse, prerequisites_of_calc=state)
        self.DeclareVectorOutputPort("sit_down", 1, self._CalcSitDown, prerequisites_of_calc=state)
        self._add_controls()

    def _add_controls(self) -> None:
        m = self._meshcat
        for name in SLIDERS.values():
            m.AddSlider(name, -self._cap, self._cap, SLIDER_STEP_N, 0.0)
        m.AddSlider(TOGETHER, 0.0, 1.0, 1.0, 1.0)
        m.AddSlider(RESPONSE, 0.0, len(self._responses) - 1.0, 1.0, float(self._response))
        if self._stand_up_button:
            m.AddButton(STAND_UP)
        if self._sit_down_button:
            m.AddButton(SIT_DOWN)

    def forget_clicks(self) -> None:
        """Stand-up and sit-down clicks so far no longer count (after a reset)."""
        if self._stand_up_button:
            self._clicks_seen = self._meshcat.GetButtonClicks(STAND_UP)
        if self._sit_down_button:
            self._sit_clicks_seen = self._meshcat.GetButtonClicks(SIT_DOWN)

    def read_page(self) -> tuple[np.ndarray, bool]:
        """(2, 3) world pull on the left and right hand, N, and whether the stand-up
        was asked for, as the page says now. Writes the sliders the helper does not
        drive (the right hand's when together, all four from a gamepad) so that the
        page shows the pull."""
        m = self._meshcat
        gamepad = m.GetGamepad()
        together = m.GetSliderValue(TOGETHER) > 0.5
        asked = False
        if gamepad.index is not None:
            # On the sliders' grid, so that the sliders show it exactly.
            pull = SLIDER_STEP_N * np.round(gamepad_pull(gamepad.axes, self._cap) / SLIDER_STEP_N)
            buttons = gamepad.button_values
            asked = len(buttons) > GAMEPAD_START_BUTTON and buttons[GAMEPAD_START_BUTTON] > 0.5
            driven = HANDS
        else:
            pull = np.array(
                [[m.GetSliderValue(SLIDERS[hand, axis]) for axis in AXES] for hand in HANDS]
            )
            driven = ("right",) if together else ()
        if together:
            pull[1] = pull[0]
        for i, hand in enumerate(HANDS):
            if hand in driven:
                for j, axis in enumerate(AXES):
                    name = SLIDERS[hand, axis]
                    if m.GetSliderValue(name) != pull[i, j]:
                        m.SetSliderValue(name, float(pull[i, j]))
        pull = np.clip(pull, -self._cap, self._cap)
        if self._stand_up_button:
            asked = asked or m.GetButtonClicks(STAND_UP) > self._clicks_seen
        return np.column_stack([pull[:, 0], np.zeros(2), pull[:, 1]]), asked

    def read_response(self) -> int:
        """The response switch's code (the run's responses' index), as the page says now."""
        code = round(self._meshcat.GetSliderValue(RESPONSE))
        return min(max(code, 0), len(self._responses) - 1)

    def _Update(self, context: Context, discrete_state: DiscreteValues) -> None:
        forces, asked = self.read_page()
        last = context.get_discrete_state(self._index).value()
        # How many times each was asked for since the reset: the state machine takes the
        # k-th stand-up (after k - 1 sit-downs) and the k-th sit-down from the k-th click.
        stand_ups = max(last[6], float(asked), self._clicks(STAND_UP, self._clicks_seen))
        sit_downs = max(last[8], self._clicks(SIT_DOWN, self._sit_clicks_seen))
        discrete_state.set_value(
            self._index,
            np.r_[forces.ravel(), stand_ups, float(self.read_response()), sit_downs],
        )

    def _clicks(self, button: str, seen: int) -> float:
        """The button's clicks since the last reset (0 where the page has no such button)."""
        shown = self._stand_up_button if button == STAND_UP else self._sit_down_button
        return float(self._meshcat.GetButtonClicks(button) - seen) if shown else 0.0

    def _state(self, context: Context) -> np.ndarray:
        return context.get_discrete_state(self._index).value()

    def _wrenches(self, context: Context) -> np.ndarray:
        """hand_wrenches_W (12,): [0, f_l, 0, f_r], from the page's last reading."""
        x = self._state(context)
        return np.r_[np.zeros(3), x[0:3], np.zeros(3), x[3:6]]

    def _CalcWrenches(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self._wrenches(context))

    def _CalcSpatialForces(self, context: Context, output) -> None:
        output.set_value(spatial_forces(self._applied, self._wrenches(context)))

    def _CalcStandUp(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._state(context)[6])

    def _CalcResponse(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._state(context)[7])

    def _CalcSitDown(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._state(context)[8])


def make_live_meshcat() -> Meshcat:
    """Meshcat on localhost only, on the first free port from 7000 (a stable address
    to keep open in a browser tab), without Drake's own log line about it."""
    drake_log = logging.getLogger("drake")
    level = drake_log.level
    drake_log.setLevel(logging.WARNING)
    try:
        return Meshcat(MeshcatParams(host="localhost", show_stats_plot=False))
    finally:
        drake_log.setLevel(level)


class LiveSession:
    """A live run's page: the human to build (make_human, for runner.prepare), then after
    Initialize (started) and after every chunk of simulated time (after_chunk, True:
    stop). Owns the page's Reset and Stop buttons and the pacing report."""

    def __init__(self, scenario: Scenario, meshcat: Meshcat, report=print):
        self.meshcat = meshcat
        self._scenario = scenario
        self._report = report
        self.human: LiveHumanSource | None = None
        self.stopped_by: str | None = None
        self.fell: str | None = None  # what the fall monitor said, until a Reset
        self._fall = None
        self.interrupted = False  # Ctrl-C (set by the signal handler)
        self.resets = 0
        self._response = scenario.response  # the switch's last reported setting
        self._names = response_names(scenario.response)  # the switch's settings, by code
        self._initial_state = None
        self._reset_clicks = 0

    def make_human(
        self, plant: MultibodyPlant, robot: Robot, config: HumanConfig
    ) -> LiveHumanSource:
        step = self._scenario.plant.time_step
        self.human = LiveHumanSource(
            plant,
            robot,
            config,
            self.meshcat,
            step,
            stand_up_button=self._scenario.standup.trigger == "hands",
            sit_down_button=self._scenario.standup.sit_down.trigger == "hands",
            response=self._names.index(self._scenario.response),
            responses=self._names,
        )
        # Below the helper's controls.
        self.meshcat.AddButton(RESET)
        self.meshcat.AddButton(STOP, "Escape")
        return self.human

    def started(self, run: Run) -> None:
        """After Initialize: the seated state that Reset returns to; and the run's fall
        monitor, which in a live run reports a fall (or the QP failing) once instead of
        ending the run: Reset puts the robot back."""
        simulator = run.simulator
        self._initial_state = simulator.get_context().Clone()
        self._fall = run.fall
        simulator.set_monitor(self._monitor)
        self._restart_clocks(simulator)

    def _monitor(self, root_context: Context) -> EventStatus:
        status = self._fall(root_context)
        if status.severity() != EventStatus.Severity.kReachedTermination:
            return status
        if self.fell is None:
            self.fell = status.message()
            self._report(f"{self.fell}; Reset puts the robot back on the chair")
        return EventStatus.DidNothing()

    def _restart_clocks(self, simulator: Simulator) -> None:
        """The pacing's origin and the rate report's, now (Drake's pacing restarts at
        Initialize and ResetStatistics)."""
        self._wall = self._pace_wall = time.perf_counter()
        self._sim = self._pace_sim = simulator.get_context().get_time()

    def reset(self, run: Run) -> None:
        """The robot back on the chair as at t = 0, time running on: every state
        (plant, controller, psi, state machine, the helper's) from the start, then
        the initialization events at the current time (the state machine's clock and
        the controller's first torques)."""
        simulator = run.simulator
        context = simulator.get_mutable_context()
        context.SetStateAndParametersFrom(self._initial_state)
        run.built.diagram.ExecuteInitializationEvents(context)
        if self.human is not None:
            self.human.forget_clicks()
        if self._fall is not None:
            self._fall.reset()
        self.fell = None
        simulator.ResetStatistics()
        self.resets += 1

    def after_chunk(self, run: Run) -> bool:
        simulator = run.simulator
        m = self.meshcat
        if self.interrupted:
            self.stopped_by = "Ctrl-C"
        elif m.GetButtonClicks(STOP) > 0:
            self.stopped_by = "the Stop button"
        if self.stopped_by is not None:
            return True
        clicks = m.GetButtonClicks(RESET)
        if clicks > self._reset_clicks:
            self._reset_clicks = clicks
            self.reset(run)
            self._restart_clocks(simulator)
            return False
        response = self._names[self.human.read_response()]
        if response != self._response:
            self._response = response
            self._report(f"t = {run.time_s:.2f} s: the robot's response is now {response}")
        self._pace(simulator)
        return False

    def _pace(self, simulator: Simulator) -> None:
        """Once a second of wall time, the achieved rate if below the target; and when
        the simulation lags the wall clock by more than MAX_LAG_S, the pacing restarts
        from here (the simulation slows down instead of catching up in a burst)."""
        target = simulator.get_target_realtime_rate()
        if target <= 0.0:
            return
        wall = time.perf_counter()
        t = simulator.get_context().get_time()
        if target * (wall - self._pace_wall) - (t - self._pace_sim) > MAX_LAG_S:
            simulator.ResetStatistics()
            self._pace_wall, self._pace_sim = wall, t
        if wall - self._wall >= 1.0:
            rate = (t - self._sim) / (wall - self._wall)
            if rate < SLOW_FRACTION * target:
                self._report(f"behind real time: {rate:.2f}x at t = {t:.1f} s")
            self._wall, self._sim = wall, t


def run_session(
    scenario: Scenario, session: LiveSession, out_dir: Path | None = None, chunk_s: float = 0.05
) -> RunResult:
    """A live run with session at the page: runner.py's prepare, advance and collect, the
    page between the chunks; the run's files into out_dir if given (no psi = t run:
    nobody knows the pull in advance)."""
    run = prepare(scenario, session.meshcat, make_human=session.make_human, live_transforms=True)
    session.started(run)
    chunk_s = on_step_grid(chunk_s, scenario.plant.time_step)
    chunk = 0
    while not finished(run):
        chunk += 1
        advance(run, chunk * chunk_s)
        if session.after_chunk(run):
            break
    if run.failure_reason is None:
        run.failure_reason = session.fell  # a fall that no Reset undid
    result = collect(run)
    if out_dir is not None:
        result.files = write_run(run, result, out_dir)
    return result


def run_live(
    scenario: Scenario, out_dir: Path, duration_s: float | None = None, realtime_rate: float = 1.0
) -> RunResult:
    """The live run: prints the page's address, runs to --duration (or Stop, Escape,
    Ctrl-C) paced at realtime_rate, writes the run's files and returns its RunResult."""
    scenario = copy.deepcopy(scenario)
    scenario.duration_s = DEFAULT_DURATION_S if duration_s is None else duration_s
    scenario.simulator.target_realtime_rate = realtime_rate
    meshcat = make_live_meshcat()
    session = LiveSession(scenario, meshcat)
    print(f"meshcat: {meshcat.web_url()}", flush=True)

    def interrupt(signum, frame) -> None:
        session.interrupted = True

    previous = signal.signal(signal.SIGINT, interrupt)
    try:
        result = run_session(scenario, session, out_dir)
    finally:
        signal.signal(signal.SIGINT, previous)
    if session.stopped_by is not None:
        print(f"stopped by {session.stopped_by} at t = {result.metrics['sim_time_s']:.2f} s")
    return result
