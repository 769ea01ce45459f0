"""The world of the stand-up: a discrete MultibodyPlant with the iCub, a chair
and a floor, hydroelastic contact, and the robot's seated initial state; and the
scene's derived standing numbers (StandingGeometry: the CoM's erect height, the hands'
and soles' offsets from the CoM in a standing posture), each posture's worked out once
per build, which the station, the sensing and the plan all read (scene.standing)."""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, SceneGraph
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import Context, DiagramBuilder

from drake_standup.config import ChairConfig, Scenario, ScenarioError
from drake_standup.config.chair_kind import make_chair
from drake_standup.config.inputs import add_sdf
from drake_standup.config.phases import PHASES
from drake_standup.config.resources import model_file
from drake_standup.helper.body import GRIPS, HelperBody, add_helper_body
from drake_standup.robot.icub import Robot, add_icub, reflects_motor_inertia, set_joint_positions
from drake_standup.robot.last_com import LastCoM
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
    # The robot standing in a posture, each posture's numbers worked out once (add_scene).
    standing: StandingGeometry | None = None
    # The controller's model's CoM of the last state, for the sensing (robot_last_com).
    last_com: LastCoM | None = None
    # Viscous damping the joints carry beyond the URDF's, by joint name (add_scene's
    # joint_damping: the robot's friction under icub); not the controller's to know.
    added_damping: dict[str, float] = dataclasses.field(default_factory=dict)


@dataclass(frozen=True)
class StandingPose:
    """The robot standing in one posture, its soles flat at the height they rest at when
    seated, upright at the seated yaw (world axes, m)."""

    com_height_m: float  # the CoM above the floor
    hands_from_com_m: np.ndarray  # (2, 3) the hands' origins from the CoM, left, right
    soles_from_com_m: np.ndarray  # (2, 3) the soles' origins from the CoM


class StandingGeometry:
    """The scene's standing numbers: one forward-kinematics pass per distinct posture, in
    one context of its own, kept for every later question of the build (the station's
    checks and standing support, the sensing, the plan's CoM heights). passes counts them.

    A posture names some joints; the others stay as seated (the arms of a braced posture).
    With the sagittal leg angles summing to zero (hip pitch + knee + ankle pitch, as in the
    authors' state-4 posture) the soles are flat on the floor (checked by the tests)."""

    def __init__(self, scene: Scene, yaw_rad: float):
        self._scene, self._yaw = scene, yaw_rad
        self._poses: dict[tuple, StandingPose] = {}
        self._context = None
        self._sole_z_seated = 0.0
        self.passes = 0

    def pose(self, posture_rad: dict[str, float]) -> StandingPose:
        key = tuple(sorted(posture_rad.items()))
        if key not in self._poses:
            self._poses[key] = self._solve(posture_rad)
        return self._poses[key]

    def erect_com_height_m(self, posture_rad: dict[str, float]) -> float:
        return self.pose(posture_rad).com_height_m

    def straight_com_height_m(self, posture_rad: dict[str, float]) -> float:
        """The highest the CoM stands with the soles flat: posture_rad with the legs and
        the torso straight (their joints at 0), the arms as posture_rad has them."""
        instance = self._scene.robot.model_instance
        plant = self._scene.plant
        straight = {n: 0.0 for n in _STRAIGHT if plant.HasJointNamed(n, instance)}
        return self.erect_com_height_m({**posture_rad, **straight})

    def _solve(self, posture_rad: dict[str, float]) -> StandingPose:
        scene, plant = self._scene, self._scene.plant
        instance = scene.robot.model_instance
        soles = [scene.robot.frame(plant, name) for name in ("l_sole", "r_sole")]
        hands = [scene.robot.frame(plant, name) for name in ("l_hand", "r_hand")]
        if self._context is None:
            self._context = plant.CreateDefaultContext()
            set_seated_state(scene, self._context)
            self._sole_z_seated = min(
                f.CalcPoseInWorld(self._context).translation()[2] for f in soles
            )
        context = self._context
        self.passes += 1
        set_joint_positions(plant, context, instance, scene.seated.joints_rad)
        set_joint_positions(plant, context, instance, posture_rad)
        root = plant.GetBodyByName("root_link", instance)
        upright = RigidTransform(RollPitchYaw(0.0, 0.0, self._yaw), [0.0, 0.0, 1.0])
        plant.SetFreeBodyPose(context, root, upright)
        com = plant.CalcCenterOfMassPositionInWorld(context, [instance])
        sole_p = np.array([f.CalcPoseInWorld(context).translation() for f in soles])
        hand_p = np.array([f.CalcPoseInWorld(context).translation() for f in hands])
        return StandingPose(
            com_height_m=float(com[2] - sole_p[:, 2].min() + self._sole_z_seated),
            hands_from_com_m=hand_p - com,
            soles_from_com_m=sole_p - com,
        )


def add_scene(
    builder: DiagramBuilder,
    scenario: Scenario,
    *,
    pd_gains: tuple[float, float] | None = None,
    visuals: bool = True,
    joint_damping: Callable[[str], float] | None = None,
) -> Scene:
    """Adds plant and scene graph to builder; returns the finalized scene. joint_damping:
    viscous damping (N m s/rad) to add to each actuated joint's own (by its name), which
    the plant integrates implicitly (None: the URDF's alone)."""
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
    added = {}
    if joint_damping is not None:
        for index in plant.GetJointActuatorIndices():  # by instance: empty before Finalize
            actuator = plant.get_joint_actuator(index)
            if actuator.model_instance() != robot.model_instance:
                continue
            joint = actuator.joint()
            added[joint.name()] = joint_damping(joint.name())
            joint.set_default_damping(joint.default_damping() + added[joint.name()])
    parser = Parser(plant)
    (floor,) = add_sdf(parser, model_file("floor.sdf"))
    chair = _add_chair(parser, scenario.chair)
    world = plant.world_frame()
    plant.WeldFrames(world, plant.GetFrameByName("floor", floor))
    plant.WeldFrames(
        world,
        plant.GetFrameByName("chair", chair),
        RigidTransform(scenario.chair.xyz_m),
    )
    helper = alone = None
    if _adds_body(scenario.human.mode):  # the person holds the hands where the robot sits
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
    scene = Scene(plant, scene_graph, robot, seated, helper, alone, added_damping=added)
    scene.standing = StandingGeometry(scene, scenario.initial.base_rpy_rad[2])
    return scene


def _add_chair(parser: Parser, chair: ChairConfig) -> ModelInstanceIndex:
    """The chair chair.kind makes (config/chair_kind.py; standard: the one of chair's numbers,
    a user's SDF file, or a mesh), with a frame 'chair'. Its seat is where the scenario
    says: load_scenario set seat_height_m from the made chair; one made in code is checked."""
    made = make_chair(chair)
    if abs(chair.seat_height_m - made.seat_height_m) > 5e-4:
        raise ScenarioError(
            f"chair.seat_height_m: {chair.seat_height_m:g}; accepted: "
            f"{made.seat_height_m:.4f}, the seat of the chair chair.kind '{chair.kind}' makes "
            "(load_scenario sets it so)"
        )
    if made.path is not None:
        (model,) = add_sdf(parser, Path(made.path))
    else:
        (model,) = parser.AddModelsFromString(made.sdf, "sdf")
    return model


def robot_last_com(scene: Scene) -> LastCoM:
    """The robot's LastCoM (robot/last_com.py), one per scene: the controller's model
    puts each state's CoM, the sensing reads it."""
    own = scene.alone or scene
    if own.last_com is None:
        own.last_com = LastCoM()
    return own.last_com


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


# The joints StandingGeometry.straight_com_height_m straightens (those the model has):
# legs and torso.
_STRAIGHT = [f"{s}_{j}" for s in "lr" for j in ("hip_pitch", "hip_roll", "hip_yaw", "knee")]
_STRAIGHT += [f"{s}_{j}" for s in "lr" for j in ("ankle_pitch", "ankle_roll")]
_STRAIGHT += ["torso_pitch", "torso_roll", "torso_yaw"]
# How far above the model's straight standing CoM a phase's com_height_m may end: the arms
# raised higher than the posture's and the soles' rest height, well under 1 cm each. m.
COM_HEIGHT_MARGIN_M = 0.02


def check_com_heights(scene: Scene, scenario: Scenario) -> None:
    """Each phase's com_height_m within the robot's reach: at most its CoM standing
    straight (scene.standing.straight_com_height_m of the phase's posture) +
    COM_HEIGHT_MARGIN_M; raises ScenarioError (one line). config.validate, which builds
    no plant, has checked that it is > 0."""
    model = scenario.robot.model
    for name in PHASES:
        phase = getattr(scenario.phases, name)
        if phase.com_height_m is None:
            continue
        straight = scene.standing.straight_com_height_m(phase.posture_rad)
        top = round(straight + COM_HEIGHT_MARGIN_M, 3)
        if not 0.0 < phase.com_height_m <= top:
            raise ScenarioError(
                f"phases.{name}.com_height_m: {phase.com_height_m}; accepted: a number > 0 "
                f"and <= {top} (m: {model}'s CoM standing straight, {straight:.3f}, "
                f"+ {COM_HEIGHT_MARGIN_M})"
            )


def _adds_body(mode: str) -> bool:
    """The helper human.mode names puts a person's body into the plant (plugins: adds_body)."""
    from drake_standup.config.plugins import resolve

    return bool(getattr(resolve("helpers", mode).obj, "adds_body", False))
