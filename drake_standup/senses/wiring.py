"""The robot's senses and muscles in the stand-up diagram (robot.hardware: icub).

add_senses puts the sensors (sensors.py, with Drake's Gyroscope and Accelerometer at the
IMU frame) on the station's plant ports and the estimator (estimator.py) behind them, and
returns, by the station's names, every port the stand-up controller reads: the
estimator's robot_state, hand_wrenches_W and pad_forces_W, the leg sensors' loads made of
those pads' forces, and the sensing (world/sensing.py) of the estimated state. add_muscles
puts the joints (muscles.py, with the delay's extra ticks) between the controller's
torques and the plant.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.systems.framework import DiagramBuilder, OutputPort, System
from pydrake.systems.primitives import DiscreteTimeDelay, MatrixGain
from pydrake.systems.sensors import Accelerometer, Gyroscope

from drake_standup.config import Scenario
from drake_standup.robot.icub import velocity_start
from drake_standup.senses.estimator import RobotEstimator
from drake_standup.senses.hardware import IMU_FRAME, ICubHardware, hardware
from drake_standup.senses.muscles import JointMuscles
from drake_standup.senses.sensors import RobotSensors
from drake_standup.world.scene import robot_last_com, set_seated_state
from drake_standup.world.sensing import SENSED, pad_sensing
from drake_standup.world.station import Station, pad_load_gains

# The estimates logged beside the truth (signals.npz): name -> the estimator's port.
ESTIMATES = {
    "estimated_robot_state": "robot_state",
    "estimated_hand_wrenches_W": "hand_wrenches_W",
    "estimated_pad_forces_W": "pad_forces_W",
    "imu_attitude_W": "imu_attitude_W",
}


@dataclass
class Senses:
    """The robot's senses in a diagram: the ports the controller reads (by the station's
    names) and the estimates to log beside the truth (ESTIMATES, estimated_com_W, ...)."""

    hardware: ICubHardware
    controller_inputs: dict[str, OutputPort]
    estimates: dict[str, OutputPort]


def joint_damping(scenario: Scenario) -> Callable[[str], float] | None:
    """The joints' viscous friction (N m s/rad by joint name, the identified times
    hardware.friction_scale) for the plant's joint damping under icub; None under ideal."""
    if scenario.robot.hardware != "icub":
        return None
    hw = hardware(scenario.hardware)
    return lambda name: hw.friction_of(name).viscous_Nms * hw.friction_scale


def add_senses(
    builder: DiagramBuilder, station: Station, scenario: Scenario, world: System
) -> Senses:
    """The sensors and the estimator on the station (the module docstring)."""
    hw = hardware(scenario.hardware)
    plant, robot = station.plant, station.robot
    sensors = builder.AddNamedSystem("robot_sensors", RobotSensors(plant, robot.model_instance, hw))
    builder.Connect(world.GetOutputPort("robot_state"), sensors.GetInputPort("robot_state"))
    builder.Connect(world.GetOutputPort("reaction_forces"), sensors.GetInputPort("reaction_forces"))
    _add_imu(builder, station, world, sensors)
    own = station.scene.alone or station.scene  # the robot's own model (the controller's)
    context = own.plant.CreateDefaultContext()
    set_seated_state(own, context)
    x0 = own.plant.GetPositionsAndVelocities(context, own.robot.model_instance)
    pads = [
        shape.frame
        for name in station.pad_groups
        for shape in robot.contact_shapes
        if shape.name == name
    ]
    estimator = builder.AddNamedSystem(
        "estimator", RobotEstimator(own.plant, own.robot, hw, x0, pads)
    )
    for name in ("encoder_positions", "encoder_velocities", "imu", "ft_wrenches"):
        builder.Connect(sensors.GetOutputPort(name), estimator.GetInputPort(name))
    inputs = {
        name: estimator.GetOutputPort(name)
        for name in ("robot_state", "hand_wrenches_W", "pad_forces_W")
    }
    for name, gain in pad_load_gains(robot, list(station.pad_groups)).items():
        system = builder.AddNamedSystem(f"estimated_{name}", MatrixGain(gain))
        builder.Connect(inputs["pad_forces_W"], system.get_input_port())
        inputs[name] = system.get_output_port()
    sensing = builder.AddNamedSystem(
        "estimated_sensing",
        pad_sensing(plant, robot, station.standing, station.braced, robot_last_com(station.scene)),
    )
    builder.Connect(inputs["robot_state"], sensing.GetInputPort("robot_state"))
    builder.Connect(inputs["hand_wrenches_W"], sensing.GetInputPort("hand_wrenches_W"))
    inputs |= {name: sensing.GetOutputPort(name) for name in SENSED}
    estimates = {name: estimator.GetOutputPort(port) for name, port in ESTIMATES.items()}
    estimates["estimated_com_W"] = sensing.GetOutputPort("com_W")
    estimates["estimated_com_velocity_W"] = sensing.GetOutputPort("com_velocity_W")
    return Senses(hw, inputs, estimates)


def _add_imu(builder: DiagramBuilder, station: Station, world: System, sensors: System) -> None:
    """Drake's Gyroscope and Accelerometer at the IMU frame, into the sensors."""
    plant = station.plant
    frame = plant.GetFrameByName(IMU_FRAME, station.robot.model_instance)
    body = frame.body()
    X_BS = frame.GetFixedPoseInBodyFrame()
    gravity = plant.gravity_field().gravity_vector()
    for name, system in (
        ("gyroscope", Gyroscope(body, RigidTransform(X_BS))),
        ("accelerometer", Accelerometer(body, RigidTransform(X_BS), gravity)),
    ):
        system = builder.AddNamedSystem(name, system)
        builder.Connect(world.GetOutputPort("body_poses"), system.get_body_poses_input_port())
        builder.Connect(
            world.GetOutputPort("body_spatial_velocities"),
            system.get_body_velocities_input_port(),
        )
        if name == "accelerometer":
            builder.Connect(
                world.GetOutputPort("body_spatial_accelerations"),
                system.get_body_accelerations_input_port(),
            )
        builder.Connect(system.get_measurement_output_port(), sensors.GetInputPort(name))


def add_muscles(
    builder: DiagramBuilder,
    station: Station,
    scenario: Scenario,
    world: System,
    senses: Senses,
    command: OutputPort,
) -> None:
    """The joints between the controller's torques (command) and the plant: the delay's
    ticks past the first (which the estimator's tick already makes), then JointMuscles,
    which compensate friction at the senses' estimated velocities."""
    hw = senses.hardware
    plant, robot = station.plant, station.robot
    nu = len(station.joints.names)
    if hw.delay_ticks > 1:
        delay = builder.AddNamedSystem(
            "command_delay", DiscreteTimeDelay(hw.period_s, hw.delay_ticks - 1, nu)
        )
        builder.Connect(command, delay.get_input_port())
        command = delay.get_output_port()
    context = plant.CreateDefaultContext()
    set_seated_state(station.scene, context)
    M = plant.CalcMassMatrix(context)
    start = velocity_start(plant, robot.model_instance)
    # What a torque at each joint alone moves: 1 / (M^-1)_jj (below M_jj: the links it carries
    # move with it).
    inertia = 1.0 / np.diag(np.linalg.inv(M))[start + np.asarray(station.joints.v_index)]
    muscles = builder.AddNamedSystem(
        "muscles",
        JointMuscles(
            plant,
            robot.model_instance,
            station.joints,
            hw,
            scenario.plant.time_step,
            inertia=inertia,
            q0=plant.GetPositions(context, robot.model_instance),
        ),
    )
    builder.Connect(command, muscles.GetInputPort("command"))
    builder.Connect(world.GetOutputPort("robot_state"), muscles.GetInputPort("robot_state"))
    builder.Connect(
        senses.controller_inputs["robot_state"], muscles.GetInputPort("estimated_state")
    )
    builder.Connect(muscles.GetOutputPort("actuation"), world.GetInputPort("actuation"))
    builder.Connect(
        muscles.GetOutputPort("generalized_friction"), world.GetInputPort("generalized_friction")
    )
