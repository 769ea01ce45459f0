"""The helper body's systems (human.mode: body; the body itself: helper/body.py).

- intent: human.reactive's partner (helper/hands.py, HumanWrenchSource): the pull each hand is
  meant to get, decided on what the person saw reaction_time_s ago.
- PersonController, the person's muscles. Feed-forward: their own weight held and the
  intended pull pushed through their arms, u_ff = -g(q) + sum_i J_i(q)^T f_i. Impedance:
  Drake's implicit joint PD toward a set-point that follows their posture with a time
  constant T (helper.body.YIELD_TIME_S, how soon they give way; dq_d/dt = v_d =
  (q - q_d) / T): a spring in series with a damper K T, passive, so it cannot ring.
  Their arms go with the hands they hold: they feel those hands move YIELD_LATENCY_S
  late and predict the motion now (carried on at the acceleration felt); the arms'
  set-point moves at that velocity less what their trunk's motion already gives the
  grips (least squares through the arms' Jacobian), and their muscles carry their arms'
  own inertia for that acceleration (M(q) qdd, through a muscle's activation lag,
  ACTIVATION_S; not while they give way). Without it the arms' mass and the impedance
  dragged the robot's hands at each start (the lean, the rise) exactly where the pull
  advances psi (docs/design.md).
  The trunk is not dragged along but moves on its own: its flexion's set-point is the
  bend it takes to hold hands as high as they started plus the robot's CoM rise as the
  person saw it reaction_time_s ago, carried on at the rate seen (helper.body.bend_for):
  they straighten, leaning back, as the robot comes up, at most at their own pace
  (TRUNK_RATE_RAD_PER_S). Feeling a pull beyond their
  intent's cap (YIELD_LATENCY_S ago) they give way, wholly from twice it: the set-point
  jumps to the posture and moves with it, and the trunk stops straightening. They let go (the
  grip fades over ramp_s, never taken again) once the intent has eased off wholly (the
  robot's CoM risen by ease_com_rise_m's upper end, as they saw it) or the pull's time
  is over; a grip released while the intent still pulled dropped the robot's pull at once.
  The plant clamps each joint's sum to its strength.
  What failed, measured (docs/design.md): a set-point at the posture felt T ago carried
  on at the velocity felt (rang to 190 N in 1.3 s); a trunk following what moved it (a
  130 N m s/rad damper holding the rising robot down with 30 N); a trunk set by the
  hands' height seen, which it lifts itself (ran away to upright in 0.4 s); arms set to
  where the robot's hands were seen (yanked at 70 N); the arms' inertia carried for
  their own hands' felt acceleration (a negative mass: fell at once); arms going with
  the held hands with no regard to the trunk's motion (lifted the robot: 290-450 N
  sole spikes in 3 of 8 people).
- Grips: the hands' spring-damper (helper/body.py), on the robot's hands and on the
  person's, what the robot's wrist sensors read.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import Value
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.framework import (
    BasicVector,
    Context,
    Diagram,
    DiagramBuilder,
    LeafSystem,
)

from drake_standup.config import HumanConfig, ReactiveHumanConfig
from drake_standup.helper.body import (
    GRIPS,
    YIELD_TIME_S,
    HelperBody,
    bend_for,
    grips_jacobian,
    instance_joint_names,
    joint_names,
    person_model,
)
from drake_standup.helper.hands import PERCEPTION_PERIOD_S, HumanWrenchSource, applied_at
from drake_standup.ports.caching import declare_cached
from drake_standup.robot.icub import Robot

# What the person perceives each update: the robot's CoM height and rate, the larger of
# the pulls they feel in their hands, and the velocities of the robot's hands they hold.
_SEEN = 9
# How late they feel what their hands hold (the pull, the held hands' motion): a
# long-latency stretch reflex's latency (50-100 ms; a modelling choice). s.
YIELD_LATENCY_S = 0.05
# Muscles' activation time constant: a muscle's force follows its drive as a first-order
# lag of 30-50 ms (activation 10-20 ms, deactivation 30-60 ms: Zajac 1989, Crit Rev
# Biomed Eng 17:359); it low-passes the arms' inertia feed-forward. s.
ACTIVATION_S = 0.04
# How fast a person straightens their trunk as the robot rises: about a rad/s, their own
# trunk's flexion in rising from a chair (59 deg in a full-flexion stand-up: "Effect of
# trunk angle on lower limb joint moment in different strategies of sit-to-stand-to-sit
# motion", Med Biol Eng Comput 2025) undone within the second or so of a whole stand-up
# (1.67 s on average: Baer and Ashburn, "Trunk movements in older subjects during
# sit-to-stand", Arch Phys Med Rehabil 1995). Unbounded, the set-point stepped 0.6 rad
# after a fast helped rise and drove a relaxed person's back at 3.5 rad/s, to its strength.
TRUNK_RATE_RAD_PER_S = 1.0
# The damping of the least-squares map from the grips' motion to the arms' joints. m^2.
_ARMS_DAMPING = 1e-4


class PersonController(LeafSystem):
    """The person's muscles (module docstring). Inputs person_state (2n, the plant's
    order for the person's instance), robot_state (what they see of the robot: its CoM)
    and intent_wrenches_W (12, [0, f_l, 0, f_r]: the pull meant for the robot's l_hand
    and r_hand). Outputs desired_state (2n) and feedforward (n), actuator order."""

    def __init__(
        self, plant: MultibodyPlant, robot: Robot, helper: HelperBody, reactive: ReactiveHumanConfig
    ):
        super().__init__()
        self._plant, self._robot_instance = plant, robot.model_instance
        self._plant_context = plant.CreateDefaultContext()
        self._hands = [robot.frame(plant, hand) for hand in GRIPS]
        self._height_m = helper.config.height_m
        self._model = person_model(helper.config, helper.X_WP)
        self._context = self._model.CreateDefaultContext()
        names = joint_names(self._model)
        n = self._n = len(names)
        in_plant = instance_joint_names(plant, helper.person.model_instance)
        self._from_plant = np.array([in_plant.index(name) for name in names])
        self._to_actuators = np.array([names.index(name) for name in helper.person.joint_names])
        self._lumbar = names.index("lumbar_flexion")
        self._arms = np.array([not name.startswith("lumbar") for name in names])
        self._bend0 = helper.q0["lumbar_flexion"]
        # The set-point's time constant and its step toward the posture per update.
        self._yield_s = YIELD_TIME_S[helper.config.tone]
        self._follow = min(1.0, PERCEPTION_PERIOD_S / self._yield_s)
        # The trunk set-point's largest step per update, at a person's own pace.
        self._trunk_step = TRUNK_RATE_RAD_PER_S * PERCEPTION_PERIOD_S
        # When they let go: as the intent eases off (the robot's CoM rising through
        # ease_com_rise_m as they saw it), or over ramp_s once the pull's time is over.
        self._ease_m = reactive.ease_com_rise_m
        self._pull_end_s = reactive.start_s + reactive.duration_s
        self._release_step = min(1.0, PERCEPTION_PERIOD_S / max(reactive.ramp_s, 1e-9))
        # What they saw and felt: one sample (_SEEN) per update over their reaction time,
        # oldest first. Feeling more than they mean to pull, they give way (a strong
        # person's trunk straightening at its set-point pulled 54 N and toppled the robot
        # forward; firm arms held its rising hands back with 83 N: measured).
        self._cap_N = reactive.force_cap_N
        self._slots = round(reactive.reaction_time_s / PERCEPTION_PERIOD_S)
        self._yield_lag = min(round(YIELD_LATENCY_S / PERCEPTION_PERIOD_S), self._slots)
        self._state = self.DeclareVectorInputPort("person_state", 2 * n)
        self._robot_state = self.DeclareVectorInputPort(
            "robot_state", plant.num_multibody_states(robot.model_instance)
        )
        self._intent = self.DeclareVectorInputPort("intent_wrenches_W", 12)
        self._felt = self.DeclareVectorInputPort("grip_wrenches_W", 12)
        self._seen = self.DeclareDiscreteState(_SEEN * (self._slots + 1))
        self._command = self.DeclareDiscreteState(3 * n + 1)
        self._inertia = self.DeclareDiscreteState(n)  # the arms' inertia torques, as activated
        self._activate = min(1.0, PERCEPTION_PERIOD_S / ACTIVATION_S)
        self.DeclarePeriodicDiscreteUpdateEvent(PERCEPTION_PERIOD_S, 0.0, self._Update)
        self.DeclareInitializationDiscreteUpdateEvent(self._Start)
        ticket = {self.discrete_state_ticket(self._command)}
        self.DeclareVectorOutputPort(
            "desired_state", 2 * n, self._CalcDesired, prerequisites_of_calc=ticket
        )
        self.DeclareVectorOutputPort(
            "feedforward", n, self._CalcFeedforward, prerequisites_of_calc=ticket
        )
        self.DeclareVectorOutputPort(
            "grip",
            1,
            lambda c, out: out.SetAtIndex(0, c.get_discrete_state(self._command).value()[-1]),
            prerequisites_of_calc=ticket,
        )

    def _posture(self, context: Context) -> np.ndarray:
        """The person's joint angles now, model order."""
        return self._state.Eval(context)[: self._n][self._from_plant]

    def _rates(self, context: Context) -> np.ndarray:
        """The person's joint rates now, model order."""
        return self._state.Eval(context)[self._n :][self._from_plant]

    def _look(self, context: Context) -> np.ndarray:
        """(_SEEN,) [z, dz/dt, |f|, v_l, v_r]: the robot's CoM height and its rate, the
        larger grip force on their hands, and the velocities of the robot's hands they
        hold (GRIPS' order, world), now."""
        plant, c, instances = self._plant, self._plant_context, [self._robot_instance]
        plant.SetPositionsAndVelocities(c, self._robot_instance, self._robot_state.Eval(context))
        z = plant.CalcCenterOfMassPositionInWorld(c, instances)[2]
        rate = plant.CalcCenterOfMassTranslationalVelocityInWorld(c, instances)[2]
        felt = self._felt.Eval(context).reshape(2, 6)[:, 3:]
        world = plant.world_frame()
        held = [f.CalcSpatialVelocity(c, world, world).translational() for f in self._hands]
        return np.concatenate([[z, rate, np.linalg.norm(felt, axis=1).max()], *held])

    def _held_motion(self, seen: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(6,), (6,): the held hands' velocity and acceleration now as the person predicts
        them from what they felt YIELD_LATENCY_S ago (carried on at the acceleration then)."""
        samples = seen.reshape(-1, _SEEN)[:, 3:]
        lag = self._yield_lag
        if lag + 1 >= len(samples):  # too short a memory for a rate: no prediction
            return samples[-1 - lag], np.zeros(6)
        accel = (samples[-1 - lag] - samples[-2 - lag]) / PERCEPTION_PERIOD_S
        return samples[-1 - lag] + lag * PERCEPTION_PERIOD_S * accel, accel

    def _Start(self, context: Context, discrete_state) -> None:
        q = self._posture(context)
        seen = self._look(context)
        c = self._plant_context  # the hands where they start (set by _look)
        self._hands_z0 = np.mean([f.CalcPoseInWorld(c).translation()[2] for f in self._hands])
        self._com_z0 = seen[0]
        discrete_state.set_value(self._seen, np.tile(seen, self._slots + 1))
        v_d = np.zeros(self._n)
        discrete_state.set_value(
            self._command, self._command_from(context, q, q, v_d, 1.0, np.zeros(self._n))
        )

    def _Update(self, context: Context, discrete_state) -> None:
        q = self._posture(context)
        seen = discrete_state.get_mutable_value(self._seen)
        seen[:-_SEEN] = seen[_SEEN:].copy()
        seen[-_SEEN:] = self._look(context)
        command = context.get_discrete_state(self._command).value()
        q_d = np.empty(self._n)
        q_d[self._to_actuators] = command[: self._n]  # back to the model's order
        # They give way to a pull beyond what they mean (felt YIELD_LATENCY_S ago): not at
        # all up to their intent's cap, wholly from twice it.
        felt = seen[-_SEEN * (1 + self._yield_lag) + 2]
        give = min(1.0, max(0.0, felt / self._cap_N - 1.0)) if self._cap_N > 0 else 0.0
        q_d += (self._follow + give * (1.0 - self._follow)) * (q - q_d)
        # Their arms move with the hands they hold, as far as they still hold them: the
        # set-point at the held hands' predicted velocity, and their arms' own inertia
        # carried (inverse dynamics of that motion, a feed-forward).
        grip = command[-1]
        velocity, accel = self._held_motion(seen)
        model, c = self._model, self._context
        model.SetPositions(c, q)
        J_grips = grips_jacobian(model, c)
        trunk = ~self._arms  # the hands' motion their trunk already makes is not the arms'
        velocity = velocity - J_grips[:, trunk] @ self._rates(context)[trunk]
        J = J_grips[:, self._arms]
        to_joints = np.linalg.solve(J.T @ J + _ARMS_DAMPING * np.eye(J.shape[1]), J.T)
        dq, ddq = np.zeros(self._n), np.zeros(self._n)
        dq[self._arms] = grip * (to_joints @ velocity)
        ddq[self._arms] = (1.0 - give) * grip * (to_joints @ accel)
        q_d += (1.0 - give) * PERCEPTION_PERIOD_S * dq
        # The CoM's rise they expect now: what they saw, carried on at its rate.
        rise = seen[0] + self._slots * PERCEPTION_PERIOD_S * seen[1] - self._com_z0
        height = self._height_m
        planned = (
            self._bend0 + bend_for(height, self._hands_z0 + rise) - bend_for(height, self._hands_z0)
        )
        step = self._trunk_step
        q_d[self._lumbar] += (1.0 - give) * np.clip(planned - q_d[self._lumbar], -step, step)
        # Their grip: held, let go of (never taken again) once the robot is up.
        eased = seen[0] - self._com_z0 >= self._ease_m[1]  # the intent eased off wholly
        if eased or context.get_time() >= self._pull_end_s:
            grip = max(0.0, grip - self._release_step)
        v_d = (1.0 - give) * ((q - q_d) / self._yield_s + dq) + give * self._rates(context)
        inertia = discrete_state.get_mutable_value(self._inertia)
        inertia += self._activate * (model.CalcMassMatrix(c) @ ddq - inertia)
        discrete_state.set_value(
            self._command, self._command_from(context, q, q_d, v_d, grip, inertia, J_grips=J_grips)
        )

    def _command_from(
        self,
        context: Context,
        q: np.ndarray,
        q_d: np.ndarray,
        v_d: np.ndarray,
        grip: float,
        inertia: np.ndarray,
        *,
        J_grips: np.ndarray | None = None,
    ) -> np.ndarray:
        """[q_d, v_d, u_ff, grip]: in actuator order the set-point and its rate (model
        order), and from the posture now (q) their weight, their arms' inertia (the torques
        that move them with the held hands, model order) and the intended pull (as far as
        they still hold the hands); their grip, 1 held, 0 let go. J_grips: the grips'
        Jacobian at q, if the caller has it (_Update does)."""
        model, c = self._model, self._context
        model.SetPositions(c, q)
        u = inertia - model.CalcGravityGeneralizedForces(c)
        f = self._intent.Eval(context).reshape(2, 6)[:, 3:]
        if np.any(f):
            if J_grips is None:
                J_grips = grips_jacobian(model, c)
            u += grip * (J_grips.T @ f.ravel())
        v_d = v_d.copy()
        v_d[self._lumbar] = 0.0  # the trunk's set-point is its own (not following q)
        order = self._to_actuators
        return np.concatenate([q_d[order], v_d[order], u[order], [grip]])

    def _CalcDesired(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(context.get_discrete_state(self._command).value()[: 2 * self._n])

    def _CalcFeedforward(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(context.get_discrete_state(self._command).value()[2 * self._n : -1])


class Grips(LeafSystem):
    """The hands' spring-damper, f = k (p_grip - p_hand) + d (v_grip - v_hand) on each of
    the robot's hands (GRIPS: l_hand, r_hand), -f on the person's grip, at the frames'
    origins. Input plant_state (the whole plant's). Outputs spatial_forces (the plant's
    applied forces, all four), hand_wrenches_W (12, [0, f_l, 0, f_r]: what the robot's
    wrist sensors read) and grip_wrenches_W (12: the same on the person's grips)."""

    def __init__(self, plant: MultibodyPlant, robot: Robot, helper: HelperBody):
        super().__init__()
        self._plant = plant
        self._context = plant.CreateDefaultContext()
        cfg = helper.config
        self._k, self._d = cfg.grip_stiffness_N_per_m, cfg.grip_damping_Ns_per_m
        instance = helper.person.model_instance
        self._pairs = [
            (robot.frame(plant, hand), plant.GetFrameByName(grip, instance))
            for hand, grip in GRIPS.items()
        ]
        self._applied = [applied_at(frame) for pair in self._pairs for frame in pair]
        self._x = self.DeclareVectorInputPort("plant_state", plant.num_multibody_states())
        self._grip = self.DeclareVectorInputPort("grip", 1)
        cache = declare_cached(
            self, "grip forces", self._forces, {self._x.ticket(), self._grip.ticket()}
        )
        prereq = {cache.ticket()}
        self._cache = cache
        self.DeclareVectorOutputPort(
            "hand_wrenches_W",
            12,
            lambda c, out: out.SetFromVector(self._wrenches(c, 1.0)),
            prerequisites_of_calc=prereq,
        )
        self.DeclareVectorOutputPort(
            "grip_wrenches_W",
            12,
            lambda c, out: out.SetFromVector(self._wrenches(c, -1.0)),
            prerequisites_of_calc=prereq,
        )
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
            self._CalcSpatialForces,
            prerequisites_of_calc=prereq,
        )

    def _forces(self, context: Context) -> np.ndarray:
        """(2, 3) the grips' forces on the robot's l_hand and r_hand, world, as far as
        the person holds them (grip input). N."""
        held = float(self._grip.Eval(context)[0])
        if held == 0.0:
            return np.zeros((2, 3))
        plant, c = self._plant, self._context
        plant.SetPositionsAndVelocities(c, self._x.Eval(context))
        world = plant.world_frame()
        forces = np.zeros((2, 3))
        for i, (hand, grip) in enumerate(self._pairs):
            stretch = grip.CalcPoseInWorld(c).translation() - hand.CalcPoseInWorld(c).translation()
            rate = (
                grip.CalcSpatialVelocity(c, world, world).translational()
                - hand.CalcSpatialVelocity(c, world, world).translational()
            )
            forces[i] = held * (self._k * stretch + self._d * rate)
        return forces

    def _wrenches(self, context: Context, sign: float) -> np.ndarray:
        wrenches = np.zeros(12)
        wrenches.reshape(2, 6)[:, 3:] = sign * self._cache.Eval(context)
        return wrenches

    def _CalcSpatialForces(self, context: Context, output) -> None:
        forces = self._cache.Eval(context)
        for i in range(2):
            self._applied[2 * i].F_Bq_W = SpatialForce(np.zeros(3), forces[i])
            self._applied[2 * i + 1].F_Bq_W = SpatialForce(np.zeros(3), -forces[i])
        output.set_value(list(self._applied))


def make_body_helper(
    plant: MultibodyPlant,
    robot: Robot,
    config: HumanConfig,
    helper: HelperBody,
    intent: LeafSystem | None = None,
) -> Diagram:
    """The person's intent, muscles and grips as one system: inputs robot_state,
    person_state and plant_state; outputs spatial_forces, hand_wrenches_W (the grips' on
    the robot), grip_wrenches_W, intent_wrenches_W, desired_state, feedforward and grip
    (diagram.py wires them to the station). intent: what they mean to pull, a system with
    HumanWrenchSource's ports (the live page's sliders, live.py: its stand_up and response
    outputs are exported too); default human.reactive's partner."""
    builder = DiagramBuilder()
    if intent is None:
        reactive = HumanConfig(mode="reactive", reactive=config.reactive)
        intent = HumanWrenchSource(plant, robot, reactive)
    intent = builder.AddNamedSystem("intent", intent)
    for name in ("stand_up", "response"):
        if intent.HasOutputPort(name):
            builder.ExportOutput(intent.GetOutputPort(name), name)
    muscles = builder.AddNamedSystem(
        "muscles", PersonController(plant, robot, helper, config.reactive)
    )
    grips = builder.AddNamedSystem("grips", Grips(plant, robot, helper))
    builder.ExportInput(intent.GetInputPort("robot_state"), "robot_state")
    builder.ConnectInput("robot_state", muscles.GetInputPort("robot_state"))
    builder.ExportInput(muscles.GetInputPort("person_state"), "person_state")
    builder.ExportInput(grips.GetInputPort("plant_state"), "plant_state")
    builder.Connect(
        intent.GetOutputPort("hand_wrenches_W"), muscles.GetInputPort("intent_wrenches_W")
    )
    builder.Connect(muscles.GetOutputPort("grip"), grips.GetInputPort("grip"))
    builder.Connect(grips.GetOutputPort("grip_wrenches_W"), muscles.GetInputPort("grip_wrenches_W"))
    for name in ("spatial_forces", "hand_wrenches_W", "grip_wrenches_W"):
        builder.ExportOutput(grips.GetOutputPort(name), name)
    builder.ExportOutput(intent.GetOutputPort("hand_wrenches_W"), "intent_wrenches_W")
    builder.ExportOutput(muscles.GetOutputPort("desired_state"), "desired_state")
    builder.ExportOutput(muscles.GetOutputPort("feedforward"), "feedforward")
    builder.ExportOutput(muscles.GetOutputPort("grip"), "grip")
    diagram = builder.Build()
    diagram.set_name("helper_body")
    return diagram


def body_helper(
    plant: MultibodyPlant,
    robot: Robot,
    config: HumanConfig,
    person: HelperBody,
    intent: LeafSystem | None = None,
) -> Diagram:
    """A person's body kneeling in front of the robot, pulling with human.reactive's intent
    (make_body_helper)."""
    return make_body_helper(plant, robot, config, person, intent)


body_helper.adds_body = True  # the scene puts the person's body into the plant (world/scene.py)
