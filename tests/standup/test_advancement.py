"""Trajectory advancement: the update law, psi as continuous state, Omega f."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.analysis import Simulator

from drake_standup.config import RESPONSES, AdvancementConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.robot.icub import ContactModel, add_icub
from drake_standup.standup.advancement import (
    AdvancementLaw,
    TrajectoryAdvancement,
    for_robot,
    lead,
    psi_dot_law,
)
from drake_standup.world.sensing import RobotSensing

# The paper's on/off law (alpha_full <= alpha_min): the laws' values below are the
# paper's and the authors' formulas; the graded gates have tests of their own.
CFG = AdvancementConfig(alpha_full_mps2=0.0)
GRADED = for_robot(AdvancementConfig(), 33.0)  # alpha_full from 10 N per hand on 33 kg
TANGENT = np.array([0.12, 0.0, 0.02])  # a state-2-like path tangent, m per unit psi


def _cfg(**kw) -> AdvancementConfig:
    return dataclasses.replace(CFG, **kw)


@pytest.mark.parametrize("law", ["tangent", "interaction"])
def test_no_pull_gives_psi_dot_one_whatever_the_motion(law):
    rng = np.random.default_rng(0)
    for _ in range(200):
        v = rng.normal(scale=0.5, size=3)
        t = rng.normal(scale=0.2, size=3)
        assert psi_dot_law(_cfg(law=law), v, np.zeros(3), t)[0] == 1.0


@pytest.mark.parametrize("law", ["tangent", "interaction"])
def test_disabled_gives_psi_dot_one_even_when_helped(law):
    omega_f = TANGENT / np.linalg.norm(TANGENT)  # 1 m/s^2 along the path
    v = 2.0 * TANGENT
    assert psi_dot_law(_cfg(law=law, enabled=False), v, omega_f, TANGENT)[0] == 1.0
    assert psi_dot_law(_cfg(law=law), v, omega_f, TANGENT)[0] > 1.0


@pytest.mark.parametrize("law", ["tangent", "interaction"])
def test_psi_dot_stays_within_bounds_under_any_input(law):
    """Random velocities, tangents and wrenches (helpful, hindering, lateral,
    huge): psi_dot is always in [1, psi_dot_upper]."""
    rng = np.random.default_rng(1)
    cfg = _cfg(law=law, psi_dot_upper=2.5)
    seen_upper = seen_one = False
    for _ in range(5000):
        scale = 10.0 ** rng.uniform(-3, 2)
        v, t, f = (rng.normal(scale=scale, size=3) for _ in range(3))
        psi_dot, _ = psi_dot_law(cfg, v, f, t)
        assert 1.0 <= psi_dot <= 2.5
        seen_upper |= psi_dot == 2.5
        seen_one |= psi_dot == 1.0
    assert seen_upper and seen_one  # both bounds are actually reached


@pytest.mark.parametrize("law", ["tangent", "interaction"])
def test_hindering_and_perpendicular_pulls_do_not_advance(law):
    direction = TANGENT / np.linalg.norm(TANGENT)
    lateral = np.array([0.0, 1.0, 0.0])
    v_fast = 2.0 * TANGENT  # CoM moving along the path faster than psi = t
    assert psi_dot_law(_cfg(law=law), v_fast, -0.9 * direction, TANGENT)[0] == 1.0
    assert psi_dot_law(_cfg(law=law), v_fast, 0.9 * lateral, TANGENT)[0] == 1.0


def test_tangent_law_value_matches_the_proposition():
    """Helpful pull, CoM faster than the reference: the paper's ratio exactly."""
    v = 1.8 * TANGENT + np.array([0.0, 0.01, 0.0])
    omega_f = 0.9 * TANGENT / np.linalg.norm(TANGENT)
    expected = (v @ TANGENT) / (TANGENT @ TANGENT + CFG.eps)
    psi_dot, alpha = psi_dot_law(CFG, v, omega_f, TANGENT)
    assert psi_dot == pytest.approx(expected, rel=1e-12)
    assert 1.7 < psi_dot < 1.8
    assert alpha == pytest.approx(0.9)


def test_interaction_law_value_matches_the_authors_ratio():
    v = 1.5 * TANGENT
    omega_f = np.array([0.6, 0.0, 0.5])
    a = TANGENT @ omega_f
    expected = (v @ omega_f) * a / (a * a + CFG.eps)
    assert psi_dot_law(_cfg(law="interaction"), v, omega_f, TANGENT)[0] == pytest.approx(
        expected, rel=1e-12
    )


def _simulate_advancement(cfg, v, omega_f, tangent, t_end, advances=True, response=0):
    system = TrajectoryAdvancement(cfg)
    context = system.CreateDefaultContext()
    system.GetInputPort("advances").FixValue(context, [float(advances)])
    system.GetInputPort("response").FixValue(context, [float(response)])
    system.GetInputPort("path_progress").FixValue(context, [0.0])  # no taper
    # CoM on its reference: the lead gate is open.
    system.GetInputPort("com_W").FixValue(context, np.zeros(3))
    system.GetInputPort("x_d_W").FixValue(context, np.zeros(3))
    system.GetInputPort("com_velocity_W").FixValue(context, v)
    system.GetInputPort("omega_f_W").FixValue(context, omega_f)
    system.GetInputPort("path_tangent_W").FixValue(context, tangent)
    simulator = Simulator(system, context)
    simulator.get_mutable_integrator().set_target_accuracy(1e-10)
    simulator.AdvanceTo(t_end)
    return system, context


def test_psi_equals_time_without_help():
    system, context = _simulate_advancement(CFG, 2.0 * TANGENT, np.zeros(3), TANGENT, 7.3)
    assert system.GetOutputPort("psi").Eval(context)[0] == pytest.approx(7.3, abs=1e-9)
    assert system.GetOutputPort("psi_dot").Eval(context)[0] == 1.0
    assert system.GetOutputPort("psi_ddot").Eval(context)[0] == 0.0


def test_psi_integrates_the_rate_that_follows_the_law():
    """Constant helpful inputs, law value r: psi_dot tends to r from 1 with time constant
    tau, psi_dot(t) = r - (r - 1) e^(-t/tau), so psi(t) = r t - (r - 1) tau (1 - e^(-t/tau))
    (the analytic integral), and psi_ddot = (r - psi_dot) / tau."""
    v = 1.6 * TANGENT
    omega_f = TANGENT / np.linalg.norm(TANGENT)
    r = (v @ TANGENT) / (TANGENT @ TANGENT + CFG.eps)
    tau = CFG.psi_ddot_filter_s
    for t in (0.03, 0.1, 2.0):
        system, context = _simulate_advancement(CFG, v, omega_f, TANGENT, t)
        decay = math.exp(-t / tau)
        psi = r * t - (r - 1.0) * tau * (1.0 - decay)
        psi_dot = r - (r - 1.0) * decay
        assert system.GetOutputPort("psi").Eval(context)[0] == pytest.approx(psi, rel=1e-6)
        assert system.GetOutputPort("psi_dot").Eval(context)[0] == pytest.approx(psi_dot, rel=1e-6)
        assert system.GetOutputPort("psi_ddot").Eval(context)[0] == pytest.approx(
            (r - psi_dot) / tau, rel=1e-5, abs=1e-9
        )
        assert system.GetOutputPort("psi_dot_law").Eval(context)[0] == pytest.approx(r)


@pytest.mark.parametrize("state", [1, 2, 3, 4])
def test_psi_advances_only_where_the_phase_table_lets_it(state):
    """The same helpful inputs, the phase of each state's advances flag (phases.py):
    psi = t in state 1 (seated, or returning to the seat after a hindering pull), the
    law's rate r in states 2-4."""
    v = 1.6 * TANGENT
    omega_f = TANGENT / np.linalg.norm(TANGENT)
    r = (v @ TANGENT) / (TANGENT @ TANGENT + CFG.eps)
    advances = PhaseTable().phase(state).advances
    assert advances == (state > 1)
    system, context = _simulate_advancement(CFG, v, omega_f, TANGENT, 1.0, advances)
    expected = r if advances else 1.0
    assert system.GetOutputPort("psi_dot_law").Eval(context)[0] == pytest.approx(expected)
    if not advances:
        assert system.GetOutputPort("psi").Eval(context)[0] == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("response", RESPONSES)
def test_only_the_advancement_response_advances(response):
    """The same helpful inputs under each response (config.RESPONSES): the law's rate r
    under advancement; psi = t exactly (psi_dot 1, psi_ddot 0) under stiff and compliant,
    with alpha still the help along the path."""
    v = 1.6 * TANGENT
    omega_f = TANGENT / np.linalg.norm(TANGENT)
    r = (v @ TANGENT) / (TANGENT @ TANGENT + CFG.eps)
    code = RESPONSES.index(response)
    system, context = _simulate_advancement(CFG, v, omega_f, TANGENT, 1.3, response=code)
    alpha = system.GetOutputPort("alpha").Eval(context)[0]
    assert alpha == pytest.approx(omega_f @ TANGENT / np.linalg.norm(TANGENT))
    if response == "advancement":
        assert system.GetOutputPort("psi_dot_law").Eval(context)[0] == pytest.approx(r)
        return
    assert system.GetOutputPort("psi").Eval(context)[0] == pytest.approx(1.3, abs=1e-12)
    assert system.GetOutputPort("psi_dot").Eval(context)[0] == 1.0
    assert system.GetOutputPort("psi_ddot").Eval(context)[0] == 0.0


def test_graded_gate_weights_the_laws_excess_by_the_help():
    """Between alpha_min and alpha_full psi_dot = 1 + w (clip(ratio) - 1) with w linear
    in alpha: continuous at alpha_min (psi_dot -> 1), the paper's value from alpha_full."""
    v = 1.8 * TANGENT
    unit = TANGENT / np.linalg.norm(TANGENT)
    ratio = (v @ TANGENT) / (TANGENT @ TANGENT + GRADED.eps)
    lo, hi = GRADED.alpha_min_mps2, GRADED.alpha_full_mps2
    for alpha in np.linspace(lo + 1e-9, hi, 7):
        w = (alpha - lo) / (hi - lo)
        assert psi_dot_law(GRADED, v, alpha * unit, TANGENT)[0] == pytest.approx(
            1.0 + w * (ratio - 1.0), rel=1e-12
        )
    assert psi_dot_law(GRADED, v, (lo + 1e-9) * unit, TANGENT)[0] == pytest.approx(1.0)
    assert psi_dot_law(GRADED, v, 3.0 * hi * unit, TANGENT)[0] == pytest.approx(ratio)


def test_graded_lead_gate_is_continuous_in_the_lag():
    """The gate's weight is 1 + lead / lag_tolerance between a lag of lag_tolerance (0)
    and no lag (1): no jump of psi_dot when the lag crosses the tolerance."""
    v = 1.8 * TANGENT
    omega_f = 2.0 * TANGENT / np.linalg.norm(TANGENT)  # above alpha_full: w = 1
    ratio = (v @ TANGENT) / (TANGENT @ TANGENT + GRADED.eps)
    tol = GRADED.lag_tolerance_m
    for lag in np.linspace(0.0, tol, 6):
        expected = 1.0 + (1.0 - lag / tol) * (ratio - 1.0)
        assert psi_dot_law(GRADED, v, omega_f, TANGENT, -lag)[0] == pytest.approx(expected)
    assert psi_dot_law(GRADED, v, omega_f, TANGENT, -2.0 * tol)[0] == 1.0


def test_lead_gate_waits_while_the_com_lags():
    """Helped and fast, but 2 cm behind the reference along the path (beyond the 1.5 cm
    tolerance): no advancement with the gate (the default), the paper's ratio without it."""
    v = 1.8 * TANGENT
    omega_f = TANGENT / np.linalg.norm(TANGENT)
    x_d = np.array([0.2, 0.0, 0.4])
    behind = x_d - 0.02 * TANGENT / np.linalg.norm(TANGENT)
    lag = lead(behind, x_d, TANGENT)
    assert lag == pytest.approx(-0.02)
    assert psi_dot_law(CFG, v, omega_f, TANGENT, lag)[0] == 1.0
    assert psi_dot_law(_cfg(lead_gate=False), v, omega_f, TANGENT, lag)[0] > 1.7
    # Within the tolerance (the tracker's steady lag) it advances, fully on a lead.
    assert psi_dot_law(CFG, v, omega_f, TANGENT, -0.014)[0] > 1.0
    assert psi_dot_law(CFG, v, omega_f, TANGENT, 0.001)[0] > 1.7


def test_the_lead_is_measured_from_the_leaned_target():
    """A CoM standing exactly where the controller leans its target (back 5 cm against a
    pull, 1.3 cm lower with the arms braced) leads by 0 along a rising path, whatever
    the lean: the leaned target keeps its distance from the floor point below x_d
    (sqrt(h^2 - 0.05^2) - 0.013, worked out here). Against the bare x_d the same CoM
    would read as 1.6 cm behind, past the 1.5 cm tolerance: psi held at t."""
    x_d = np.array([0.226, 0.0, 0.45])
    rising = np.array([0.0, 0.0, 0.3])
    lean = np.array([-0.05, 0.0, -0.013])
    com = np.array([0.176, 0.0, math.sqrt(0.45**2 - 0.05**2) - 0.013])
    assert lead(com, x_d, rising, lean) == pytest.approx(0.0, abs=1e-12)
    bare = lead(com, x_d, rising)
    assert bare == pytest.approx(com[2] - 0.45)
    assert bare < -GRADED.lag_tolerance_m
    # 1 cm above the leaned target along the path: 1 cm of lead.
    assert lead(com + [0.0, 0.0, 0.01], x_d, rising, lean) == pytest.approx(0.01)
    # No lean: the bare x_d.
    assert lead(com, x_d, rising, np.zeros(3)) == pytest.approx(bare)


@pytest.mark.parametrize("leaned", [False, True])
def test_the_law_reads_the_lean_only_where_asked(leaned):
    """AdvancementLaw with the CoM where the controller leans its target on a rising path
    (lean_W connected): with lead_from_leaned_target the gate sees no lag and the law
    advances; without it the lean reads as a lag past the tolerance and psi_dot is 1."""
    cfg = dataclasses.replace(GRADED, lead_from_leaned_target=leaned)
    law = AdvancementLaw(cfg)
    context = law.CreateDefaultContext()
    rising = np.array([0.0, 0.0, 0.3])
    x_d, lean = np.array([0.226, 0.0, 0.45]), np.array([-0.05, 0.0, -0.013])
    com = np.array([0.176, 0.0, math.sqrt(0.45**2 - 0.05**2) - 0.013])
    for name, value in (
        ("com_W", com),
        ("com_velocity_W", 2.0 * rising),
        ("omega_f_W", 2.0 * rising / np.linalg.norm(rising)),  # above alpha_full
        ("x_d_W", x_d),
        ("lean_W", lean),
        ("path_tangent_W", rising),
        ("path_progress", [0.0]),
        ("advances", [1.0]),
        ("response", [0.0]),
    ):
        law.GetInputPort(name).FixValue(context, value)
    psi_dot = law.GetOutputPort("psi_dot_law").Eval(context)[0]
    if leaned:
        t2 = rising @ rising  # the tangent law's ratio, within the bounds
        assert psi_dot == pytest.approx(2.0 * t2 / (t2 + cfg.eps), rel=1e-12)
    else:
        assert psi_dot == 1.0


def _sensing_rig():
    """(plant, RobotSensing, its context, a plant context, the hand frames): the iCub
    without pads, finalized, its sensing with no heels."""
    plant = MultibodyPlant(0.0)
    robot = add_icub(plant, visuals=False, contact=ContactModel())
    plant.Finalize()
    sensing = RobotSensing(plant, robot, {})
    hands = [robot.frame(plant, name) for name in ("l_hand", "r_hand")]
    return plant, sensing, sensing.CreateDefaultContext(), plant.CreateDefaultContext(), hands


def test_omega_f_matches_the_papers_formula():
    """RobotSensing returns sum F / m (linear momentum theorem); the paper's
    Omega f = J_com M^-1 sum J_h^T F_h, computed here with Drake's mass matrix,
    CoM Jacobian and hand Jacobians, must agree at any configuration, wherever
    the force acts (hand torques do not move the CoM)."""
    plant, sensing, context, plant_context, hands = _sensing_rig()
    world = plant.world_frame()
    rng = np.random.default_rng(3)
    nq = plant.num_positions()
    for _ in range(5):
        q = np.concatenate([rng.normal(size=4), rng.normal(size=3), rng.uniform(-1, 1, nq - 7)])
        q[:4] /= np.linalg.norm(q[:4])
        x = np.concatenate([q, rng.normal(size=plant.num_velocities())])
        wrenches = rng.normal(scale=10.0, size=12)
        sensing.GetInputPort("robot_state").FixValue(context, x)
        sensing.GetInputPort("hand_wrenches_W").FixValue(context, wrenches)
        omega_f = sensing.GetOutputPort("omega_f_W").Eval(context)

        plant.SetPositionsAndVelocities(plant_context, x)
        tau = sum(
            plant.CalcJacobianSpatialVelocity(
                plant_context, JacobianWrtVariable.kV, frame, np.zeros(3), world, world
            ).T
            @ wrenches[6 * k : 6 * k + 6]
            for k, frame in enumerate(hands)
        )
        J_com = plant.CalcJacobianCenterOfMassTranslationalVelocity(
            plant_context, JacobianWrtVariable.kV, world, world
        )
        expected = J_com @ np.linalg.solve(plant.CalcMassMatrix(plant_context), tau)
        np.testing.assert_allclose(omega_f, expected, rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(
            sensing.GetOutputPort("com_W").Eval(context),
            plant.CalcCenterOfMassPositionInWorld(plant_context),
            atol=1e-12,
        )
        np.testing.assert_allclose(
            sensing.GetOutputPort("com_velocity_W").Eval(context),
            plant.CalcCenterOfMassTranslationalVelocityInWorld(plant_context),
            atol=1e-12,
        )


def test_hand_velocities_are_the_hand_origins_displacement_rate():
    """RobotSensing's hand_velocities_W against forward kinematics alone: the hand
    frames' origins at q and at q + eps qdot (qdot = N(q) v, the quaternion
    renormalised), over eps, at random states."""
    plant, sensing, context, plant_context, hands = _sensing_rig()
    rng = np.random.default_rng(7)
    nq, eps = plant.num_positions(), 1e-7

    def origins(q):
        plant.SetPositions(plant_context, q)
        return np.concatenate([h.CalcPoseInWorld(plant_context).translation() for h in hands])

    for _ in range(5):
        q = np.concatenate([rng.normal(size=4), rng.normal(size=3), rng.uniform(-1, 1, nq - 7)])
        q[:4] /= np.linalg.norm(q[:4])
        v = rng.normal(size=plant.num_velocities())
        sensing.GetInputPort("robot_state").FixValue(context, np.concatenate([q, v]))
        measured = sensing.GetOutputPort("hand_velocities_W").Eval(context)
        plant.SetPositions(plant_context, q)
        q_next = q + eps * plant.MapVelocityToQDot(plant_context, v)
        q_next[:4] /= np.linalg.norm(q_next[:4])
        expected = (origins(q_next) - origins(q)) / eps
        np.testing.assert_allclose(measured, expected, rtol=1e-4, atol=1e-5)


def test_full_help_is_a_trained_helpers_pull_on_the_robots_mass():
    """alpha_full (None by default) is what full_help_pull_N on each hand, along the path,
    does to the CoM: the law acts in full from exactly that pull on (RobotSensing's Omega f,
    at any posture), graded below it; an explicit alpha_full is kept."""
    assert for_robot(AdvancementConfig(alpha_full_mps2=0.9), 33.0).alpha_full_mps2 == 0.9
    with pytest.raises(ValueError, match="alpha_full_mps2"):
        TrajectoryAdvancement(AdvancementConfig())
    plant, sensing, context, _, _ = _sensing_rig()
    cfg = for_robot(AdvancementConfig(), plant.CalcTotalMass(plant.CreateDefaultContext()))
    assert cfg.alpha_full_mps2 == pytest.approx(2.0 * 10.0 / 33.06, rel=1e-3)
    unit = TANGENT / np.linalg.norm(TANGENT)
    v = 1.8 * TANGENT
    ratio = (v @ TANGENT) / (TANGENT @ TANGENT + cfg.eps)
    x = plant.GetPositionsAndVelocities(plant.CreateDefaultContext())
    sensing.GetInputPort("robot_state").FixValue(context, x)

    def law(per_hand_N):
        f = per_hand_N * unit
        wrenches = np.concatenate([np.zeros(3), f, np.zeros(3), f])
        sensing.GetInputPort("hand_wrenches_W").FixValue(context, wrenches)
        return psi_dot_law(cfg, v, sensing.GetOutputPort("omega_f_W").Eval(context), TANGENT)

    psi_dot, alpha = law(10.0 * (1.0 + 1e-9))
    assert alpha == pytest.approx(cfg.alpha_full_mps2, rel=1e-6)
    assert psi_dot == pytest.approx(ratio, rel=1e-9)
    w = (law(5.0)[1] - cfg.alpha_min_mps2) / (cfg.alpha_full_mps2 - cfg.alpha_min_mps2)
    assert law(5.0)[0] == pytest.approx(1.0 + w * (ratio - 1.0), rel=1e-9)
    assert 0.3 < w < 0.5
