"""Each task's law (drake_standup/control/tasks/) on its own, at a random seated-plant
state, against values computed here without the package's code: Drake's frame poses,
CoM, mass, Jacobians, SpatialForce shifts and axis-angles, hand-computed feedback laws,
and the constant-acceleration motion integrated step by step."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.tree import JacobianWrtVariable

from drake_standup.config import ControllerConfig
from drake_standup.control.model import HANDS, ControllerJoints, contact_specs
from drake_standup.control.qp import ContactMap
from drake_standup.control.targets import TaskReferences
from drake_standup.control.tasks import (
    BaseOrientationTask,
    BaseTarget,
    CopCenteringTask,
    JointLimitBounds,
    MomentumLaw,
    MomentumTask,
    PostureTask,
    StancePostureTask,
    next_posture_reference,
)
from drake_standup.control.terms import RobotKinematics

SEEDS = range(3)


@pytest.fixture(scope="module")
def rig(seated_scene):
    scene, context = seated_scene
    plant, robot = scene.plant, scene.robot
    specs = contact_specs(plant, robot, ControllerConfig())
    kinematics = RobotKinematics(
        plant, robot, held_frames=[], other_frames=[s.frame for s in specs] + list(HANDS)
    )
    x0 = plant.GetPositionsAndVelocities(context, robot.model_instance)
    joints = ControllerJoints.of(plant, robot)
    return plant, robot, context, specs, kinematics, x0, joints


def _state(rig, seed):
    """Drake's context at the seated posture, joints +-0.3 rad (within limits), a random
    base pose and random rates; and the package's terms at it (every contact, the hands)."""
    plant, robot, context, specs, kinematics, x0, _ = rig
    rng, instance = np.random.default_rng(seed), robot.model_instance
    plant.SetPositionsAndVelocities(context, instance, x0)
    for joint in map(plant.get_joint, plant.GetJointIndices(instance)):
        if joint.num_positions() == 1:
            q = joint.get_angle(context) + rng.uniform(-0.3, 0.3)
            low, high = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
            joint.set_angle(context, float(np.clip(q, low, high)))
    R = RotationMatrix(AngleAxis(rng.uniform(0.1, 1.0), _unit(rng)))
    base = plant.GetBodyByName("root_link", instance)
    plant.SetFreeBodyPose(context, base, RigidTransform(R, rng.uniform(-1.0, 1.0, 3)))
    plant.SetVelocities(context, instance, rng.normal(scale=0.3, size=plant.num_velocities()))
    x = plant.GetPositionsAndVelocities(context, instance)
    terms = kinematics.calc(x, [s.frame for s in specs], list(HANDS))
    return rng, terms


def _unit(rng) -> np.ndarray:
    axis = rng.normal(size=3)
    return axis / np.linalg.norm(axis)


def _references(**fields) -> TaskReferences:
    values = dict(
        standup_state=2, state=None, Ldot_star=np.zeros(6), tau_hand=None, q_reference=None,
        R_WB_target=np.eye(3), helpful_force_W=np.zeros(3), lean_W=np.zeros(3),
        vertical_weight_scale=1.0, stance=1.0, next_height_integral=0.0,
        next_momentum_integral=np.zeros(3), next_posture=None,
    )  # fmt: skip
    return TaskReferences(**(values | fields))


def _about(F_W: SpatialForce, p_WA: np.ndarray, p_WCom: np.ndarray) -> np.ndarray:
    """[tau; f] about the CoM of a wrench F_W (in W) applied at A."""
    return F_W.Shift(p_WCom - p_WA).get_coeffs()


@pytest.mark.parametrize("seed", SEEDS)
def test_momentum_task_is_the_wrench_balance_about_drakes_com(rig, seed):
    """A F = sum of the contact wrenches (each [tau_C; f_C] in C at Co, rotated by Drake's
    R_WC and shifted to Drake's CoM); b = Ldot* - [0; m g] - (hands' wrenches about the
    CoM), m Drake's total mass; the vertical force row's weight scaled."""
    plant, robot, context, specs, _, _, _ = rig
    rng, terms = _state(rig, seed)
    instance = robot.model_instance
    contact_map = ContactMap(specs, plant.num_velocities())
    layout = contact_map.layout
    gravity = plant.gravity_field().gravity_vector()
    task = MomentumTask(layout, contact_map, gravity, weight=7.0)
    p_WCom = plant.CalcCenterOfMassPositionInWorld(context, [instance])
    mass = plant.CalcTotalMass(context, [instance])

    F = rng.normal(scale=50.0, size=layout.n_wrench)
    total = np.zeros(6)
    for c, spec in enumerate(specs):
        F_c = np.r_[np.zeros(3), F[layout.wrench(c)]] if spec.point else F[layout.wrench(c)]
        X_WC = robot.frame(plant, spec.frame).CalcPoseInWorld(context)
        F_W = SpatialForce(X_WC.rotation() @ F_c[:3], X_WC.rotation() @ F_c[3:])
        total += _about(F_W, X_WC.translation(), p_WCom)

    F_hand = rng.normal(scale=20.0, size=(2, 6))  # [tau; f] in W at each hand's origin
    tau_hand = np.zeros(plant.num_velocities())
    W_hand = np.zeros(6)
    for name, F_h in zip(HANDS, F_hand, strict=True):
        frame = robot.frame(plant, name)
        world = plant.world_frame()
        kV = JacobianWrtVariable.kV
        J = plant.CalcJacobianSpatialVelocity(context, kV, frame, np.zeros(3), world, world)
        tau_hand += J.T @ F_h
        p_WH = frame.CalcPoseInWorld(context).translation()
        W_hand += _about(SpatialForce(F_h[:3], F_h[3:]), p_WH, p_WCom)

    Ldot = rng.normal(scale=10.0, size=6)
    for hand, W_h in ((None, 0.0), (tau_hand, W_hand)):
        task.update(terms, _references(Ldot_star=Ldot, tau_hand=hand, vertical_weight_scale=0.25))
        np.testing.assert_allclose(task.A @ F, total, rtol=1e-9, atol=1e-9)
        expected_b = Ldot - np.r_[np.zeros(3), mass * gravity] - W_h
        np.testing.assert_allclose(task.b, expected_b, rtol=1e-9, atol=1e-9)
    assert task.columns == layout.wrenches
    np.testing.assert_array_equal(task.weight, [7.0] * 5 + [7.0 * 0.25])
    # A phase its posture leads: the CoM rows (force) at their scale, the moment rows whole.
    led = _references(Ldot_star=Ldot, vertical_weight_scale=0.25, com_weight_scale=1e-3)
    task.update(terms, led)
    np.testing.assert_allclose(task.weight, [7.0] * 3 + [7e-3] * 2 + [7e-3 * 0.25], rtol=1e-15)


def _joint_rates(plant, context, names):
    """q, qdot and the index in v of the named joints, from Drake's joint objects."""
    joints = [plant.GetJointByName(name) for name in names]
    return (
        np.array([j.get_angle(context) for j in joints]),
        np.array([j.get_angular_rate(context) for j in joints]),
        np.array([j.velocity_start() for j in joints]),
    )


@pytest.mark.parametrize("seed", SEEDS)
def test_posture_task_is_a_pd_law_on_its_joints(rig, seed):
    """b = -K_P (q - q_ref) - 2 zeta sqrt(K_P) qdot with q, qdot read from Drake's joints;
    A z[columns] picks those joints' vdot (a non-consecutive subset); the stance task's
    weights are the full weights times references.stance."""
    plant, _, context, specs, _, _, joints = rig
    rng, terms = _state(rig, seed)
    layout = ContactMap(specs, plant.num_velocities()).layout
    chosen = np.sort(rng.choice(len(joints.names), size=12, replace=False))
    names = [joints.names[k] for k in chosen]
    kp, zeta = 25.0, 0.7
    weights = rng.uniform(0.1, 2.0, len(chosen))
    q_ref = rng.uniform(-0.5, 0.5, len(chosen))
    q, qdot, v_index = _joint_rates(plant, context, names)
    expected = -kp * (q - q_ref) - 2.0 * zeta * math.sqrt(kp) * qdot
    z = rng.normal(size=layout.n)
    for stance in (0.0, 0.4, 1.0):
        for kind in (PostureTask, StancePostureTask):
            task = kind(
                layout, joints.q_indices[chosen], joints.v_indices[chosen], weights, kp, zeta
            )
            task.update(terms, _references(q_reference=q_ref, stance=stance))
            np.testing.assert_allclose(task.b, expected, rtol=1e-12, atol=1e-12)
            np.testing.assert_array_equal(task.A @ z[task.columns], z[layout.vdot][v_index])
            scale = stance if kind is StancePostureTask else 1.0
            np.testing.assert_allclose(task.weight, weights * scale, rtol=1e-15)


@pytest.mark.parametrize("seed", SEEDS)
def test_base_orientation_law_against_drakes_axis_angle(rig, seed):
    """b = -K_P theta k - K_D w_WB with theta k Drake's axis-angle of R_WB R_target^T (in W,
    as w_WB and vdot[:3] are: checked against Drake's base spatial velocity) and w_WB
    Drake's; a target is chosen at a known world-frame rotation theta k from R_WB."""
    plant, robot, context, specs, _, _, _ = rig
    rng, terms = _state(rig, seed)
    layout = ContactMap(specs, plant.num_velocities()).layout
    base = plant.GetBodyByName("root_link", robot.model_instance)
    R_WB = base.EvalPoseInWorld(context).rotation()
    w_WB = base.EvalSpatialVelocityInWorld(context).rotational()
    np.testing.assert_allclose(terms.v[:3], w_WB, atol=1e-12)
    theta, k = rng.uniform(0.05, 2.5), _unit(rng)
    R_target = RotationMatrix(AngleAxis(-theta, k)) @ R_WB
    error = (R_WB @ R_target.inverse()).ToAngleAxis()
    np.testing.assert_allclose(error.angle() * error.axis(), theta * k, atol=1e-9)
    kp, zeta = 30.0, 0.8
    task = BaseOrientationTask(layout, weight=3.0, kp_per_s2=kp, damping_ratio=zeta)
    task.update(terms, _references(R_WB_target=R_target.matrix()))
    expected = -kp * theta * k - 2.0 * zeta * math.sqrt(kp) * w_WB
    np.testing.assert_allclose(task.b, expected, atol=1e-9)
    assert task.columns == slice(layout.vdot.start, layout.vdot.start + 3)
    np.testing.assert_array_equal(task.A, np.eye(3))


@pytest.mark.parametrize("seed", SEEDS)
def test_base_orientation_law_brings_the_base_back_to_its_target(rig, seed):
    """Physically: a base pitched 0.3 rad forward of an upright target at rest gets a
    backward pitch acceleration; and the law integrated as the world-frame angular
    acceleration (R <- exp([w dt]) R, Drake's AngleAxis) from a random orientation and rate
    brings R_WB to a random target (critically damped: within 1e-3 rad in 3 s)."""
    plant, _, _, specs, _, _, _ = rig
    rng, terms = _state(rig, seed)
    layout = ContactMap(specs, plant.num_velocities()).layout
    task = BaseOrientationTask(layout, weight=1.0, kp_per_s2=30.0, damping_ratio=1.0)
    terms.R_WB = RotationMatrix.MakeYRotation(0.3).matrix()  # x forward, z up: pitch down
    terms.v = np.zeros_like(terms.v)
    task.update(terms, _references(R_WB_target=np.eye(3)))
    np.testing.assert_allclose(task.b, [0.0, -30.0 * 0.3, 0.0], atol=1e-12)

    R_target = RotationMatrix(AngleAxis(rng.uniform(0.5, 2.5), _unit(rng)))
    R = RotationMatrix(AngleAxis(rng.uniform(0.5, 2.5), _unit(rng)))
    w, dt = rng.normal(scale=0.5, size=3), 1e-3
    for _ in range(3000):
        terms.R_WB, terms.v[:3] = R.matrix(), w
        task.update(terms, _references(R_WB_target=R_target.matrix()))
        w = w + dt * task.b
        R = RotationMatrix(AngleAxis(np.linalg.norm(w) * dt, w / np.linalg.norm(w))) @ R
    assert (R.inverse() @ R_target).ToAngleAxis().angle() < 1e-3


@pytest.mark.parametrize("seed", SEEDS)
def test_cop_centering_residual_is_the_cops_offset_times_the_normal_force(rig, seed):
    """Each sole's and the seat's wrench is built from a force applied at a known CoP p
    (x, y, 0) in C plus a free moment about z, moved to Co by Drake's SpatialForce.Shift:
    the task's residual for it is [(y - c_y) f_z, -(x - c_x) f_z] (c the box centre), zero
    at the centre; the thighs' point forces do not enter."""
    plant, _, _, specs, _, _, _ = rig
    rng = np.random.default_rng(seed)
    layout = ContactMap(specs, plant.num_velocities()).layout
    task = CopCenteringTask(layout, specs, weight=1.0)
    wrenches = [c for c, spec in enumerate(specs) if not spec.point]
    assert task.A.shape == (2 * len(wrenches), layout.n_wrench)
    for centred in (True, False):
        F = rng.normal(scale=30.0, size=layout.n_wrench)  # thighs: any force
        expected = []
        for c in wrenches:
            spec = specs[c]
            centre = np.array([sum(spec.cop_x_m) / 2.0, sum(spec.cop_y_m) / 2.0])
            cop = centre if centred else centre + rng.uniform(-0.05, 0.05, 2)
            f = np.r_[rng.normal(scale=20.0, size=2), rng.uniform(10.0, 200.0)]
            p_CoP = np.r_[cop, 0.0]
            F_P = SpatialForce(np.r_[0.0, 0.0, rng.normal()], f)
            F[layout.wrench(c)] = F_P.Shift(-p_CoP).get_coeffs()
            expected += [(cop[1] - centre[1]) * f[2], -(cop[0] - centre[0]) * f[2]]
        residual = task.A @ F - task.b
        np.testing.assert_allclose(residual, expected, atol=1e-9)
        if centred:
            np.testing.assert_allclose(residual, 0.0, atol=1e-9)


@pytest.mark.parametrize("seed", SEEDS)
def test_joint_limit_bounds_land_on_the_limits_at_the_horizon(rig, seed):
    """At Drake's joint limits: at rest halfway the bounds are -+(q_max - q_min) / T^2;
    at a random state, vdot_max (vdot_min) held for T, integrated step by step from
    (q, qdot) read from Drake's joints, lands on q_max (q_min); anything between the
    bounds ends inside the limits."""
    plant, _, context, _, _, _, joints = rig
    rng, terms = _state(rig, seed)
    q_min = np.array([plant.GetJointByName(n).position_lower_limits()[0] for n in joints.names])
    q_max = np.array([plant.GetJointByName(n).position_upper_limits()[0] for n in joints.names])
    T = 0.1
    bounds = JointLimitBounds(joints.q_indices, joints.v_indices, q_min, q_max, T)

    terms.q[joints.q_indices], terms.v[:] = (q_min + q_max) / 2.0, 0.0
    low, high = bounds.calc(terms)
    np.testing.assert_allclose(high, (q_max - q_min) / T**2, rtol=1e-12)
    np.testing.assert_allclose(low, -(q_max - q_min) / T**2, rtol=1e-12)

    _, terms = _state(rig, seed)
    q, qdot, _ = _joint_rates(plant, context, joints.names)
    low, high = bounds.calc(terms)
    between = low + rng.uniform(size=len(q)) * (high - low)
    steps, dt = 1000, T / 1000
    ends = []
    for vdot in (low, high, between):
        position, rate = q.copy(), qdot.copy()
        for _ in range(steps):  # trapezoidal: exact at constant acceleration
            position += dt * (rate + 0.5 * dt * vdot)
            rate += dt * vdot
        ends.append(position)
    np.testing.assert_allclose(ends[0], q_min, atol=1e-9)
    np.testing.assert_allclose(ends[1], q_max, atol=1e-9)
    assert np.all((ends[2] >= q_min - 1e-9) & (ends[2] <= q_max + 1e-9))


# --- The laws that make the tasks' targets, each on its own ----------------------------


def _terms_at(p, v, L, mass_kg):
    """The RobotTerms fields the momentum law reads."""
    return SimpleNamespace(
        p_WCom=np.array(p, float),
        v_WCom=np.array(v, float),
        L_WCom=np.array(L, float),
        mass_kg=mass_kg,
    )


def test_the_momentum_law_is_the_papers_objective_component_by_component():
    """Ldot* = [-K_D,ang L - K_P,ang int L; m (xd_ddot - K_D (v - xd_dot) - K_P (p - x_d))]
    written out per component; no pull, no stance: no help, no height integral."""
    config = ControllerConfig()
    law = MomentumLaw(config, period_s=0.004, gravity_mps2=9.81)
    terms = _terms_at([0.1, -0.02, 0.5], [0.2, 0.01, -0.1], [0.3, -0.4, 0.5, 0, 0, 0], 33.0)
    target = [0.12, 0.0, 0.52, 0.25, 0.0, 0.05, 0.5, 0.1, -0.2]
    kp, kd = np.array([60.0, 40.0, 30.0]), np.array([15.0, 12.0, 10.0])
    integral = np.array([0.01, 0.02, -0.03])
    out = law.target(
        terms, np.array(target), kp, kd, integral, 0.0, height_integral=0.0, pull_W=None
    )
    expected = []
    for i in range(3):
        expected.append(
            -config.angular_momentum_kd_per_s * terms.L_WCom[i]
            - config.angular_momentum_kp_per_s2 * integral[i]
        )
    for i in range(3):
        xddot = target[6 + i] - kd[i] * (terms.v_WCom[i] - target[3 + i])
        xddot -= kp[i] * (terms.p_WCom[i] - target[i])
        expected.append(33.0 * xddot)
    np.testing.assert_allclose(out.Ldot_star, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(out.helpful_force_W, np.zeros(3))
    assert out.next_height_integral == 0.0
    np.testing.assert_allclose(out.next_momentum_integral, integral + 0.004 * terms.L_WCom[:3])


def test_the_momentum_integral_about_the_pitch_axis_only_keeps_that_component():
    """angular_momentum_integral_axes 'pitch': int L <- ((int L + T L) . a) a with a the
    heading's pitch axis (-sin psi, cos psi, 0); its roll and yaw parts are dropped, so a
    pitch-only integral acts as the authors' on a sagittal motion; 'all' keeps the sum."""
    config = ControllerConfig(angular_momentum_integral_axes="pitch")
    law = MomentumLaw(config, period_s=0.004, gravity_mps2=9.81)
    terms = _terms_at([0.1, 0.0, 0.5], np.zeros(3), [0.3, -0.4, 0.5, 0, 0, 0], 33.0)
    target, zero = np.array([0.1, 0.0, 0.5, 0, 0, 0, 0, 0, 0]), np.zeros(3)
    integral = np.array([0.01, 0.02, -0.03])
    summed = integral + 0.004 * terms.L_WCom[:3]
    for heading in (0.0, math.pi, 0.3):
        axis = np.array([-math.sin(heading), math.cos(heading), 0.0])
        out = law.target(
            terms,
            target,
            zero,
            zero,
            integral,
            0.0,
            height_integral=0.0,
            pull_W=None,
            heading_rad=heading,
        )
        np.testing.assert_allclose(out.next_momentum_integral, (summed @ axis) * axis, atol=1e-15)
    sagittal = np.array([0.0, 0.05, 0.0])
    out = law.target(terms, target, zero, zero, sagittal, 0.0, height_integral=0.0, pull_W=None)
    authors = MomentumLaw(ControllerConfig(), 0.004, 9.81).target(
        terms, target, zero, zero, sagittal, 0.0, height_integral=0.0, pull_W=None
    )
    np.testing.assert_array_equal(out.Ldot_star, authors.Ldot_star)  # this tick's, unchanged
    assert ControllerConfig().angular_momentum_integral_axes == "all"


def test_the_momentum_law_lets_through_only_the_pull_along_the_path():
    """Past the fade speed and at the reference (no lead), f_par = (f . u) u for a pull
    with a component along xd_dot, 0 for one against it; it adds to m xddot*, faded by the
    stance."""
    config = ControllerConfig()
    law = MomentumLaw(config, period_s=0.004, gravity_mps2=9.81)
    terms = _terms_at([0.1, 0.0, 0.5], [0.0, 0.0, 0.0], np.zeros(6), 33.0)
    speed = 2.0 * config.help_fade_speed_mps
    target = np.array([0.1, 0.0, 0.5, speed * 0.6, 0.0, speed * 0.8, 0.0, 0.0, 0.0])
    kp = kd = np.zeros(3)
    pull = np.array([20.0, 5.0, 10.0])
    along = 20.0 * 0.6 + 10.0 * 0.8
    for stance in (0.0, 0.5):
        out = law.target(
            terms, target, kp, kd, np.zeros(3), stance, height_integral=0.0, pull_W=pull
        )
        f_par = (1.0 - stance) * along * np.array([0.6, 0.0, 0.8])
        np.testing.assert_allclose(out.helpful_force_W, f_par, atol=1e-12)
        np.testing.assert_allclose(out.Ldot_star[3:5], f_par[:2], atol=1e-12)
    against = law.target(terms, target, kp, kd, np.zeros(3), 0.0, height_integral=0.0, pull_W=-pull)
    np.testing.assert_array_equal(against.helpful_force_W, np.zeros(3))


def test_the_stance_height_integral_accumulates_and_is_bounded():
    """I <- clip(I + T s (z_d - z), +-0.2 g / K_I), and m K_I I adds to the vertical
    force; a large error saturates at the bound."""
    config = ControllerConfig()
    law = MomentumLaw(config, period_s=0.004, gravity_mps2=9.81)
    terms = _terms_at([0.0, 0.0, 0.50], np.zeros(3), np.zeros(6), 33.0)
    target = np.array([0.0, 0.0, 0.52, 0, 0, 0, 0, 0, 0])
    zero = np.zeros(3)
    out = law.target(terms, target, zero, zero, zero, 0.5, height_integral=0.001, pull_W=None)
    integral = 0.001 + 0.004 * 0.5 * 0.02
    assert out.next_height_integral == pytest.approx(integral, rel=1e-12)
    ki = config.stance_height_ki_per_s3
    assert out.Ldot_star[5] == pytest.approx(33.0 * ki * integral, rel=1e-12)
    limit = 0.2 * 9.81 / ki
    saturated = law.target(
        terms, target, zero, zero, zero, 1.0, height_integral=10.0 * limit, pull_W=None
    )
    assert saturated.next_height_integral == pytest.approx(limit, rel=1e-12)


def test_the_posture_reference_is_a_first_order_filter():
    """After n ticks toward a fixed target from q0: q_n = q* + (q0 - q*) (1 - b)^n (closed
    form); a held joint's target is the first posture, clamped inside the limits."""
    q0 = np.array([0.5, -1.0, 2.0])
    target = np.array([0.1, -0.2, np.nan])
    hold = np.array([False, False, True])
    low, high = np.full(3, -1.5), np.full(3, 1.5)
    blend = 0.04
    q = q0.copy()
    for _ in range(25):
        q = next_posture_reference(q0, q, hold, target, low, high, blend=blend)
    goal = np.array([0.1, -0.2, 1.5])  # the held joint: 2.0 clamped to 1.5
    np.testing.assert_allclose(q, goal + (q0 - goal) * (1.0 - blend) ** 25, rtol=1e-12)


def test_the_base_target_is_the_first_yaw_and_the_states_forward_pitch():
    """R_WB* = Rz(yaw) Ry(-pitch) by Drake's RotationMatrix. root_link's x axis points
    backwards: seated facing +x its yaw is pi, and a forward pitch must tip the base's z
    axis toward +x, by sin(pitch)."""
    target = BaseTarget()
    for yaw, pitch in ((0.0, 0.4), (0.7, 0.3), (-1.2, 0.0)):
        expected = RotationMatrix.MakeZRotation(yaw) @ RotationMatrix.MakeYRotation(-pitch)
        np.testing.assert_allclose(target(yaw, pitch), expected.matrix(), atol=1e-15)
    z_axis = target(math.pi, 0.4)[:, 2]
    np.testing.assert_allclose(z_axis, [math.sin(0.4), 0.0, math.cos(0.4)], atol=1e-15)
