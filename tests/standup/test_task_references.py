"""The task references (standup/task_references.py) from the phase table, against values
computed here from Drake's CoM, momentum and joint limits: gains, posture targets, the
centroidal momentum target, the help let through, the stance, the lean, the base target,
and the generator's memory over ticks."""

from __future__ import annotations

import dataclasses
import math
from functools import partial

import numpy as np
import pytest
from pydrake.math import RotationMatrix

from drake_standup.config import ControllerConfig, Scenario
from drake_standup.config.inputs import TASK_FRAMES
from drake_standup.config.phases import PHASES, PhaseTable
from drake_standup.control.model import HANDS, ControllerJoints
from drake_standup.control.qp import as_slice
from drake_standup.control.terms import RobotKinematics
from drake_standup.robot.balance import static_lean
from drake_standup.standup.task_references import (
    ADVANCEMENT,
    COMPLIANT,
    STIFF,
    CarriedState,
    PhaseReferences,
    TaskReferenceGenerator,
    TickInputs,
)
from drake_standup.world.sensing import StandingSupport, standing_lean, standing_pull_usage

T = 0.004
CONFIG = ControllerConfig()
TABLE = PhaseTable()


@pytest.fixture(scope="module")
def rig(seated_scene):
    scene, context = seated_scene
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    rng = np.random.default_rng(4)
    plant.SetVelocities(context, instance, rng.normal(scale=0.2, size=plant.num_velocities()))
    x = plant.GetPositionsAndVelocities(context, instance)
    joints = ControllerJoints.of(plant, robot)
    phases = PhaseReferences(TABLE, CONFIG, joints.names, joints.q_min, joints.q_max)
    g = -plant.gravity_field().gravity_vector()[2]
    generator = TaskReferenceGenerator(CONFIG, phases, as_slice(joints.q_indices), T, g)
    kinematics = RobotKinematics(plant, robot, held_frames=[], other_frames=list(HANDS))
    return {
        "plant": plant,
        "instance": instance,
        "context": context,
        "x": x,
        "joints": joints,
        "phases": phases,
        "generator": generator,
        "kinematics": kinematics,
        "g": g,
    }


def _drake_com(rig):
    plant, context, instance = rig["plant"], rig["context"], rig["instance"]
    p = plant.CalcCenterOfMassPositionInWorld(context, [instance])
    v = plant.CalcCenterOfMassTranslationalVelocityInWorld(context, [instance])
    L = plant.CalcSpatialMomentumInWorldAboutPoint(context, [instance], p).rotational()
    return p, v, L, plant.CalcTotalMass(context, [instance])


def test_the_schedule_is_the_phase_tables(rig):
    """Per state: K_P as the table says, K_D = 2 zeta sqrt(K_P); the posture target the
    table's joints, clamped posture_limit_margin_rad inside Drake's joint limits; the
    joints a phase does not name hold."""
    plant, instance, phases = rig["plant"], rig["instance"], rig["phases"]
    margin = CONFIG.posture_limit_margin_rad
    for state, name in enumerate(PHASES, start=1):
        phase, ref = getattr(TABLE, name), phases[state]
        np.testing.assert_array_equal(ref.com_kp_per_s2, phase.com_kp_per_s2)
        kd = [2.0 * CONFIG.com_damping_ratio * math.sqrt(kp) for kp in phase.com_kp_per_s2]
        np.testing.assert_allclose(ref.com_kd_per_s, kd, rtol=1e-15)
        assert ref.base_pitch_rad == phase.base_pitch_rad
        assert (ref.lean, ref.stance) == (phase.lean, phase.stance)
        for k, joint in enumerate(rig["joints"].names):
            if joint not in phase.posture_rad:
                assert ref.posture_hold[k]
                continue
            limits = plant.GetJointByName(joint, instance)
            low = limits.position_lower_limits()[0] + margin
            high = limits.position_upper_limits()[0] - margin
            assert not ref.posture_hold[k]
            assert ref.posture_rad[k] == min(max(phase.posture_rad[joint], low), high)
    # [authors-code]'s elbow target 0.2473 rad lies below the URDF's 0.262 limit: clamped.
    k = rig["joints"].names.index("l_elbow")
    assert phases[2].posture_rad[k] > TABLE.forward.posture_rad["l_elbow"]


def _calc(
    rig,
    state,
    *,
    reference=None,
    hands=None,
    integral=None,
    progress=1.0,
    lean=None,
    response=ADVANCEMENT,
    compliance=None,
    psi_dot=1.0,
):
    terms = rig["kinematics"].calc(rig["x"], [], HANDS if hands is not None else ())
    nu = len(rig["joints"].names)
    p, v, _, _ = _drake_com(rig)
    if reference is None:
        reference = np.concatenate([p + [0.02, 0.0, -0.01], [0.1, 0.0, 0.05], [0.3, 0.0, 0.1]])
    now = TickInputs(state, reference, hands, progress, response, psi_dot)
    carried = CarriedState(
        momentum_integral=np.zeros(3) if integral is None else integral,
        posture=np.zeros(2 + 3 * nu),
        lean_W=lean,
        compliance=compliance,
    )
    return rig["generator"].calc(terms, now, carried), reference


def test_the_momentum_target_is_the_com_law_and_the_angular_damping(rig):
    """State 2, no pull: Ldot* = [-K_D,ang L - K_P,ang int L; m (xd_ddot - K_D (v - xd_dot)
    - K_P (x - x_d))], with Drake's CoM, its velocity and the angular momentum."""
    integral = np.array([0.01, -0.02, 0.03])
    references, ref = _calc(rig, 2, integral=integral)
    p, v, L, m = _drake_com(rig)
    kp = np.array(TABLE.forward.com_kp_per_s2)
    kd = 2.0 * np.sqrt(kp)
    xddot = ref[6:9] - kd * (v - ref[3:6]) - kp * (p - ref[:3])
    np.testing.assert_allclose(references.Ldot_star[3:], m * xddot, rtol=1e-9, atol=1e-9)
    angular = -CONFIG.angular_momentum_kd_per_s * L - CONFIG.angular_momentum_kp_per_s2 * integral
    np.testing.assert_allclose(references.Ldot_star[:3], angular, atol=1e-9)
    assert references.tau_hand is None and not references.helpful_force_W.any()
    np.testing.assert_allclose(references.next_momentum_integral, integral + T * L, atol=1e-12)


def test_the_help_let_through_is_the_pull_along_the_desired_velocity(rig):
    """State 2, the reference moving forward at 0.1 m/s (5x the fade speed), the CoM on
    it: a 15 N forward + 15 N up pull per hand lets its 30 N forward part through into
    the linear momentum target, and its hands' generalized force is J_h^T F."""
    p, _, _, _ = _drake_com(rig)
    reference = np.concatenate([p, [0.1, 0.0, 0.0], np.zeros(3)])
    hands = np.tile([0.0, 0.0, 0.0, 15.0, 0.0, 15.0], 2)
    pulled, _ = _calc(rig, 2, reference=reference, hands=hands)
    alone, _ = _calc(rig, 2, reference=reference)
    np.testing.assert_allclose(pulled.helpful_force_W, [30.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(pulled.Ldot_star[3:] - alone.Ldot_star[3:], [30.0, 0, 0])
    terms = rig["kinematics"].calc(rig["x"], [], HANDS)
    J = np.concatenate([terms.J_W[0], terms.J_W[1]])
    np.testing.assert_allclose(pulled.tau_hand, J.T @ hands, atol=1e-12)


@pytest.mark.parametrize("response", [STIFF, COMPLIANT])
def test_stiff_and_compliant_compensate_the_whole_pull(rig, response):
    """The pull of the test above under stiff and compliant: no help passes, so the
    linear momentum target is the CoM law's alone (the pull is compensated in full, the
    QP having it in the dynamics); the hands' generalized force is the same."""
    p, _, _, _ = _drake_com(rig)
    reference = np.concatenate([p, [0.1, 0.0, 0.0], np.zeros(3)])
    hands = np.tile([0.0, 0.0, 0.0, 15.0, 0.0, 15.0], 2)
    alone, _ = _calc(rig, 2, reference=reference)
    pulled, _ = _calc(rig, 2, reference=reference, hands=hands, response=response)
    assert not pulled.helpful_force_W.any()
    helped, _ = _calc(rig, 2, reference=reference, hands=hands)
    np.testing.assert_allclose(pulled.tau_hand, helped.tau_hand, atol=0.0)
    if response == STIFF:
        np.testing.assert_allclose(pulled.Ldot_star, alone.Ldot_star, atol=1e-12)
        assert not pulled.next_compliance.any()


def _admittance_run(rig, force, ticks):
    """The compliant response's offset and rate over ticks under a constant total hand
    force (N, W), state 2, the reference fixed."""
    hands = np.concatenate([[0.0, 0.0, 0.0], force / 2.0, [0.0, 0.0, 0.0], force / 2.0])
    state, trace = np.zeros(6), []
    for _ in range(ticks):
        references, _ = _calc(rig, 2, hands=hands, response=COMPLIANT, compliance=state)
        state = references.next_compliance
        trace.append(state)
    return np.array(trace)


def test_the_compliant_reference_follows_the_admittance(rig):
    """A 10 N forward step (inside the bound): the offset follows M x'' + D x' + K x = F,
    critically damped, x(t) = F/K (1 - (1 + w t) e^(-w t)), w = sqrt(K/M), to the
    semi-implicit Euler's O(T) error; it settles at F/K without overshoot; the reference
    the CoM law tracks moves by the offset and its rate."""
    compliance = Scenario().compliance
    M, K = compliance.virtual_mass_kg, compliance.stiffness_N_per_m
    w = math.sqrt(K / M)
    F = np.array([10.0, 0.0, 0.0])
    trace = _admittance_run(rig, F, 1000)  # 4 s, 20 time constants
    t = T * np.arange(1, 1001)
    exact = F[0] / K * (1.0 - (1.0 + w * t) * np.exp(-w * t))
    # The step's error: a fraction w T (2.5 %) of the response's amplitude F/K.
    np.testing.assert_allclose(trace[:, 0], exact, atol=w * T * F[0] / K)
    assert trace[:, 0].max() <= F[0] / K * (1.0 + 1e-3)  # no overshoot (to the step's error)
    assert trace[-1, 0] == pytest.approx(F[0] / K, rel=1e-6)
    assert not trace[:, 1:3].any()  # no force sideways or up: no offset there


def test_the_compliant_offset_settles_at_its_bound(rig):
    """A pull far beyond the bound (100 N forward, 100 N down): the offset settles at
    compliance.max_offset_m on each axis, never beyond it, and at rest there."""
    bound = np.array(Scenario().compliance.max_offset_m)
    trace = _admittance_run(rig, np.array([100.0, 0.0, -100.0]), 1000)
    assert (np.abs(trace[:, :3]) <= bound + 1e-15).all()
    np.testing.assert_allclose(trace[-1, :3], [bound[0], 0.0, -bound[2]], atol=1e-7)
    np.testing.assert_allclose(trace[-1, 3:], np.zeros(3), atol=1e-6)


SUPPORT = StandingSupport(
    com_height_m=0.575,
    hands_m=np.array([[0.20, 0.12, 0.285], [0.20, -0.12, 0.285]]),
    soles_m=np.array([[0.0, 0.07, -0.575], [0.0, -0.07, -0.575]]),
    lean_m=(CONFIG.lean_max_forward_m, CONFIG.lean_max_back_m, CONFIG.lean_max_m),
    cop_x_m=tuple(CONFIG.foot_cop_x_m),
    cop_y_m=tuple(CONFIG.foot_cop_y_m),
)


@pytest.mark.parametrize("pull_N", [5.0, 10.0, 25.0, -8.0])
def test_the_compliant_offset_settles_only_where_the_standing_feet_hold_the_pull(rig, pull_N):
    """A horizontal pull_N per hand (forward; negative: back) judged on the standing
    robot (sensing.standing_pull_usage, the stand-up's own measure): moving the CoM by x
    toward the pull adds x to the lean the feet must give, so the offset may settle
    where the usage reaches the limit, x = (limit - usage) reach (reach: lean plus half
    the CoP box on that side), within the box, and at 0 where the pull alone uses more;
    away from the pull, the box."""
    limit = 0.6
    joints = rig["joints"]
    generator = TaskReferenceGenerator(
        CONFIG,
        rig["phases"],
        as_slice(joints.q_indices),
        T,
        rig["g"],
        None,
        standing_need=partial(standing_lean, support=SUPPORT),
        usage_limit=limit,
    )
    _, _, _, mass = _drake_com(rig)
    weight = mass * rig["g"]
    hands = np.tile([0.0, 0.0, 0.0, pull_N, 0.0, 0.0], 2)
    usage = standing_pull_usage(hands, weight, SUPPORT)
    half_x = (SUPPORT.cop_x_m[1] - SUPPORT.cop_x_m[0]) / 2
    reach = (CONFIG.lean_max_back_m if pull_N > 0 else CONFIG.lean_max_forward_m) + half_x
    box = np.array(Scenario().compliance.max_offset_m)
    low, high = generator.com_target.offset_bounds(rig["phases"][3], hands, weight)
    toward, away = (high[0], low[0]) if pull_N > 0 else (-low[0], -high[0])
    assert toward == pytest.approx(min(max(0.0, (limit - usage) * reach), box[0]), abs=1e-12)
    assert away == -box[0]
    if pull_N == 25.0:  # beyond the limit already: no yield forward
        assert usage > limit and toward == 0.0
    if pull_N == 10.0:  # inside the box: the bound is the feet's
        assert 0.0 < toward < box[0]


def test_on_the_feet_alone_the_compliant_offset_settles_no_higher_than_the_path(rig):
    """An upward pull: seated (states 1-2) the offset may settle up to the box; on the
    feet alone (states 3-4, the states that lean) at most at the path's height; down,
    the box in every state."""
    generator = rig["generator"]
    box = np.array(Scenario().compliance.max_offset_m)
    pull = np.tile([0.0, 0.0, 0.0, 0.0, 0.0, 10.0], 2)
    for state in (1, 2, 3, 4):
        low, high = generator.com_target.offset_bounds(rig["phases"][state], pull, 300.0)
        assert high[2] == (0.0 if TABLE.phase(state).lean else box[2])
        assert low[2] == -box[2]


def test_the_compliant_offset_returns_once_the_pull_stops(rig):
    """From a held offset and no pull, the admittance takes the reference back to the
    path: after 4 s (20 time constants) within 1 um, never past it (critically damped)."""
    state, trace = np.array([0.03, 0.0, 0.0, 0.0, 0.0, 0.0]), []
    for _ in range(1000):
        references, _ = _calc(rig, 2, response=COMPLIANT, compliance=state)
        state = references.next_compliance
        trace.append(state[0])
    assert abs(trace[-1]) < 1e-6
    assert min(trace) > -1e-6
    # The CoM law tracks x_d + x, xd_dot + x', xd_ddot + x'' (x'' the tick's change of x').
    held = np.array([0.03, 0.0, 0.0, 0.0, 0.0, 0.0])
    moved, _ = _calc(rig, 2, response=COMPLIANT, compliance=held)
    still, _ = _calc(rig, 2)
    x, v = moved.next_compliance[:3], moved.next_compliance[3:]
    kp = np.array(TABLE.forward.com_kp_per_s2)
    _, _, _, m = _drake_com(rig)
    expected = m * ((v - held[3:]) / T + 2.0 * CONFIG.com_damping_ratio * np.sqrt(kp) * v + kp * x)
    np.testing.assert_allclose(moved.Ldot_star[3:] - still.Ldot_star[3:], expected, atol=1e-9)


def test_the_stance_hands_the_height_to_the_legs(rig):
    """State 4 at 85 % of the rise (stance_from_progress 0.7): the stance factor is the
    smoothstep of (0.85 - 0.7) / 0.3 = 0.5, i.e. 0.5; the vertical row keeps 1 - 0.5 (1 -
    0.1); the height integral grows by T 0.5 (z_d - z) and adds m K_I of it to the
    vertical momentum target; no help passes."""
    p, _, _, m = _drake_com(rig)
    reference = np.concatenate([p + [0.0, 0.0, 0.05], np.zeros(6)])
    hands = np.tile([0.0, 0.0, 0.0, 5.0, 0.0, 0.0], 2)
    references, _ = _calc(rig, 4, reference=reference, hands=hands, progress=0.85)
    assert references.stance == pytest.approx(0.5, rel=1e-12)
    assert references.vertical_weight_scale == pytest.approx(1.0 - 0.5 * 0.9, rel=1e-12)
    assert references.next_height_integral == pytest.approx(T * 0.5 * 0.05, rel=1e-6)
    without, _ = _calc(rig, 4, reference=reference, hands=hands, progress=0.7)
    assert without.stance == 0.0 and without.next_height_integral == 0.0
    assert not references.helpful_force_W.any()
    ki = CONFIG.stance_height_ki_per_s3
    vertical = references.Ldot_star[5] - without.Ldot_star[5]
    assert vertical == pytest.approx(m * ki * references.next_height_integral, rel=1e-9)


def test_the_lean_moves_toward_the_static_lean_in_the_phases_that_lean(rig):
    """A 10 N backward pull per hand: in state 3 (lean) the lean takes one filter step
    toward static_lean of the hands' wrench about the CoM (T / tau of the way); in state
    2 (no lean) it stays zero."""
    hands = np.tile([0.0, 0.0, 0.0, -10.0, 0.0, 0.0], 2)
    plant, context = rig["plant"], rig["context"]
    p, _, _, m = _drake_com(rig)
    wrench = np.zeros(6)
    for k, hand in enumerate(HANDS):
        frame = plant.GetFrameByName(TASK_FRAMES[hand], rig["instance"])
        p_hand = frame.CalcPoseInWorld(context).translation()
        f = hands[6 * k + 3 : 6 * k + 6]
        wrench[:3] += np.cross(p_hand - p, f)
        wrench[3:] += f
    target = static_lean(wrench, p[2], m * rig["g"], CONFIG.lean_max_m)
    target[0] = min(max(target[0], -CONFIG.lean_max_back_m), CONFIG.lean_max_forward_m)
    leaning, _ = _calc(rig, 3, hands=hands)
    blend = T / CONFIG.lean_filter_time_constant_s
    np.testing.assert_allclose(leaning.lean_W, blend * target, atol=1e-12)
    assert leaning.lean_W[0] > 0.0  # pulled back: the CoM target leans forward
    upright, _ = _calc(rig, 2, hands=hands)
    assert not upright.lean_W.any()


@pytest.mark.parametrize("psi_dot", [0.5, 2.5])
def test_posture_and_lean_filters_run_on_psi(rig, psi_dot):
    """With psi advancing at psi_dot the posture reference and the lean take a filter step
    of T max(psi_dot, 1) / tau: psi's clock, never slower than time."""
    hands = np.tile([0.0, 0.0, 0.0, -10.0, 0.0, 0.0], 2)
    on_time, _ = _calc(rig, 3, hands=hands)
    on_psi, _ = _calc(rig, 3, hands=hands, psi_dot=psi_dot)
    rate = max(psi_dot, 1.0)
    np.testing.assert_allclose(on_psi.lean_W, rate * on_time.lean_W, rtol=1e-12)
    nu = len(rig["joints"].names)
    q = rig["x"][rig["joints"].q_indices]
    stage = slice(1 + 2 * nu, 1 + 3 * nu)  # the filter's stage that follows the target
    step = on_time.next_posture[stage] - q
    np.testing.assert_allclose(on_psi.next_posture[stage] - q, rate * step, rtol=1e-9, atol=1e-12)
    assert np.abs(step).max() > 1e-4 and np.abs(on_time.lean_W).max() > 1e-4


def test_the_posture_and_the_base_target_at_the_first_tick(rig):
    """The first tick latches the posture it starts from; the filter's first stage then
    moves T / tau toward the phase's targets (held joints toward where they are) and the
    reference, its second stage, starts at rest; the base target is upright at the
    current yaw, pitched forward by the phase's base pitch: the base's up axis tilts
    toward where the robot faces by that angle."""
    references, _ = _calc(rig, 2)
    joints, phases = rig["joints"], rig["phases"]
    q = rig["x"][joints.q_indices]
    state = phases[2]
    clamped = np.clip(q, phases.q_target_min, phases.q_target_max)
    target = np.where(state.posture_hold, clamped, state.posture_rad)
    blend = T / CONFIG.posture_filter_time_constant_s
    nu = len(q)
    np.testing.assert_allclose(references.q_reference, q, atol=0.0)
    np.testing.assert_allclose(references.next_posture[1 + nu : 1 + 2 * nu], q, atol=0.0)
    np.testing.assert_allclose(
        references.next_posture[1 + 2 * nu : 1 + 3 * nu], q + blend * (target - q), atol=1e-12
    )
    R_target = references.R_WB_target
    R_WB = rig["kinematics"].calc(rig["x"], []).R_WB
    facing = -R_WB[:, 0]  # root_link's x axis points backwards
    facing[2] = 0.0
    facing /= np.linalg.norm(facing)
    up = R_target[:, 2]
    assert up @ facing == pytest.approx(math.sin(TABLE.forward.base_pitch_rad), abs=1e-12)
    assert up[2] == pytest.approx(math.cos(TABLE.forward.base_pitch_rad), abs=1e-12)


@pytest.mark.parametrize("stages", [1, 2])
def test_the_posture_filter_steps_as_its_stages_in_series(rig, stages):
    """Over n ticks toward a state's posture from the latched one, a gap e closes as n
    first-order stages of blend a = T / tau in series do: one, e (1 - (1 - a)^n), its
    rate a jump at the switch; two, e (1 - (1 - a)^n - n a (1 - a)^(n - 1)), starting at
    rest (zero first step) and never faster than (1 - a)^(1/a - 1) e / tau ~ e / (e tau)."""
    config = dataclasses.replace(CONFIG, posture_filter_stages=stages)
    generator = TaskReferenceGenerator(
        config, rig["phases"], as_slice(rig["joints"].q_indices), T, rig["g"]
    )
    terms = rig["kinematics"].calc(rig["x"], [])
    p, _, _, _ = _drake_com(rig)
    phases, nu = rig["phases"], len(rig["joints"].names)
    q = rig["x"][rig["joints"].q_indices]
    gap = np.where(phases[2].posture_hold, 0.0, phases[2].posture_rad - q)
    a = T / config.posture_filter_time_constant_s
    posture, references = np.zeros(2 + 3 * nu), []
    for _ in range(120):
        tick = generator.calc(
            terms,
            TickInputs(2, np.concatenate([p, np.zeros(6)])),
            CarriedState(momentum_integral=np.zeros(3), posture=posture),
        )
        references.append(tick.q_reference)
        posture = tick.next_posture
    n = np.arange(120)[:, None]
    share = 1.0 - (1.0 - a) ** n
    if stages == 2:
        share -= n * a * (1.0 - a) ** np.maximum(n - 1, 0)
    np.testing.assert_allclose(np.array(references) - q, share * gap, atol=1e-12)
    rates = np.abs(np.diff(references, axis=0)).max(axis=0) / T
    first = np.abs(references[1] - references[0]) / T
    moving = np.abs(gap) > 0.1
    assert moving.any()
    if stages == 1:
        np.testing.assert_allclose(first[moving], np.abs(gap[moving]) * a / T, rtol=1e-9)
    else:
        assert first.max() == 0.0
        bound = np.abs(gap) / (math.e * config.posture_filter_time_constant_s)
        assert (rates[moving] <= 1.05 * bound[moving]).all()
        assert (rates[moving] >= 0.95 * bound[moving]).all()  # it reaches its peak


def test_the_generator_integrates_the_angular_momentum_over_its_ticks(rig):
    """Four ticks, each from the state the last one left (as the whole-body controller's
    tick keeps it): int L dt = 4 T L (Drake's angular momentum), and the lean stays zero
    without a pull."""
    terms = rig["kinematics"].calc(rig["x"], [])
    p, _, L, _ = _drake_com(rig)
    nu = len(rig["generator"].phases.q_target_min)
    now = TickInputs(2, np.concatenate([p, np.zeros(6)]), path_progress=0.0)
    carried = CarriedState(np.zeros(3), np.zeros(2 + 3 * nu), np.zeros(3), 0.0, np.zeros(6))
    for _ in range(4):
        carried = CarriedState.after(rig["generator"].calc(terms, now, carried))
    np.testing.assert_allclose(carried.momentum_integral, 4 * T * L, atol=1e-12)
    np.testing.assert_array_equal(carried.lean_W, np.zeros(3))


def test_the_psi_clock_blend_is_a_first_order_step_never_slower_than_time():
    """One step of dt / tau of the gap at psi = t, psi_dot times that ahead of time, the
    time step below psi_dot 1, and never past the target (1)."""
    from drake_standup.control.smooth import psi_clock_blend

    assert psi_clock_blend(0.01, 0.2, 1.0) == pytest.approx(0.05)
    assert psi_clock_blend(0.01, 0.2, 2.5) == pytest.approx(0.125)
    assert psi_clock_blend(0.01, 0.2, 0.3) == pytest.approx(0.05)
    assert psi_clock_blend(0.3, 0.2, 1.0) == 1.0


def test_standing_the_contacts_are_asked_the_trunks_posture_moment(rig):
    """In the stance (state 4 at the segment's end: stance 1) Ldot_ang* gains
    A_G,ang[trunk] qddot*_trunk, qddot* = -K_P (q - q_ref) - K_D qdot (the first tick: q_ref
    = q); each column of A_G,ang is Drake's angular momentum about the CoM with a unit
    rate of that joint alone. Before the stance (progress 0.5) and without the trunk it
    adds nothing."""
    plant, context, instance, joints = rig["plant"], rig["context"], rig["instance"], rig["joints"]
    names = list(joints.names)
    trunk = np.array([names.index("torso_roll"), names.index("torso_yaw")])
    v_joints = np.asarray(joints.v_indices)
    held = TaskReferenceGenerator(
        CONFIG,
        rig["phases"],
        as_slice(joints.q_indices),
        T,
        rig["g"],
        v_joints=v_joints,
        trunk=trunk,
    )
    plain = rig["generator"]
    try:
        rig["generator"] = held
        standing, _ = _calc(rig, 4, progress=1.0)
        rising, _ = _calc(rig, 4, progress=0.5)
    finally:
        rig["generator"] = plain
    alone_standing, _ = _calc(rig, 4, progress=1.0)
    alone_rising, _ = _calc(rig, 4, progress=0.5)
    np.testing.assert_array_equal(rising.Ldot_star, alone_rising.Ldot_star)
    p, _, _, _ = _drake_com(rig)
    v = rig["x"][plant.num_positions(instance) :]
    scratch = plant.CreateDefaultContext()
    plant.SetPositions(scratch, instance, plant.GetPositions(context, instance))
    columns = []
    for j in v_joints[trunk]:
        unit = np.zeros(plant.num_velocities(instance))
        unit[j] = 1.0
        plant.SetVelocities(scratch, instance, unit)
        columns.append(
            plant.CalcSpatialMomentumInWorldAboutPoint(scratch, [instance], p).rotational()
        )
    kd = 2.0 * CONFIG.posture_damping_ratio * math.sqrt(CONFIG.posture_kp_per_s2)
    expected = np.array(columns).T @ (-kd * v[v_joints[trunk]])
    assert np.abs(expected).max() > 1e-3  # the rig's trunk moves
    np.testing.assert_allclose(
        standing.Ldot_star[:3] - alone_standing.Ldot_star[:3], expected, rtol=1e-9, atol=1e-12
    )
    np.testing.assert_array_equal(standing.Ldot_star[3:], alone_standing.Ldot_star[3:])


def test_lowering_the_contacts_are_asked_the_pelvis_and_trunk_pitch_moment(rig):
    """In a sit-down's lowering and landing (the phases led by the legs' posture) and its
    settle (led by the whole posture) Ldot_ang* gains A_G,ang [wdot*_WB; qddot*_trunk]: the
    pelvis toward its pitch target (wdot* = -K_P theta k - K_D w, with Drake's pelvis pose)
    and the torso's and hips' pitch joints toward the posture reference; each column of
    A_G,ang is Drake's angular momentum about the CoM with a unit rate of that velocity
    alone. Standing and with lowering_attitude off it adds nothing. Only the settle
    releases the CoM rows (com_weight_scale)."""
    plant, context, instance, joints = rig["plant"], rig["context"], rig["instance"], rig["joints"]
    names = list(joints.names)
    v_joints = np.asarray(joints.v_indices)
    pitch_joints = [k for k, n in enumerate(names) if n.startswith("torso_") or "hip_pitch" in n]

    def generator(config):
        return TaskReferenceGenerator(
            config, rig["phases"], as_slice(joints.q_indices), T, rig["g"], v_joints=v_joints
        )

    plain = rig["generator"]
    results = {}
    try:
        for on in (True, False):
            rig["generator"] = generator(dataclasses.replace(CONFIG, lowering_attitude=on))
            for state in (4, 5, 6, 7):
                results[on, state] = _calc(rig, state, progress=0.5)[0]
    finally:
        rig["generator"] = plain
    np.testing.assert_array_equal(results[True, 4].Ldot_star, results[False, 4].Ldot_star)
    for on in (True, False):
        scales = [results[on, state].com_weight_scale for state in (4, 5, 6, 7)]
        assert scales == [1.0, 1.0, 1.0, CONFIG.posture_led_com_weight_scale]
    p, _, _, _ = _drake_com(rig)
    v = rig["x"][plant.num_positions(instance) :]
    q = plant.GetPositions(context, instance)
    scratch = plant.CreateDefaultContext()
    plant.SetPositions(scratch, instance, q)
    R_WB = plant.EvalBodyPoseInWorld(scratch, plant.GetBodyByName("root_link", instance))
    R_WB = R_WB.rotation().matrix()

    def column(j):
        unit = np.zeros(plant.num_velocities(instance))
        unit[j] = 1.0
        plant.SetVelocities(scratch, instance, unit)
        return plant.CalcSpatialMomentumInWorldAboutPoint(scratch, [instance], p).rotational()

    base = np.array([column(j) for j in range(3)]).T
    trunk = np.array([column(v_joints[k]) for k in pitch_joints]).T
    kp, zeta = CONFIG.posture_kp_per_s2, CONFIG.posture_damping_ratio
    kp_b, zeta_b = CONFIG.base_orientation_kp_per_s2, CONFIG.base_orientation_damping_ratio
    for state in (5, 6, 7):
        on = results[True, state]
        q_ref = on.q_reference[pitch_joints]
        q_now = q[joints.q_indices][pitch_joints]
        qddot = -kp * (q_now - q_ref) - 2.0 * zeta * math.sqrt(kp) * v[v_joints[pitch_joints]]
        # theta k: the rotation vector of R_WB R_target^T, from its angle-axis.
        error = RotationMatrix(R_WB @ on.R_WB_target.T).ToAngleAxis()
        wdot = -kp_b * error.angle() * error.axis() - 2.0 * zeta_b * math.sqrt(kp_b) * v[:3]
        expected = base @ wdot + trunk @ qddot
        assert np.abs(expected).max() > 1e-2  # the rig's pelvis and trunk move
        np.testing.assert_allclose(
            on.Ldot_star[:3] - results[False, state].Ldot_star[:3], expected, rtol=1e-9, atol=1e-9
        )
        np.testing.assert_array_equal(on.Ldot_star[3:], results[False, state].Ldot_star[3:])


def test_a_posture_led_phase_releases_the_com_rows_a_decade_at_a_time(rig):
    """The settle (Phase.posture_leads) weighs the momentum task's CoM rows by
    posture_led_com_weight_scale ** smoothstep(progress / posture_led_fade_progress):
    1 at the path's start, the scale from the fade's end on (and where the share of the
    path is unknown, NaN); every other phase 1."""
    generator, phases = rig["generator"], rig["generator"].phases
    scale, fade = CONFIG.posture_led_com_weight_scale, CONFIG.posture_led_fade_progress
    settle = phases[7]
    assert settle.posture_leads and not any(phases[k].posture_leads for k in range(1, 7))
    assert generator._com_weight_scale(settle, 0.0) == 1.0
    half = generator._com_weight_scale(settle, fade / 2)
    assert half == pytest.approx(scale**0.5, rel=1e-12)  # smoothstep(1/2) = 1/2
    for progress in (fade, 0.6, 1.0, math.nan):
        assert generator._com_weight_scale(settle, progress) == scale
    assert generator._com_weight_scale(phases[5], 0.1) == 1.0


def test_where_the_body_leans_the_standing_trunks_moment_is_not_asked_twice(rig):
    """The lean's joints (the torso's three, the hips' pitch) hold the torso's roll and yaw
    too: in the lowering and the landing (stance 1) the standing trunk's term adds nothing
    to it, while standing (state 4, stance 1) it is the only trunk term."""
    joints = rig["joints"]
    names = list(joints.names)
    twist = np.array([names.index("torso_roll"), names.index("torso_yaw")])
    v_joints = np.asarray(joints.v_indices)

    def generator(trunk):
        return TaskReferenceGenerator(
            CONFIG, rig["phases"], as_slice(joints.q_indices), T, rig["g"],
            v_joints=v_joints, trunk=trunk,
        )  # fmt: skip

    plain = rig["generator"]
    results = {}
    try:
        for held in (True, False):
            rig["generator"] = generator(twist if held else None)
            for state in (4, 5, 6):
                results[held, state] = _calc(rig, state, progress=1.0)[0]
    finally:
        rig["generator"] = plain
    for state in (5, 6):
        np.testing.assert_array_equal(
            results[True, state].Ldot_star, results[False, state].Ldot_star
        )
    assert np.abs(results[True, 4].Ldot_star[:3] - results[False, 4].Ldot_star[:3]).max() > 1e-6
