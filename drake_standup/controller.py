"""WholeBodyController: the momentum-based whole-body torque controller (SPEC 2, 3, 7).

A thin LeafSystem around drake_standup/control/: every period_s it reads the robot's
state, the CoM reference, the contact plan and the measured hand wrenches, computes the
tick's references (control/references.py), solves one QP over [contact wrenches, vdot]
with the task objects of control/tasks.py (control/qp.py) and holds the resulting joint
torques.

Ports
    robot_state      (nq + nv)  [q (quaternion wxyz, p_WB, joints); v (w_WB, v_WB, joints)]
    com_reference    (9)        [x_d, xd_dot, xd_ddot], world, m, m/s, m/s^2
    contact_plan     (6)        [standup_state 1-4, seat_scale 0-1, feet_scale 0-1, what is
                                 left of the load of seat, l_thigh, r_thigh (0-1; NaN:
                                 seated)]
    hand_wrenches_W  (12)       [tau_l, f_l, tau_r, f_r], world, at the hand frames' origins
    -> actuation     (nu)       joint torques, actuator order, N m (zero-order held)
    -> diagnostics   (14)       see DIAGNOSTICS

Contacts: the seat (a 6-D contact on root_link under the buttocks), both thighs (point
forces on the thigh pads) and both soles (6-D). The seat and soles are held by the QP
(their frames do not accelerate); the thighs are then pinned already and carry forces
only. The seat may let the pelvis pitch about the hip axis from seat_hinge_from_state on,
but only until its unloading begins: with the default plan that is the same instant
(state 2), so the hinge no longer acts. Hinged through state 2 (held rows, no force) the
QP counted on a support the chair did not give: the thighs chattered 0-150 N and the
stand-up fell backwards for a 0.05 s change of the unloading time (measured).

Contact plan: seat_scale scales the seat's and thighs' normal-force bounds while seated
(the plan ramps it to 0 to release the seat; at 0 they are dropped); feet_scale scales
the soles' minimum normal force (0 drops them). While a seat pad unloads, the plan gives
what is left of its load (state_machine.seat_unloading, 1 -> 0): its normal force is then
bounded by that fraction of the force the controller commanded it when its unloading
began, with no minimum (a pad lifting off cannot push). From the moment the buttocks
start to unload the seat holds no rows: nothing holds the pelvis then but the thighs' and
soles' forces, and the CoM task moves the whole body. standup_state picks, in one table
(control/references.py: StandupSchedule), the CoM gains (seated 1-2, standing 3-4), the
base pitch, the posture reference (state 1: the posture at the first tick) and whether
the seat is hinged.
"""

import math
import time
from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from drake_standup.config import ControllerConfig
from drake_standup.control.contacts import NORMAL, WRENCH_SIZE, ContactSpec
from drake_standup.control.qp import (
    ContactCommands,
    ContactMap,
    QpSolution,
    WholeBodyQp,
    as_slice,
)
from drake_standup.control.references import ReferenceGenerator, StandupSchedule, joint_values
from drake_standup.control.tasks import (
    BaseOrientationTask,
    CopCenteringTask,
    JointLimitBounds,
    MomentumTask,
    PostureTask,
    StancePostureTask,
)
from drake_standup.control.terms import RobotKinematics, RobotTerms
from drake_standup.phases import PhaseTable
from drake_standup.robot import Robot, actuated_joints


def _contact_specs(
    plant: MultibodyPlant, robot: Robot, config: ControllerConfig
) -> list[ContactSpec]:
    """Seat (held at the hip axis), both thighs (point forces, pinned by the others),
    both soles."""
    seat = robot.frame(plant, "seat")
    context = plant.CreateDefaultContext()
    p_SeatHinge = np.mean(
        [
            plant.GetJointByName(name, robot.model_instance)
            .frame_on_parent()
            .CalcPose(context, seat)
            .translation()
            for name in config.seat_hinge_joints
        ],
        axis=0,
    )
    friction = {
        "friction_coefficient": config.friction_coefficient,
        "torsional_friction_coefficient": config.torsional_friction_coefficient_m,
    }
    seat_box = {"cop_x_m": tuple(config.seat_cop_x_m), "cop_y_m": tuple(config.seat_cop_y_m)}
    foot_box = {"cop_x_m": tuple(config.foot_cop_x_m), "cop_y_m": tuple(config.foot_cop_y_m)}
    return [
        ContactSpec("seat", **friction, **seat_box, hold_point_m=tuple(p_SeatHinge.tolist())),
        ContactSpec("l_thigh", **friction, point=True, constrained=False),
        ContactSpec("r_thigh", **friction, point=True, constrained=False),
        ContactSpec("l_sole", **friction, **foot_box),
        ContactSpec("r_sole", **friction, **foot_box),
    ]


@dataclass
class _Joints:
    """The actuated joints, in actuator order."""

    names: list[str]
    q_indices: np.ndarray  # index of each joint's angle in q
    v_indices: np.ndarray  # index of each joint's rate in v
    q_min: np.ndarray  # position limits, rad
    q_max: np.ndarray


def _actuated_joints(plant: MultibodyPlant, robot: Robot) -> _Joints:
    # Indices into the robot's state: the chair and floor are welded, so the
    # robot's q and v are the plant's.
    actuated = actuated_joints(plant, robot.model_instance)
    joints = [plant.GetJointByName(name, robot.model_instance) for name in actuated.names]
    return _Joints(
        names=actuated.names,
        q_indices=actuated.q_index,
        v_indices=actuated.v_index,
        q_min=np.array([joint.position_lower_limits()[0] for joint in joints]),
        q_max=np.array([joint.position_upper_limits()[0] for joint in joints]),
    )


@dataclass
class ControllerTick:
    """One tick's solution and the controller's memory after it."""

    solution: QpSolution  # for the active contacts only
    terms: RobotTerms
    normal_forces_N: np.ndarray  # commanded f_z of every contact (CONTACTS), 0 if inactive
    helpful_force_W: np.ndarray  # f_par, N
    posture: np.ndarray  # next value of the posture state (see __init__)
    lean_W: np.ndarray  # next value of the lean state, m
    height_integral: float  # next value of the stance's height integral, m s
    mass_scale: tuple[float, float]  # next value of the mass estimate's state
    unloading: np.ndarray  # next value of the unloading memory (see __init__)
    inputs_s: float  # evaluating the input ports (and the upstream systems behind them)
    kinematics_s: float
    assembly_s: float


class WholeBodyController(LeafSystem):
    """Momentum-based whole-body torque controller (module docstring)."""

    CONTACTS = ("seat", "l_thigh", "r_thigh", "l_sole", "r_sole")
    HANDS = ("l_hand", "r_hand")
    # Entry of contact_plan that scales each contact: seat_scale (1) or feet_scale (2).
    PLAN_SCALE = {"seat": 1, "l_thigh": 1, "r_thigh": 1, "l_sole": 2, "r_sole": 2}
    # Layout of the diagnostics output.
    DIAGNOSTICS = (
        "qp_ok",  # 1 if this tick's QP succeeded, else 0 (torques held)
        "qp_failures",  # failed QPs since the start
        "solve_time_s",  # QP solver time this tick
        "tick_time_s",  # whole tick: kinematics, assembly, solve
        "seat_fz_N",  # commanded normal force, seat contact
        "l_thigh_fz_N",  # commanded normal force, left thigh
        "r_thigh_fz_N",  # commanded normal force, right thigh
        "l_sole_fz_N",  # commanded normal force, left sole
        "r_sole_fz_N",  # commanded normal force, right sole
        "helpful_force_N",  # ||f_par||: the part of the pull the controller lets act
        "joint_limit_slack",  # largest slack of the soft joint-limit bounds, rad/s^2
        "lean_x_m",  # the CoM target's lean against the pull, x
        "lean_y_m",  # ... and y, m
        "qp_relaxed",  # ticks solved only with the contacts relaxed, since the start
        "mass_scale",  # the model's mass scale, estimated while seated (1: nominal)
    )
    # Columns of timing_s().
    TIMING = ("inputs_s", "kinematics_s", "assembly_s", "solve_s", "total_s")

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: Robot,
        config: ControllerConfig,
        table: PhaseTable | None = None,
        period_s: float = 0.001,
    ):
        super().__init__()
        table = PhaseTable() if table is None else table
        self._stance_states = {k for k, phase in enumerate(table, start=1) if phase.stance}
        self._config = config
        self._period_s = period_s
        self._B = plant.MakeActuationMatrix()
        actuators = plant.GetJointActuatorIndices(robot.model_instance)
        self._torque_limit_Nm = config.torque_limit_Nm or min(
            plant.get_joint_actuator(i).effort_limit() for i in actuators
        )
        self._nv, self._nu = nv, nu = self._B.shape
        self.contact_specs = _contact_specs(plant, robot, config)
        held_frames = [spec.frame for spec in self.contact_specs if spec.constrained]
        self._joints = joints = _actuated_joints(plant, robot)
        self._references = ReferenceGenerator(
            config,
            StandupSchedule(table, config, joints.names, joints.q_min, joints.q_max),
            as_slice(joints.q_indices),
            period_s,
            gravity_mps2=-plant.gravity_field().gravity_vector()[2],
        )
        self._posture_weights = joint_values(
            joints.names,
            config.posture_weight_by_joint,
            "posture_weight_by_joint",
            config.posture_weight,
        )
        self._stance_weights, self._stance_arm_weights = (
            joint_values(joints.names, getattr(config, key), key, 0.0)
            for key in ("stance_posture_weight_by_joint", "stance_arm_weight_by_joint")
        )
        self._joint_limits = JointLimitBounds(
            joints.q_indices,
            joints.v_indices,
            joints.q_min,
            joints.q_max,
            config.joint_limit_horizon_s,
        )
        self._kinematics = RobotKinematics(
            plant,
            robot,
            held_frames=held_frames,
            other_frames=[spec.frame for spec in self.contact_specs if not spec.constrained]
            + list(self.HANDS),
            hold_points_m={spec.frame: spec.hold_point_m for spec in self.contact_specs},
        )
        # The weight's wrench about the CoM, [0; m g], N.
        self._gravity_W = plant.gravity_field().gravity_vector()
        self._nominal_weight_N = -self._kinematics.nominal_mass_kg * self._gravity_W[2]
        self._W_gravity = np.zeros(6)  # updated in place with the mass estimate
        self._W_gravity[3:] = self._kinematics.mass_kg * self._gravity_W
        # Held rows of the seat's acceleration from seat_hinge_from_state: all but the
        # pitch about the hip axis (alpha_y in C).
        self._hinged_rows = np.ones(WRENCH_SIZE, dtype=bool)
        self._hinged_rows[1] = False
        self._hands = list(self.HANDS)
        # One program per set of active contacts (seat and thighs, soles), built when
        # first needed.
        self._programs: dict[tuple[bool, bool], _Program] = {}
        self._timing: list[tuple[float, ...]] = []

        nx = plant.num_positions(robot.model_instance) + nv
        self._state_port = self.DeclareVectorInputPort("robot_state", nx)
        self._reference_port = self.DeclareVectorInputPort("com_reference", 9)
        self._plan_port = self.DeclareVectorInputPort("contact_plan", 6)
        self._hands_port = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        # Measured normal forces on the buttocks, left and right thigh pads (N), in
        # CONTACTS' order of the seat contacts; unconnected (unit tests): not used.
        self._seat_pads_port = self.DeclareVectorInputPort("seat_pad_normal_forces_N", 3)
        # The measured vertical force on all the robot's pads, N; unconnected (unit
        # tests): the nominal model throughout.
        self._support_port = self.DeclareVectorInputPort("pads_vertical_force_N", 1)
        # Unconnected (unit tests): taken as 1, the segment finished.
        self._progress_port = self.DeclareVectorInputPort("path_progress", 1)
        self._actuation = self.DeclareDiscreteState(nu)
        self._diagnostics = self.DeclareDiscreteState(len(self.DIAGNOSTICS))
        self._momentum_integral = self.DeclareDiscreteState(3)  # int L_ang dt, N m s^2
        # [latched flag, state-1 posture (nu), filtered posture reference (nu), base yaw].
        self._posture = self.DeclareDiscreteState(2 + 2 * nu)
        self._lean = self.DeclareDiscreteState(3)  # the CoM target's lean, m
        self._height_integral = self.DeclareDiscreteState(1)  # stance, int (z_d - z), m s
        # [the model's mass scale, estimated while seated; 1 once the stand-up has begun].
        self._mass_scale = self.DeclareDiscreteState(np.array([1.0, 0.0]))
        # Unloading memory of the seat and thighs: [the commanded loads their unloading
        # started from (3), their last commanded loads (3)], N.
        self._unloading = self.DeclareDiscreteState(6)
        self.DeclareStateOutputPort("actuation", self._actuation)
        self.DeclareStateOutputPort("diagnostics", self._diagnostics)
        # Initialization event: the plant's first step already sees computed torques.
        self.DeclareInitializationDiscreteUpdateEvent(self._Update)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._Update)

    # --- Timing --------------------------------------------------------------------

    def timing_s(self) -> np.ndarray:
        """Per-tick compute times since construction (or reset_timing), (ticks, 5), in
        the columns of TIMING: input ports (including the upstream systems' outputs they
        evaluate), kinematics/dynamics terms, tasks + QP assembly, QP solve, and the whole
        discrete update."""
        return np.array(self._timing).reshape(-1, len(self.TIMING))

    def reset_timing(self) -> None:
        self._timing.clear()

    # --- One tick ------------------------------------------------------------------

    def CalcTick(self, context: Context) -> ControllerTick:
        """Solves the QP for the inputs and discrete state in context (no side effects)."""
        t_start = time.perf_counter()
        x = self._state_port.Eval(context)
        com_reference = self._reference_port.Eval(context)
        plan = self._plan_port.Eval(context)
        F_hand_W = self._hands_port.Eval(context)
        progress = (
            float(self._progress_port.Eval(context)[0])
            if self._progress_port.HasValue(context)
            else 1.0
        )
        t_inputs = time.perf_counter()

        standup_state, seat_scale, feet_scale = plan[:3].tolist()
        standup_state = min(max(int(round(standup_state)), 1), 4)
        program = self._program((seat_scale > 0.0, feet_scale > 0.0))
        state = context.get_discrete_state()
        mass_scale, began = state.get_value(self._mass_scale)
        began = began or standup_state > 1
        tau_m = self._config.mass_estimation_filter_s
        if not began and tau_m > 0.0 and self._support_port.HasValue(context):
            # Weighing while first seated: at rest m g = the pads' and the hands' vertical
            # forces. Frozen from the first stand-up on: a robot sat back by a hindering
            # pull rocks on the seat, and weighing it then put the model 3 % off (measured).
            weight_N = float(self._support_port.Eval(context)[0]) + F_hand_W[5] + F_hand_W[11]
            measured = weight_N / self._nominal_weight_N
            lo, hi = self._config.mass_scale_bounds
            mass_scale += min(self._period_s / tau_m, 1.0) * (measured - mass_scale)
            mass_scale = min(max(mass_scale, lo), hi)
        if abs(mass_scale - self._kinematics.mass_scale) > 1e-4:
            # 1e-4: the model follows the estimate within 0.01 % and is not rescaled
            # at every seated tick (83 us a time, measured, against a ~600 us tick).
            self._kinematics.set_mass_scale(mass_scale)
            self._W_gravity[3:] = self._kinematics.mass_kg * self._gravity_W
        pulled = bool(F_hand_W.any())
        terms = self._kinematics.calc(x, program.frames, self._hands if pulled else ())
        t_kinematics = time.perf_counter()

        references = self._references.calc(
            terms,
            standup_state,
            com_reference,
            F_hand_W if pulled else None,
            state.get_value(self._momentum_integral),
            state.get_value(self._posture),
            state.get_value(self._lean),
            progress,
            float(state.get_value(self._height_integral)[0]),
        )
        unloading = self._next_unloading(state.get_value(self._unloading), plan)
        measured = (
            self._seat_pads_port.Eval(context) if self._seat_pads_port.HasValue(context) else None
        )
        commands = self._contact_commands(
            program, references.state.seat_hinged, plan, unloading[:3], measured, bool(began)
        )
        t_tasks = time.perf_counter()
        solution = program.qp.solve(terms, references, commands)

        normal_forces_N = np.zeros(len(self.CONTACTS))
        normal_forces_N[program.contact_index] = solution.F_C[:, NORMAL]
        if solution.ok:
            unloading[3:] = normal_forces_N[:3]
        return ControllerTick(
            solution=solution,
            terms=terms,
            normal_forces_N=normal_forces_N,
            helpful_force_W=references.helpful_force_W,
            posture=references.next_posture,
            lean_W=references.lean_W,
            height_integral=references.next_height_integral,
            mass_scale=(mass_scale, float(began)),
            unloading=unloading,
            inputs_s=t_inputs - t_start,
            kinematics_s=t_kinematics - t_inputs,
            assembly_s=t_tasks - t_kinematics + solution.assembly_s,
        )

    def _program(self, active: tuple[bool, bool]) -> "_Program":
        """The QP over the active contacts (seat and thighs, soles: built at the first
        tick that needs it)."""
        program = self._programs.get(active)
        if program is None:
            config = self._config
            contacts = [
                spec for spec in self.contact_specs if active[self.PLAN_SCALE[spec.frame] - 1]
            ]
            contact_map = ContactMap(contacts, self._nv)
            layout = contact_map.layout
            joints = self._joints

            def posture(kind, weights, name="posture", states=None):
                return kind(
                    layout,
                    joints.q_indices,
                    joints.v_indices,
                    weights,
                    config.posture_kp_per_s2,
                    config.posture_damping_ratio,
                    name=name,
                    active_states=None if states is None else frozenset(states),
                )

            tasks = [
                MomentumTask(layout, contact_map, self._W_gravity, config.momentum_weight),
                CopCenteringTask(layout, contacts, config.cop_centering_weight),
                posture(PostureTask, self._posture_weights),
                # State 4: the legs (and the arms a little) from its start; the arms
                # more as the stance grows (ControllerConfig.stance_*).
                posture(PostureTask, self._stance_weights, "stance_posture", self._stance_states),
                posture(
                    StancePostureTask, self._stance_arm_weights, "stance_arms", self._stance_states
                ),
                BaseOrientationTask(
                    layout,
                    config.base_orientation_weight,
                    config.base_orientation_kp_per_s2,
                    config.base_orientation_damping_ratio,
                ),
            ]
            qp = WholeBodyQp(
                contact_map,
                self._B,
                torque_limit_Nm=self._torque_limit_Nm,
                torque_weight=config.torque_weight,
                wrench_weight=config.wrench_weight,
                acceleration_weight=config.acceleration_weight,
                tasks=tasks,
                soft_bounds=self._joint_limits,
                soft_bound_weight=config.joint_limit_weight,
                solver=config.qp_solver,
            )
            soles = np.array([spec.frame in ("l_sole", "r_sole") for spec in contacts])
            seated = np.flatnonzero(~soles)
            program = _Program(
                qp=qp,
                frames=qp.frames,
                contact_index=[self.CONTACTS.index(spec.frame) for spec in contacts],
                plan_index=np.array([self.PLAN_SCALE[spec.frame] for spec in contacts]),
                soles=soles,
                seated=seated,
                seat_index=np.array(
                    [self.CONTACTS.index(contacts[c].frame) for c in seated], dtype=int
                ),
                partially_held={
                    "held": {},
                    "hinged": {
                        c: self._hinged_rows
                        for c, spec in enumerate(contacts)
                        if spec.constrained and not soles[c]
                    },
                    "free": {
                        c: np.zeros(WRENCH_SIZE, dtype=bool)
                        for c, spec in enumerate(contacts)
                        if spec.constrained and not soles[c]
                    },
                },
            )
            self._programs[active] = program
        return program

    @staticmethod
    def _next_unloading(memory: np.ndarray, plan: np.ndarray) -> np.ndarray:
        """The unloading memory for this tick: a seat pad whose unloading starts now (its
        fraction at 1 or above, i.e. the ramp's first ticks, or NaN before) starts from
        its last commanded load. Seated (NaN) pads keep following their commands."""
        unloading = memory.copy()
        seated = ~np.isfinite(plan[3:6]) | (plan[3:6] >= 1.0)
        unloading[:3][seated] = memory[3:][seated]
        return unloading

    def _contact_commands(
        self,
        program: "_Program",
        seat_hinged: bool,
        plan: np.ndarray,
        unload_from_N: np.ndarray,
        measured_N: np.ndarray | None = None,
        resat: bool = False,
    ) -> ContactCommands:
        """Normal-force bounds from the plan: seat and thighs in seat_scale * [f_min,
        f_max_seat] while seated, in [0, fraction * the load they unload from] while they
        unload; soles in [feet_scale * f_min, f_max_foot]. The seat holds all six rows until
        it is hinged (StateReferences.seat_hinged), then all but the pitch about the hip
        axis, and none once the buttocks unload: held with no force, the seat kept
        the hips still while the thighs unloaded, asking the soles to keep the pelvis
        hovering; the CoM fell 2-7 cm behind its reference, and when the hold dropped at
        the end of the release that error came back as a 300 N jolt on the soles and the
        thighs landed again (measured). While they unload, the seat pads are also bounded
        by their measured load plus seat_measured_margin_N: the thighs are forces the QP
        does not pin, and it planned on up to three times what the compliant pads carried
        (in state 3, 145 N against 49 N, measured). Not in state 2: there the bound fed
        back (less commanded, less carried) and unloaded the thighs with the CoM still
        behind the feet: every scenario fell backwards (measured)."""
        config = self._config
        scales = plan[program.plan_index]
        min_normal_force_N = scales * config.min_normal_force_N
        max_normal_force_N = np.where(
            program.soles, config.foot_max_normal_force_N, scales * config.seat_max_normal_force_N
        )
        fractions = plan[3 + program.seat_index]
        unloading = np.isfinite(fractions)
        seated = program.seated[unloading]
        min_normal_force_N[seated] = 0.0
        max_normal_force_N[seated] = (
            fractions[unloading] * unload_from_N[program.seat_index[unloading]]
        )
        if measured_N is not None:
            max_normal_force_N[seated] = np.minimum(
                max_normal_force_N[seated],
                np.maximum(measured_N[program.seat_index[unloading]], 0.0)
                + config.seat_measured_margin_N,
            )
        if np.isfinite(plan[3]):  # the buttocks unloading
            hold = "free"
        else:
            # Sat back by a hindering pull (state 1 after a stand-up began), the pelvis
            # still pitched forward: hinged, so that the base task brings it upright.
            # Held, the QP pinned a pelvis that was pitching back onto the chair, and
            # it rocked +-0.45 rad between buttocks and thighs until the feet slid
            # (measured).
            hold = "hinged" if (seat_hinged or resat) else "held"
        return ContactCommands(min_normal_force_N, max_normal_force_N, program.partially_held[hold])

    def _Update(self, context: Context, discrete_state: DiscreteValues) -> None:
        t_start = time.perf_counter()
        tick = self.CalcTick(context)
        solution = tick.solution
        state = context.get_discrete_state()
        failures = state.get_value(self._diagnostics)[1] + (0.0 if solution.ok else 1.0)
        if solution.ok:  # on failure the last torques stay in the actuation state
            discrete_state.set_value(self._actuation, solution.tau)
        integral = state.get_value(self._momentum_integral) + self._period_s * tick.terms.L_WCom[:3]
        discrete_state.set_value(self._momentum_integral, integral)
        discrete_state.set_value(self._posture, tick.posture)
        discrete_state.set_value(self._lean, tick.lean_W)
        discrete_state.set_value(self._height_integral, [tick.height_integral])
        discrete_state.set_value(self._unloading, tick.unloading)
        discrete_state.set_value(self._mass_scale, tick.mass_scale)
        total_s = time.perf_counter() - t_start
        diagnostics = np.empty(len(self.DIAGNOSTICS))
        f_par = tick.helpful_force_W
        diagnostics[:4] = float(solution.ok), failures, solution.solve_s, total_s
        diagnostics[4:9] = tick.normal_forces_N if solution.ok else np.nan
        diagnostics[9] = math.sqrt(float(f_par @ f_par))
        diagnostics[10] = float(np.abs(solution.slack).max()) if solution.slack.size else 0.0
        diagnostics[11:13] = tick.lean_W[:2]
        diagnostics[13] = state.get_value(self._diagnostics)[13] + float(solution.relaxed)
        diagnostics[14] = tick.mass_scale[0]
        discrete_state.set_value(self._diagnostics, diagnostics)
        self._timing.append(
            (tick.inputs_s, tick.kinematics_s, tick.assembly_s, solution.solve_s, total_s)
        )


@dataclass
class _Program:
    """A WholeBodyQp and what the tick needs to know of its contacts."""

    qp: WholeBodyQp
    frames: list[str]  # its contacts' frames, the frames terms are asked for
    contact_index: list[int]  # of each contact in WholeBodyController.CONTACTS
    plan_index: np.ndarray  # of each contact's scale in contact_plan
    soles: np.ndarray  # True for a sole
    seated: np.ndarray  # the program's seat and thigh contacts (indices)
    seat_index: np.ndarray  # ... their index in CONTACTS (0 seat, 1-2 thighs)
    # ContactCommands.partially_held with the seat held (all rows: state 1), hinged (from
    # seat_hinge_from_state: all but the pitch about the hip axis) and free (no rows: the
    # release, from state 3).
    partially_held: dict[str, dict[int, np.ndarray]]
