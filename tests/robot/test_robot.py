"""The iCub model (drake_standup.robot.icub) against values taken outside Drake.

Reference values come from the icub-models URDF read with xml.etree, from
models/icub_contact.yaml read with PyYAML and from models/chair.sdf and
models/floor.sdf read with xml.etree; the reduced model is checked against the
unreduced one, state by state.
"""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from pathlib import Path

import icub_models
import numpy as np
import pytest
import yaml
from pydrake.common.eigen_geometry import Quaternion
from pydrake.geometry import Box
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.multibody.tree import RevoluteJoint
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import Scenario
from drake_standup.robot.icub import (
    DEFAULT_MODEL,
    ContactModel,
    ModelError,
    Robot,
    add_icub,
    load_contact_model,
)
from drake_standup.world.scene import add_scene, set_seated_state

REPO = Path(__file__).resolve().parents[2]
URDF = Path(icub_models.get_model_file(DEFAULT_MODEL))
CONTACT_YAML = yaml.safe_load((REPO / "models" / "icub_contact.yaml").read_text())
PAD_NAMES = [shape["name"] for shape in CONTACT_YAML["shapes"]]
EFFORT_LIMIT_NM = 60.0
TOL = 1e-9
# Lowest pad points may sit this far from the surface they rest on (the seated
# pose was tuned for contact, not computed from it). m.
PAD_GAP_TOL_M = 0.002


# --- Independent references ----------------------------------------------------


def _urdf_root() -> ET.Element:
    return ET.parse(URDF).getroot()


def _urdf_total_mass() -> float:
    return sum(float(m.get("value")) for m in _urdf_root().findall("link/inertial/mass"))


def _urdf_revolute_joint_names() -> set[str]:
    return {j.get("name") for j in _urdf_root().findall("joint") if j.get("type") == "revolute"}


def _sdf_plane_height(path: Path, collision: str) -> float:
    """Height of an SDF <plane> collision with normal +z (a half-space floor)."""
    root = ET.parse(path).getroot()
    (col,) = [c for c in root.iter("collision") if c.get("name") == collision]
    normal = [float(s) for s in col.find("geometry/plane/normal").text.split()]
    assert normal == [0.0, 0.0, 1.0], "floor plane must face up"
    pose = col.find("pose")
    return float(pose.text.split()[2]) if pose is not None else 0.0


def _sdf_box_top(path: Path, collision: str) -> tuple[float, np.ndarray, np.ndarray]:
    """Top z and the x-y extent (lower, upper corners) of an axis-aligned SDF box."""
    root = ET.parse(path).getroot()
    (col,) = [c for c in root.iter("collision") if c.get("name") == collision]
    x, y, z, roll, pitch, yaw = (float(s) for s in col.find("pose").text.split())
    assert (roll, pitch, yaw) == (0.0, 0.0, 0.0), "box must be axis-aligned"
    sx, sy, sz = (float(s) for s in col.find("geometry/box/size").text.split())
    half = np.array([sx, sy]) / 2
    return z + sz / 2, np.array([x, y]) - half, np.array([x, y]) + half


# --- Fixtures --------------------------------------------------------------------


@pytest.fixture(scope="module", autouse=True)
def isolated_cache(tmp_path_factory):
    """Prepared URDFs go to a fresh cache, so tests neither read nor touch the user's."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("DRAKE_STANDUP_CACHE", str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="module")
def plants(isolated_cache) -> dict[bool, tuple[MultibodyPlant, Robot, object]]:
    """reduce -> (finalized plant, robot handles, context), without contact pads."""
    out = {}
    for reduce in (True, False):
        plant = MultibodyPlant(0.0)
        robot = add_icub(plant, reduce=reduce, visuals=False, contact=ContactModel())
        plant.Finalize()
        out[reduce] = (plant, robot, plant.CreateDefaultContext())
    return out


@pytest.fixture(scope="module")
def seated(isolated_cache):
    """The default scenario's scene (reduced, with pads) in its seated state."""
    scenario = Scenario()
    builder = DiagramBuilder()
    scene = add_scene(builder, scenario, visuals=False)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = scene.plant.GetMyContextFromRoot(context)
    set_seated_state(scene, plant_context)
    return scene, plant_context, scenario, diagram


def _pad_scene(reduce: bool):
    """Plant + SceneGraph with the robot and its pads, at the default state."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    robot = add_icub(plant, reduce=reduce, visuals=False)
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return plant, scene_graph, robot, plant.GetMyContextFromRoot(context), diagram


# --- Model contents ----------------------------------------------------------------


@pytest.mark.parametrize("reduce", [True, False], ids=["reduced", "full"])
def test_total_mass_matches_urdf(plants, reduce):
    """Drake's total mass vs the sum of every <mass value> in the URDF."""
    plant, robot, context = plants[reduce]
    expected = _urdf_total_mass()
    assert expected > 30.0  # the iCub is about 33 kg: guards an empty parse
    assert plant.CalcTotalMass(context, [robot.model_instance]) == pytest.approx(expected, abs=TOL)


@pytest.mark.parametrize("reduce", [True, False], ids=["reduced", "full"])
def test_joints_and_dimensions_match_urdf(plants, reduce):
    """Revolute joints by name vs type="revolute" in the URDF (32); nq = 7 + 32, nv = 6 + 32."""
    plant, robot, _ = plants[reduce]
    expected = _urdf_revolute_joint_names()
    assert len(expected) == 32
    revolute = {
        plant.get_joint(j).name()
        for j in plant.GetJointIndices(robot.model_instance)
        if isinstance(plant.get_joint(j), RevoluteJoint)
    }
    assert revolute == expected
    assert set(robot.joint_names) == expected
    assert len(robot.joint_names) == len(expected)
    assert plant.num_positions(robot.model_instance) == 7 + 32
    assert plant.num_velocities(robot.model_instance) == 6 + 32


@pytest.mark.parametrize("reduce", [True, False], ids=["reduced", "full"])
def test_one_actuator_per_revolute_joint_at_60_Nm(plants, reduce):
    """Actuated joint names vs the URDF's revolute joints, each once, effort limit 60 N m."""
    plant, robot, _ = plants[reduce]
    actuators = [
        plant.get_joint_actuator(a) for a in plant.GetJointActuatorIndices(robot.model_instance)
    ]
    joint_names = [a.joint().name() for a in actuators]
    assert sorted(joint_names) == sorted(_urdf_revolute_joint_names())
    assert [a.effort_limit() for a in actuators] == [EFFORT_LIMIT_NM] * len(actuators)


def test_reduction_shrinks_the_tree(plants):
    """Body counts: reduced < 50 (the point of reducing), unreduced > 200 (all 213 URDF links)."""
    n_reduced = len(plants[True][0].GetBodyIndices(plants[True][1].model_instance))
    n_full = len(plants[False][0].GetBodyIndices(plants[False][1].model_instance))
    assert n_reduced < 50
    assert n_full > 200
    assert n_full == len(_urdf_root().findall("link"))


@pytest.mark.parametrize("reduce", [True, False], ids=["reduced", "full"])
def test_task_frames_exist(isolated_cache, reduce):
    """Every Robot.TASK_FRAMES entry resolves to a frame of the robot (with the YAML's frames)."""
    plant = MultibodyPlant(0.0)
    robot = add_icub(plant, reduce=reduce, visuals=False, contact=load_contact_model())
    plant.Finalize()
    assert set(Robot.TASK_FRAMES) >= {"l_sole", "r_sole", "l_hand", "r_hand", "buttocks"}
    for task, frame_name in Robot.TASK_FRAMES.items():
        frame = robot.frame(plant, task)
        assert frame.name() == frame_name
        assert frame.model_instance() == robot.model_instance


def test_unknown_model_raises_one_line_model_error():
    """The ModelError message vs icub_models.get_robot_names(): one line, names robot.model."""
    with pytest.raises(ModelError) as info:
        add_icub(MultibodyPlant(0.0), "NoSuchRobot", visuals=False)
    message = str(info.value)
    assert "\n" not in message
    assert "robot.model" in message
    assert "NoSuchRobot" in message
    for name in icub_models.get_robot_names():
        assert name in message


# --- Reduced vs unreduced: same dynamics, same frames ---------------------------------


def _velocity_indices(plant: MultibodyPlant, instance) -> dict[tuple[str, int], int]:
    """(joint name, k) -> index of the joint's k-th velocity in the plant's v."""
    out = {}
    for index in plant.GetJointIndices(instance):
        joint = plant.get_joint(index)
        for k in range(joint.num_velocities()):
            out[(joint.name(), k)] = joint.velocity_start() + k
    return out


@pytest.fixture(scope="module")
def reduced_from_full(plants) -> np.ndarray:
    """perm with v_full[i] == v_reduced[perm[i]], matched by joint name."""
    full = _velocity_indices(plants[False][0], plants[False][1].model_instance)
    reduced = _velocity_indices(plants[True][0], plants[True][1].model_instance)
    assert set(full) == set(reduced)
    perm = np.empty(len(full), dtype=int)
    for key, i in full.items():
        perm[i] = reduced[key]
    assert sorted(perm) == list(range(len(full)))
    return perm


@pytest.fixture(params=range(5), ids=lambda seed: f"state{seed}")
def same_state(request, plants):
    """Sets one random state (by joint name and on root_link) in both plants."""
    rng = np.random.default_rng(request.param)
    quaternion = rng.normal(size=4)
    X_WB = RigidTransform(
        Quaternion(quaternion / np.linalg.norm(quaternion)), rng.uniform(-1.0, 1.0, 3)
    )
    V_WB = SpatialVelocity(w=rng.normal(size=3), v=rng.normal(size=3))
    full_plant, full_robot, _ = plants[False]
    q, v = {}, {}
    for name in sorted(full_robot.joint_names):
        joint = full_plant.GetJointByName(name, full_robot.model_instance)
        q[name] = rng.uniform(joint.position_lower_limits()[0], joint.position_upper_limits()[0])
        v[name] = rng.normal()
    for plant, robot, context in plants.values():
        for name in robot.joint_names:
            joint = plant.GetJointByName(name, robot.model_instance)
            joint.set_angle(context, q[name])
            joint.set_angular_rate(context, v[name])
        root = plant.GetBodyByName("root_link", robot.model_instance)
        plant.SetFreeBodyPose(context, root, X_WB)
        plant.SetFreeBodySpatialVelocity(context, root, V_WB)
    return plants


def test_mass_matrix_equal(same_state, reduced_from_full):
    """CalcMassMatrix of the reduced model, reordered by joint name, vs the unreduced one."""
    (r_plant, _, r_ctx), (f_plant, _, f_ctx) = same_state[True], same_state[False]
    M_full = f_plant.CalcMassMatrix(f_ctx)
    M_reduced = r_plant.CalcMassMatrix(r_ctx)[np.ix_(reduced_from_full, reduced_from_full)]
    np.testing.assert_allclose(M_reduced, M_full, rtol=0, atol=TOL)


def test_bias_and_gravity_terms_equal(same_state, reduced_from_full):
    """CalcBiasTerm and CalcGravityGeneralizedForces, reduced (reordered) vs unreduced."""
    (r_plant, _, r_ctx), (f_plant, _, f_ctx) = same_state[True], same_state[False]
    C_full = f_plant.CalcBiasTerm(f_ctx)
    assert np.abs(C_full).max() > 1.0  # the random velocities make it non-trivial
    np.testing.assert_allclose(
        r_plant.CalcBiasTerm(r_ctx)[reduced_from_full], C_full, rtol=0, atol=TOL
    )
    np.testing.assert_allclose(
        r_plant.CalcGravityGeneralizedForces(r_ctx)[reduced_from_full],
        f_plant.CalcGravityGeneralizedForces(f_ctx),
        rtol=0,
        atol=TOL,
    )


def test_center_of_mass_equal(same_state):
    """CalcCenterOfMassPositionInWorld of the robot instance, reduced vs unreduced."""
    (r_plant, r_robot, r_ctx), (f_plant, f_robot, f_ctx) = same_state[True], same_state[False]
    np.testing.assert_allclose(
        r_plant.CalcCenterOfMassPositionInWorld(r_ctx, [r_robot.model_instance]),
        f_plant.CalcCenterOfMassPositionInWorld(f_ctx, [f_robot.model_instance]),
        rtol=0,
        atol=TOL,
    )


def test_every_frame_pose_equal(same_state):
    """World pose of every frame of the unreduced model vs the reduced model's frame.

    Frames are matched by name. The only unreduced names allowed to be missing
    are Drake's own '<joint>_parent' frames of the removed fixed joints; each
    is checked against the reduced frame of that joint's child link instead.
    """
    (r_plant, r_robot, r_ctx), (f_plant, f_robot, f_ctx) = same_state[True], same_state[False]
    joint_of_parent_frame = {}
    for index in f_plant.GetJointIndices(f_robot.model_instance):
        joint = f_plant.get_joint(index)
        joint_of_parent_frame[joint.frame_on_parent().index()] = joint

    full_frames = [f_plant.get_frame(i) for i in f_plant.GetFrameIndices(f_robot.model_instance)]
    reduced_names = {
        r_plant.get_frame(i).name() for i in r_plant.GetFrameIndices(r_robot.model_instance)
    }
    assert reduced_names <= {frame.name() for frame in full_frames}
    same_name = 0
    for frame in full_frames:
        if frame.name() in reduced_names:
            counterpart = frame.name()
            same_name += 1
        else:
            joint = joint_of_parent_frame.get(frame.index())
            assert joint is not None, f"frame {frame.name()} missing from the reduced model"
            assert joint.type_name() == "weld", frame.name()
            assert joint.frame_on_child().name() == joint.child_body().name()
            counterpart = joint.child_body().name()
        X_full = frame.CalcPoseInWorld(f_ctx).GetAsMatrix4()
        X_reduced = (
            r_plant.GetFrameByName(counterpart, r_robot.model_instance)
            .CalcPoseInWorld(r_ctx)
            .GetAsMatrix4()
        )
        np.testing.assert_allclose(X_reduced, X_full, rtol=0, atol=TOL, err_msg=frame.name())
    # Every URDF link (body frame) at least must have been compared by name.
    assert same_name >= len(_urdf_root().findall("link"))


# --- Contact pads ---------------------------------------------------------------------


def _geometry_pose(plant, context, inspector, gid) -> RigidTransform:
    """X_WG from the body pose and the geometry's registered pose in its body frame."""
    body = plant.GetBodyFromFrameId(inspector.GetFrameId(gid))
    return plant.EvalBodyPoseInWorld(context, body) @ inspector.GetPoseInFrame(gid)


def _box_corners_W(X_WG: RigidTransform, box: Box) -> np.ndarray:
    half = np.array([box.width(), box.depth(), box.height()]) / 2
    return np.array(
        [X_WG.multiply(np.array(s) * half) for s in itertools.product((-1, 1), repeat=3)]
    )


def test_pads_are_hydroelastic_boxes_as_in_yaml(seated):
    """Each YAML pad vs its SceneGraph geometry: compliant hydroelastic, box of the YAML size."""
    scene, *_ = seated
    inspector = scene.scene_graph.model_inspector()
    assert sorted(scene.robot.contact_geometries) == sorted(PAD_NAMES)
    assert len(PAD_NAMES) == 5
    for spec in CONTACT_YAML["shapes"]:
        gid = scene.robot.contact_geometries[spec["name"]]
        assert inspector.GetName(gid).endswith(spec["name"])
        props = inspector.GetProximityProperties(gid)
        assert props is not None, spec["name"]
        assert props.HasProperty("hydroelastic", "compliance_type"), spec["name"]
        # Compliant, not rigid: only compliant hydroelastic geometry has a modulus.
        assert props.HasProperty("hydroelastic", "hydroelastic_modulus"), spec["name"]
        assert props.GetProperty("hydroelastic", "hydroelastic_modulus") == pytest.approx(
            CONTACT_YAML["hydroelastic_modulus_Pa"]
        )
        shape = inspector.GetShape(gid)
        assert spec["shape"] == "box" and isinstance(shape, Box)
        np.testing.assert_allclose(
            [shape.width(), shape.depth(), shape.height()], spec["size_m"], rtol=0, atol=1e-12
        )
        assert spec["name"] in scene.robot.contact_groups[spec["group"]]


@pytest.mark.parametrize("reduce", [True, False], ids=["reduced", "full"])
def test_pad_poses_follow_yaml(isolated_cache, reduce):
    """Pad world pose vs the world pose of its YAML frame composed with the YAML xyz/rpy."""
    plant, scene_graph, robot, context, _ = _pad_scene(reduce)
    inspector = scene_graph.model_inspector()
    for spec in CONTACT_YAML["shapes"]:
        X_FG = RigidTransform(RollPitchYaw(spec.get("rpy_rad", [0, 0, 0])), spec["xyz_m"])
        frame = plant.GetFrameByName(spec["frame"], robot.model_instance)
        expected = (frame.CalcPoseInWorld(context) @ X_FG).GetAsMatrix4()
        gid = robot.contact_geometries[spec["name"]]
        actual = _geometry_pose(plant, context, inspector, gid).GetAsMatrix4()
        np.testing.assert_allclose(actual, expected, rtol=0, atol=TOL, err_msg=spec["name"])


@pytest.mark.parametrize("pad", PAD_NAMES)
def test_seated_pad_rests_on_its_surface(seated, pad):
    """Lowest box corner in the seated pose vs the floor top (soles) or the seat top (others).

    Surfaces come from models/floor.sdf and models/chair.sdf (plus the
    scenario's chair position); pads on the seat must also be centred over it.
    """
    scene, plant_context, scenario, _ = seated
    (spec,) = [s for s in CONTACT_YAML["shapes"] if s["name"] == pad]
    inspector = scene.scene_graph.model_inspector()
    gid = scene.robot.contact_geometries[pad]
    X_WG = _geometry_pose(scene.plant, plant_context, inspector, gid)
    lowest = _box_corners_W(X_WG, inspector.GetShape(gid))[:, 2].min()

    if spec["group"] == "sole":
        floor_top = _sdf_plane_height(REPO / "models" / "floor.sdf", "floor_collision")
        assert floor_top == 0.0
        assert abs(lowest - floor_top) <= PAD_GAP_TOL_M, f"{pad} lowest z = {lowest:.4f}"
    else:
        seat_top, lo, hi = _sdf_box_top(REPO / "models" / "chair.sdf", "seat_collision")
        chair_xyz = np.asarray(scenario.chair.xyz_m)
        seat_top += chair_xyz[2]
        assert seat_top == pytest.approx(0.2195, abs=1e-12)
        assert abs(lowest - seat_top) <= PAD_GAP_TOL_M, f"{pad} lowest z = {lowest:.4f}"
        centre = X_WG.translation()[:2]
        assert np.all(centre >= lo + chair_xyz[:2]) and np.all(centre <= hi + chair_xyz[:2])


# --- Motor reflected inertia ---------------------------------------------------------

# The authors' motor model ([authors-code]), written out here: gear ratio 100; rotor inertia
# 0.0827e-4 kg m^2 on the legs and torso pitch/roll, 0.0585e-4 on torso yaw and the arms.
_LEGS_TORSO = [
    f"{side}_{joint}"
    for side in "lr"
    for joint in ("hip_pitch", "hip_roll", "hip_yaw", "knee", "ankle_pitch", "ankle_roll")
] + ["torso_pitch", "torso_roll"]
_ARMS_YAW = ["torso_yaw"] + [
    f"{side}_{joint}"
    for side in "lr"
    for joint in ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")
]


def _mass_matrix(motor_inertia: bool) -> tuple[np.ndarray, MultibodyPlant]:
    plant = MultibodyPlant(0.0)
    add_icub(plant, visuals=False, contact=ContactModel(), motor_inertia=motor_inertia)
    plant.Finalize()
    context = plant.CreateDefaultContext()
    q = plant.GetPositions(context)
    q[7:] += 0.1 * np.random.default_rng(3).standard_normal(len(q) - 7)  # joints only
    plant.SetPositions(context, q)
    return plant.CalcMassMatrix(context), plant


def test_reflected_inertia_is_ratio_squared_times_rotor_on_the_motor_joints():
    """M with the motors minus M without: 100^2 x the rotor inertia on each listed
    joint's diagonal entry, nothing anywhere else (neck, wrists, base, off-diagonal)."""
    M_off, _ = _mass_matrix(False)
    M_on, plant = _mass_matrix(True)
    expected = np.zeros(plant.num_velocities())
    for names, rotor in ((_LEGS_TORSO, 0.0827e-4), (_ARMS_YAW, 0.0585e-4)):
        for name in names:
            expected[plant.GetJointByName(name).velocity_start()] = 100.0**2 * rotor
    assert np.count_nonzero(expected) == len(_LEGS_TORSO) + len(_ARMS_YAW) == 23
    np.testing.assert_allclose(M_on - M_off, np.diag(expected), atol=1e-12)


def test_reflected_inertia_setting_by_model():
    from drake_standup.robot.icub import reflects_motor_inertia

    assert not reflects_motor_inertia("none", "iCubGenova04")
    assert reflects_motor_inertia("all", "iCubGazeboV2_5")
    assert reflects_motor_inertia("real_robots", "iCubGenova04")
    assert not reflects_motor_inertia("real_robots", "iCubGazeboV2_7")
    with pytest.raises(ValueError, match="robot.reflected_inertia.*none \\| all \\| real_robots"):
        reflects_motor_inertia("on", "iCubGenova04")


@pytest.mark.parametrize(
    ("model", "setting", "expected"),
    [
        ("iCubGenova04", None, True),  # the default: real_robots
        ("iCubGazeboV2_5", None, False),
        ("iCubGazeboV2_5", "all", True),
        ("iCubGenova04", "none", False),
    ],
)
def test_scene_gives_the_motors_their_inertia_per_setting(model, setting, expected):
    """The scenario's plant (which the controller's model is) has the knee's motor
    reflected inertia, 100^2 x 0.0827e-4 kg m^2, exactly where the setting says."""
    from drake_standup.config import load_scenario
    from drake_standup.standup.plan import feet_reach
    from drake_standup.world.station import make_station

    overrides = [("robot.model", model)]
    if setting is not None:
        overrides.append(("robot.reflected_inertia", setting))
    scenario = load_scenario(None, overrides)
    plant = make_station(scenario, feet_reach(scenario.controller)).plant
    knee = plant.GetJointActuatorByName("l_knee")
    context = plant.CreateDefaultContext()
    reflected = knee.rotor_inertia(context) * knee.gear_ratio(context) ** 2
    assert reflected == pytest.approx(0.0827 if expected else 0.0, abs=1e-12)
