"""WholeBodyController: the momentum-based whole-body torque controller ([nava2016],
[authors-code], [early-probe]).

A plain object: each tick, from the controller's model at the robot's state (RobotTerms,
control/model.py), the tick's task references (TaskReferences, control/targets.py) and
the contact commands (ContactCommands, control/contacts.py), it solves one QP over
[contact wrenches, vdot] with the task objects of control/tasks/ (control/qp.py) for
the joint torques. The system that holds the torques and calls it once a tick is the
stand-up's (standup/whole_body.py); on a failed QP the last torques stay there.
next_diagnostics packs a tick's DIAGNOSTICS.

One QP program per set of active contacts (its size, and so its solve time, shrinks once
the seat is released), built at the first tick that needs it (make_program); the tasks
active in each mode are the caller's to say (the stance tasks in the stance modes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from drake_standup.config import ControllerConfig
from drake_standup.control.contacts import (
    CONTACTS,
    HOLDS,
    NORMAL,
    SOLES,
    THIGH_HOLDS,
    WRENCH_SIZE,
    ContactCommands,
    ContactSpec,
)
from drake_standup.control.model import ControllerJoints
from drake_standup.control.qp import ContactMap, QpContactBounds, QpSolution, WholeBodyQp
from drake_standup.control.targets import TaskReferences, joint_values
from drake_standup.control.tasks import (
    BaseOrientationTask,
    CopCenteringTask,
    JointLimitBounds,
    MomentumTask,
    PostureTask,
    SoleMomentRateTask,
    StancePostureTask,
)
from drake_standup.control.terms import RobotTerms
from drake_standup.ports.payloads import VectorLayout
from drake_standup.robot.limbs import joint_group, shoulder_tendon_limits

# Limbs the trunk carries, whose posture weight follows their mass (posture_weights).
CARRIED_LIMBS = ("arms", "neck")

DIAGNOSTICS = VectorLayout(
    ("qp_ok", 1),  # 1 if this tick's QP succeeded, else 0 (torques held)
    ("qp_failures", 1),  # failed QPs since the start
    ("solve_time_s", 1),  # QP solver time this tick
    ("tick_time_s", 1),  # the whole discrete update
    ("commanded_normal_force_N", len(CONTACTS)),  # f_z asked of CONTACTS (NaN: failed)
    ("joint_limit_slack", 1),  # largest slack of the soft joint-limit bounds, rad/s^2
    ("qp_relaxed", 1),  # ticks solved only with the contacts relaxed, since the start
    ("qp_fallback", 1),  # ticks daqp failed and the fallback solver solved, since the start
)
# Columns of WholeBodyController.timing_s().
TIMING = ("inputs_s", "kinematics_s", "assembly_s", "solve_s", "total_s")
_COMMANDED = DIAGNOSTICS["commanded_normal_force_N"]
_FAILURES, _RELAXED = DIAGNOSTICS.index("qp_failures"), DIAGNOSTICS.index("qp_relaxed")
_FALLBACK = DIAGNOSTICS.index("qp_fallback")


@dataclass(frozen=True)
class Program:
    """A WholeBodyQp over some active contacts, and how CONTACTS map into it."""

    qp: WholeBodyQp
    contact_index: np.ndarray  # of each of its contacts in CONTACTS
    # (HOLDS, THIGH_HOLDS) -> ContactCommands'
    partially_held: dict[tuple[str, str], dict[int, np.ndarray]]
    # The soles' moment-rate task, whose last wrenches the caller gives (None: none).
    moment_rate: SoleMomentRateTask | None = None
    # The soles' rows in the program's contacts (F_C).
    soles: tuple[int, int] = (0, 0)


def make_program(
    specs: list[ContactSpec],
    active: tuple[bool, ...],
    plant: MultibodyPlant,
    joints: ControllerJoints,
    config: ControllerConfig,
    stance_states: set[int],
    *,
    torque_limit_Nm: float,
    modes: tuple[int, ...],
    period_s: float = 0.0,
) -> Program:
    """The QP over the active contacts with the controller's tasks (control/tasks/):
    momentum, CoP centering, posture; in the stance states the legs' posture and the
    arms' (growing with the stance); base orientation; soft joint-limit bounds."""
    contacts = [spec for spec, on in zip(specs, active, strict=True) if on]
    contact_map = ContactMap(contacts, plant.num_velocities())
    tasks = _tasks(contacts, contact_map, plant, joints, config, stance_states, period_s=period_s)
    qp = WholeBodyQp(
        contact_map,
        plant.MakeActuationMatrix(),
        torque_limit_Nm=torque_limit_Nm,
        torque_weight=config.torque_weight,
        wrench_weight=config.wrench_weight,
        acceleration_weight=config.acceleration_weight,
        tasks=tasks,
        modes=modes,
        soft_bounds=JointLimitBounds(
            joints.q_indices,
            joints.v_indices,
            joints.q_min,
            joints.q_max,
            config.joint_limit_horizon_s,
            config.joint_braking_rad_per_s2,
            linear_limits=shoulder_tendon_limits(joints.names) if config.shoulder_tendons else None,
            num_velocities=plant.num_velocities(),
            speed_limit_rad_per_s=_speed_limits(joints, config),
            speed_time_constant_s=config.arm_speed_time_constant_s,
        ),
        soft_bound_weight=config.joint_limit_weight,
        solver=config.qp_solver,
        contact_velocity_gain_per_s=config.contact_velocity_gain_per_s,
        pad_period_s=period_s,
    )
    frames = [spec.frame for spec in contacts]
    return Program(
        qp=qp,
        contact_index=np.array([CONTACTS.index(spec.frame) for spec in contacts]),
        partially_held=_partially_held(contacts),
        moment_rate=next((t for t in tasks if isinstance(t, SoleMomentRateTask)), None),
        soles=tuple(frames.index(sole) for sole in CONTACTS[SOLES]),
    )


def _tasks(
    contacts: list[ContactSpec],
    contact_map: ContactMap,
    plant: MultibodyPlant,
    joints: ControllerJoints,
    config: ControllerConfig,
    stance_states: set[int],
    *,
    period_s: float = 0.0,
) -> list:
    """The program's tasks, in the order the QP adds their costs (the soles' moment rate
    only with a control period and a weight)."""
    layout = contact_map.layout

    def weights(table: dict[str, float], key: str, default: float) -> np.ndarray:
        return joint_values(joints.names, table, key, default)

    def posture(kind, table, name, states=None):
        return kind(
            layout,
            joints.q_indices,
            joints.v_indices,
            table,
            config.posture_kp_per_s2,
            config.posture_damping_ratio,
            name=name,
            active_states=states,
        )

    return [
        MomentumTask(
            layout, contact_map, plant.gravity_field().gravity_vector(), config.momentum_weight
        ),
        CopCenteringTask(layout, contacts, config.cop_centering_weight),
        posture(PostureTask, posture_weights(plant, joints, config), "posture"),
        posture(
            PostureTask,
            weights(config.stance_posture_weight_by_joint, "stance_posture_weight_by_joint", 0.0),
            "stance_posture",
            stance_states,
        ),
        posture(
            StancePostureTask,
            weights(config.stance_arm_weight_by_joint, "stance_arm_weight_by_joint", 0.0),
            "stance_arms",
            stance_states,
        ),
        BaseOrientationTask(
            layout,
            config.base_orientation_weight,
            config.base_orientation_kp_per_s2,
            config.base_orientation_damping_ratio,
        ),
    ] + (
        [SoleMomentRateTask(layout, contacts, config.sole_moment_rate_weight_s, period_s)]
        if config.sole_moment_rate_weight_s > 0.0 and period_s > 0.0
        else []
    )


def _speed_limits(joints: ControllerJoints, config: ControllerConfig) -> np.ndarray | None:
    """Each joint's speed limit for JointLimitBounds: the arms' (None: none)."""
    if config.arm_speed_limit_rad_per_s is None or joints.arms is None:
        return None
    return np.where(joints.arms, config.arm_speed_limit_rad_per_s, np.inf)


def posture_weights(plant: MultibodyPlant, joints: ControllerJoints, config: ControllerConfig):
    """The posture task's weight per joint: posture_weight_by_joint where it names one;
    with carried_limb_weight_by_mass, each joint of a limb the trunk carries (the arms, the
    neck) the torso pitch's weight times (the mass the torso carries over the mass that
    joint carries) ** carried_limb_weight_exponent; posture_weight elsewhere."""
    table = config.posture_weight_by_joint
    w = joint_values(joints.names, table, "posture_weight_by_joint", config.posture_weight)
    if not config.carried_limb_weight_by_mass or "torso_pitch" not in joints.names:
        return w
    carried = {name: _carried_mass_kg(plant, joints.instance, name) for name in joints.names}
    w_torso = w[joints.names.index("torso_pitch")]
    for i, name in enumerate(joints.names):
        if name not in table and joint_group(name) in CARRIED_LIMBS:
            ratio = carried["torso_pitch"] / carried[name]
            w[i] = w_torso * ratio**config.carried_limb_weight_exponent
    return w


def _carried_mass_kg(plant: MultibodyPlant, instance, joint_name: str) -> float:
    """The mass of the bodies a joint moves (its outboard subtree), kg, the model's."""
    joint = plant.GetJointByName(joint_name, instance)
    bodies = plant.GetBodiesKinematicallyAffectedBy([joint.index()])
    return sum(plant.get_body(body).default_mass() for body in bodies)


def _partially_held(
    contacts: list[ContactSpec],
) -> dict[tuple[str, str], dict[int, np.ndarray]]:
    """(HOLDS, THIGH_HOLDS) -> the rows each seat and thigh contact holds. The seat's:
    all (held), all but its pitch about the hip axis (hinged: alpha_y in C), none (free);
    a thigh on the chair does not sink (a_z in C); seated flat, it does not pitch either
    (alpha_y)."""
    seat = [c for c, spec in enumerate(contacts) if spec.frame == "seat"]
    thighs = [c for c, spec in enumerate(contacts) if spec.frame in ("l_thigh", "r_thigh")]
    hinged = np.ones(WRENCH_SIZE, dtype=bool)
    hinged[1] = False
    rows = {
        "held": np.ones(WRENCH_SIZE, dtype=bool),
        "hinged": hinged,
        "free": np.zeros(WRENCH_SIZE, dtype=bool),
    }
    thigh_rows = {hold: np.zeros(WRENCH_SIZE, dtype=bool) for hold in THIGH_HOLDS}
    thigh_rows["normal"][NORMAL] = True
    thigh_rows["flat"][[1, NORMAL]] = True
    partially_held = {}
    for hold in HOLDS:
        for thighs_hold in THIGH_HOLDS:
            held = {c: rows[hold] for c in seat}
            held.update({c: thigh_rows[thighs_hold] for c in thighs})
            partially_held[(hold, thighs_hold)] = held
    return partially_held


@dataclass
class ControllerTick:
    """One tick's solution and what it took."""

    solution: QpSolution  # for the active contacts only
    normal_forces_N: np.ndarray  # commanded f_z of every contact (CONTACTS), 0 if inactive
    inputs_s: float  # evaluating the references and commands (and the systems behind them)
    kinematics_s: float  # evaluating the terms (the model, and the systems behind it)
    assembly_s: float  # the QP's tasks and matrices
    # (2, 6) the soles' planned wrenches in their frames, [tau; f] (l_sole, r_sole).
    sole_wrenches: np.ndarray | None = None


class WholeBodyController:
    """Momentum-based whole-body torque controller (module docstring): a plain object
    whose solve() the stand-up controller's tick calls (standup/whole_body.py)."""

    def __init__(
        self,
        plant: MultibodyPlant,
        specs: list[ContactSpec],
        joints: ControllerJoints,
        config: ControllerConfig,
        modes: tuple[int, ...],
        stance_modes: set[int],
        *,
        period_s: float = 0.0,
    ):
        """modes: the values TaskReferences.standup_state takes; stance_modes: those in
        which the stance tasks act; period_s: the control period (0: no seat pad rows,
        control/pad_dynamics.py)."""
        if [spec.frame for spec in specs] != list(CONTACTS):
            raise ValueError(f"contact specs must be {CONTACTS}")
        actuators = plant.GetJointActuatorIndices()
        self.num_actuators = len(actuators)
        torque_limit = config.torque_limit_Nm or min(
            plant.get_joint_actuator(i).effort_limit() for i in actuators
        )
        self._make = lambda active: make_program(
            specs,
            active,
            plant,
            joints,
            config,
            set(stance_modes),
            torque_limit_Nm=torque_limit,
            modes=tuple(modes),
            period_s=period_s,
        )
        self._programs: dict[tuple[bool, ...], Program] = {}
        # The last contact commands and the program's form of them.
        self._last: tuple[ContactCommands | None, QpContactBounds | None] = (None, None)
        self._timing: list[tuple[float, ...]] = []

    def timing_s(self) -> np.ndarray:
        """Per-tick compute times since construction (or reset_timing), (ticks, 5), in
        TIMING's columns."""
        return np.array(self._timing).reshape(-1, len(TIMING))

    def reset_timing(self) -> None:
        self._timing.clear()

    def record_timing(self, tick: ControllerTick, total_s: float) -> None:
        self._timing.append(
            (tick.inputs_s, tick.kinematics_s, tick.assembly_s, tick.solution.solve_s, total_s)
        )

    def program(self, active: tuple[bool, ...]) -> Program:
        """The QP over the active contacts (built when first needed)."""
        program = self._programs.get(active)
        if program is None:
            program = self._programs[active] = self._make(active)
        return program

    def solve(
        self,
        terms: RobotTerms,
        references: TaskReferences,
        commands: ContactCommands,
        inputs_s: float = 0.0,
        kinematics_s: float = 0.0,
        last_sole_wrenches: np.ndarray | None = None,
    ) -> ControllerTick:
        """This tick's QP; inputs_s, kinematics_s: what making its inputs took;
        last_sole_wrenches: the soles' wrenches of the last solved tick (ControllerTick.
        sole_wrenches; NaN or None: none), for the moment-rate task."""
        program = self.program(commands.active)
        if program.moment_rate is not None:
            program.moment_rate.set_last(
                np.full(12, np.nan) if last_sole_wrenches is None else last_sole_wrenches
            )
        index = program.contact_index
        if commands is not self._last[0]:  # the schedule's constant commands repeat
            self._last = (
                commands,
                QpContactBounds(
                    commands.min_normal_force_N[index],
                    commands.max_normal_force_N[index],
                    program.partially_held[(commands.seat_hold, commands.thighs_hold)],
                    None
                    if commands.measured_normal_force_N is None
                    else commands.measured_normal_force_N[index],
                ),
            )
        solution = program.qp.solve(terms, references, self._last[1])
        normal_forces_N = np.zeros(len(CONTACTS))
        normal_forces_N[index] = solution.F_C[:, NORMAL]
        return ControllerTick(
            solution=solution,
            normal_forces_N=normal_forces_N,
            inputs_s=inputs_s,
            kinematics_s=kinematics_s,
            assembly_s=solution.assembly_s,
            sole_wrenches=solution.F_C[list(program.soles)],
        )


def next_diagnostics(before: np.ndarray, tick: ControllerTick, total_s: float) -> np.ndarray:
    """DIAGNOSTICS after tick, from those before it (the failure and relaxation counts
    carry on)."""
    solution = tick.solution
    return DIAGNOSTICS.pack(
        qp_ok=float(solution.ok),
        qp_failures=before[_FAILURES] + (0.0 if solution.ok else 1.0),
        solve_time_s=solution.solve_s,
        tick_time_s=total_s,
        commanded_normal_force_N=tick.normal_forces_N if solution.ok else np.nan,
        joint_limit_slack=float(np.abs(solution.slack).max()) if solution.slack.size else 0.0,
        qp_relaxed=before[_RELAXED] + float(solution.relaxed),
        qp_fallback=before[_FALLBACK] + float(solution.fallback),
    )
