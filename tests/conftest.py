"""Shared fixtures: one seated run, simulated once per test session; the default scene
seated, once per test module; a limp robot rig for the human sources."""

from __future__ import annotations

import pytest

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.sim.simulate import simulate


@pytest.fixture(scope="session")
def seated_run(tmp_path_factory):
    """scenarios/seated.yaml, 5 s, with recording, written to a tmp dir."""
    scenario = load_scenario(SCENARIO_DIR / "seated.yaml")
    scenario.duration_s = 5.0
    out = tmp_path_factory.mktemp("seated")
    result = simulate(scenario, out, record=True, progress=False)
    return scenario, result, out


@pytest.fixture(scope="module")
def seated_scene():
    """The default scenario's scene (world/scene.py, no diagram around it) and a plant
    context in its seated pose; each test module gets its own (they move the context)."""
    from pydrake.systems.framework import DiagramBuilder

    from drake_standup.config import Scenario
    from drake_standup.world.scene import add_scene, set_seated_state

    scene = add_scene(DiagramBuilder(), Scenario(), pd_gains=None, visuals=False)
    context = scene.plant.CreateDefaultContext()
    set_seated_state(scene, context)
    return scene, context


@pytest.fixture
def limp_robot_rig():
    """A factory: make_human(plant, robot, dt) -> a human source, wired to a floating,
    limp iCub (zero torques) with no gravity and no contact, 3 m up; returns
    (simulator, plant, plant_context). The human sources' momentum tests share it."""
    import numpy as np
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from drake_standup.robot.icub import ContactModel, add_icub

    def build(make_human, dt: float = 1e-3):
        builder = DiagramBuilder()
        plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=dt)
        robot = add_icub(plant, visuals=False, contact=ContactModel())
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
        plant.Finalize()
        human = builder.AddSystem(make_human(plant, robot, dt))
        builder.Connect(
            human.GetOutputPort("spatial_forces"), plant.get_applied_spatial_force_input_port()
        )
        builder.Connect(
            plant.get_state_output_port(robot.model_instance), human.GetInputPort("robot_state")
        )
        zero = builder.AddSystem(ConstantVectorSource(np.zeros(plant.num_actuated_dofs())))
        builder.Connect(zero.get_output_port(), plant.get_actuation_input_port())
        simulator = Simulator(builder.Build())
        plant_context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
        plant.SetFreeBodyPose(
            plant_context, plant.GetBodyByName("root_link"), RigidTransform([0, 0, 3])
        )
        return simulator, plant, plant_context

    return build
