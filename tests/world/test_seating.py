"""The chair from its numbers and the seated pose solved from its geometry (issue 30):
checked against the authors' seated pose, the pads' surfaces by forward kinematics, the
joint limits, and the shipped chair file."""

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import ScenarioError, apply_overrides, load_scenario
from drake_standup.config.chair import SEATED_BASE_XYZ_M, SEATED_JOINTS, ChairConfig
from drake_standup.world.chair import chair_sdf
from drake_standup.world.scene import add_scene
from drake_standup.world.seating import JOINT_MARGIN_RAD, PAD_SINK_M, seat_height_range

REPO = Path(__file__).resolve().parents[2]
MODEL = "iCubGazeboV2_5"


def _scene(**overrides):
    scenario = apply_overrides(load_scenario("assisted"), list(overrides.items()))
    return scenario, add_scene(DiagramBuilder(), scenario, visuals=False)


def _posed(scene):
    plant = scene.plant
    context = plant.CreateDefaultContext()
    plant.SetFreeBodyPose(
        context, plant.GetBodyByName("root_link", scene.robot.model_instance), scene.seated.base
    )
    for name, value in scene.seated.joints_rad.items():
        plant.GetJointByName(name, scene.robot.model_instance).set_angle(context, value)
    return plant, context


def _boxes(text: str) -> dict[str, tuple]:
    """Each collision box of an SDF text: name -> (pose, size)."""
    root = ET.fromstring(text)
    found = {}
    for collision in root.iter("collision"):
        pose = [float(v) for v in collision.find("pose").text.split()]
        size = [float(v) for v in collision.find("geometry/box/size").text.split()]
        found[collision.get("name")] = (pose, size)
    return found


def test_the_default_chair_is_the_shipped_file():
    """chair_sdf of the default numbers collides where models/chair.sdf does."""
    made = _boxes(chair_sdf(ChairConfig()))
    shipped = _boxes((REPO / "models" / "chair.sdf").read_text())
    assert made.keys() == shipped.keys() == {"seat_collision"}
    np.testing.assert_allclose(made["seat_collision"][0], shipped["seat_collision"][0], atol=1e-9)
    np.testing.assert_allclose(made["seat_collision"][1], shipped["seat_collision"][1], atol=1e-9)


def test_the_solved_pose_on_the_shipped_chair_is_the_authors():
    """On the shipped chair the solved legs are [authors-code]'s seated pose (the feasibility
    probe's knee and flat-sole ankle) to 1 mrad, its base to 1 mm."""
    _, scene = _scene()
    for name in ("l_hip_pitch", "l_knee", "l_ankle_pitch", "r_hip_pitch", "r_knee"):
        assert scene.seated.joints_rad[name] == pytest.approx(SEATED_JOINTS[name], abs=1e-3)
    np.testing.assert_allclose(scene.seated.base.translation(), SEATED_BASE_XYZ_M, atol=1e-3)


@pytest.mark.parametrize(
    "overrides",
    [
        {"chair.seat_height_m": 0.18},
        {"chair.seat_height_m": 0.20, "initial.hips_behind_seat_edge_m": 0.12},
        {"chair.seat_height_m": 0.25},
        {"chair.seat_height_m": 0.21, "chair.cushion": {"modulus_Pa": 1e5}},
        {"chair.seat_height_m": 0.22, "chair.xyz_m": [0.3, 0.0, -0.02]},
    ],
    ids=["low", "shallow", "high_perched", "cushion", "moved_chair"],
)
def test_a_solved_pose_rests_on_seat_and_floor(overrides):
    """By forward kinematics of the solved pose: the soles' pads flat on the floor, the
    buttocks pad on the seat top, no thigh pad in the seat, the hips where asked, every
    joint inside its limits by the margin."""
    scenario, scene = _scene(**overrides)
    plant, context = _posed(scene)
    robot = scene.robot
    top = scenario.chair.seat_top_z_m()
    for sole in ("l_sole", "r_sole"):
        pose = robot.frame(plant, sole).CalcPoseInWorld(context)
        for corner in ([-0.064, 0.0, -0.011], [0.126, 0.0, -0.011]):  # heel, toe
            # Within 1 mm, what the pads sink under the robot's weight: the legs are
            # solved alike and the model's two legs differ by 0.1 mm.
            assert pose.multiply(corner)[2] == pytest.approx(0.0, abs=1e-3), sole
    buttocks = robot.frame(plant, "buttocks").CalcPoseInWorld(context).translation()
    assert buttocks[2] == pytest.approx(top, abs=1e-9)
    edge = scenario.chair.seat_edge_x_m()
    for thigh in ("l_thigh", "r_thigh"):
        pose = robot.frame(plant, thigh).CalcPoseInWorld(context)
        for x in np.linspace(-0.07, 0.07, 15):
            point = pose.multiply([x, 0.0, 0.0])
            if point[0] <= edge:
                assert point[2] >= top - PAD_SINK_M - 1e-4, (thigh, x)
    hips = overrides.get("initial.hips_behind_seat_edge_m")
    if hips is not None:
        assert scene.seated.hips_behind_seat_edge_m == pytest.approx(hips, abs=1e-6)
    for name, value in scene.seated.joints_rad.items():
        joint = plant.GetJointByName(name, robot.model_instance)
        low, high = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        if name in SEATED_JOINTS and name.endswith(("hip_pitch", "knee", "ankle_pitch")):
            assert low + JOINT_MARGIN_RAD - 1e-6 <= value <= high - JOINT_MARGIN_RAD + 1e-6


def test_the_range_holds_and_ends():
    """iCubGazeboV2_5 sits on 0.19-0.25 m seats at least; just outside its range the
    scene refuses with one line naming the range."""
    low, high = map(float, seat_height_range(MODEL))
    assert low <= 0.19 and high >= 0.25
    for outside in (low - 0.005, high + 0.005):
        with pytest.raises(ScenarioError, match=rf"accepted: a seat {low:.3f}-{high:.3f} m"):
            _scene(**{"chair.seat_height_m": outside})


@pytest.mark.parametrize(
    "setting, message",
    [
        ("chair.seat_height_m=0.32", "chair.seat_height_m: 0.32; the iCubGazeboV2_5 cannot sit"),
        (
            "chair.cushion={thickness_m: 0.2}",
            "chair.cushion.thickness_m: 0.2; accepted: a number in (0, 0.1795) m",
        ),
        ("initial.feet_ahead_of_seat_edge_m=0.45", "cannot sit on this chair with its soles"),
        (
            "initial.hips_behind_seat_edge_m=0.45",
            "initial.hips_behind_seat_edge_m: 0.45; accepted: a number in [-0.014, 0.316] m",
        ),
    ],
    ids=["seat_too_high", "cushion_thicker_than_seat", "feet_out_of_reach", "hips_off_seat"],
)
def test_a_chair_it_cannot_sit_on_is_one_error_line(tmp_path, setting, message):
    """run_diagram.py: one `error:` line naming the key and what is accepted, exit 2."""
    done = subprocess.run(
        [sys.executable, str(REPO / "run_diagram.py"), "--no-recording", "--duration", "0.1"]
        + ["--out", str(tmp_path), "--set", setting],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], lines


@pytest.mark.parametrize("height", [0.18, 0.2195, 0.25])
def test_the_forward_target_follows_the_feet(height):
    """The plan ends state 2's CoM segment where the table says about the seated soles
    (the soles' frames by forward kinematics), on every seat; on the shipped one that is
    [authors-code]'s 0.1277 m in front of where the CoM sits, to 0.5 mm."""
    from drake_standup.standup.plan import feet_reach, make_plan
    from drake_standup.world.station import make_station

    scenario = apply_overrides(load_scenario("assisted"), [("chair.seat_height_m", height)])
    station = make_station(scenario, feet_reach(scenario.controller))
    plan = make_plan(scenario, station)
    plant, context = _posed(station.scene)
    soles = [station.scene.robot.frame(plant, f"{s}_sole") for s in "lr"]
    soles_x = np.mean([f.CalcPoseInWorld(context).translation()[0] for f in soles])
    forward = plan.table.forward
    assert forward.com_x_m == pytest.approx(soles_x + forward.com_x_over_soles_m, abs=1e-9)
    if height == 0.2195:
        com = plant.CalcCenterOfMassPositionInWorld(context, [station.scene.robot.model_instance])
        assert forward.com_x_m - com[0] == pytest.approx(0.1277, abs=5e-4)


def test_the_lift_off_postures_move_with_the_seated_pose():
    """resolve_postures shifts the flagged phases' joints by the seat's shift and keeps
    them inside the limits; others as given. On a 0.18 m seat the plan's state-2 knee is
    the seated knee ([authors-code]'s state 2 keeps the knees as they sit), on the shipped seat
    [authors-code]'s numbers to 1 mrad."""
    from drake_standup.config.phases import PhaseTable, resolve_postures
    from drake_standup.standup.plan import feet_reach, make_plan
    from drake_standup.world.station import make_station

    table = PhaseTable()
    shifted = resolve_postures(
        table, {"l_knee": -0.3, "l_hip_pitch": 0.5}, {"l_hip_pitch": (-0.5, 1.9)}, 0.05
    )
    assert shifted.forward.posture_rad["l_knee"] == table.forward.posture_rad["l_knee"] - 0.3
    assert shifted.forward.posture_rad["l_hip_pitch"] == pytest.approx(1.85)  # clamped
    assert shifted.lift_off.posture_rad["l_knee"] == table.lift_off.posture_rad["l_knee"] - 0.3
    assert shifted.rise.posture_rad == table.rise.posture_rad
    assert shifted.forward.posture_rad["r_knee"] == table.forward.posture_rad["r_knee"]
    for height in (0.18, 0.2195):
        scenario = apply_overrides(load_scenario("assisted"), [("chair.seat_height_m", height)])
        station = make_station(scenario, feet_reach(scenario.controller))
        plan = make_plan(scenario, station)
        knee = station.scene.seated.joints_rad["l_knee"]
        assert plan.table.forward.posture_rad["l_knee"] == pytest.approx(knee, abs=1e-12)
        if height == 0.2195:
            for name in ("forward", "lift_off"):
                planned = getattr(plan.table, name).posture_rad
                for joint, value in getattr(PhaseTable(), name).posture_rad.items():
                    assert planned[joint] == pytest.approx(value, abs=1e-3), (name, joint)
