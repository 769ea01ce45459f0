"""make_station(scenario, feet): the world the stand-up controller acts in, as one diagram.

The plant with the iCub, the chair and the floor (scene.py), the contact forces on the
robot's pads (contacts.py) and the leg force sensors made of them, what the robot senses
of itself (sensing.py: CoM, Omega f, the heels), the hands' force/torque sensors (noisy
with perturbation.hand_wrench_noise_N) and the pushes of the perturbations (the shape of
RussTedrake/manipulation's MakeHardwareStation: a diagram with named exported ports).

Inputs
    actuation                 (nu) joint torques, actuator order, N m
    hand_spatial_forces       the hands' pull on the robot (abstract, helper/hands.py)
    applied_hand_wrenches_W   (12) the same pull as wrenches, what the hands' sensors read
    desired_state             (2 nu) only with pd_gains (the seat-hold benchmark)
Outputs
    robot_state, net_actuation, contact_results, query_object
    pad_forces_W              (3 per pad) the contact force on each pad, world
    pad_impulses_Ns           (3 per pad) int pad_forces_W dt over the plant's steps so far
    seat_pad_normal_forces_N  (3) normal force on the buttocks, left and right thigh pads
    pads_vertical_force_N     (1) the vertical force on all the robot's pads
    hand_wrenches_W           (12) the hands' sensors' wrenches (payloads.HAND_WRENCHES)
    com_W, com_velocity_W, omega_f_W, heel_x_W, thigh_x_W, thigh_z_W,
    buttocks_z_W              sensing.py
    hand_positions_W, hand_velocities_W   (6 each) where the hands are pulled, m, m/s
    standing_pull_usage       (1) the share of the standing feet's hold a pull needs
    braced_pull_usage         (1) the same with the arms braced (held as seated)
    pull_cop_shift_m          (1) how far the pull moves the CoP under the posture now
    push_force_W              (3) only with perturbation.pushes
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import ExternallyAppliedSpatialForceMultiplexer, MultibodyPlant
from pydrake.systems.framework import Diagram, DiagramBuilder, OutputPort
from pydrake.systems.primitives import MatrixGain, PassThrough

from drake_standup.config import Scenario
from drake_standup.config.phases import SEAT_PAD_ROWS
from drake_standup.ports.payloads import HAND_WRENCHES
from drake_standup.robot.icub import ActuatedJoints, Robot, actuated_joints, arm_joint_names
from drake_standup.world.pad_forces import ContactForceReporter, PadImpulses
from drake_standup.world.perturbations import NoisyWrenchSensor, PushSource
from drake_standup.world.scene import (
    Scene,
    add_scene,
    check_com_heights,
    robot_last_com,
)
from drake_standup.world.sensing import SENSED, FeetReach, StandingSupport, pad_sensing

# Pad groups as metrics.json reports them (plural where there are two).
_GROUP_LABELS = {"sole": "soles", "thigh": "thighs", "buttocks": "buttocks"}
# The pads under the seat pads of the contact schedule (standup/contact_schedule.py), in order.
SEAT_PAD_FRAMES = tuple(frame for frame, _ in SEAT_PAD_ROWS)


@dataclass
class Station:
    """The station's diagram and what its users build on: the plant (the controller's
    model, the human's and the visuals' kinematics), the robot's handles, its pads."""

    diagram: Diagram
    scene: Scene
    pad_groups: dict[str, str]  # pad geometry name -> group, in pad_forces_W's order
    joints: ActuatedJoints
    standing: StandingSupport  # what the standing robot's feet can hold (sensing.py)
    # ... with its arms braced: held as seated, not reaching out (arm_joint_names).
    braced: StandingSupport
    braced_drop_m: float  # how much lower the erect CoM stands with the arms braced
    arm_joints: list[str]  # the joints a brace holds (arm_joint_names)

    @property
    def plant(self) -> MultibodyPlant:
        return self.scene.plant

    @property
    def robot(self) -> Robot:
        return self.scene.robot

    def sole_rows(self) -> tuple[int, int]:
        """The rows of the left and right soles' pads in pad_forces_W."""
        names = list(self.pad_groups)
        return tuple(
            names.index(shape.name)
            for frame in ("l_sole", "r_sole")
            for shape in self.robot.contact_shapes
            if shape.frame == frame
        )


def make_station(
    scenario: Scenario,
    feet: FeetReach,
    pd_gains: tuple[float, float] | None = None,
    joint_damping: Callable[[str], float] | None = None,
) -> Station:
    """The station of the module docstring; feet: how far the stand-up leans on the
    standing feet (for standing_pull_usage); pd_gains: Drake's joint PD on every actuator
    (the seat-hold benchmark), with the desired_state input; joint_damping: the joints'
    viscous friction beyond the URDF's (scene.add_scene; robot.hardware: icub)."""
    builder = DiagramBuilder()
    scene = add_scene(builder, scenario, pd_gains=pd_gains, joint_damping=joint_damping)
    # The first check that needs the robot's geometry, before anything simulates.
    check_com_heights(scene, scenario)
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    pad_groups, reporter = _add_pad_forces(builder, plant, robot)
    measured = _add_pushes_and_hand_sensors(builder, scenario, plant, robot)
    arms = arm_joint_names(plant, robot)
    (standing, braced), robot_state = _add_sensing(builder, scene, scenario, feet, measured, arms)
    drop = scene.standing.erect_com_height_m(scenario.phases.rise.posture_rad) - (
        braced.com_height_m
    )

    builder.ExportInput(plant.get_actuation_input_port(instance), "actuation")
    if pd_gains is not None:
        builder.ExportInput(plant.get_desired_state_input_port(instance), "desired_state")
    builder.ExportOutput(robot_state, "robot_state")
    builder.ExportOutput(plant.get_net_actuation_output_port(instance), "net_actuation")
    builder.ExportOutput(plant.get_contact_results_output_port(), "contact_results")
    builder.ExportOutput(scene.scene_graph.get_query_output_port(), "query_object")
    builder.ExportOutput(reporter.get_output_port(), "pad_forces_W")
    impulses = builder.AddNamedSystem(
        "pad_impulses", PadImpulses(len(pad_groups), scenario.plant.time_step)
    )
    builder.Connect(reporter.get_output_port(), impulses.get_input_port())
    builder.ExportOutput(impulses.get_output_port(), "pad_impulses_Ns")
    if scene.helper is not None:
        _export_helper_ports(builder, plant, scene.helper.person.model_instance)
    if scenario.robot.hardware == "icub":
        _export_sensor_ports(builder, plant)
    diagram = builder.Build()
    diagram.set_name("station")
    joints = actuated_joints(plant, instance)
    return Station(diagram, scene, pad_groups, joints, standing, braced, max(drop, 0.0), arms)


def _export_helper_ports(builder: DiagramBuilder, plant: MultibodyPlant, person) -> None:
    """The helper's body's ports (human.mode: body): their state and the whole plant's
    (the grips read both hands), their muscles' PD set-point and feed-forward, and the
    torque their joints apply (Drake's PD and feed-forward, clamped to their strength)."""
    builder.ExportOutput(plant.get_state_output_port(person), "person_state")
    builder.ExportOutput(plant.get_state_output_port(), "plant_state")
    builder.ExportInput(plant.get_desired_state_input_port(person), "person_desired_state")
    builder.ExportInput(plant.get_actuation_input_port(person), "person_actuation")
    builder.ExportOutput(plant.get_net_actuation_output_port(person), "helper_torques_Nm")


def _export_sensor_ports(builder: DiagramBuilder, plant: MultibodyPlant) -> None:
    """What the robot's own sensors read of the plant (robot.hardware: icub,
    drake_standup/senses): the joints' reaction forces (the F/T sensors), the bodies'
    poses, velocities and accelerations (the IMU), and the joints' friction's input."""
    builder.ExportOutput(plant.get_reaction_forces_output_port(), "reaction_forces")
    builder.ExportOutput(plant.get_body_poses_output_port(), "body_poses")
    builder.ExportOutput(plant.get_body_spatial_velocities_output_port(), "body_spatial_velocities")
    builder.ExportOutput(
        plant.get_body_spatial_accelerations_output_port(), "body_spatial_accelerations"
    )
    builder.ExportInput(plant.get_applied_generalized_force_input_port(), "generalized_friction")


def _add_pad_forces(
    builder: DiagramBuilder, plant: MultibodyPlant, robot: Robot
) -> tuple[dict[str, str], ContactForceReporter]:
    """The contact force on each pad and the leg force sensors made of them; returns pad
    name -> group and the reporter (its output: pad_forces_W)."""
    pad_groups = {
        name: _GROUP_LABELS.get(group, group)
        for group, names in robot.contact_groups.items()
        for name in names
    }
    pads = list(pad_groups)
    reporter = builder.AddNamedSystem(
        "contact_forces", ContactForceReporter(pads, [robot.contact_geometries[n] for n in pads])
    )
    builder.Connect(plant.get_contact_results_output_port(), reporter.get_input_port())
    for name, gain in pad_load_gains(robot, pads).items():
        system = builder.AddNamedSystem(name, MatrixGain(gain))
        builder.Connect(reporter.get_output_port(), system.get_input_port())
        builder.ExportOutput(system.get_output_port(), name)
    return pad_groups, reporter


def pad_load_gains(robot: Robot, pads: list[str]) -> dict[str, np.ndarray]:
    """The leg force sensors as gains on pad_forces_W (pads: the pads' names in its
    order): the seat pads' normal forces (SEAT_PAD_FRAMES), and the vertical force on all
    pads (the robot's weight while it sits still)."""
    by_frame = {shape.frame: shape.name for shape in robot.contact_shapes}
    seat = np.zeros((len(SEAT_PAD_FRAMES), 3 * len(pads)))
    for row, task in enumerate(SEAT_PAD_FRAMES):
        seat[row, 3 * pads.index(by_frame[robot.TASK_FRAMES[task]]) + 2] = 1.0
    total = np.zeros((1, 3 * len(pads)))
    total[0, 2::3] = 1.0
    return {"seat_pad_normal_forces_N": seat, "pads_vertical_force_N": total}


def _add_pushes_and_hand_sensors(
    builder: DiagramBuilder, scenario: Scenario, plant: MultibodyPlant, robot: Robot
) -> OutputPort:
    """The hands' pull and the perturbation's pushes on the plant, and the hands' sensors
    (noisy or not); returns the sensors' output, the measured hand wrenches."""
    pert = scenario.perturbation
    if pert.pushes:
        pushes = builder.AddNamedSystem("pushes", PushSource(plant, robot, pert.pushes))
        mux = builder.AddNamedSystem("applied_forces", ExternallyAppliedSpatialForceMultiplexer(2))
        builder.ExportInput(mux.get_input_port(0), "hand_spatial_forces")
        builder.Connect(pushes.GetOutputPort("spatial_forces"), mux.get_input_port(1))
        builder.Connect(mux.get_output_port(), plant.get_applied_spatial_force_input_port())
        builder.ExportOutput(pushes.GetOutputPort("push_force_W"), "push_force_W")
    else:
        builder.ExportInput(plant.get_applied_spatial_force_input_port(), "hand_spatial_forces")
    if pert.hand_wrench_noise_N > 0.0:
        sensor = NoisyWrenchSensor(
            pert.hand_wrench_noise_N, pert.hand_wrench_noise_period_s, pert.noise_seed
        )
    else:
        sensor = PassThrough(HAND_WRENCHES.size)
    sensor = builder.AddNamedSystem("hand_wrench_sensor", sensor)
    builder.ExportInput(sensor.get_input_port(), "applied_hand_wrenches_W")
    measured = sensor.get_output_port()
    builder.ExportOutput(measured, "hand_wrenches_W")
    return measured


def braced_posture(posture_rad: dict[str, float], arm_joints: list[str]) -> dict[str, float]:
    """posture_rad with the arms braced: their joints (arm_joint_names) left out, so they
    stay as the robot sat (scene.StandingGeometry, the controller's posture hold)."""
    return {name: value for name, value in posture_rad.items() if name not in arm_joints}


def _add_sensing(
    builder: DiagramBuilder,
    scene: Scene,
    scenario: Scenario,
    feet: FeetReach,
    measured: OutputPort,
    arm_joints: list[str],
) -> tuple[tuple[StandingSupport, StandingSupport], OutputPort]:
    """What the robot senses of itself (sensing.py), with what its standing feet can hold,
    its arms reaching as the rise's posture has them or braced (arm_joints held as
    seated); returns those two StandingSupports and the robot's state output."""
    plant, robot = scene.plant, scene.robot
    rise = scenario.phases.rise

    def support(posture: dict[str, float], height_m: float | None) -> StandingSupport:
        pose = scene.standing.pose(posture)
        return StandingSupport(
            com_height_m=height_m or pose.com_height_m,
            hands_m=pose.hands_from_com_m,
            soles_m=pose.soles_from_com_m,
            lean_m=feet.lean_m,
            cop_x_m=feet.cop_x_m,
            cop_y_m=feet.cop_y_m,
        )

    standing = support(rise.posture_rad, rise.com_height_m)
    braced = support(braced_posture(rise.posture_rad, arm_joints), None)
    sensing = builder.AddNamedSystem(
        "sensing",
        pad_sensing(plant, robot, standing, braced, robot_last_com(scene)),
    )
    robot_state = plant.get_state_output_port(robot.model_instance)
    builder.Connect(robot_state, sensing.GetInputPort("robot_state"))
    builder.Connect(measured, sensing.GetInputPort("hand_wrenches_W"))
    for name in (*SENSED, "hand_positions_W", "hand_velocities_W"):
        builder.ExportOutput(sensing.GetOutputPort(name), name)
    return (standing, braced), robot_state
