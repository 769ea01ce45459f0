"""The scene's standing numbers are worked out once per build: one forward-kinematics pass
per distinct posture (world/scene.StandingGeometry), shared by the station's checks, its
standing support, the sensing and the plan; each equal to a pass of its own in a fresh
context (the old way, written out here)."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform, RollPitchYaw

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.robot.icub import set_joint_positions
from drake_standup.sim.diagram import build_diagram
from drake_standup.world.scene import set_seated_state


@pytest.fixture(scope="module")
def built():
    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    built = build_diagram(scenario)
    built.scenario = scenario  # the test's handle on what it built
    return built


def test_a_build_makes_one_pass_per_distinct_posture(built):
    standing = built.station.scene.standing
    postures = len(standing._poses)
    assert postures >= 2  # the rise's posture and its braced twin at least
    assert standing.passes == postures
    rise = built.scenario.phases.rise.posture_rad
    again = standing.pose(rise)
    assert standing.pose(dict(reversed(list(rise.items())))) is again  # order-blind
    assert standing.passes == postures  # asked again: no new pass


def test_the_plan_and_the_station_read_the_same_numbers(built):
    scene, plan = built.station.scene, built.plan
    rise = built.scenario.phases.rise.posture_rad
    assert plan.erect_com_height_m == scene.standing.erect_com_height_m(rise)
    assert built.station.standing.com_height_m == scene.standing.erect_com_height_m(rise)
    np.testing.assert_array_equal(
        built.station.standing.hands_m, scene.standing.pose(rise).hands_from_com_m
    )


def test_a_pose_equals_a_fresh_forward_kinematics_pass(built):
    """The shared context gives what a context of its own gives: the robot seated, the
    posture's joints set, upright at the seated yaw, the soles lowered to their seated
    height."""
    scene, scenario = built.station.scene, built.scenario
    plant, instance = scene.plant, scene.robot.model_instance
    for posture in (scenario.phases.rise.posture_rad, scenario.phases.lift_off.posture_rad):
        context = plant.CreateDefaultContext()
        set_seated_state(scene, context)
        soles = [scene.robot.frame(plant, n) for n in ("l_sole", "r_sole")]
        seated_z = min(f.CalcPoseInWorld(context).translation()[2] for f in soles)
        set_joint_positions(plant, context, instance, posture)
        yaw = scenario.initial.base_rpy_rad[2]
        pose_W = RigidTransform(RollPitchYaw(0.0, 0.0, yaw), [0.0, 0.0, 1.0])
        plant.SetFreeBodyPose(context, plant.GetBodyByName("root_link", instance), pose_W)
        com = plant.CalcCenterOfMassPositionInWorld(context, [instance])
        sole_z = min(f.CalcPoseInWorld(context).translation()[2] for f in soles)
        pose = scene.standing.pose(posture)
        assert pose.com_height_m == pytest.approx(com[2] - sole_z + seated_z, abs=1e-12)
        hand = scene.robot.frame(plant, "l_hand").CalcPoseInWorld(context).translation()
        np.testing.assert_allclose(pose.hands_from_com_m[0], hand - com, atol=1e-12)
