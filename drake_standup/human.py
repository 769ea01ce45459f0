"""HumanWrenchSource: the helper's hands on the robot's hands.

Two humans: 'scripted' applies the scenario's pulls (trapezoids in time, each
on one hand, constant world direction); 'reactive' pulls each hand toward a
target that leaves from where the hand was and moves up and forward, like a
person guiding the robot up: an impedance with a force cap.
The wrench acts at the origin of the hand task frame (the hand's DH frame).
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import Value
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.caching import declare_cached
from drake_standup.config import HumanConfig, Pull, ReactiveHumanConfig
from drake_standup.robot import Robot

HANDS = {"left": 0, "right": 1}
TASK_FRAMES = ("l_hand", "r_hand")


def trapezoid(t: float, start_s: float, duration_s: float, ramp_s: float) -> float:
    """0 -> 1 over ramp_s from start_s, 1, then 1 -> 0 over the last ramp_s."""
    local = t - start_s
    if local <= 0.0 or local >= duration_s:
        return 0.0
    if ramp_s <= 0.0:
        return 1.0
    return min(1.0, local / ramp_s, (duration_s - local) / ramp_s)


def scripted_forces(pulls: list[Pull], t: float) -> np.ndarray:
    """(2, 3) world forces on the left and right hand at time t. N."""
    forces = np.zeros((2, 3))
    for pull in pulls:
        scale = trapezoid(t, pull.start_s, pull.duration_s, pull.ramp_s)
        forces[HANDS[pull.hand]] += scale * np.asarray(pull.force_N)
    return forces


def reactive_force(
    cfg: ReactiveHumanConfig, t: float, p_hand: np.ndarray, v_hand: np.ndarray, p_start: np.ndarray
) -> np.ndarray:
    """Impedance pull of one hand toward its moving target, capped. N."""
    scale = trapezoid(t, cfg.start_s, cfg.duration_s, cfg.ramp_s)
    if scale == 0.0:
        return np.zeros(3)
    v_target = np.asarray(cfg.target_velocity_mps)
    speed = np.linalg.norm(v_target)
    travel = min(speed * (t - cfg.start_s), cfg.travel_m)
    direction = v_target / speed if speed > 0 else np.zeros(3)
    target = p_start + travel * direction
    f = cfg.stiffness_N_per_m * (target - p_hand) - cfg.damping_Ns_per_m * v_hand
    norm = np.linalg.norm(f)
    if norm > cfg.force_cap_N:
        f *= cfg.force_cap_N / norm
    return scale * f


class HumanWrenchSource(LeafSystem):
    """Outputs spatial_forces (for the plant's applied_spatial_force input)
    and hand_wrenches_W (12: [torque_l, force_l, torque_r, force_r]), the same
    wrenches as the robot's wrist sensors would measure them.

    Input robot_state [q; v] (used by the reactive human only).
    """

    def __init__(self, plant: MultibodyPlant, robot: Robot, config: HumanConfig):
        super().__init__()
        self._cfg = config
        self._plant = plant
        self._instance = robot.model_instance
        self._context = plant.CreateDefaultContext()
        self._frames = [robot.frame(plant, name) for name in TASK_FRAMES]
        # One applied force per hand, at the hand frame's origin; each tick
        # sets its force only.
        self._applied = []
        for frame in self._frames:
            applied = ExternallyAppliedSpatialForce()
            applied.body_index = frame.body().index()
            applied.p_BoBq_B = frame.GetFixedPoseInBodyFrame().translation()
            self._applied.append(applied)
        nx = plant.num_multibody_states(self._instance)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        prereq = {self.time_ticket()}
        if config.mode == "reactive":
            # Where the hands are at t = 0: the targets leave from there (the
            # robot sits still until the pull starts).
            self._start_index = self.DeclareDiscreteState(6)
            self.DeclareInitializationDiscreteUpdateEvent(self._CaptureStart)
            prereq |= {self._state.ticket(), self.all_state_ticket()}
        # The scripted pulls are a function of time alone: the last time and
        # its wrenches, because the integrator sets each step's end time twice
        # (its last stage, then the step's end), which Drake counts as a change.
        self._last_scripted: tuple[float, np.ndarray] | None = None
        # Both outputs read one evaluation of the human per time (and state):
        # hand_wrenches_W itself, (12,).
        self._wrenches_cache = declare_cached(self, "hand wrenches", self._wrenches, prereq)
        prereq = {self._wrenches_cache.ticket()}
        self.DeclareVectorOutputPort(
            "hand_wrenches_W", 12, self._CalcWrenches, prerequisites_of_calc=prereq
        )
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
            self._CalcSpatialForces,
            prerequisites_of_calc=prereq,
        )

    def _hands(self, context: Context) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """World positions and velocities of the hand frames' origins."""
        plant, c = self._plant, self._context
        plant.SetPositionsAndVelocities(c, self._instance, self._state.Eval(context))
        world = plant.world_frame()
        p = [f.CalcPoseInWorld(c).translation() for f in self._frames]
        v = [f.CalcSpatialVelocity(c, world, world).translational() for f in self._frames]
        return p, v

    def _CaptureStart(self, context: Context, discrete_state) -> None:
        p, _ = self._hands(context)
        discrete_state.set_value(self._start_index, np.concatenate(p))

    def _forces(self, context: Context) -> np.ndarray:
        """(2, 3) world forces on the left and right hand. N."""
        t = context.get_time()
        if self._cfg.mode == "scripted":
            return scripted_forces(self._cfg.pulls, t)
        start = context.get_discrete_state(self._start_index).value().reshape(2, 3)
        r = self._cfg.reactive
        if not r.start_s < t < r.start_s + r.duration_s:
            return np.zeros((2, 3))  # no kinematics needed outside the pull
        p, v = self._hands(context)
        return np.array(
            [reactive_force(self._cfg.reactive, t, p[i], v[i], start[i]) for i in range(2)]
        )

    def _wrenches(self, context: Context) -> np.ndarray:
        """hand_wrenches_W (12,): [0, f_l, 0, f_r]."""
        scripted = self._cfg.mode == "scripted"
        if scripted and self._last_scripted is not None:
            t, wrenches = self._last_scripted
            if t == context.get_time():
                return wrenches
        wrenches = np.zeros(12)
        wrenches.reshape(2, 6)[:, 3:] = self._forces(context)
        if scripted:
            self._last_scripted = context.get_time(), wrenches
        return wrenches

    def _CalcWrenches(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self._wrenches_cache.Eval(context))

    def _CalcSpatialForces(self, context: Context, output) -> None:
        """One force per pulled hand (none while nobody pulls: the plant then
        has nothing to apply)."""
        wrenches = self._wrenches_cache.Eval(context)
        forces = []
        for applied, f in zip(self._applied, (wrenches[3:6], wrenches[9:12])):
            if f.any():
                applied.F_Bq_W = SpatialForce(np.zeros(3), f)
                forces.append(applied)
        output.set_value(forces)
