"""make_standup_controller(scenario, station, plan): the stand-up controller, as one diagram
of the systems of the paper: the state machine, the psi integrator, the CoM reference
generator and the whole-body controller.

    state machine ──mode──────────────────────────────────────────┐
       │ state, segment, advances                                  ▼
    advancement ◄──► CoM reference ──com_reference, progress──► whole-body controller
    (psi)            (x_d(psi))                                   (contact schedule, model,
                                                                   task references, QP) │ torques

The state machine (state_machine.py) follows the phase table (config/phases.py); the
advancement (advancement.py) integrates psi as continuous state; the CoM reference
(com_path.py) is x_d(psi) and its derivatives (its height the measured com_W's in a phase
whose height follows the CoM); the whole-body controller (whole_body.py)
runs the contact schedule (contact_schedule.py), the controller's model with its mass
estimate (control/model.py), the task references (task_references.py) and the QP
(control/controller.py) as plain objects, in one tick.

Inputs (a station's outputs of the same names, station.py): robot_state, pad_forces_W,
seat_pad_normal_forces_N, pads_vertical_force_N, hand_wrenches_W (measured), com_W,
com_velocity_W, omega_f_W, heel_x_W, thigh_x_W, thigh_z_W, buttocks_z_W,
standing_pull_usage, braced_pull_usage, pull_cop_shift_m;
response (1: the response code, config.RESPONSES' index: which of the pull the advancement
and the task references take, standup/task_references.py); and stand_up (1; > 0.5: start;
unconnected: never), which only the live helper has.
Outputs: actuation; controller_diagnostics (control/controller.py: DIAGNOSTICS); psi,
psi_dot, alpha; com_reference, x_d_W; standup_state, held_back, arms_braced, segment,
entry_times_s;
lean_W; compliance_W (the compliant response's offset and rate); mass_estimate.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
from pydrake.systems.framework import Diagram, DiagramBuilder

from drake_standup.config import Scenario
from drake_standup.config.responses import response_names, responses_of
from drake_standup.control.controller import WholeBodyController
from drake_standup.control.model import ControllerJoints, ControllerModel, contact_specs
from drake_standup.control.qp import as_slice
from drake_standup.robot.limbs import TRUNK_TWIST_JOINTS
from drake_standup.standup.advancement import TrajectoryAdvancement, for_robot
from drake_standup.standup.com_path import CoMReferenceGenerator
from drake_standup.standup.contact_schedule import ContactSchedule
from drake_standup.standup.plan import StandupPlan
from drake_standup.standup.state_machine import StandupStateMachine
from drake_standup.standup.task_references import PhaseReferences, TaskReferenceGenerator
from drake_standup.standup.whole_body import StandupWholeBodyController
from drake_standup.world.scene import robot_last_com
from drake_standup.world.sensing import standing_lean
from drake_standup.world.station import Station

# (system, its input) <- (system or "" for the diagram's own input, its output)
_WIRES = [
    ("state_machine", "psi", "advancement", "psi"),
    ("state_machine", "com_W", "", "com_W"),
    ("state_machine", "heel_x_W", "", "heel_x_W"),
    ("state_machine", "thigh_x_W", "", "thigh_x_W"),
    ("state_machine", "thigh_z_W", "", "thigh_z_W"),
    ("state_machine", "buttocks_z_W", "", "buttocks_z_W"),
    ("state_machine", "standing_pull_usage", "", "standing_pull_usage"),
    ("state_machine", "braced_pull_usage", "", "braced_pull_usage"),
    ("state_machine", "pull_cop_shift_m", "", "pull_cop_shift_m"),
    ("state_machine", "pad_forces_W", "", "pad_forces_W"),
    ("state_machine", "hand_wrenches_W", "", "hand_wrenches_W"),
    ("state_machine", "stand_up", "", "stand_up"),
    ("state_machine", "sit_down", "", "sit_down"),
    ("state_machine", "seat_pad_normal_forces_N", "", "seat_pad_normal_forces_N"),
    ("advancement", "com_W", "", "com_W"),
    ("advancement", "com_velocity_W", "", "com_velocity_W"),
    ("advancement", "omega_f_W", "", "omega_f_W"),
    ("advancement", "x_d_W", "com_reference", "x_d_W"),
    ("advancement", "lean_W", "controller", "lean_W"),
    ("advancement", "path_tangent_W", "com_reference", "path_tangent_W"),
    ("advancement", "path_progress", "com_reference", "path_progress"),
    ("advancement", "advances", "state_machine", "advances"),
    ("advancement", "hand_wrenches_W", "", "hand_wrenches_W"),
    ("advancement", "standup_state", "state_machine", "standup_state"),
    ("com_reference", "psi", "advancement", "psi"),
    ("com_reference", "psi_dot", "advancement", "psi_dot"),
    ("com_reference", "psi_ddot", "advancement", "psi_ddot"),
    ("com_reference", "segment", "state_machine", "segment"),
    ("com_reference", "com_W", "", "com_W"),
    ("controller", "mode", "state_machine", "mode"),
    ("controller", "robot_state", "", "robot_state"),
    ("controller", "seat_pad_normal_forces_N", "", "seat_pad_normal_forces_N"),
    ("controller", "pads_vertical_force_N", "", "pads_vertical_force_N"),
    ("controller", "hand_wrenches_W", "", "hand_wrenches_W"),
    ("controller", "com_reference", "com_reference", "com_reference"),
    ("controller", "path_progress", "com_reference", "path_progress"),
    ("controller", "psi_dot", "advancement", "psi_dot"),
    ("controller", "response", "", "response"),
    ("advancement", "response", "", "response"),
]
# The diagram's outputs: name -> (system, its output).
_OUTPUTS = {
    "actuation": ("controller", "actuation"),
    "controller_diagnostics": ("controller", "diagnostics"),
    "psi": ("advancement", "psi"),
    "psi_dot": ("advancement", "psi_dot"),
    "alpha": ("advancement", "alpha"),
    "com_reference": ("com_reference", "com_reference"),
    "x_d_W": ("com_reference", "x_d_W"),
    "standup_state": ("state_machine", "standup_state"),
    "held_back": ("state_machine", "held_back"),
    "arms_braced": ("state_machine", "arms_braced"),
    "segment": ("state_machine", "segment"),
    "entry_times_s": ("state_machine", "entry_times_s"),
    "lean_W": ("controller", "lean_W"),
    "compliance_W": ("controller", "compliance_W"),
    "mass_estimate": ("controller", "mass_estimate"),
    # What an advancement law beside this one reads (sim/diagram.py: the law from the truth).
    "path_tangent_W": ("com_reference", "path_tangent_W"),
    "path_progress": ("com_reference", "path_progress"),
    "advances": ("state_machine", "advances"),
    "psi_dot_law": ("advancement", "psi_dot_law"),
}


@dataclass
class StandupController:
    diagram: Diagram
    controller: WholeBodyController  # for its compute times (bench.py)


def make_standup_controller(
    scenario: Scenario, station: Station, plan: StandupPlan
) -> StandupController:
    """The diagram of the module docstring for the station's robot and its plan."""
    systems = _standup_systems(scenario, station, plan)
    diagram = _wired(systems)
    return StandupController(diagram, systems["controller"].controller)


def _standup_systems(scenario: Scenario, station: Station, plan: StandupPlan) -> dict:
    """The diagram's systems by name (_WIRES' names)."""
    # The robot's own model: a helper's body is no part of it (scene.alone).
    scene = station.scene.alone or station.scene
    plant, robot = scene.plant, scene.robot
    config, period_s = scenario.controller, scenario.controller_period_s
    table = plan.table
    g = -plant.gravity_field().gravity_vector()[2]
    specs = contact_specs(plant, robot, config, scenario.chair)
    joints = ControllerJoints.of(plant, robot)
    phases = PhaseReferences(
        table,
        config,
        joints.names,
        joints.q_min,
        joints.q_max,
        station.arm_joints,
        braced_drop_m=station.braced_drop_m,
    )
    model = ControllerModel(
        plant,
        robot,
        specs,
        config,
        period_s,
        last_com=robot_last_com(station.scene),
        # The joints' friction beyond the URDF's damping is the boards' to compensate (icub).
        unknown_damping=scene.added_damping,
    )
    responses = responses_of(response_names(scenario.response))
    return {
        "state_machine": StandupStateMachine(
            scenario.standup,
            table,
            len(station.pad_groups),
            station.sole_rows(),
            seat_top_z_m=scenario.chair.seat_top_z_m(),
        ),
        "advancement": TrajectoryAdvancement(
            for_robot(scenario.advancement, model.kinematics.nominal_mass_kg),
            tuple(r.advances for r in responses),
        ),
        "com_reference": CoMReferenceGenerator(),
        "controller": StandupWholeBodyController(
            ContactSchedule(config, table),
            model,
            TaskReferenceGenerator(
                config,
                phases,
                as_slice(joints.q_indices),
                period_s,
                g,
                scenario.compliance,
                standing_need=partial(standing_lean, support=station.standing),
                usage_limit=scenario.standup.standing_pull_usage_limit,
                v_joints=np.asarray(joints.v_indices),
                trunk=np.array([i for i, n in enumerate(joints.names) if n in TRUNK_TWIST_JOINTS]),
                responses=responses,
            ),
            WholeBodyController(
                plant,
                specs,
                joints,
                config,
                modes=plan.states,
                stance_modes=plan.stance_states,
                period_s=period_s,
            ),
            plant.num_multibody_states(robot.model_instance),
            period_s,
        ),
    }


def _wired(systems: dict) -> Diagram:
    """systems connected by _WIRES, the rest of their inputs and _OUTPUTS exported."""
    builder = DiagramBuilder()
    for name, system in systems.items():
        builder.AddNamedSystem(name, system)
    exported: set[str] = set()
    for system, port, source, output in _WIRES:
        destination = systems[system].GetInputPort(port)
        if source:
            builder.Connect(systems[source].GetOutputPort(output), destination)
        elif output in exported:
            builder.ConnectInput(output, destination)
        else:
            builder.ExportInput(destination, output)
            exported.add(output)
    for name, (system, port) in _OUTPUTS.items():
        builder.ExportOutput(systems[system].GetOutputPort(port), name)
    diagram = builder.Build()
    diagram.set_name("standup_controller")
    return diagram
