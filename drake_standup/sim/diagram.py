"""build_diagram(scenario): the station, the stand-up controller and the human, wired.

The diagram's own output ports are the run's signals, by name (LOGGED, and the visuals'
inputs); runner.py logs and reads those, never a system's insides.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer, MeshcatVisualizerParams, Role
from pydrake.multibody.meshcat import ContactVisualizer, ContactVisualizerParams
from pydrake.systems.framework import Diagram, DiagramBuilder, OutputPort, System
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, VectorLogSink

from drake_standup.config import Scenario, validate
from drake_standup.config.plugins import resolve
from drake_standup.config.responses import response_names, responses_of
from drake_standup.control.controller import WholeBodyController
from drake_standup.helper.plugin import check_helper_ports
from drake_standup.helper.work import HelperWork
from drake_standup.robot.icub import actuated_joints
from drake_standup.senses.wiring import add_muscles, add_senses, joint_damping
from drake_standup.sim.visuals import StandupVisuals
from drake_standup.standup.advancement import AdvancementLaw, for_robot
from drake_standup.standup.plan import StandupPlan, feet_reach, make_plan
from drake_standup.standup.standup_controller import StandupController, make_standup_controller
from drake_standup.world.scene import Scene, set_seated_state
from drake_standup.world.station import Station, make_station

CONTROLLERS = ("whole_body", "seat_hold")
# The diagram's outputs that every run logs (the station's, the controller's, the human's).
STATION_SIGNALS = (
    "robot_state",
    "pad_forces_W",
    "pad_impulses_Ns",
    "hand_wrenches_W",
    "com_W",
    "net_actuation",
    "standing_pull_usage",
    "braced_pull_usage",
    "pull_cop_shift_m",
    "hand_velocities_W",
)
CONTROLLER_SIGNALS = (
    "psi",
    "psi_dot",
    "alpha",
    "com_reference",
    "x_d_W",
    "standup_state",
    "held_back",
    "arms_braced",
    "segment",
    "entry_times_s",
    "controller_diagnostics",
    "lean_W",
    "compliance_W",
    "mass_estimate",
)
# Not logged: the visuals' (every publish) and the table's last values only.
UNLOGGED = ("x_d_W", "entry_times_s", "applied_hand_wrenches_W")


@dataclass
class StandupDiagram:
    """The built diagram, the station it simulates and the loggers of its outputs."""

    diagram: Diagram
    station: Station
    controller: WholeBodyController | None  # for its compute times (bench.py)
    logs: dict[str, VectorLogSink]  # output name -> logger
    visualizer: MeshcatVisualizer | None
    plan: StandupPlan  # the phase table resolved for this robot and scene (standup/plan.py)
    responses: tuple[str, ...]  # the run's responses, by the code the port response carries

    def output(self, name: str, root_context) -> np.ndarray:
        """The diagram's output name in the root context."""
        return self.diagram.GetOutputPort(name).Eval(root_context)


def build_diagram(
    scenario: Scenario,
    meshcat: Meshcat | None = None,
    controller: str = "whole_body",
    make_human: Callable | None = None,
) -> StandupDiagram:
    """The stand-up diagram: station, human, stand-up controller, loggers and
    (optionally) Meshcat.

    controller: 'whole_body' (the stand-up controller) or 'seat_hold' (Drake's joint PD
    holding the seated pose: the plant-only benchmark). make_human(plant, robot,
    scenario.human): another human with the ports of HumanWrenchSource (live.py's
    helper at the Meshcat page); an output port stand_up, if it has one, goes to the
    stand-up controller.
    """
    if controller not in CONTROLLERS:
        raise ValueError(f"controller: '{controller}'; accepted: {', '.join(CONTROLLERS)}")
    validate(scenario)  # the one check of a scenario's inputs, however it was made
    hold = scenario.seat_hold
    seat_hold = controller == "seat_hold"
    station = make_station(
        scenario,
        feet_reach(scenario.controller),
        (hold.kp_Nm_per_rad, hold.kd_Nms_per_rad) if seat_hold else None,
        joint_damping(scenario),
    )
    plan = make_plan(scenario, station)
    builder = DiagramBuilder()
    world, human, outputs = _add_station_and_human(builder, station, scenario, make_human)
    standup = None
    if seat_hold:
        add_seat_hold(
            builder,
            station.scene,
            scenario,
            world.GetInputPort("desired_state"),
            world.GetInputPort("actuation"),
        )
    else:
        standup = _add_standup_controller(
            builder, scenario, station, plan, world, human, outputs=outputs
        )
    logs = _export_and_log(builder, outputs, scenario.log_period_s)
    visualizer = None
    if meshcat is not None:
        visualizer = _add_meshcat(builder, world, scenario, meshcat)
        if standup is not None:
            _add_visuals(builder, station, scenario, meshcat, outputs, plan.n_states)
    diagram = builder.Build()
    diagram.set_name("standup")
    whole_body = None if standup is None else standup.controller
    names = response_names(scenario.response)
    return StandupDiagram(diagram, station, whole_body, logs, visualizer, plan, names)


def _add_station_and_human(
    builder: DiagramBuilder, station: Station, scenario: Scenario, make_human: Callable | None
) -> tuple[System, System, dict[str, OutputPort]]:
    """The station, the human pulling at its hands and what the helper spends, wired;
    returns the station's and the human's systems and their outputs to export by name."""
    world = builder.AddNamedSystem("station", station.diagram)
    human = builder.AddNamedSystem("human", _make_helper(station, scenario, make_human))
    builder.Connect(world.GetOutputPort("robot_state"), human.GetInputPort("robot_state"))
    builder.Connect(
        human.GetOutputPort("spatial_forces"), world.GetInputPort("hand_spatial_forces")
    )
    builder.Connect(
        human.GetOutputPort("hand_wrenches_W"), world.GetInputPort("applied_hand_wrenches_W")
    )
    # What the helper spends, on the plant's own steps (helper.work.HelperWork).
    spent = builder.AddNamedSystem("helper_work", HelperWork(scenario.plant.time_step))
    builder.Connect(world.GetOutputPort("hand_positions_W"), spent.GetInputPort("hand_positions_W"))
    builder.Connect(human.GetOutputPort("hand_wrenches_W"), spent.GetInputPort("hand_wrenches_W"))
    outputs = {name: world.GetOutputPort(name) for name in STATION_SIGNALS}
    outputs["applied_hand_wrenches_W"] = human.GetOutputPort("hand_wrenches_W")
    outputs["helper_spent"] = spent.GetOutputPort("helper_spent")
    if human.HasInputPort("person_state"):
        for source, sink in (("person_state", "person_state"), ("plant_state", "plant_state")):
            builder.Connect(world.GetOutputPort(source), human.GetInputPort(sink))
        builder.Connect(
            human.GetOutputPort("desired_state"), world.GetInputPort("person_desired_state")
        )
        builder.Connect(human.GetOutputPort("feedforward"), world.GetInputPort("person_actuation"))
        outputs["helper_torques_Nm"] = world.GetOutputPort("helper_torques_Nm")
        outputs["helper_state"] = world.GetOutputPort("person_state")
        outputs["helper_grip_wrenches_W"] = human.GetOutputPort("grip_wrenches_W")
        outputs["helper_intent_wrenches_W"] = human.GetOutputPort("intent_wrenches_W")
    if station.diagram.HasOutputPort("push_force_W"):
        outputs["push_force_W"] = world.GetOutputPort("push_force_W")
    return world, human, outputs


def _make_helper(station: Station, scenario: Scenario, make_human: Callable | None) -> System:
    """The helper human.mode names (drake_standup/plugins), or make_human's (the live page)."""
    spec = scenario.human.mode
    factory = resolve("helpers", spec).obj
    plant, robot = station.plant, station.robot
    if getattr(factory, "adds_body", False):  # the person's body; the page's sliders: intent
        intent = make_human(plant, robot, scenario.human) if make_human else None
        human = factory(plant, robot, scenario.human, station.scene.helper, intent)
    else:
        human = (make_human or factory)(plant, robot, scenario.human)
    check_helper_ports(human, spec)
    return human


def _add_standup_controller(
    builder: DiagramBuilder,
    scenario: Scenario,
    station: Station,
    plan: StandupPlan,
    world: System,
    human: System,
    *,
    outputs: dict[str, OutputPort],
) -> StandupController:
    """The stand-up controller, fed by the station (and the human's stand_up, if it has
    one), driving its actuation; its signals and the response join outputs."""
    standup = make_standup_controller(scenario, station, plan)
    brain = builder.AddNamedSystem("standup_controller", standup.diagram)
    # The robot's response to the pull: the scenario's, or the live helper's switch.
    if human.HasOutputPort("response"):
        outputs["response"] = human.GetOutputPort("response")
    else:
        code = response_names(scenario.response).index(scenario.response)
        response = ConstantVectorSource([float(code)])
        outputs["response"] = builder.AddNamedSystem("response", response).get_output_port()
    builder.Connect(outputs["response"], brain.GetInputPort("response"))
    # What the controller reads: the station's truth (ideal) or the robot's own senses.
    senses = None
    if scenario.robot.hardware == "icub":
        senses = add_senses(builder, station, scenario, world)
        outputs |= senses.estimates
        outputs["com_velocity_W"] = world.GetOutputPort("com_velocity_W")
    for i in range(brain.num_input_ports()):
        port = brain.get_input_port(i)
        name = port.get_name()
        if name in ("stand_up", "sit_down"):
            if human.HasOutputPort(name):
                builder.Connect(human.GetOutputPort(name), port)
        elif name != "response":
            source = senses.controller_inputs[name] if senses else world.GetOutputPort(name)
            builder.Connect(source, port)
    if senses is None:
        builder.Connect(brain.GetOutputPort("actuation"), world.GetInputPort("actuation"))
    else:
        add_muscles(builder, station, scenario, world, senses, brain.GetOutputPort("actuation"))
    outputs |= {name: brain.GetOutputPort(name) for name in CONTROLLER_SIGNALS}
    if senses is not None:
        outputs |= _add_law_from_truth(builder, scenario, station, world, brain, outputs)
    return standup


def _add_law_from_truth(
    builder, scenario: Scenario, station: Station, world, brain, outputs: dict
) -> dict:
    """Under robot.hardware: icub, the advancement's law as the truth would have it: the
    same law on the true CoM, its velocity and the true pull, along the same reference,
    beside the law the robot's estimates drive (psi_dot_law)."""
    plant, robot = station.plant, station.robot
    mass = plant.CalcTotalMass(plant.CreateDefaultContext(), [robot.model_instance])
    # The law alone, evaluated where it is logged: a psi of its own would be integrated
    # at every integrator stage for nothing (0.4 ms a tick).
    advances = tuple(r.advances for r in responses_of(response_names(scenario.response)))
    law = builder.AddNamedSystem(
        "advancement_from_truth",
        AdvancementLaw(for_robot(scenario.advancement, mass), advances=advances),
    )
    for name in ("com_W", "com_velocity_W", "omega_f_W", "hand_wrenches_W"):
        builder.Connect(world.GetOutputPort(name), law.GetInputPort(name))
    for name in (
        *("x_d_W", "lean_W", "path_tangent_W", "path_progress", "advances"),
        *("psi", "psi_dot", "standup_state"),
    ):
        builder.Connect(brain.GetOutputPort(name), law.GetInputPort(name))
    builder.Connect(outputs["response"], law.GetInputPort("response"))
    return {
        "psi_dot_law": brain.GetOutputPort("psi_dot_law"),
        "psi_dot_law_from_truth": law.GetOutputPort("psi_dot_law"),
    }


def _export_and_log(
    builder: DiagramBuilder, outputs: dict[str, OutputPort], log_period_s: float
) -> dict[str, VectorLogSink]:
    """Exports every output by its name and logs those not UNLOGGED; returns the loggers."""
    logs = {}
    for name, port in outputs.items():
        builder.ExportOutput(port, name)
        if name not in UNLOGGED:
            logs[name] = LogVectorOutput(port, builder, log_period_s)
            logs[name].set_name(f"log_{name}")
    return logs


def _add_meshcat(builder, world, scenario: Scenario, meshcat: Meshcat) -> MeshcatVisualizer:
    """The scene and its contact forces, on the plant's step grid."""
    vis, step_s = scenario.visualization, scenario.plant.time_step
    visualizer = MeshcatVisualizer.AddToBuilder(
        builder,
        world.GetOutputPort("query_object"),
        meshcat,
        MeshcatVisualizerParams(
            publish_period=on_step_grid(vis.publish_period_s, step_s), role=Role.kIllustration
        ),
    )
    if vis.show_contact_forces:
        ContactVisualizer.AddToBuilder(
            builder,
            world.GetOutputPort("contact_results"),
            world.GetOutputPort("query_object"),
            meshcat,
            ContactVisualizerParams(
                publish_period=on_step_grid(vis.contact_publish_period_s, step_s),
                newtons_per_meter=400.0,
            ),
        )
    return visualizer


def _add_visuals(
    builder, station: Station, scenario: Scenario, meshcat: Meshcat, outputs: dict, n_states: int
) -> None:
    """The pull's arrows, the CoM and its reference, the state and psi (visuals.py), at
    the recording's rate."""
    visuals = builder.AddNamedSystem(
        "visuals",
        StandupVisuals(
            station.plant,
            station.robot,
            meshcat,
            on_step_grid(scenario.visualization.publish_period_s, scenario.plant.time_step),
            scenario.advancement.psi_dot_upper,
            n_states,
        ),
    )
    sources: dict[str, OutputPort] = {
        **outputs,
        "hand_wrenches_W": outputs["applied_hand_wrenches_W"],
    }
    for i in range(visuals.num_input_ports()):
        port = visuals.get_input_port(i)
        builder.Connect(sources[port.get_name()], port)


# How long a run's periodic events are checked to land on the plant's steps (s): past
# any run's duration.
ON_GRID_HORIZON_S = 3600.0


@functools.cache  # pure; each build asks the same few periods (publishes, chunks)
def on_step_grid(period_s: float, step_s: float) -> float:
    """period_s as a whole number n (>= 1) of plant steps, the nearest n whose event times
    are the plant's own in floating point: Drake puts a periodic event k at k * period
    and the plant's step m at m * step_s, and k * (n h) == (k n) h does not hold for
    every n (n = 25 at h = 4 ms: 3.9 s is one ulp apart). An event between the plant's
    steps, even by an ulp, splits an integrator step of psi, so a recording (its
    publishes) or a run's chunk ends would change the simulation (step_s > 0: a discrete
    plant, config.validate)."""
    nearest = max(1, round(period_s / step_s))
    for n in sorted(range(1, 2 * nearest + 1), key=lambda n: (abs(n - nearest), n)):
        if n == 1:  # k * (1 h) is k h exactly: every step is on the grid
            return step_s
        k = np.arange(1, int(ON_GRID_HORIZON_S / (n * step_s)) + 2)
        if np.array_equal(k * (step_s * n), (k * n) * step_s):
            return step_s * n
    return step_s * nearest


def add_seat_hold(builder, scene: Scene, scenario: Scenario, desired_state, actuation) -> None:
    """Drake's implicit joint PD toward the seated pose (into the plant's desired_state
    input, here the port desired_state) plus constant gravity feed-forward evaluated at
    that pose (into actuation): the chair carries the base."""
    plant = scene.plant
    instance = scene.robot.model_instance
    plant_context = plant.CreateDefaultContext()
    set_seated_state(scene, plant_context)
    q0 = plant.GetPositions(plant_context, instance)
    robot_actuators = [int(i) for i in plant.GetJointActuatorIndices(instance)]
    B = plant.MakeActuationMatrix()[:, robot_actuators]  # a helper's body has its own
    u_ff = B.T @ (-plant.CalcGravityGeneralizedForces(plant_context))
    q_index = actuated_joints(plant, instance).q_index
    x0 = np.concatenate([q0[q_index], np.zeros(len(q_index))])
    setpoint = builder.AddNamedSystem("seat_hold_setpoint", ConstantVectorSource(x0))
    feedforward = builder.AddNamedSystem("seat_hold_feedforward", ConstantVectorSource(u_ff))
    builder.Connect(setpoint.get_output_port(), desired_state)
    builder.Connect(feedforward.get_output_port(), actuation)
