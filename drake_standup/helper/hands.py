"""HumanWrenchSource: the helper's hands on the robot's hands.

Two humans: 'scripted' applies the scenario's pulls (trapezoids in time, each
on one hand, constant world direction); 'reactive' is a person guiding each hand
(helper/partner.py: the velocity and the path guide), who acts on what they saw of the
robot reaction_time_s ago (this system keeps it), carried on at the velocity they saw
(predicted), through their arm's impedance.
The wrench acts at the origin of the hand task frame (the hand's DH frame).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from pydrake.common.value import Value
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.config import HumanConfig, Pull
from drake_standup.helper.partner import Path, path_force, reactive_force, trapezoid
from drake_standup.ports.caching import declare_cached
from drake_standup.robot.icub import Robot

HANDS = {"left": 0, "right": 1}
# What a reactive person perceives, every PERCEPTION_PERIOD_S: the hands' positions (6)
# and velocities (6) and the robot's CoM height (1). s.
PERCEIVED = 13
PERCEPTION_PERIOD_S = 0.01
TASK_FRAMES = ("l_hand", "r_hand")


def applied_at(frame) -> ExternallyAppliedSpatialForce:
    """An applied force on frame's body at the frame's origin (its F_Bq_W set by the user)."""
    force = ExternallyAppliedSpatialForce()
    force.body_index = frame.body().index()
    force.p_BoBq_B = frame.GetFixedPoseInBodyFrame().translation()
    return force


def hand_forces(plant: MultibodyPlant, robot: Robot) -> list[ExternallyAppliedSpatialForce]:
    """One applied force per hand (TASK_FRAMES), at the hand frame's origin; a human
    source sets their forces each time it outputs them (spatial_forces)."""
    return [applied_at(robot.frame(plant, name)) for name in TASK_FRAMES]


def spatial_forces(
    applied: list[ExternallyAppliedSpatialForce], hand_wrenches_W: np.ndarray
) -> list[ExternallyAppliedSpatialForce]:
    """applied (hand_forces) set to the forces of hand_wrenches_W = [0, f_l, 0, f_r], the
    pulled hands only (none while nobody pulls: the plant then has nothing to apply)."""
    pulled = []
    for force, f in zip(applied, (hand_wrenches_W[3:6], hand_wrenches_W[9:12])):
        if np.count_nonzero(f):
            force.F_Bq_W = SpatialForce(np.zeros(3), f)
            pulled.append(force)
    return pulled


def applied_wrenches(
    applied: list[ExternallyAppliedSpatialForce], hand_wrenches_W: np.ndarray
) -> list[ExternallyAppliedSpatialForce]:
    """applied (hand_forces) set to hand_wrenches_W's torques and forces, the hands whose
    wrench is not zero only (a recorded or a plug-in helper's, which may twist the hands)."""
    pulled = []
    for force, wrench in zip(applied, hand_wrenches_W.reshape(2, 6)):
        if np.count_nonzero(wrench):
            force.F_Bq_W = SpatialForce(wrench[:3], wrench[3:])
            pulled.append(force)
    return pulled


def declare_hand_outputs(
    system: LeafSystem,
    calc: Callable[[Context], np.ndarray],
    prerequisites: set,
    applied: list[ExternallyAppliedSpatialForce],
    to_forces: Callable = spatial_forces,
):
    """A helper's two outputs, hand_wrenches_W (12) and spatial_forces (to_forces of
    applied and those wrenches), from one evaluation of calc(context) per change of
    prerequisites. Returns the cache entry of calc's wrenches."""
    cache = declare_cached(system, "hand wrenches", calc, prerequisites)
    ticket = {cache.ticket()}

    def wrenches(context: Context, output: BasicVector) -> None:
        output.SetFromVector(cache.Eval(context))

    def forces(context: Context, output) -> None:
        output.set_value(to_forces(applied, cache.Eval(context)))

    system.DeclareVectorOutputPort("hand_wrenches_W", 12, wrenches, prerequisites_of_calc=ticket)
    system.DeclareAbstractOutputPort(
        "spatial_forces",
        lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
        forces,
        prerequisites_of_calc=ticket,
    )
    return cache


def scripted_forces(pulls: list[Pull], t: float) -> np.ndarray:
    """(2, 3) world forces on the left and right hand at time t. N."""
    forces = np.zeros((2, 3))
    for pull in pulls:
        scale = trapezoid(t, pull.start_s, pull.duration_s, pull.ramp_s)
        forces[HANDS[pull.hand]] += scale * np.asarray(pull.force_N)
    return forces


def predicted(sample: np.ndarray, hand: int, lag_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(position, velocity) of hand (0 left, 1 right) a person expects now from a sample
    (PERCEIVED) seen lag_s ago: carried on at the velocity seen. People track a steady
    motion without their reaction time's lag and lag its changes ([reaction-time]); a person
    without it drags a hand moving at v back by K v lag_s (15 N at 0.5 m/s, 0.2 s)."""
    p, v = sample[3 * hand : 3 * hand + 3], sample[6 + 3 * hand : 9 + 3 * hand]
    return p + lag_s * v, v


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
        self._applied = hand_forces(plant, robot)
        nx = plant.num_multibody_states(self._instance)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        prereq = {self.time_ticket()}
        self._path = None
        if config.mode == "reactive":
            # Where the hands are at t = 0: the targets leave from there (the
            # robot sits still until the pull starts); and the CoM height then,
            # from which the path guide sees the robot rise.
            if config.reactive.guide == "path":
                r = config.reactive
                self._path = Path(r.path_xz_m, r.path_corner_radius_m)
            self._start_index = self.DeclareDiscreteState(7)
            # What the person saw: one sample (PERCEIVED) per PERCEPTION_PERIOD_S over
            # their reaction time, oldest first; they act on the oldest.
            self._slots = round(config.reactive.reaction_time_s / PERCEPTION_PERIOD_S)
            if self._slots:
                self._seen_index = self.DeclareDiscreteState(PERCEIVED * (self._slots + 1))
                self.DeclarePeriodicDiscreteUpdateEvent(PERCEPTION_PERIOD_S, 0.0, self._Perceive)
            self.DeclareInitializationDiscreteUpdateEvent(self._CaptureStart)
            prereq |= {self._state.ticket(), self.all_state_ticket()}
        # The scripted pulls are a function of time alone: the last time and
        # its wrenches, because the integrator sets each step's end time twice
        # (its last stage, then the step's end), which Drake counts as a change.
        self._last_scripted: tuple[float, np.ndarray] | None = None
        # The pulls as _wrenches sums them: (start, duration, ramp, their rows of
        # hand_wrenches_W, force).
        self._pulls = [
            (
                pull.start_s,
                pull.duration_s,
                pull.ramp_s,
                slice(6 * HANDS[pull.hand] + 3, 6 * HANDS[pull.hand] + 6),
                np.asarray(pull.force_N, dtype=float),
            )
            for pull in (config.pulls if config.mode == "scripted" else [])
        ]
        # Both outputs read one evaluation of the human per time (and state).
        declare_hand_outputs(self, self._wrenches, prereq, self._applied)

    def _hands(self, context: Context) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """World positions and velocities of the hand frames' origins."""
        plant, c = self._plant, self._context
        plant.SetPositionsAndVelocities(c, self._instance, self._state.Eval(context))
        world = plant.world_frame()
        p = [f.CalcPoseInWorld(c).translation() for f in self._frames]
        v = [f.CalcSpatialVelocity(c, world, world).translational() for f in self._frames]
        return p, v

    def _com_height(self) -> float:
        """The robot's CoM height in the context _hands last set. m."""
        com = self._plant.CalcCenterOfMassPositionInWorld(self._context, [self._instance])
        return float(com[2])

    def _sample(self, context: Context) -> np.ndarray:
        """(PERCEIVED,) the hands' positions and velocities and the CoM height now."""
        p, v = self._hands(context)
        return np.concatenate([*p, *v, [self._com_height()]])

    def _CaptureStart(self, context: Context, discrete_state) -> None:
        sample = self._sample(context)
        discrete_state.set_value(self._start_index, np.concatenate([sample[:6], sample[12:]]))
        if self._slots:  # seen at rest until then
            discrete_state.set_value(self._seen_index, np.tile(sample, self._slots + 1))

    def _Perceive(self, context: Context, discrete_state) -> None:
        seen = discrete_state.get_mutable_value(self._seen_index)
        seen[:-PERCEIVED] = seen[PERCEIVED:].copy()
        seen[-PERCEIVED:] = self._sample(context)

    def _forces(self, context: Context) -> np.ndarray:
        """(2, 3) world forces on the left and right hand. N."""
        t = context.get_time()
        if self._cfg.mode == "scripted":
            return scripted_forces(self._cfg.pulls, t)
        captured = context.get_discrete_state(self._start_index).value()
        start = captured[:6].reshape(2, 3)
        r = self._cfg.reactive
        if not r.start_s < t < r.start_s + r.duration_s:
            return np.zeros((2, 3))  # no kinematics needed outside the pull
        p, v = self._hands(context)
        if self._slots:  # what the person saw reaction_time_s ago, carried on to now
            oldest = context.get_discrete_state(self._seen_index).value()[:PERCEIVED]
            seen = [predicted(oldest, i, self._slots * PERCEPTION_PERIOD_S) for i in range(2)]
            rise = oldest[12] - captured[6]
        else:
            seen, rise = [None, None], self._com_height() - captured[6]
        if self._path is not None:
            return np.array(
                [
                    path_force(
                        r, self._path, t, p[i], v[i], start[i], com_rise_m=rise, seen=seen[i]
                    )
                    for i in range(2)
                ]
            )
        return np.array(
            [reactive_force(r, t, p[i], v[i], start[i], rise, seen=seen[i]) for i in range(2)]
        )

    def _wrenches(self, context: Context) -> np.ndarray:
        """hand_wrenches_W (12,): [0, f_l, 0, f_r]."""
        if self._cfg.mode != "scripted":
            wrenches = np.zeros(12)
            wrenches.reshape(2, 6)[:, 3:] = self._forces(context)
            return wrenches
        t = context.get_time()
        if self._last_scripted is not None and self._last_scripted[0] == t:
            return self._last_scripted[1]
        # scripted_forces' sums, straight into the wrenches (a pull at scale 0 adds
        # nothing: no entry is ever -0.0).
        wrenches = np.zeros(12)
        for start_s, duration_s, ramp_s, rows, force in self._pulls:
            scale = trapezoid(t, start_s, duration_s, ramp_s)
            if scale != 0.0:
                wrenches[rows] += scale * force
        self._last_scripted = t, wrenches
        return wrenches
