"""The human: scripted pulls reach the plant exactly; physics agrees; the
reactive helper pulls toward its target within its force cap."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_standup.config import HumanConfig, Pull, ReactiveHumanConfig, Scenario
from drake_standup.diagram import build_diagram
from drake_standup.human import HumanWrenchSource, reactive_force, trapezoid
from drake_standup.robot import ContactModel, add_icub

PULLS = [
    Pull(hand="left", start_s=1.0, duration_s=2.0, ramp_s=0.5, force_N=[20.0, 0.0, 10.0]),
    Pull(hand="right", start_s=1.5, duration_s=1.0, ramp_s=0.25, force_N=[5.0, -3.0, 8.0]),
]


def _expected(t: float) -> np.ndarray:
    """(2, 3) scripted forces written out by hand from PULLS."""

    def ramp(t, start, dur, r):
        if t <= start or t >= start + dur:
            return 0.0
        return min(1.0, (t - start) / r, (start + dur - t) / r)

    return np.array(
        [
            ramp(t, 1.0, 2.0, 0.5) * np.array([20.0, 0.0, 10.0]),
            ramp(t, 1.5, 1.0, 0.25) * np.array([5.0, -3.0, 8.0]),
        ]
    )


def test_trapezoid_values():
    assert trapezoid(0.99, 1.0, 2.0, 0.5) == 0.0
    assert trapezoid(1.25, 1.0, 2.0, 0.5) == pytest.approx(0.5)
    assert trapezoid(2.0, 1.0, 2.0, 0.5) == 1.0
    assert trapezoid(2.9, 1.0, 2.0, 0.5) == pytest.approx(0.2)
    assert trapezoid(3.0, 1.0, 2.0, 0.5) == 0.0
    assert trapezoid(1.5, 1.0, 2.0, 0.0) == 1.0


def test_plant_receives_exactly_the_scripted_force():
    """Read the applied_spatial_force the plant sees, at times on the ramps."""
    scenario = Scenario()
    scenario.human = HumanConfig(pulls=PULLS)
    built = build_diagram(scenario)
    plant = built.scene.plant
    robot = built.scene.robot
    root = built.diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(root)
    hand_bodies = [robot.frame(plant, h).body().index() for h in ("l_hand", "r_hand")]
    for t in (0.5, 1.1, 1.3, 1.6, 1.7, 2.2, 2.6, 2.9, 3.2):
        root.SetTime(t)
        applied = plant.get_applied_spatial_force_input_port().Eval(plant_context)
        got = np.zeros((2, 3))
        for f in applied:
            assert not f.F_Bq_W.rotational().any()
            got[hand_bodies.index(f.body_index)] += f.F_Bq_W.translational()
        np.testing.assert_allclose(got, _expected(t), atol=1e-12)
        measured = built.diagram.GetSubsystemByName("human").GetOutputPort("hand_wrenches_W")
        w = measured.Eval(built.diagram.GetSubsystemByName("human").GetMyContextFromRoot(root))
        np.testing.assert_allclose(w.reshape(2, 6)[:, 3:], _expected(t), atol=1e-12)


def test_pulls_change_linear_momentum_by_their_impulse():
    """Zero gravity, no contact, a limp floating robot: its linear momentum
    changes by the pulls' impulse sum F(t_n) dt (Newton's second law). The
    discrete plant updates velocities with the mass matrix of the step's start
    while the limp robot spins, an O(dt) error: 0.6% at 1 ms, hence 1%; a
    wrong hand, sign, body or ramp is off by far more."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    robot = add_icub(plant, visuals=False, contact=ContactModel())
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    human = builder.AddSystem(HumanWrenchSource(plant, robot, HumanConfig(pulls=PULLS)))
    builder.Connect(
        human.GetOutputPort("spatial_forces"), plant.get_applied_spatial_force_input_port()
    )
    builder.Connect(
        plant.get_state_output_port(robot.model_instance), human.GetInputPort("robot_state")
    )
    zero = builder.AddSystem(ConstantVectorSource(np.zeros(plant.num_actuated_dofs())))
    builder.Connect(zero.get_output_port(), plant.get_actuation_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(root)
    plant.SetFreeBodyPose(
        plant_context, plant.GetBodyByName("root_link"), RigidTransform([0, 0, 3])
    )
    mass = plant.CalcTotalMass(plant_context)
    t_end = 3.5
    simulator.AdvanceTo(t_end)
    momentum = mass * plant.CalcCenterOfMassTranslationalVelocityInWorld(plant_context)
    steps = np.arange(0.0, t_end - 1e-9, 1e-3)
    impulse = sum(_expected(t).sum(axis=0) for t in steps) * 1e-3
    assert np.linalg.norm(momentum - impulse) < 0.01 * np.linalg.norm(impulse)
    assert np.linalg.norm(impulse) > 10.0  # the check is not vacuous


def test_reactive_human_pulls_toward_target_within_cap():
    cfg = ReactiveHumanConfig(start_s=1.0, duration_s=5.0, ramp_s=0.5, force_cap_N=20.0)
    start = np.array([0.24, 0.01, 0.31])
    assert not reactive_force(cfg, 0.9, start, np.zeros(3), start).any()
    # Mid-pull, hand still at the start: pulled along the target's direction
    # (0.5 s of target travel: 10.6 N, under the cap).
    f = reactive_force(cfg, 1.5, start, np.zeros(3), start)
    direction = np.array(cfg.target_velocity_mps) / np.linalg.norm(cfg.target_velocity_mps)
    travel = np.linalg.norm(cfg.target_velocity_mps) * 0.5
    np.testing.assert_allclose(f, cfg.stiffness_N_per_m * travel * direction, rtol=1e-12)
    # Far from the target: capped.
    f = reactive_force(cfg, 5.5, start - 1.0, np.zeros(3), start)
    assert np.linalg.norm(f) == pytest.approx(20.0 * trapezoid(5.5, 1.0, 5.0, 0.5))
    # Hand moving toward the target: damping reduces the pull.
    f_moving = reactive_force(cfg, 1.5, start, 0.1 * direction, start)
    assert np.linalg.norm(f_moving) < cfg.stiffness_N_per_m * travel
