"""The world of the stand-up: a discrete MultibodyPlant with the iCub, a chair
and a floor, hydroelastic contact, and the robot's seated initial state."""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, SceneGraph
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant
from pydrake.systems.framework import Context, DiagramBuilder

from drake_standup.config import Scenario, ScenarioError, chair_file
from drake_standup.config.inputs import add_sdf
from drake_standup.config.phases import PHASES
from drake_standup.config.resources import model_file
from drake_standup.helper.body import GRIPS, HelperBody, add_helper_body
from drake_standup.robot.icub import Robot, add_icub, reflects_motor_inertia, set_joint_positions
from drake_standup.world.chair import chair_sdf
from drake_standup.world.perturbations import scale_friction
from drake_standup.world.seating import SeatedPose, seated_pose


class _NoDeformableHalfSpaceWarning(logging.Filter):
    """Drake warns, for every rigid half-space, that deformable bodies cannot
    touch it; the scene has no deformable bodies, so the warning says nothing."""

    def filter(self, record: logging.LogRecord) -> bool:
        return "half spaces are not currently supported for deformable" not in record.getMessage()


logging.getLogger("drake").addFilter(_NoDeformableHalfSpaceWarning())


@dataclass
class Scene:
    plant: MultibodyPlant
    scene_graph: SceneGraph
    robot: Robot
    # The robot on its chair at t = 0 (world/seating.py).
    seated: SeatedPose
    # The helper's body (human.mode: body, helper/body.py), or None.
    helper: HelperBody | None = None
    # With a helper's body: the same scene without it (the robot's own model, for the
    # controller: it needs every other model welded), else None.
    alone: Scene | None = None


def add_scene(
    builder: DiagramBuilder,
    scenario: Scenario,
    *,
    pd_gains: tuple[float, float] | None = None,
    visuals: bool = True,
) -> Scene:
    """Adds plant and scene graph to builder; returns the finalized scene."""
    plant, scene_graph = AddMultibodyPlant(scenario.plant, builder)
    robot = add_icub(
        plant,
        scenario.robot.model,
        reduce=scenario.robot.reduced,
        visuals=visuals,
        effort_limit_Nm=scenario.robot.effort_limit_Nm,
        pd_gains=pd_gains,
        visual_max_faces=scenario.robot.visual_max_faces,
        motor_inertia=reflects_motor_inertia(
            scenario.robot.reflected_inertia, scenario.robot.model
        ),
    )
    parser = Parser(plant)
    (floor,) = add_sdf(parser, model_file("floor.sdf"))
    # One model with a frame 'chair' (config.validate parsed a user's file so).
    if scenario.chair.file:
        (chair,) = add_sdf(parser, chair_file(scenario.chair.file))
    else:
        (chair,) = parser.AddModelsFromString(chair_sdf(scenario.chair), "sdf")
    world = plant.world_frame()
    plant.WeldFrames(world, plant.GetFrameByName("floor", floor))
    plant.WeldFrames(
        world,
        plant.GetFrameByName("chair", chair),
        RigidTransform(scenario.chair.xyz_m),
    )
    helper = alone = None
    if scenario.human.mode == "body":  # the person holds the hands where the robot sits
        alone = _scene_alone(scenario)
        helper = add_helper_body(plant, scenario.human.body, seated_hands_W(alone))
    plant.Finalize()
    seated = seated_pose(plant, robot, scenario)
    # Model error of perturbation.friction_scale: every surface, in the model.
    scale_friction(plant, scene_graph, scenario.perturbation.friction_scale)

    # The robot touches the world only through its pads; pads never touch each
    # other (self-collision is not part of this task).
    robot_geometries = GeometrySet(list(robot.contact_geometries.values()))
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration().ExcludeWithin(robot_geometries)
    )
    return Scene(plant, scene_graph, robot, seated, helper, alone)


def without_body(scenario: Scenario) -> Scenario:
    """scenario with the helper's body taken out of the plant (human.mode scripted)."""
    return dataclasses.replace(scenario, human=dataclasses.replace(scenario.human, mode="scripted"))


def _scene_alone(scenario: Scenario) -> Scene:
    """The scenario's scene without the helper's body, nor visuals."""
    return add_scene(DiagramBuilder(), without_body(scenario), visuals=False)


def seated_hands_W(scene: Scene) -> np.ndarray:
    """(2, 3) the robot's l_hand and r_hand frames' origins as it sits in scene (the
    helper's body is placed from them before the plant is built)."""
    context = scene.plant.CreateDefaultContext()
    set_seated_state(scene, context)
    return np.array(
        [scene.robot.frame(scene.plant, h).CalcPoseInWorld(context).translation() for h in GRIPS]
    )


def set_seated_state(scene: Scene, plant_context: Context) -> None:
    """Puts the robot in the scene's seated pose (scene.seated), at rest."""
    plant = scene.plant
    instance = scene.robot.model_instance
    set_joint_positions(plant, plant_context, instance, scene.seated.joints_rad)
    root = plant.GetBodyByName("root_link", instance)
    plant.SetFreeBodyPose(plant_context, root, scene.seated.base)
    plant.SetVelocities(plant_context, instance, 0.0 * plant.GetVelocities(plant_context, instance))
    if scene.helper is not None:
        person = scene.helper.person.model_instance
        for name, angle in scene.helper.q0.items():
            plant.GetJointByName(name, person).set_angle(plant_context, angle)
        plant.SetVelocities(plant_context, person, np.zeros(plant.num_velocities(person)))


def _standing_context(scene: Scene, scenario: Scenario, posture_rad: dict[str, float]):
    """A plant context of the robot in a standing posture: the joints named in
    posture_rad at their values (the others as seated), the base upright at the seated
    yaw, 1 m up; and the soles' heights when seated."""
    plant = scene.plant
    instance = scene.robot.model_instance
    context = plant.CreateDefaultContext()
    set_seated_state(scene, context)
    soles = [scene.robot.frame(plant, name) for name in ("l_sole", "r_sole")]
    sole_z_seated = [frame.CalcPoseInWorld(context).translation()[2] for frame in soles]
    set_joint_positions(plant, context, instance, posture_rad)
    root = plant.GetBodyByName("root_link", instance)
    yaw = scenario.initial.base_rpy_rad[2]
    plant.SetFreeBodyPose(context, root, RigidTransform(RollPitchYaw(0.0, 0.0, yaw), [0, 0, 1]))
    return context, soles, sole_z_seated


def erect_com_height_m(scene: Scene, scenario: Scenario, posture_rad: dict[str, float]) -> float:
    """The CoM's height above the floor in a standing posture (_standing_context), the
    soles at the height they rest at on the floor when seated. With the sagittal
    leg angles summing to zero (hip pitch + knee + ankle pitch, as in the authors' state-4
    posture) the soles are then flat on the floor (checked by the caller's tests)."""
    plant = scene.plant
    context, soles, sole_z_seated = _standing_context(scene, scenario, posture_rad)
    sole_z = [frame.CalcPoseInWorld(context).translation()[2] for frame in soles]
    com_z = plant.CalcCenterOfMassPositionInWorld(context, [scene.robot.model_instance])[2]
    return float(com_z - min(sole_z) + min(sole_z_seated))


# The joints standing_com_height_m straightens (those the model has): legs and torso.
_STRAIGHT = [f"{s}_{j}" for s in "lr" for j in ("hip_pitch", "hip_roll", "hip_yaw", "knee")]
_STRAIGHT += [f"{s}_{j}" for s in "lr" for j in ("ankle_pitch", "ankle_roll")]
_STRAIGHT += ["torso_pitch", "torso_roll", "torso_yaw"]
# How far above the model's straight standing CoM a phase's com_height_m may end: the arms
# raised higher than the posture's and the soles' rest height, well under 1 cm each. m.
COM_HEIGHT_MARGIN_M = 0.02


def standing_straight_com_height_m(
    scene: Scene, scenario: Scenario, posture_rad: dict[str, float]
) -> float:
    """The highest the CoM stands with the soles flat on the floor: erect_com_height_m of
    posture_rad with the legs and the torso straight (their joints at 0), the arms as
    posture_rad has them."""
    instance = scene.robot.model_instance
    straight = {n: 0.0 for n in _STRAIGHT if scene.plant.HasJointNamed(n, instance)}
    return erect_com_height_m(scene, scenario, {**posture_rad, **straight})


def check_com_heights(scene: Scene, scenario: Scenario) -> None:
    """Each phase's com_height_m within the robot's reach: at most its CoM standing
    straight (standing_straight_com_height_m of the phase's posture) + COM_HEIGHT_MARGIN_M;
    raises ScenarioError (one line). config.validate, which builds no plant, has checked
    that it is > 0."""
    model = scenario.robot.model
    for name in PHASES:
        phase = getattr(scenario.phases, name)
        if phase.com_height_m is None:
            continue
        straight = standing_straight_com_height_m(scene, scenario, phase.posture_rad)
        top = round(straight + COM_HEIGHT_MARGIN_M, 3)
        if not 0.0 < phase.com_height_m <= top:
            raise ScenarioError(
                f"phases.{name}.com_height_m: {phase.com_height_m}; accepted: a number > 0 "
                f"and <= {top} (m: {model}'s CoM standing straight, {straight:.3f}, "
                f"+ {COM_HEIGHT_MARGIN_M})"
            )


def standing_offsets_m(
    scene: Scene, scenario: Scenario, posture_rad: dict[str, float]
) -> tuple[np.ndarray, np.ndarray]:
    """In a standing posture (_standing_context): the hands' origins from the CoM (2 x 3,
    left, right) and the soles' origins from it (2 x 3), world axes, m."""
    plant = scene.plant
    context, soles, _ = _standing_context(scene, scenario, posture_rad)
    com = plant.CalcCenterOfMassPositionInWorld(context, [scene.robot.model_instance])

    def offsets(names):
        frames = [scene.robot.frame(plant, name) for name in names]
        return np.array([f.CalcPoseInWorld(context).translation() - com for f in frames])

    return offsets(("l_hand", "r_hand")), offsets(("l_sole", "r_sole"))
