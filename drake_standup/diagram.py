"""build_diagram(scenario) -> the Drake diagram of a run and handles to its parts."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer, MeshcatVisualizerParams, Role
from pydrake.multibody.meshcat import ContactVisualizer, ContactVisualizerParams
from pydrake.multibody.plant import ExternallyAppliedSpatialForceMultiplexer
from pydrake.systems.framework import Diagram, DiagramBuilder, OutputPort
from pydrake.systems.primitives import (
    ConstantVectorSource,
    LogVectorOutput,
    MatrixGain,
    VectorLogSink,
)

from drake_standup.advancement import TrajectoryAdvancement
from drake_standup.config import Scenario, ScenarioError
from drake_standup.contacts import ContactForceReporter
from drake_standup.controller import WholeBodyController
from drake_standup.human import HumanWrenchSource
from drake_standup.perturbations import NoisyWrenchSensor, PushSource
from drake_standup.reference import CoMReferenceGenerator
from drake_standup.robot import ActuatedJoints, actuated_joints
from drake_standup.scene import Scene, add_scene, set_seated_state
from drake_standup.sensing import RobotSensing, heel_points
from drake_standup.state_machine import StandupStateMachine
from drake_standup.visuals import StandupVisuals


@dataclass
class StandupDiagram:
    """The built diagram and the parts that simulate.py and outputs.py read."""

    diagram: Diagram
    scene: Scene
    pad_groups: dict[str, str]  # pad geometry name -> group, in reporter order
    joints: ActuatedJoints
    state_machine: StandupStateMachine
    advancement: TrajectoryAdvancement
    controller: WholeBodyController | None
    logs: dict[str, VectorLogSink]  # signal name -> logger
    visualizer: MeshcatVisualizer | None


def _seat_hold_gains(scenario: Scenario, joint_names: list[str]) -> dict:
    hold = scenario.seat_hold
    return {name: (hold.kp_Nm_per_rad, hold.kd_Nms_per_rad) for name in joint_names}


CONTROLLERS = ("whole_body", "seat_hold")


def build_diagram(
    scenario: Scenario,
    meshcat: Meshcat | None = None,
    controller: str = "whole_body",
    make_human: Callable | None = None,
) -> StandupDiagram:
    """The stand-up diagram: plant, human, advancement, reference, state machine,
    the controller, loggers and (optionally) Meshcat.

    controller: 'whole_body' (the momentum-based controller) or 'seat_hold'
    (Drake's joint PD holding the seated pose; the plant-only benchmark).
    make_human(plant, robot, scenario.human): another human with the ports of
    HumanWrenchSource (live.py's helper at the Meshcat page); an output port
    stand_up, if it has one, goes to the state machine.
    """
    if controller not in CONTROLLERS:
        raise ValueError(f"controller: '{controller}'; accepted: {', '.join(CONTROLLERS)}")
    builder = DiagramBuilder()
    hold = scenario.seat_hold
    pd_gains = (hold.kp_Nm_per_rad, hold.kd_Nms_per_rad) if controller == "seat_hold" else None
    scene = add_scene(builder, scenario, pd_gains=pd_gains)
    plant = scene.plant
    instance = scene.robot.model_instance
    if controller == "seat_hold":
        add_seat_hold(builder, scene, scenario)

    # Group names as metrics.json reports them (plural where there are two).
    group_labels = {"sole": "soles", "thigh": "thighs", "buttocks": "buttocks"}
    pad_groups = {
        name: group_labels.get(group, group)
        for group, names in scene.robot.contact_groups.items()
        for name in names
    }
    pad_names = list(pad_groups)
    reporter = builder.AddNamedSystem(
        "contact_forces",
        ContactForceReporter(pad_names, [scene.robot.contact_geometries[n] for n in pad_names]),
    )
    builder.Connect(plant.get_contact_results_output_port(), reporter.get_input_port())

    robot = scene.robot
    make_human = make_human or HumanWrenchSource
    human = builder.AddNamedSystem("human", make_human(plant, robot, scenario.human))
    sensing = builder.AddNamedSystem("sensing", RobotSensing(plant, robot, heel_points(robot)))
    advancement = builder.AddNamedSystem("advancement", TrajectoryAdvancement(scenario.advancement))
    reference = builder.AddNamedSystem("com_reference", CoMReferenceGenerator())
    sole_rows = tuple(
        pad_names.index(s.name)
        for frame in ("l_sole", "r_sole")
        for s in robot.contact_shapes
        if s.frame == frame
    )
    state_machine = builder.AddNamedSystem(
        "state_machine",
        StandupStateMachine(scenario.standup, scenario.phases, len(pad_names), sole_rows),
    )

    robot_state = plant.get_state_output_port(instance)
    pushes, hand_wrenches = _add_perturbations(builder, scene, scenario, human)
    builder.Connect(robot_state, human.GetInputPort("robot_state"))
    builder.Connect(robot_state, sensing.GetInputPort("robot_state"))
    builder.Connect(hand_wrenches, sensing.GetInputPort("hand_wrenches_W"))
    for name in ("com_W", "com_velocity_W", "omega_f_W"):
        builder.Connect(sensing.GetOutputPort(name), advancement.GetInputPort(name))
    for name in ("x_d_W", "path_tangent_W", "path_progress"):
        builder.Connect(reference.GetOutputPort(name), advancement.GetInputPort(name))
    for name in ("psi", "psi_dot", "psi_ddot"):
        builder.Connect(advancement.GetOutputPort(name), reference.GetInputPort(name))
    builder.Connect(state_machine.GetOutputPort("segment"), reference.GetInputPort("segment"))
    builder.Connect(advancement.GetOutputPort("psi"), state_machine.GetInputPort("psi"))
    builder.Connect(
        state_machine.GetOutputPort("standup_state"), advancement.GetInputPort("standup_state")
    )
    builder.Connect(sensing.GetOutputPort("com_W"), state_machine.GetInputPort("com_W"))
    builder.Connect(sensing.GetOutputPort("heel_x_W"), state_machine.GetInputPort("heel_x_W"))
    builder.Connect(reporter.get_output_port(), state_machine.GetInputPort("pad_forces_W"))
    builder.Connect(hand_wrenches, state_machine.GetInputPort("hand_wrenches_W"))
    if human.HasOutputPort("stand_up"):
        builder.Connect(human.GetOutputPort("stand_up"), state_machine.GetInputPort("stand_up"))

    controller_system = None
    if controller == "whole_body":
        try:
            whole_body = WholeBodyController(
                plant, robot, scenario.controller, scenario.phases, scenario.controller_period_s
            )
        except ValueError as err:  # a setting only the model can check: a joint's name
            raise ScenarioError(" ".join(str(err).split())) from None
        controller_system = builder.AddNamedSystem("controller", whole_body)
        builder.Connect(robot_state, controller_system.GetInputPort("robot_state"))
        builder.Connect(
            reference.GetOutputPort("com_reference"),
            controller_system.GetInputPort("com_reference"),
        )
        builder.Connect(
            state_machine.GetOutputPort("contact_plan"),
            controller_system.GetInputPort("contact_plan"),
        )
        builder.Connect(hand_wrenches, controller_system.GetInputPort("hand_wrenches_W"))
        builder.Connect(
            reference.GetOutputPort("path_progress"),
            controller_system.GetInputPort("path_progress"),
        )
        # The seat pads' measured normal forces (z of the buttocks and thigh pads).
        select = np.zeros((3, 3 * len(pad_names)))
        for row, pad in enumerate(_seat_pads(robot)):
            select[row, 3 * pad_names.index(pad) + 2] = 1.0
        seat_pads = builder.AddNamedSystem("seat_pad_forces", MatrixGain(select))
        builder.Connect(reporter.get_output_port(), seat_pads.get_input_port())
        builder.Connect(
            seat_pads.get_output_port(), controller_system.GetInputPort("seat_pad_normal_forces_N")
        )
        # The vertical force on all the robot's pads (its weight while it sits still).
        total = np.zeros((1, 3 * len(pad_names)))
        total[0, 2::3] = 1.0
        support = builder.AddNamedSystem("pads_vertical_force", MatrixGain(total))
        builder.Connect(reporter.get_output_port(), support.get_input_port())
        builder.Connect(
            support.get_output_port(), controller_system.GetInputPort("pads_vertical_force_N")
        )
        builder.Connect(
            controller_system.GetOutputPort("actuation"), plant.get_actuation_input_port(instance)
        )

    logged = {
        "robot_state": robot_state,
        "pad_forces_W": reporter.get_output_port(),
        "hand_wrenches_W": hand_wrenches,
        "com_W": sensing.GetOutputPort("com_W"),
        "psi": advancement.GetOutputPort("psi"),
        "psi_dot": advancement.GetOutputPort("psi_dot"),
        "alpha": advancement.GetOutputPort("alpha"),
        "com_reference": reference.GetOutputPort("com_reference"),
        "standup_state": state_machine.GetOutputPort("standup_state"),
        "held_back": state_machine.GetOutputPort("held_back"),
        "segment": state_machine.GetOutputPort("segment"),
        "net_actuation": plant.get_net_actuation_output_port(instance),
    }
    if pushes is not None:
        logged["push_force_W"] = pushes.GetOutputPort("push_force_W")
    if controller_system is not None:
        logged["controller_diagnostics"] = controller_system.GetOutputPort("diagnostics")
    logs = {}
    for name, port in logged.items():
        logs[name] = LogVectorOutput(port, builder, scenario.log_period_s)
        logs[name].set_name(f"log_{name}")

    visualizer = None
    if meshcat is not None:
        vis = scenario.visualization
        step_s = scenario.plant.time_step
        visualizer = MeshcatVisualizer.AddToBuilder(
            builder,
            scene.scene_graph,
            meshcat,
            MeshcatVisualizerParams(
                publish_period=on_step_grid(vis.publish_period_s, step_s), role=Role.kIllustration
            ),
        )
        if vis.show_contact_forces:
            ContactVisualizer.AddToBuilder(
                builder,
                plant,
                meshcat,
                ContactVisualizerParams(
                    publish_period=on_step_grid(vis.contact_publish_period_s, step_s),
                    newtons_per_meter=400.0,
                ),
            )
        _add_visuals(builder, scene, scenario, meshcat, human, sensing, reference, advancement)

    diagram = builder.Build()
    diagram.set_name("standup")
    return StandupDiagram(
        diagram,
        scene,
        pad_groups,
        actuated_joints(plant, instance),
        state_machine,
        advancement,
        controller_system,
        logs,
        visualizer,
    )


def _add_visuals(builder, scene, scenario, meshcat, human, sensing, reference, advancement):
    """The pull's arrows, the CoM and its reference, the state and psi (visuals.py), at
    the recording's rate."""
    visuals = builder.AddNamedSystem(
        "visuals",
        StandupVisuals(
            scene.plant,
            scene.robot,
            meshcat,
            on_step_grid(scenario.visualization.publish_period_s, scenario.plant.time_step),
            scenario.advancement.psi_dot_upper,
        ),
    )
    state_machine = builder.GetSubsystemByName("state_machine")
    sources = {
        "robot_state": scene.plant.get_state_output_port(scene.robot.model_instance),
        "hand_wrenches_W": human.GetOutputPort("hand_wrenches_W"),
        "com_W": sensing.GetOutputPort("com_W"),
        "x_d_W": reference.GetOutputPort("x_d_W"),
        "standup_state": state_machine.GetOutputPort("standup_state"),
        "psi": advancement.GetOutputPort("psi"),
        "psi_dot": advancement.GetOutputPort("psi_dot"),
        "entry_times_s": state_machine.GetOutputPort("entry_times_s"),
    }
    for name, port in sources.items():
        builder.Connect(port, visuals.GetInputPort(name))


def _seat_pads(robot) -> list[str]:
    """The contact pads under the controller's seat contacts, in its order: the buttocks,
    the left thigh, the right thigh."""
    by_frame = {shape.frame: shape.name for shape in robot.contact_shapes}
    return [by_frame[robot.TASK_FRAMES[task]] for task in ("buttocks", "l_thigh", "r_thigh")]


def on_step_grid(period_s: float, step_s: float) -> float:
    """period_s rounded to a whole number (>= 1) of plant steps (step_s 0: a
    continuous plant, unchanged). A visualizer that publishes between the
    plant's steps splits an integrator step of psi, so a recording would
    change the simulation it records."""
    if step_s <= 0.0:
        return period_s
    return step_s * max(1, round(period_s / step_s))


def _add_perturbations(
    builder: DiagramBuilder, scene: Scene, scenario: Scenario, human: HumanWrenchSource
) -> tuple[PushSource | None, OutputPort]:
    """Connects the human's forces to the plant, with the scenario's pushes if
    any (a multiplexer sums both lists), and returns the push source (or None)
    and the measured hand wrenches: the human's own, or through the noisy
    sensor when perturbation.hand_wrench_noise_N > 0. With no perturbation
    this adds no system."""
    plant = scene.plant
    pert = scenario.perturbation
    human_forces = human.GetOutputPort("spatial_forces")
    pushes = None
    if pert.pushes:
        pushes = builder.AddNamedSystem("pushes", PushSource(plant, scene.robot, pert.pushes))
        mux = builder.AddNamedSystem("applied_forces", ExternallyAppliedSpatialForceMultiplexer(2))
        builder.Connect(human_forces, mux.get_input_port(0))
        builder.Connect(pushes.GetOutputPort("spatial_forces"), mux.get_input_port(1))
        builder.Connect(mux.get_output_port(), plant.get_applied_spatial_force_input_port())
    else:
        builder.Connect(human_forces, plant.get_applied_spatial_force_input_port())
    hand_wrenches = human.GetOutputPort("hand_wrenches_W")
    if pert.hand_wrench_noise_N > 0.0:
        sensor = builder.AddNamedSystem(
            "hand_wrench_sensor",
            NoisyWrenchSensor(
                pert.hand_wrench_noise_N, pert.hand_wrench_noise_period_s, pert.noise_seed
            ),
        )
        builder.Connect(hand_wrenches, sensor.GetInputPort("hand_wrenches_W"))
        hand_wrenches = sensor.GetOutputPort("hand_wrenches_W")
    return pushes, hand_wrenches


def add_seat_hold(builder: DiagramBuilder, scene: Scene, scenario: Scenario) -> None:
    """Drake's implicit joint PD toward the seated pose plus constant gravity
    feed-forward evaluated at that pose (the chair carries the base)."""
    plant = scene.plant
    instance = scene.robot.model_instance
    plant_context = plant.CreateDefaultContext()
    set_seated_state(scene, plant_context, scenario)
    q0 = plant.GetPositions(plant_context, instance)
    B = plant.MakeActuationMatrix()
    tau_g = plant.CalcGravityGeneralizedForces(plant_context)
    u_ff = B.T @ (-tau_g)
    Bq = _actuated_position_selector(plant, instance)
    desired_state = np.concatenate([Bq @ q0, np.zeros(Bq.shape[0])])
    setpoint = builder.AddNamedSystem("seat_hold_setpoint", ConstantVectorSource(desired_state))
    feedforward = builder.AddNamedSystem("seat_hold_feedforward", ConstantVectorSource(u_ff))
    builder.Connect(setpoint.get_output_port(), plant.get_desired_state_input_port(instance))
    builder.Connect(feedforward.get_output_port(), plant.get_actuation_input_port(instance))


def _actuated_position_selector(plant, instance) -> np.ndarray:
    """Rows pick each actuated joint's position out of the instance's q."""
    joints = actuated_joints(plant, instance)
    S = np.zeros((len(joints.names), plant.num_positions(instance)))
    S[np.arange(len(joints.names)), joints.q_index] = 1.0
    return S
