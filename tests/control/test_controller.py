"""The whole-body controller (drake_standup/control/): the QP's solution, the model's
terms, the help, the fallbacks.

Every check recomputes its reference from Drake's own functions (CalcMassMatrix,
CalcBiasTerm, CalcGravityGeneralizedForces, CalcJacobianSpatialVelocity, the CoM and
momentum functions), frame poses and the joints' damping, independently of the
controller's code; a second QP solver checks the first.
"""

import dataclasses
import math

import numpy as np
import pytest
from pydrake.common.value import Value
from pydrake.common.yaml import yaml_load_typed
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import EFFORT_LIMIT_NM, ControllerConfig, Scenario
from drake_standup.config.phases import PhaseTable
from drake_standup.control.contacts import CONTACTS, rectangle_yaw_rows
from drake_standup.control.controller import (
    DIAGNOSTICS,
    WholeBodyController,
    next_diagnostics,
    posture_weights,
)
from drake_standup.control.model import ControllerJoints, ControllerModel, contact_specs
from drake_standup.control.qp import as_slice
from drake_standup.control.tasks import helpful_force
from drake_standup.control.tasks.joint_limits import (
    braking_bounds,
    joint_limit_acceleration_bounds,
)
from drake_standup.control.terms import RobotKinematics
from drake_standup.robot.limbs import SHOULDER_JOINTS, shoulder_tendon_rows
from drake_standup.standup.contact_schedule import contact_commands, phase_seat_hold
from drake_standup.standup.task_references import PhaseReferences, TaskReferenceGenerator
from drake_standup.standup.transitions import initial_mode
from drake_standup.standup.whole_body import StandupWholeBodyController
from drake_standup.world.scene import add_scene, set_seated_state

G = 9.81
N_SAMPLES = 12


@pytest.fixture(scope="module")
def scene():
    """The default scenario's plant (no seat hold) and its seated state x0."""
    scenario = Scenario()
    builder = DiagramBuilder()
    scene = add_scene(builder, scenario, pd_gains=None, visuals=False)
    context = scene.plant.CreateDefaultContext()
    set_seated_state(scene, context)
    x0 = scene.plant.GetPositionsAndVelocities(context, scene.robot.model_instance)
    return scene, x0


PERIOD_S = 0.001
NO_PULL = np.zeros(12)


class _FixedSchedule:
    """A contact schedule that answers every tick with the commands the rig fixed (its
    phase table, as ContactSchedule's, the one the controller reads the sit-down's from)."""

    def __init__(self, table: PhaseTable):
        self.commands = None
        self.table = table

    def tick(self, mode, t, memory, commanded_N, measured_N):
        return self.commands, memory.copy()


class _Rig:
    """The stand-up's whole-body controller system (the controller's model, the task
    references and the QP, one tick) with its inputs and contact commands fixed: one
    tick from given inputs."""

    def __init__(self, scene, **config):
        """config: ControllerConfig's fields; the nominal model (no weighing) unless
        mass_estimation_filter_s says otherwise."""
        plant, robot = scene.plant, scene.robot
        self.config = ControllerConfig(**{"mass_estimation_filter_s": 0.0} | config)
        self.table = PhaseTable()
        self.specs = contact_specs(plant, robot, self.config)
        joints = ControllerJoints.of(plant, robot)
        g = -plant.gravity_field().gravity_vector()[2]
        schedule = PhaseReferences(
            self.table, self.config, joints.names, joints.q_min, joints.q_max
        )
        self.schedule = _FixedSchedule(self.table)
        self.controller = WholeBodyController(
            plant,
            self.specs,
            joints,
            self.config,
            modes=(1, 2, 3, 4),
            stance_modes={k for k, phase in enumerate(self.table, start=1) if phase.stance},
            period_s=PERIOD_S,
        )
        self.system = StandupWholeBodyController(
            self.schedule,
            ControllerModel(plant, robot, self.specs, self.config, PERIOD_S),
            TaskReferenceGenerator(self.config, schedule, as_slice(joints.q_indices), PERIOD_S, g),
            self.controller,
            plant.num_multibody_states(robot.model_instance),
            PERIOD_S,
        )
        self.context = self.system.CreateDefaultContext()

    def fix(self, x, com_reference, standup_state, hands=NO_PULL, loads=None):
        """Inputs of a tick in standup_state with the seat pads' loads (seat_loads: None,
        every pad seated; released ones from 100 N)."""
        loads = np.full(3, math.nan) if loads is None else np.asarray(loads, dtype=float)
        mode = dataclasses.replace(initial_mode(np.zeros(3)), state=standup_state)
        self.schedule.commands = contact_commands(
            self.config, loads, np.full(3, 100.0), None, phase_seat_hold(mode, self.table)
        )
        inputs = {
            "robot_state": x,
            "seat_pad_normal_forces_N": np.zeros(3),
            "hand_wrenches_W": hands,
            "pads_vertical_force_N": [0.0],
            "com_reference": com_reference,
            "path_progress": [1.0],
            "response": [0.0],  # advancement's: the help let through
        }
        for name, value in inputs.items():
            self.system.GetInputPort(name).FixValue(self.context, value)
        self.system.GetInputPort("mode").FixValue(self.context, Value[object](mode))

    def tick(self):
        return self.system.calc_tick(self.context)[0].solution

    def diagnostics(self) -> dict[str, float]:
        values = self.system.GetOutputPort("diagnostics").Eval(self.context)
        return {
            name: part[0] for name, part in DIAGNOSTICS.unpack(values).items() if len(part) == 1
        }


def _com(plant, instance, x):
    context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(context, instance, x)
    return plant.CalcCenterOfMassPositionInWorld(context, [instance])


def _random_state(plant, instance, x0, rng):
    """Seated joint angles +-0.3 rad (within limits), a random base pose, random rates."""
    context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(context, instance, x0)
    for index in plant.GetJointIndices(instance):
        joint = plant.get_joint(index)
        if joint.num_positions() == 1:
            q = joint.GetOnePosition(context) + rng.uniform(-0.3, 0.3)
            lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
            joint.set_angle(context, float(np.clip(q, lower, upper)))
    R = RotationMatrix(
        np.linalg.qr(rng.normal(size=(3, 3)))[0] * np.sign(np.linalg.det(rng.normal(size=(3, 3))))
    )
    if np.linalg.det(R.matrix()) < 0:
        R = RotationMatrix(-R.matrix())
    base = plant.GetBodyByName("root_link", instance)
    plant.SetFreeBodyPose(context, base, RigidTransform(R, rng.uniform(-1.0, 1.0, 3)))
    plant.SetVelocities(context, instance, rng.normal(scale=0.3, size=plant.num_velocities()))
    return plant.GetPositionsAndVelocities(context, instance)


def _joint_damping(plant, instance):
    D = np.zeros(plant.num_velocities())
    for index in plant.GetJointIndices(instance):
        joint = plant.get_joint(index)
        D[joint.velocity_start() : joint.velocity_start() + joint.num_velocities()] = (
            joint.default_damping_vector()
        )
    return D


# --- (a) the solution obeys the floating-base dynamics and the contact limits -----------


@pytest.mark.parametrize("standup_state", [1, 2], ids=["seat_held", "seat_hinged"])
def test_solution_satisfies_dynamics_and_contact_limits(scene, standup_state):
    """On random states, with seat, thighs and soles in contact and random hand wrenches:

        M vdot + C v - tau_g + D v = B tau + sum_c J_c^T F_c + sum_h J_h^T F_h   (1e-6)

    with Drake's M, Cv, tau_g, Jacobians (D: the joints' damping, which the plant
    applies); each contact wrench in its frame obeys the friction pyramid (mu 1/3),
    torsion (1/75), CoP box, the soles' rectangle yaw bounds and normal-force bounds
    (the minimum not where the tick was solved relaxed); |tau| <= 60 N m."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    config = ControllerConfig()
    rig = _Rig(scene)
    specs = {spec.frame: spec for spec in rig.specs}
    B = plant.MakeActuationMatrix()
    D = _joint_damping(plant, instance)
    world = plant.world_frame()
    rng = np.random.default_rng(standup_state)
    plant_context = plant.CreateDefaultContext()

    def jacobian(frame_name):
        frame = robot.frame(plant, frame_name)
        return plant.CalcJacobianSpatialVelocity(
            plant_context, JacobianWrtVariable.kV, frame, np.zeros(3), world, world
        )

    for _ in range(N_SAMPLES):
        x = _random_state(plant, instance, x0, rng)
        hands = np.concatenate([rng.normal(scale=[2, 2, 2, 20, 20, 20]) for _ in range(2)])
        com = _com(plant, instance, x)
        reference = np.concatenate([com + rng.normal(scale=0.02, size=3), np.zeros(6)])
        rig.fix(x, reference, standup_state, hands)
        solution = rig.tick()
        assert solution.ok
        assert sorted(solution.frames) == sorted(CONTACTS)

        plant.SetPositionsAndVelocities(plant_context, instance, x)
        v = x[plant.num_positions() :]
        lhs = (
            plant.CalcMassMatrix(plant_context) @ solution.vdot
            + plant.CalcBiasTerm(plant_context)
            - plant.CalcGravityGeneralizedForces(plant_context)
            + D * v
        )
        rhs = B @ solution.tau
        rhs += sum(jacobian(f).T @ F for f, F in zip(solution.frames, solution.F_W, strict=True))
        rhs += jacobian("l_hand").T @ hands[:6] + jacobian("r_hand").T @ hands[6:]
        np.testing.assert_allclose(lhs, rhs, atol=1e-6 * max(1.0, np.abs(lhs).max()))

        assert np.abs(solution.tau).max() <= EFFORT_LIMIT_NM + 1e-6
        for frame_name, F_W in zip(solution.frames, solution.F_W, strict=True):
            R_WC = robot.frame(plant, frame_name).CalcPoseInWorld(plant_context).rotation()
            tau_C = R_WC.inverse() @ F_W[:3]
            f_C = R_WC.inverse() @ F_W[3:]
            spec, fz, tol = specs[frame_name], f_C[2], 1e-5
            # Solved relaxed (no held rows, no minimum force: qp.py) where the contacts
            # could not hold this random state.
            assert fz >= (0.0 if solution.relaxed else config.min_normal_force_N) - tol
            assert fz <= (
                config.foot_max_normal_force_N
                if "sole" in frame_name
                else config.seat_max_normal_force_N
            )
            mu = config.friction_coefficient
            assert abs(f_C[0]) <= mu * fz + tol and abs(f_C[1]) <= mu * fz + tol
            if spec.point:  # thighs: a force at the pad's centre
                np.testing.assert_allclose(tau_C, 0.0, atol=1e-12)
                continue
            assert abs(tau_C[2]) <= config.torsional_friction_coefficient_m * fz + tol
            # The CoP (-tau_y / f_z, tau_x / f_z) in its box, multiplied through by f_z
            # (a relaxed tick may leave a contact with none).
            assert spec.cop_x_m[0] * fz - tol <= -tau_C[1] <= spec.cop_x_m[1] * fz + tol
            assert spec.cop_y_m[0] * fz - tol <= tau_C[0] <= spec.cop_y_m[1] * fz + tol
            if spec.rectangle_yaw:  # the soles' yaw moment within their rectangle
                rows = np.array(rectangle_yaw_rows(mu, spec.cop_x_m, spec.cop_y_m))
                assert np.all(rows @ np.concatenate((tau_C, f_C)) <= tol)


def test_cop_boxes_lie_on_their_pads(scene):
    """The seat's CoP box lies on the buttocks pad, each thigh's on its thigh pad and each
    sole's on its sole pad, at least 5 mm inside (pad boxes from models/icub_contact.yaml,
    seated pose)."""
    import yaml

    from drake_standup.robot.icub import CONTACT_FILE

    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(context, robot.model_instance, x0)
    pads = {shape["name"]: shape for shape in yaml.safe_load(CONTACT_FILE.read_text())["shapes"]}
    pad_of = {
        "seat": "buttocks_pad",
        "l_thigh": "l_thigh_pad",
        "r_thigh": "r_thigh_pad",
        "l_sole": "l_sole_pad",
        "r_sole": "r_sole_pad",
    }
    for spec in contact_specs(plant, robot, ControllerConfig()):
        if spec.point:
            continue
        pad = pads[pad_of[spec.frame]]
        X_WC = robot.frame(plant, spec.frame).CalcPoseInWorld(context)
        X_WP = plant.GetFrameByName(pad["frame"], robot.model_instance).CalcPoseInWorld(
            context
        ) @ RigidTransform(pad["xyz_m"])
        half = np.array(pad["size_m"][:2]) / 2
        for x in spec.cop_x_m:
            for y in spec.cop_y_m:
                p_PCorner = X_WP.inverse() @ (X_WC @ np.array([x, y, 0.0]))
                assert np.all(np.abs(p_PCorner[:2]) <= half - 0.005), (spec.frame, x, y)


# --- (b) static seated balance ------------------------------------------------------------


def test_static_seated_reference_balances_gravity(scene):
    """Seated at rest, x_d = CoM, zero reference velocity and acceleration: the commanded
    contact forces sum to m g (1 %) and their moments about the CoM cancel."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    rig = _Rig(scene)
    com = _com(plant, instance, x0)
    rig.fix(x0, np.concatenate([com, np.zeros(6)]), 1)
    solution = rig.tick()
    assert solution.ok

    plant_context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(plant_context, instance, x0)
    weight_N = plant.CalcTotalMass(plant_context, [instance]) * G
    force = solution.F_W[:, 3:].sum(axis=0)
    np.testing.assert_allclose(force, [0.0, 0.0, weight_N], atol=0.01 * weight_N)
    moment = np.zeros(3)
    for frame_name, F_W in zip(solution.frames, solution.F_W, strict=True):
        p_WC = robot.frame(plant, frame_name).CalcPoseInWorld(plant_context).translation()
        moment += F_W[:3] + np.cross(p_WC - com, F_W[3:])
    np.testing.assert_allclose(moment, 0.0, atol=0.01 * weight_N * 0.1)  # 1 % of m g x 10 cm
    # Every contact carries part of the load: the seat does not hang on the soles alone.
    assert np.all(solution.F_C[:, 5] >= ControllerConfig().min_normal_force_N - 1e-6)


def test_the_soles_moment_rate_reads_the_last_tick_from_the_state(scene):
    """controller.sole_moment_rate_weight_s: the system keeps the soles' planned wrenches
    of each solved tick in its state (NaN before the first), and the next tick's soles'
    moments move less from them than without the rate when the CoM reference jumps."""
    scene, x0 = scene
    plant, instance = scene.plant, scene.robot.model_instance
    com = _com(plant, instance, x0)
    moved = []
    for weight_s in (0.0, 0.01):
        rig = _Rig(scene, sole_moment_rate_weight_s=weight_s)
        rig.fix(x0, np.concatenate([com, np.zeros(6)]), 1)
        system, context = rig.system, rig.context
        index = system._sole_wrenches
        assert np.isnan(context.get_discrete_state(index).value()).all()
        first = system.calc_tick(context)[0]
        context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
        np.testing.assert_array_equal(
            context.get_discrete_state(index).value(), first.sole_wrenches.ravel()
        )
        rig.fix(x0, np.concatenate([com + [0.02, 0.0, 0.0], np.zeros(6)]), 1)
        second = system.calc_tick(context)[0]
        assert second.solution.ok
        moved.append(np.abs(second.sole_wrenches[:, :3] - first.sole_wrenches[:, :3]).max())
    assert moved[0] > 0.1  # N m: the reference's jump moves the soles' CoPs
    assert moved[1] < 0.5 * moved[0]


# --- (c) the centroidal identities the controller relies on -------------------------------


def test_com_jacobian_bias_and_momentum_from_the_mass_matrix(scene):
    """With the floating-base velocities expressed in W ([drake-docs]), on random states:
    M[3:6]/m = J_com, Cv[3:6]/m = Jdot_com v, M[3:6]^T g = tau_g, and the controller's
    CoM (read off M[0:3, 3:6] = m [p_BoCom]x), centroidal momentum and base orientation
    (from the quaternion) equal Drake's CoM, spatial momentum about the CoM and root_link
    pose."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    world = plant.world_frame()
    context = plant.CreateDefaultContext()
    kinematics = RobotKinematics(plant, robot, held_frames=[], other_frames=[])
    mass = plant.CalcTotalMass(context, [instance])
    rng = np.random.default_rng(3)
    for _ in range(N_SAMPLES):
        x = _random_state(plant, instance, x0, rng)
        plant.SetPositionsAndVelocities(context, instance, x)
        M = plant.CalcMassMatrix(context)
        J_com = plant.CalcJacobianCenterOfMassTranslationalVelocity(
            context, [instance], JacobianWrtVariable.kV, world, world
        )
        np.testing.assert_allclose(M[3:6] / mass, J_com, atol=1e-10)
        bias = plant.CalcBiasCenterOfMassTranslationalAcceleration(
            context, [instance], JacobianWrtVariable.kV, world, world
        )
        np.testing.assert_allclose(plant.CalcBiasTerm(context)[3:6] / mass, bias, atol=1e-9)
        g_W = plant.gravity_field().gravity_vector()
        np.testing.assert_allclose(
            M[3:6].T @ g_W, plant.CalcGravityGeneralizedForces(context), atol=1e-9
        )
        terms = kinematics.calc(x, [])
        p_WCom = plant.CalcCenterOfMassPositionInWorld(context, [instance])
        L = plant.CalcSpatialMomentumInWorldAboutPoint(context, [instance], p_WCom)
        np.testing.assert_allclose(terms.p_WCom, p_WCom, atol=1e-12)
        np.testing.assert_allclose(terms.L_WCom[:3], L.rotational(), atol=1e-9)
        np.testing.assert_allclose(terms.L_WCom[3:], L.translational(), atol=1e-9)
        np.testing.assert_allclose(terms.v_WCom, J_com @ x[plant.num_positions() :], atol=1e-9)
        base = plant.GetBodyByName("root_link", instance)
        np.testing.assert_allclose(
            terms.R_WB, plant.EvalBodyPoseInWorld(context, base).rotation().matrix(), atol=1e-14
        )


def test_hold_point_velocity_and_bias_acceleration_by_finite_differences(scene):
    """For the held frames (the seat, held at the hip axis on root_link: the analytic bias
    w x (w x p_BoP); the soles: Drake's), on random states, with the Jacobians expressed
    in each frame F: R_WF J_P v is [w_WF; v_WP] with v_WP the finite-difference velocity
    of the hold point P (from frame poses), and R_WF Jdot_P v is the finite-difference
    derivative of R_WF J_P v along the motion at constant v (central differences,
    q +- qdot dt)."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    held = [spec for spec in contact_specs(plant, robot, ControllerConfig()) if spec.constrained]
    names = [spec.frame for spec in held]
    kinematics = RobotKinematics(
        plant,
        robot,
        held_frames=names,
        other_frames=[],
        hold_points_m={spec.frame: spec.hold_point_m for spec in held},
    )
    assert any(spec.hold_point_m != (0.0, 0.0, 0.0) for spec in held)  # the seat's hinge
    context = plant.CreateDefaultContext()
    nq, dt = plant.num_positions(), 1e-6

    def in_world(x):
        """Per held frame: p_WP, R_WF and the spatial velocity of P in W."""
        plant.SetPositionsAndVelocities(context, instance, x)
        terms = kinematics.calc(x, names)
        result = []
        for j, spec in enumerate(held):
            X_WF = robot.frame(plant, spec.frame).CalcPoseInWorld(context)
            R_WF = X_WF.rotation().matrix()
            V_WP = (R_WF @ (terms.J_P[j] @ x[nq:]).reshape(2, 3).T).T.reshape(6)
            result.append((X_WF @ np.array(spec.hold_point_m), R_WF, V_WP))
        return terms, result

    rng = np.random.default_rng(5)
    for _ in range(N_SAMPLES // 2):
        x = _random_state(plant, instance, x0, rng)
        q, v = x[:nq], x[nq:]
        plant.SetPositionsAndVelocities(context, instance, x)
        qdot = plant.MapVelocityToQDot(context, v)
        terms, now = in_world(x)
        _, ahead = in_world(np.concatenate([q + dt * qdot, v]))
        _, behind = in_world(np.concatenate([q - dt * qdot, v]))
        for j in range(len(held)):
            _, R_WF, V_WP = now[j]
            v_WP = (ahead[j][0] - behind[j][0]) / (2 * dt)
            np.testing.assert_allclose(V_WP[3:], v_WP, atol=1e-6 * max(1.0, np.abs(v_WP).max()))
            A_WP = (ahead[j][2] - behind[j][2]) / (2 * dt)
            Jdotv_WP = (R_WF @ terms.Jdotv_P[j].reshape(2, 3).T).T.reshape(6)
            np.testing.assert_allclose(Jdotv_WP, A_WP, atol=1e-5 * max(1.0, np.abs(A_WP).max()))


def _jacobian_and_bias_in_frame(plant, context, frame) -> tuple[np.ndarray, np.ndarray]:
    """Drake's spatial velocity Jacobian of frame's origin and its bias spatial
    acceleration, both expressed in frame: [alpha; a] = J vdot + bias."""
    J = plant.CalcJacobianSpatialVelocity(
        context, JacobianWrtVariable.kV, frame, np.zeros(3), plant.world_frame(), frame
    )
    bias = plant.CalcBiasSpatialAcceleration(
        context, JacobianWrtVariable.kV, frame, np.zeros(3), plant.world_frame(), frame
    ).get_coeffs()
    return J, bias


@pytest.mark.parametrize(
    ("gain", "thighs", "thigh_rows"),
    [(0.0, math.nan, [1, 5]), (20.0, math.nan, [1, 5]), (20.0, 0.5, [5])],
    ids=["seated_flat_k0", "seated_flat_k20", "unloading_k20"],
)
def test_held_contacts_brake_their_slip(scene, gain, thighs, thigh_rows):
    """Once the buttocks are off the seat: on random moving states, each sole's six rows
    and each thigh's held rows (pitch and normal while seated, the normal while they
    unload) obey J_P vdot + Jdot_P v = -k J_P v (Drake's Jacobian and bias acceleration
    of the frame, expressed in it), so a contact that has begun to slip is braked back to
    rest; the thighs' other rows are left free (their acceleration is not held)."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    # The held rows alone: on one random state the 60 N m torque limit binds, and daqp
    # 0.10-0.11 (not 0.9) calls that tight program infeasible and relaxes it (osqp and
    # clarabel solve it at 60 N m; measured), which is the torque limit's business.
    rig = _Rig(scene, contact_velocity_gain_per_s=gain, torque_limit_Nm=1000.0)
    context = plant.CreateDefaultContext()
    rng = np.random.default_rng(20)
    free_seen = 0.0
    for _ in range(N_SAMPLES // 2):
        x = _random_state(plant, instance, x0, rng)
        com = _com(plant, instance, x)
        rig.fix(x, np.concatenate([com, np.zeros(6)]), 2, loads=[0.0, thighs, thighs])
        solution = rig.tick()
        assert solution.ok and not solution.relaxed
        seat = solution.frames.index("seat")
        np.testing.assert_allclose(solution.F_C[seat], 0.0, atol=1e-6)  # released: no load
        plant.SetPositionsAndVelocities(context, instance, x)
        v = x[plant.num_positions() :]
        for name in ("l_sole", "r_sole", "l_thigh", "r_thigh"):
            frame = robot.frame(plant, name)
            J, bias = _jacobian_and_bias_in_frame(plant, context, frame)
            acceleration, velocity = J @ solution.vdot + bias, J @ v
            rows = [0, 1, 2, 3, 4, 5] if "sole" in name else thigh_rows
            np.testing.assert_allclose(
                acceleration[rows], -gain * velocity[rows], atol=1e-6 * max(1.0, gain)
            )
            if "thigh" in name:
                free = [r for r in range(6) if r not in thigh_rows]
                free_seen = max(free_seen, np.abs(acceleration[free]).max())
    assert free_seen > 1e-3  # the thighs' free rows do move


# --- The human's help ------------------------------------------------------------------------


def test_helpful_force_passes_only_the_helpful_part():
    """f_par: the component along xd_dot when it points along it; nothing against it,
    nothing at rest, full at speed, nothing once the CoM leads its reference by lead_max."""
    xd_dot = np.array([0.2, 0.0, 0.0])
    f_hand = np.array([15.0, 5.0, 30.0])
    np.testing.assert_allclose(helpful_force(f_hand, xd_dot, 0.0, 0.02, 0.02), [15.0, 0, 0])
    np.testing.assert_allclose(helpful_force(-f_hand, xd_dot, 0.0, 0.02, 0.02), 0.0)
    np.testing.assert_allclose(helpful_force(f_hand, np.zeros(3), 0.0, 0.02, 0.02), 0.0)
    np.testing.assert_allclose(helpful_force(f_hand, xd_dot, 0.02, 0.02, 0.02), 0.0)
    slow = helpful_force(f_hand, xd_dot * 0.05, 0.0, 0.02, 0.02)  # 1 cm/s: half faded
    assert 0.0 < slow[0] < 15.0 and slow[1] == slow[2] == 0.0


@pytest.mark.parametrize("moving", [False, True], ids=["at_rest", "moving_forward"])
def test_contacts_cancel_all_but_the_helpful_pull(scene, moving):
    """Seated at rest with x_d = CoM and a 15 N forward + 15 N up pull on each hand:
    with xd_dot = 0 the contacts cancel the whole pull (sum F_c + f_hand + m g = 0);
    with xd_dot along +x they leave the forward 30 N acting (sum F_c,x = m xddot*_x)
    and cancel the rest. (A momentum weight of 1e4 makes the momentum task all but hard
    against the flat posture weights: at the default weight the posture task takes ~1 N
    of it here, and with the carried limbs weighed by their mass 0.6 N at 1e4.)"""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    config = ControllerConfig()
    rig = _Rig(scene, momentum_weight=1e4, carried_limb_weight_by_mass=False)
    com = _com(plant, instance, x0)
    xd_dot = np.array([0.1, 0.0, 0.0]) if moving else np.zeros(3)
    hands = np.tile([0.0, 0.0, 0.0, 15.0, 0.0, 15.0], 2)
    rig.fix(x0, np.concatenate([com, xd_dot, np.zeros(3)]), 2, hands)
    solution = rig.tick()
    assert solution.ok
    mass = plant.CalcTotalMass(plant.CreateDefaultContext(), [instance])
    kd_x = 2.0 * config.com_damping_ratio * np.sqrt(PhaseTable().seated.com_kp_per_s2[0])
    xddot_x = kd_x * xd_dot[0]  # xddot* = xd_ddot - K_D (0 - xd_dot) - K_P 0
    contacts = solution.F_W[:, 3:].sum(axis=0)
    expected = np.array([mass * xddot_x - (0.0 if moving else 30.0), 0.0, mass * G - 30.0])
    np.testing.assert_allclose(contacts, expected, atol=0.5)


# --- Failure handling, solvers, interface ----------------------------------------------------


def _infeasible_ticks(scene, break_fallback: bool):
    """Four ticks of a controller whose QP is infeasible (minimum normal force above the
    seat's maximum), from a known last actuation; break_fallback: the relaxed re-solve
    fails too. Returns (last, actuation, diagnostics)."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    rig = _Rig(scene, min_normal_force_N=500.0)
    com = _com(plant, robot.model_instance, x0)
    rig.fix(x0, np.concatenate([com, np.zeros(6)]), 1)
    last = np.linspace(-1.0, 1.0, plant.num_actuators())
    rig.context.get_mutable_discrete_state(rig.system.actuation_state).SetFromVector(last)
    if break_fallback:
        # Build the program the ticks use, then make its fallback fail.
        rig.tick()
        program = rig.controller.program((True,) * len(CONTACTS))
        program.qp._solve_relaxed = lambda H, g: (np.full(len(g), np.nan), False)
    simulator = Simulator(rig.system, rig.context)
    simulator.Initialize()  # the initialization update
    simulator.AdvanceTo(0.0025)  # periodic updates at 0, 1 and 2 ms
    actuation = rig.system.GetOutputPort("actuation").Eval(rig.context)
    return last, actuation, rig.diagnostics()


def test_an_infeasible_qp_falls_back_to_the_relaxed_program_and_counts(scene):
    """The relaxed re-solve (no minimum normal force, no held contact rows) gives torques
    within the limits; qp_ok stays 1, qp_relaxed counts the four ticks, no failure."""
    last, actuation, diagnostics = _infeasible_ticks(scene, break_fallback=False)
    assert not np.array_equal(actuation, last)
    assert np.abs(actuation).max() <= EFFORT_LIMIT_NM + 1e-6
    assert diagnostics["qp_ok"] == 1.0 and diagnostics["qp_failures"] == 0.0
    assert diagnostics["qp_relaxed"] == 4.0


def test_a_failed_fallback_keeps_the_last_torques_and_counts(scene):
    """If the relaxed re-solve fails too, nothing raises, the actuation keeps its last
    value, qp_ok drops to 0 and the failure count rises."""
    last, actuation, diagnostics = _infeasible_ticks(scene, break_fallback=True)
    np.testing.assert_array_equal(actuation, last)
    assert diagnostics["qp_ok"] == 0.0 and diagnostics["qp_failures"] == 4.0
    assert diagnostics["qp_relaxed"] == 0.0


def _solve_with(scene, solvers, *, seed, **config):
    """One state-2 tick on a random state (CoM reference at the CoM, at rest),
    solved by each named QP solver; their solutions in that order."""
    scene, x0 = scene
    plant, instance = scene.plant, scene.robot.model_instance
    x = _random_state(plant, instance, x0, np.random.default_rng(seed))
    com = _com(plant, instance, x)
    solutions = []
    for name in solvers:
        rig = _Rig(scene, qp_solver=name, **config)
        rig.fix(x, np.concatenate([com, np.zeros(6)]), 2)
        solutions.append(rig.tick())
    return solutions


@pytest.mark.parametrize("solver", ["clarabel", "osqp"])
def test_drake_solvers_agree_with_daqp(scene, solver):
    """The same tick on a random state, solved by daqp and by Drake's Clarabel / OSQP:
    the same torques and contact wrenches."""
    reference, other = _solve_with(scene, ("daqp", solver), seed=8)
    assert reference.ok and other.ok
    np.testing.assert_allclose(other.tau, reference.tau, atol=0.05)  # OSQP: first-order
    np.testing.assert_allclose(other.F_W, reference.F_W, atol=1e-1)


def test_binding_torque_limits(scene):
    """With a 20 N m torque limit on random states the limits bind (the program tried
    first without them must be solved again with them): |tau| <= 20 N m, some at the
    limit, and Clarabel finds the same torques and wrenches. On the first of seeds 0-13
    that daqp solves: with daqp 0.11 and numpy 2.4 here it calls 7 of them infeasible,
    seed 9 among them, where Clarabel solves 6 at the limit (the tick is then relaxed),
    and which ones moves with the machine's numerics."""
    for seed in range(14):
        reference, other = _solve_with(scene, ("daqp", "clarabel"), seed=seed, torque_limit_Nm=20.0)
        if reference.ok and not reference.relaxed:
            break
    assert reference.ok and other.ok and not reference.relaxed
    assert np.abs(reference.tau).max() <= 20.0 + 1e-6
    assert np.abs(reference.tau).max() >= 20.0 - 1e-6
    np.testing.assert_allclose(other.tau, reference.tau, atol=0.05)
    np.testing.assert_allclose(other.F_W, reference.F_W, atol=1e-1)


def test_seat_hinge_follows_the_plan(scene):
    """One controller ticking states 1, 2, 1 on the same inputs (the seat's pitch row
    held, free, held again) gives what fresh controllers give in those states."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    x = _random_state(plant, instance, x0, np.random.default_rng(12))
    reference = np.concatenate([_com(plant, instance, x), np.zeros(6)])
    rig = _Rig(scene)
    for standup_state in (1, 2, 1):
        rig.fix(x, reference, standup_state)
        solution = rig.tick()
        fresh = _Rig(scene)
        fresh.fix(x, reference, standup_state)
        expected = fresh.tick()
        assert solution.ok and expected.ok
        np.testing.assert_allclose(solution.tau, expected.tau, atol=1e-9)
        np.testing.assert_allclose(solution.vdot, expected.vdot, atol=1e-9)
    # The hinge frees the seat's pitch: the two states differ.
    assert np.abs(solution.tau - _solution_in_state(scene, x, reference, 2).tau).max() > 1e-3


def _solution_in_state(scene, x, reference, standup_state):
    rig = _Rig(scene)
    rig.fix(x, reference, standup_state)
    return rig.tick()


def test_ports_and_config(scene):
    """The ports the stand-up controller wires (standup/whole_body.py's docstring); the
    config loads from YAML typed."""
    scene, _ = scene
    rig = _Rig(scene)
    system, plant = rig.system, scene.plant
    inputs = [system.get_input_port(i).get_name() for i in range(system.num_input_ports())]
    assert inputs == [
        "robot_state",
        "seat_pad_normal_forces_N",
        "pads_vertical_force_N",
        "hand_wrenches_W",
        "com_reference",
        "path_progress",
        "psi_dot",
        "response",
        "mode",
    ]
    assert system.GetOutputPort("actuation").size() == plant.num_actuators()
    assert system.GetOutputPort("diagnostics").size() == DIAGNOSTICS.size
    assert [system.GetOutputPort(name).size() for name in ("lean_W", "compliance_W")] == [3, 6]
    config = yaml_load_typed(
        schema=ControllerConfig, data="qp_solver: clarabel\nposture_weight: 0.5\n"
    )
    assert config.qp_solver == "clarabel" and config.posture_weight == 0.5
    assert config.stance_posture_weight_by_joint == (
        ControllerConfig().stance_posture_weight_by_joint
    )


@pytest.mark.parametrize("scale", [0.85, 1.15])
def test_scaled_model_terms_are_drakes_with_scaled_masses(scene, scale):
    """RobotKinematics.set_mass_scale: M, h and the CoM equal Drake's own for a plant
    context whose every robot body's mass is scaled (CoM and unit inertia kept)."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    context = plant.CreateDefaultContext()
    for index in plant.GetBodyIndices(instance):
        body = plant.get_body(index)
        body.SetMass(context, scale * body.default_mass())
    kinematics = RobotKinematics(plant, robot, held_frames=[], other_frames=[])
    nominal = kinematics.mass_kg
    kinematics.set_mass_scale(scale)
    assert kinematics.mass_kg == pytest.approx(plant.CalcTotalMass(context, [instance]))
    assert kinematics.mass_kg == pytest.approx(scale * nominal)
    rng = np.random.default_rng(5)
    for _ in range(4):
        x = _random_state(plant, instance, x0, rng)
        plant.SetPositionsAndVelocities(context, instance, x)
        terms = kinematics.calc(x, [])
        np.testing.assert_allclose(terms.M, plant.CalcMassMatrix(context), atol=1e-10)
        h = plant.CalcBiasTerm(context) - plant.CalcGravityGeneralizedForces(context)
        h += _joint_damping(plant, instance) * x[plant.num_positions() :]
        np.testing.assert_allclose(terms.h, h, atol=1e-9)
        np.testing.assert_allclose(
            terms.p_WCom, plant.CalcCenterOfMassPositionInWorld(context, [instance]), atol=1e-12
        )


def _at_a_limit(scene, seed):
    """A random seated state with three joints pressed against a limit (at it, moving
    into it): their soft rows are in play, the others' are not."""
    scene_, x0 = scene
    plant, instance = scene_.plant, scene_.robot.model_instance
    x = _random_state(plant, instance, x0, np.random.default_rng(seed)).copy()
    context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(context, instance, x)
    for name, side in (("l_knee", 1), ("torso_pitch", -1), ("r_elbow", 1)):
        joint = plant.GetJointByName(name, instance)
        limit = (joint.position_upper_limits() if side > 0 else joint.position_lower_limits())[0]
        joint.set_angle(context, float(limit) - side * 1e-3)
        joint.set_angular_rate(context, side * 0.5)
    return plant.GetPositionsAndVelocities(context, instance)


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("standup_state", [2, 4])
def test_screened_soft_rows_give_the_full_programs_solution(scene, seed, standup_state):
    """The QP solved without the soft rows of joints whose limit is not in play (and
    again with any that break in) has the full program's optimum: the same torques,
    accelerations and wrenches, tick after tick, whatever was kept from the tick before."""
    x = _at_a_limit(scene, seed)
    plant, instance = scene[0].plant, scene[0].robot.model_instance
    com = _com(plant, instance, x)
    rigs = {screen: _Rig(scene[0]) for screen in (True, False)}
    solutions = {}
    for screen, rig in rigs.items():
        rig.fix(x, np.concatenate([com, np.zeros(6)]), standup_state)
        first = rig.tick()
        qp = rig.controller.program(rig.controller._last[0].active).qp
        qp._screen = screen
        solutions[screen] = [rig.tick() for _ in range(3)]  # kept set from the tick before
        assert first.ok
    qp = rigs[True].controller.program(rigs[True].controller._last[0].active).qp
    assert 0 < qp._soft_kept.sum() < len(qp._soft_kept)  # some rows in play, most left out
    assert qp.screening_resolves >= 1  # the first tick kept none: the pressed joints broke in
    for screened, full in zip(solutions[True], solutions[False], strict=True):
        assert screened.ok and full.ok
        assert np.abs(full.slack).max() > 1e-6  # the limits are in play
        np.testing.assert_allclose(screened.tau, full.tau, atol=1e-6)
        np.testing.assert_allclose(screened.vdot, full.vdot, atol=1e-6)
        np.testing.assert_allclose(screened.F_C, full.F_C, atol=1e-6)
        np.testing.assert_allclose(screened.slack, full.slack, atol=1e-7)


def test_daqps_infeasible_verdicts_checked_against_clarabel(scene):
    """On 200 random states with a binding 20 N m torque limit, every program Clarabel
    solves is solved unrelaxed by the controller's daqp (itself, or through its Clarabel
    fallback where daqp calls it infeasible) within the limit; none is relaxed that
    Clarabel solves. (Near the limit the optimum is flat in some torques: daqp, Clarabel
    and OSQP agree on the cost but part by up to 3 N m on seed 6, so the torques are not
    compared. daqp 0.11 with numpy 2.4 here calls about one in three of these programs
    infeasible; which ones moves with the machine's numerics.)"""
    scene_, x0 = scene
    plant, instance = scene_.plant, scene_.robot.model_instance
    rigs = {
        name: _Rig(scene_, qp_solver=name, torque_limit_Nm=20.0) for name in ("daqp", "clarabel")
    }
    solvable = fallbacks = 0
    for seed in range(200):
        x = _random_state(plant, instance, x0, np.random.default_rng(seed))
        reference = np.concatenate([_com(plant, instance, x), np.zeros(6)])
        solutions = {}
        for name, rig in rigs.items():
            rig.fix(x, reference, 2)
            solutions[name] = rig.tick()
        clarabel, daqp_ = solutions["clarabel"], solutions["daqp"]
        if not (clarabel.ok and not clarabel.relaxed):
            continue
        solvable += 1
        fallbacks += daqp_.fallback
        assert daqp_.ok and not daqp_.relaxed, f"seed {seed}: Clarabel solves it, daqp relaxed it"
        assert np.abs(daqp_.tau).max() <= 20.0 + 1e-5
    assert solvable >= 100  # the check compared most states
    controller = rigs["daqp"].controller
    assert fallbacks == controller.program(controller._last[0].active).qp.fallback_solves
    print(f"{solvable} of 200 solvable, {fallbacks} of them through the fallback")


def test_a_failed_daqp_solve_is_solved_by_the_fallback_and_counted(scene, monkeypatch):
    """daqp made to fail every program: the tick is Clarabel's (the same torques as a
    Clarabel controller's), QpSolution.fallback is set and the controller counts it."""
    from drake_standup.control import backends

    scene_, x0 = scene
    plant, instance = scene_.plant, scene_.robot.model_instance
    x = _random_state(plant, instance, x0, np.random.default_rng(8))
    reference = np.concatenate([_com(plant, instance, x), np.zeros(6)])
    clarabel = _Rig(scene_, qp_solver="clarabel")
    clarabel.fix(x, reference, 2)
    expected = clarabel.tick()
    # daqp's own answer on every program: infeasible (exit flag -1).
    monkeypatch.setattr(backends.daqp, "solve", lambda H, g, *rest: (np.zeros(len(g)), 0, -1, {}))
    rig = _Rig(scene_)
    rig.fix(x, reference, 2)
    solution = rig.tick()
    assert solution.ok and solution.fallback and not solution.relaxed
    np.testing.assert_allclose(solution.tau, expected.tau, atol=1e-4)
    before = np.zeros(DIAGNOSTICS.size)
    tick = rig.system.calc_tick(rig.context)[0]
    after = next_diagnostics(before, tick, 0.0)
    assert after[DIAGNOSTICS.index("qp_fallback")] == 1.0
    assert after[DIAGNOSTICS.index("qp_relaxed")] == 0.0


def _pressed_into_a_tendon(scene, seed):
    """A random seated state with the left shoulder 1 mrad inside its tendon bound of
    row 1 (p - r < 54.3 deg: pitch up, roll down) and moving into it at 2 rad/s."""
    scene_, x0 = scene
    plant, instance = scene_.plant, scene_.robot.model_instance
    x = _random_state(plant, instance, x0, np.random.default_rng(seed)).copy()
    context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(context, instance, x)
    a, b = shoulder_tendon_rows()
    joints = [plant.GetJointByName(f"l_{name}", instance) for name in SHOULDER_JOINTS]
    q = np.array([j.get_angle(context) for j in joints])
    row = 1
    q = q - (a[row] @ q + b[row] - 1e-3) * a[row]  # onto the row's plane, 1 mrad inside
    for joint, angle, rate in zip(joints, q, -2.0 * a[row], strict=True):
        joint.set_angle(context, float(angle))
        joint.set_angular_rate(context, float(rate))
    return plant.GetPositionsAndVelocities(context, instance), a[row], joints


def test_the_shoulder_tendon_rows_brake_a_shoulder_moving_into_its_bound(scene):
    """A shoulder 1 mrad inside its tendon bound and closing on it at 2 rad/s: the QP's
    tendon row asks a^T qddot for at least the joint-limit bounds of that distance and
    rate (control/tasks/joint_limits.py's two, computed here), its slack is exactly the
    shortfall, and it brakes the shoulder harder than the same program without the rows.
    Screened and full programs agree with the row in play."""
    x, a_row, joints = _pressed_into_a_tendon(scene, 1)
    plant, instance = scene[0].plant, scene[0].robot.model_instance
    reference = np.concatenate([_com(plant, instance, x), np.zeros(6)])
    columns = np.array([j.velocity_start() for j in joints])  # the robot's v is the plant's
    config = ControllerConfig()
    # The distance to the bound (rad) and its rate; the row's lower bound on a^T qddot,
    # the tighter of the horizon's and the braking reserve's.
    distance, rate, no_bound = np.array([1e-3]), np.array([-2.0]), np.full(1, np.inf)
    horizon_s = config.joint_limit_horizon_s
    low = max(
        joint_limit_acceleration_bounds(distance, rate, np.zeros(1), no_bound, horizon_s)[0][0],
        braking_bounds(
            distance, rate, np.zeros(1), no_bound, config.joint_braking_rad_per_s2, horizon_s
        )[0][0],
    )
    values, slacks = {}, {}
    for tendons, screen in ((True, True), (True, False), (False, True)):
        rig = _Rig(scene[0], shoulder_tendons=tendons)
        rig.fix(x, reference, 2)
        rig.tick()
        qp = rig.controller.program(rig.controller._last[0].active).qp
        qp._screen = screen
        solution = rig.tick()
        assert solution.ok
        values[tendons, screen] = a_row @ solution.vdot[columns]
        slacks[tendons, screen] = solution.slack
    nu = plant.num_actuators()
    row = nu + 1  # the left shoulder's row 1, after one row per joint
    held = values[True, True]
    assert held < low  # the pull past it is strong: the row is in play, with its slack
    np.testing.assert_allclose(-slacks[True, True][row], low - held, atol=1e-6)
    np.testing.assert_allclose(values[True, False], held, atol=1e-6)
    np.testing.assert_allclose(slacks[True, False], slacks[True, True], atol=1e-7)
    assert values[False, True] < held - 10.0  # without the rows it runs on into the bound


def _outboard_mass_kg(plant, instance, joint_name):
    """The mass of the bodies outboard of a joint, walking the tree from its child body."""
    joint = plant.GetJointByName(joint_name, instance)
    bodies, grew = {joint.child_body().index()}, True
    while grew:
        grew = False
        for index in plant.GetJointIndices(instance):
            other = plant.get_joint(index)
            if other.parent_body().index() in bodies and other.child_body().index() not in bodies:
                bodies.add(other.child_body().index())
                grew = True
    return sum(plant.get_body(body).default_mass() for body in bodies)


def test_carried_limbs_weigh_by_the_mass_they_carry(scene):
    """Each arm and neck joint's posture weight is the torso pitch's times (the mass the
    torso carries over the mass the joint carries)^exponent (each walked out of the tree
    here); a joint the table names keeps its value; the legs keep posture_weight; off,
    all flat."""
    scene_, _ = scene
    plant, robot = scene_.plant, scene_.robot
    joints = ControllerJoints.of(plant, robot)
    config = ControllerConfig(
        posture_weight_by_joint={"torso_pitch": 2.0, "l_elbow": 0.5},
        carried_limb_weight_by_mass=True,
        carried_limb_weight_exponent=1.5,
    )
    w = dict(zip(joints.names, posture_weights(plant, joints, config), strict=True))
    torso = _outboard_mass_kg(plant, robot.model_instance, "torso_pitch")
    for name in ("r_shoulder_pitch", "r_elbow", "l_wrist_yaw", "neck_pitch"):
        ratio = torso / _outboard_mass_kg(plant, robot.model_instance, name)
        np.testing.assert_allclose(w[name], 2.0 * ratio**1.5, rtol=1e-12)
    assert w["r_wrist_yaw"] > w["r_elbow"] > w["r_shoulder_pitch"] > 2.0  # lighter, dearer
    assert w["l_elbow"] == 0.5 and w["torso_pitch"] == 2.0
    assert w["l_knee"] == config.posture_weight
    flat = dataclasses.replace(config, carried_limb_weight_by_mass=False)
    w_flat = dict(zip(joints.names, posture_weights(plant, joints, flat), strict=True))
    assert w_flat["r_elbow"] == config.posture_weight and w_flat["l_elbow"] == 0.5


def test_released_thigh_pads_plan_on_their_dynamics(scene):
    """controller.seat_pad_dynamics: while the thighs' load is released (state 3, their
    normal held), each thigh's planned normal force is what its pad gives for the planned
    motion, f_z + (k T^2 / 6) a_n = F measured (control/pad_dynamics.py (2)), with a_n from
    Drake's Jacobian and bias acceleration and k from the pad's tilt; without it the
    thighs have no compliance."""
    scene, x0 = scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    context = plant.CreateDefaultContext()
    rng = np.random.default_rng(46)
    measured = np.array([0.0, 40.0, 25.0])
    for dynamics in (True, False):
        rig = _Rig(scene, seat_pad_dynamics=dynamics, torque_limit_Nm=1000.0)
        pads = {spec.frame: spec.compliance for spec in rig.specs}
        for _ in range(10):
            x = _random_state(plant, instance, x0, rng)
            com = _com(plant, instance, x)
            loads = [0.0, 0.5, 0.5]
            rig.fix(x, np.concatenate([com, np.zeros(6)]), 3, loads=loads)
            mode = dataclasses.replace(initial_mode(np.zeros(3)), state=3)
            rig.schedule.commands = contact_commands(
                rig.config,
                np.array(loads),
                np.full(3, 100.0),
                measured,
                phase_seat_hold(mode, rig.table),
            )
            solution = rig.tick()
            assert solution.ok and not solution.relaxed
            plant.SetPositionsAndVelocities(context, instance, x)
            for k, name in enumerate(("l_thigh", "r_thigh"), start=1):
                frame = robot.frame(plant, name)
                J, bias = _jacobian_and_bias_in_frame(plant, context, frame)
                a_n = J[5] @ solution.vdot + bias[5]
                f_z = solution.F_C[solution.frames.index(name), 5]
                if not dynamics:
                    assert pads[name] is None
                    continue
                R_WC = frame.CalcPoseInWorld(context).rotation().matrix()
                tilt = np.arccos(np.clip(R_WC[2, 2], -1.0, 1.0))
                rolled = abs(R_WC[2, 1]) > abs(R_WC[2, 0])
                stiffness = pads[name].stiffness_N_per_m(measured[k], tilt, rolled)
                assert f_z + stiffness * PERIOD_S**2 / 6 * a_n == pytest.approx(
                    measured[k], abs=1e-6
                )
