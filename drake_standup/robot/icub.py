"""The iCub from icub-models ([icub-models]), made Drake-ready, added to a plant; its joint tables.

add_icub parses the URDF that urdf.py prepared (STL visuals as OBJ, no collision
elements, optionally reduced to the ~40 bodies that carry mass or show something) and:
  1. Adds back the removed bare links as FixedOffsetFrames on their kept ancestors.
  2. Adds the contact primitives and frames of models/icub_contact.yaml.
  3. Adds a JointActuator per revolute joint with the scenario's effort limit and,
     if asked, the motor's rotor inertia and gear ratio (MOTOR_INERTIAS).
Then the joint tables: positions by joint name, vectors in actuator order, and where
each actuated joint sits in the state (actuated_joints).
"""

import copy
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.common.yaml import yaml_load_typed
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    Box,
    Capsule,
    Ellipsoid,
    GeometryId,
    ProximityProperties,
    Sphere,
)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    JointActuator,
    ModelInstanceIndex,
    PdControllerGains,
    RevoluteJoint,
)

from drake_standup.config.inputs import CONTACT_FILE, TASK_FRAMES
from drake_standup.config.scenario import EFFORT_LIMIT_NM, REFLECTED_INERTIA
from drake_standup.robot.urdf import (
    DEFAULT_MODEL,
    LeafFrame,
    ModelError,
    prepare_urdf,
)

# The motors of the authors' controller model ([authors-code]): gear ratio 100 on every joint;
# rotor inertia 0.0827e-4 kg m^2 on the legs and torso pitch/roll, 0.0585e-4 on torso yaw
# and the arms. Drake reflects it as ratio^2 x rotor on the joint (0.0827 and 0.0585 kg m^2):
# diagonal, where the authors' model also couples the shoulder's and torso's tendon-driven
# joints. Joints the authors did not list (neck, wrists) keep none.
MOTOR_GEAR_RATIO = 100.0
MOTOR_INERTIAS: dict[str, float] = {
    **{
        f"{side}_{joint}": 0.0827e-4
        for side in "lr"
        for joint in ("hip_pitch", "hip_roll", "hip_yaw", "knee", "ankle_pitch", "ankle_roll")
    },
    "torso_pitch": 0.0827e-4,
    "torso_roll": 0.0827e-4,
    "torso_yaw": 0.0585e-4,
    **{
        f"{side}_{joint}": 0.0585e-4
        for side in "lr"
        for joint in ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")
    },
}


def reflects_motor_inertia(setting: str, model_name: str) -> bool:
    """Whether robot.reflected_inertia (REFLECTED_INERTIA) turns it on for this model:
    real_robots means every model but the Gazebo ones, which model no motors."""
    if setting not in REFLECTED_INERTIA:
        raise ValueError(
            f"robot.reflected_inertia: '{setting}'; accepted: none | all | real_robots"
        )
    return setting == "all" or (setting == "real_robots" and "Gazebo" not in model_name)


# --- Contact geometry --------------------------------------------------------


@dataclass
class ContactShape:
    """One contact primitive, posed in a named robot frame."""

    name: str = ""
    frame: str = ""
    shape: str = "box"  # box | capsule | ellipsoid | sphere
    # box: [x, y, z] edge lengths; capsule: [radius, length]; ellipsoid: [a, b, c]
    # semi-axes; sphere: [radius]. Metres.
    size_m: list[float] = field(default_factory=list)
    xyz_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy_rad: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    group: str = ""  # sole | thigh | buttocks: how contact forces are reported


@dataclass
class NamedFrame:
    """A frame added to the robot, posed in an existing robot frame."""

    name: str = ""
    parent: str = ""
    xyz_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy_rad: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class ContactModel:
    """Hydroelastic parameters and primitives for the robot (models/icub_contact.yaml)."""

    hydroelastic_modulus_Pa: float = 1.0e6
    resolution_hint_m: float = 0.02
    hunt_crossley_dissipation_s_per_m: float = 5.0
    friction_coefficient: float = 1.0
    frames: list[NamedFrame] = field(default_factory=list)
    shapes: list[ContactShape] = field(default_factory=list)


# Parsed contact models by (path, modification time): parsing the YAML took
# ~3 ms of every build_diagram (measured).
_CONTACT_MODELS: dict[tuple[str, int], ContactModel] = {}


def load_contact_model(path: Path = CONTACT_FILE) -> ContactModel:
    """The contact model in path (a fresh copy: the caller may change it)."""
    path = Path(path)
    key = (str(path.resolve()), path.stat().st_mtime_ns)
    model = _CONTACT_MODELS.get(key)
    if model is None:
        model = _CONTACT_MODELS[key] = yaml_load_typed(schema=ContactModel, filename=str(path))
    return copy.deepcopy(model)


def _shape(spec: ContactShape):
    s = spec.size_m
    expected = {"box": 3, "capsule": 2, "ellipsoid": 3, "sphere": 1}
    if spec.shape not in expected:
        raise ModelError(
            f"contact shape '{spec.name}': shape '{spec.shape}' unknown; "
            f"accepted: {', '.join(expected)}"
        )
    if len(s) != expected[spec.shape]:
        raise ModelError(f"contact shape '{spec.name}': size_m needs {expected[spec.shape]} values")
    if spec.shape == "box":
        return Box(*s)
    if spec.shape == "capsule":
        return Capsule(*s)
    if spec.shape == "ellipsoid":
        return Ellipsoid(*s)
    return Sphere(*s)


# --- Adding the robot to a plant ----------------------------------------------


@dataclass
class Robot:
    """Handles to the iCub inside a MultibodyPlant."""

    model_instance: ModelInstanceIndex
    model_name: str
    joint_names: list[str]  # revolute joints, in actuator order
    contact_groups: dict[str, list[str]]  # group -> contact geometry names
    contact_geometries: dict[str, GeometryId]  # contact geometry name -> id
    contact_shapes: list[ContactShape]
    leaf_frames: list[LeafFrame]
    contact_modulus_Pa: float  # the contact shapes' hydroelastic modulus

    # Task frame -> model frame: the controller speaks of hands and soles. The table lives
    # in config, whose validate checks that a model has these frames (scene_frames).
    TASK_FRAMES = TASK_FRAMES

    def frame(self, plant: MultibodyPlant, task_name: str):
        """The plant frame behind a task frame name (see TASK_FRAMES)."""
        return plant.GetFrameByName(self.TASK_FRAMES[task_name], self.model_instance)


def add_icub(
    plant: MultibodyPlant,
    model_name: str = DEFAULT_MODEL,
    *,
    reduce: bool = True,
    visuals: bool = True,
    effort_limit_Nm: float = EFFORT_LIMIT_NM,
    pd_gains: tuple[float, float] | None = None,
    contact: ContactModel | None = None,
    visual_max_faces: int = 1000,
    motor_inertia: bool = False,
) -> Robot:
    """Adds the iCub to plant (before Finalize) and returns its handles.

    pd_gains (Kp [N m/rad], Kd [N m s/rad]) gives every joint Drake's built-in
    implicit joint PD; None leaves the actuators pure torque sources. motor_inertia:
    the actuators of MOTOR_INERTIAS' joints get their rotor inertia and gear ratio, so
    that the plant's mass matrix (and any model of the same plant) has the reflected
    inertia on their diagonal.
    """
    prepared = prepare_urdf(
        model_name, reduce=reduce, visuals=visuals, visual_max_faces=visual_max_faces
    )
    parser = Parser(plant)
    (instance,) = parser.AddModels(str(prepared.path))
    contact = contact if contact is not None else load_contact_model()
    X_BF = _add_frames(plant, instance, prepared.leaf_frames, contact)
    joint_names = _add_actuators(plant, instance, effort_limit_Nm, pd_gains, motor_inertia)
    groups, geometries = _add_contact_geometry(plant, instance, contact, X_BF)
    return Robot(
        instance,
        model_name,
        joint_names,
        groups,
        geometries,
        list(contact.shapes),
        prepared.leaf_frames,
        contact.hydroelastic_modulus_Pa,
    )


def _add_frames(
    plant: MultibodyPlant,
    instance: ModelInstanceIndex,
    leaf_frames: list[LeafFrame],
    contact: ContactModel,
) -> dict[str, RigidTransform]:
    """Adds the removed bare links' frames and the contact model's frames; returns the pose
    of each in its body (before Finalize, frame poses are known only from these tables)."""
    for leaf in leaf_frames:
        parent = plant.GetBodyByName(leaf.parent_body, instance)
        plant.AddFrame(FixedOffsetFrame(leaf.name, parent.body_frame(), leaf.X_PF))

    X_BF: dict[str, RigidTransform] = {f.name: f.X_PF for f in leaf_frames}
    for spec in contact.frames:
        parent = plant.GetFrameByName(spec.parent, instance)
        X_PF = RigidTransform(RollPitchYaw(spec.rpy_rad), spec.xyz_m)
        X_BF[spec.name] = X_BF.get(spec.parent, RigidTransform()) @ X_PF
        plant.AddFrame(FixedOffsetFrame(spec.name, parent, X_PF))
    return X_BF


def _add_actuators(
    plant: MultibodyPlant,
    instance: ModelInstanceIndex,
    effort_limit_Nm: float,
    pd_gains: tuple[float, float] | None,
    motor_inertia: bool,
) -> list[str]:
    """Adds a JointActuator per revolute joint (see add_icub); returns their joints' names."""
    joint_names = []
    for index in plant.GetJointIndices(instance):
        joint = plant.get_joint(index)
        if isinstance(joint, RevoluteJoint):
            joint_names.append(joint.name())
            actuator = plant.AddJointActuator(joint.name(), joint, effort_limit_Nm)
            if motor_inertia and joint.name() in MOTOR_INERTIAS:
                actuator.set_default_rotor_inertia(MOTOR_INERTIAS[joint.name()])
                actuator.set_default_gear_ratio(MOTOR_GEAR_RATIO)
            if pd_gains is not None:
                kp, kd = pd_gains
                actuator.set_controller_gains(PdControllerGains(p=kp, d=kd))
    return joint_names


def _add_contact_geometry(
    plant: MultibodyPlant,
    instance: ModelInstanceIndex,
    contact: ContactModel,
    X_BF: dict[str, RigidTransform],
) -> tuple[dict[str, list[str]], dict[str, GeometryId]]:
    """Registers the contact model's shapes (none without a scene graph); returns group ->
    geometry names and geometry name -> id."""
    groups: dict[str, list[str]] = {}
    geometries: dict[str, GeometryId] = {}
    if plant.geometry_source_is_registered():
        for spec in contact.shapes:
            frame = plant.GetFrameByName(spec.frame, instance)
            X_FG = RigidTransform(RollPitchYaw(spec.rpy_rad), spec.xyz_m)
            # Before Finalize, frame poses are known only from our own tables.
            X_BG = X_BF.get(spec.frame, RigidTransform()) @ X_FG
            props = ProximityProperties()
            AddContactMaterial(
                dissipation=contact.hunt_crossley_dissipation_s_per_m,
                friction=CoulombFriction(
                    contact.friction_coefficient, contact.friction_coefficient
                ),
                properties=props,
            )
            AddCompliantHydroelasticProperties(
                contact.resolution_hint_m, contact.hydroelastic_modulus_Pa, props
            )
            geometries[spec.name] = plant.RegisterCollisionGeometry(
                frame.body(), X_BG, _shape(spec), spec.name, props
            )
            groups.setdefault(spec.group, []).append(spec.name)
    return groups, geometries


def set_joint_positions(
    plant: MultibodyPlant, context, instance, positions: dict[str, float]
) -> None:
    """Sets revolute joint angles by joint name (never by list position)."""
    for name, value in positions.items():
        plant.GetJointByName(name, instance).set_angle(context, float(value))


def actuated_vector(plant: MultibodyPlant, instance, values: dict[str, float]) -> np.ndarray:
    """Vector in actuator order from a name -> value map (missing names are 0)."""
    out = np.zeros(plant.num_actuated_dofs(instance))
    for index in plant.GetJointActuatorIndices(instance):
        actuator: JointActuator = plant.get_joint_actuator(index)
        out[actuator.input_start()] = values.get(actuator.joint().name(), 0.0)
    return out


@dataclass
class ActuatedJoints:
    """The instance's actuated joints in actuation order (the order of the
    actuation input and net_actuation output), and where each joint's position
    and velocity sit in the instance's state [q; v]."""

    names: list[str]
    q_index: np.ndarray  # (n_u,) into the instance's q
    v_index: np.ndarray  # (n_u,) into the instance's v


def velocity_start(plant: MultibodyPlant, instance: ModelInstanceIndex) -> int:
    """Where the instance's velocities start in the plant's v."""
    joints = [plant.get_joint(j) for j in plant.GetJointIndices(instance)]
    return min(j.velocity_start() for j in joints if j.num_velocities() > 0)


def actuated_joints(plant: MultibodyPlant, instance: ModelInstanceIndex) -> ActuatedJoints:
    """The instance's actuated joints (add_icub: one actuator per revolute joint)."""
    joints = [plant.get_joint(j) for j in plant.GetJointIndices(instance)]
    first_q = min(j.position_start() for j in joints if j.num_positions() > 0)
    first_v = velocity_start(plant, instance)
    actuators = sorted(
        (plant.get_joint_actuator(i) for i in plant.GetJointActuatorIndices(instance)),
        key=lambda a: a.input_start(),
    )
    return ActuatedJoints(
        names=[a.joint().name() for a in actuators],
        q_index=np.array([a.joint().position_start() - first_q for a in actuators]),
        v_index=np.array([a.joint().velocity_start() - first_v for a in actuators]),
    )


def arm_joint_names(plant: MultibodyPlant, robot: Robot) -> list[str]:
    """The arms' joints, from the kinematic tree: those on one hand's path to the root and
    not on the other's (the torso, which both paths share, is not an arm's), root to hand."""

    def path(task: str) -> list[str]:
        body, names = robot.frame(plant, task).body(), []
        while body.index() != plant.world_body().index():
            joint = _parent_joint(plant, body)
            if joint.num_velocities() == 1:
                names.append(joint.name())
            body = joint.parent_body()
        return names[::-1]

    left, right = path("l_hand"), path("r_hand")
    return [n for n in left if n not in right] + [n for n in right if n not in left]


def _parent_joint(plant: MultibodyPlant, body):
    """The joint whose child is body (a tree: exactly one)."""
    for index in plant.GetJointIndices(body.model_instance()):
        joint = plant.get_joint(index)
        if joint.child_body().index() == body.index():
            return joint
    raise ValueError(f"{body.name()}: no joint has it as child")
