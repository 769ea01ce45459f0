"""The arms braced against a strong pull (standup.brace_arms): which joints are the arms
(checked by moving them: each moves one hand only), the guards' brace and what the wait
then judges, the braced phase references, the CoM target standing lower, and the
standing metric that follows it."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import ControllerConfig, Scenario, StandupConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.control.model import ControllerJoints
from drake_standup.outputs.metrics import standup_metrics
from drake_standup.robot.icub import arm_joint_names
from drake_standup.standup.guards import GuardSignals, Measurements, update_guards
from drake_standup.standup.task_references import PhaseReferences
from drake_standup.world.scene import add_scene, set_seated_state
from drake_standup.world.station import braced_posture

CFG = StandupConfig()
TABLE = PhaseTable()
TABLE.rise.com_height_m = 0.575
LIMIT = CFG.standing_pull_usage_limit


@functools.cache
def _scene():
    scenario = Scenario()
    return scenario, add_scene(DiagramBuilder(), scenario, pd_gains=None, visuals=False)


def test_the_arms_are_the_joints_that_move_one_hand_only():
    """Every revolute joint of the robot, nudged by 0.1 rad from the seated pose: the ones
    arm_joint_names returns move one hand and neither the other hand nor a sole; every
    other joint that moves a hand moves both (the torso) or a sole too (the legs)."""
    _, scene = _scene()
    plant, robot = scene.plant, scene.robot
    context = plant.CreateDefaultContext()
    set_seated_state(scene, context)
    frames = [robot.frame(plant, n) for n in ("l_hand", "r_hand", "l_sole", "r_sole")]

    def points():
        return np.array([f.CalcPoseInWorld(context).translation() for f in frames])

    before = points()
    arms = set(arm_joint_names(plant, robot))
    moving_one_hand = set()
    for name in robot.joint_names:
        joint = plant.GetJointByName(name, robot.model_instance)
        angle = joint.get_angle(context)
        joint.set_angle(context, angle + 0.1)
        moved = np.linalg.norm(points() - before, axis=1) > 1e-6
        joint.set_angle(context, angle)
        if moved[0] != moved[1] and not moved[2:].any():
            moving_one_hand.add(name)
    assert arms == moving_one_hand
    assert {"l_shoulder_pitch", "l_elbow", "r_shoulder_pitch", "r_elbow"} <= arms
    assert not any(name.startswith("torso") for name in arms)


def test_braced_the_hands_stand_lower_and_the_com_too():
    """The braced standing posture keeps the seated arms: its erect CoM is lower than the
    rise posture's (the arms reach up and forward in it) and the legs' joints are
    those of the rise."""
    scenario, scene = _scene()
    rise = scenario.phases.rise.posture_rad
    braced = braced_posture(rise, arm_joint_names(scene.plant, scene.robot))
    assert set(braced) < set(rise)
    assert all(braced[k] == rise[k] for k in braced)
    drop = scene.standing.erect_com_height_m(rise) - scene.standing.erect_com_height_m(braced)
    assert 0.005 < drop < 0.05


def _m(t, usage, braced):
    return Measurements(
        t, t, np.zeros(3), 0.1, (200.0, 200.0), (20.0, 20.0), pull_usage=usage, braced_usage=braced
    )


def _run(usages, cfg=CFG):
    """update_guards over (usage, braced usage) pairs, one every 10 ms."""
    g, out = GuardSignals(), []
    for k, (usage, braced) in enumerate(usages):
        g = update_guards(g, _m(0.01 * k, usage, braced), cfg, TABLE)
        out.append(g)
    return out


def test_a_pull_beyond_the_reaching_feet_braces_the_arms_and_is_judged_braced():
    """1.2 x the limit with the arms reaching, 0.7 x braced, for 1 s: the arms brace once
    the filtered usage has been over the limit for the dwell, and the wait (beyond_feet)
    never comes; then the pull eases: the arms reach out again."""
    signals = _run([(1.2 * LIMIT, 0.7 * LIMIT)] * 100 + [(0.0, 0.0)] * 100)
    braced = [g.brace.on for g in signals]
    assert not braced[0] and braced[99] and not braced[-1]
    assert not any(g.beyond_feet.on for g in signals)
    on = braced.index(True)
    assert signals[on].braced_usage < LIMIT < signals[on].pull_usage


def test_a_pull_beyond_the_feet_braced_too_still_waits():
    """Over the limit braced too: the arms brace and the wait comes, as without a brace."""
    signals = _run([(1.5 * LIMIT, 1.2 * LIMIT)] * 100)
    assert signals[-1].brace.on and signals[-1].beyond_feet.on


@pytest.mark.parametrize(
    "cfg, braced", [(dataclasses.replace(CFG, brace_arms=False), 0.7), (CFG, float("nan"))]
)
def test_without_the_brace_the_wait_judges_the_reaching_arms(cfg, braced):
    """standup.brace_arms off, or no braced usage measured: no brace, and the pull beyond
    the reaching feet is waited out as before."""
    signals = _run([(1.2 * LIMIT, braced * LIMIT)] * 100, cfg)
    assert not any(g.brace.on for g in signals) and signals[-1].beyond_feet.on


def test_braced_phase_references_hold_the_arms_and_lower_the_leaning_com():
    """Braced, each state's references hold the arms' joints (the first tick's posture,
    as seated) and keep every other joint's target; the CoM target's height offset is
    -drop in the states that lean, 0 in the others and unbraced."""
    _, scene = _scene()
    joints = ControllerJoints.of(scene.plant, scene.robot)
    arms = arm_joint_names(scene.plant, scene.robot)
    schedule = PhaseReferences(
        TABLE,
        ControllerConfig(),
        joints.names,
        joints.q_min,
        joints.q_max,
        arms,
        braced_drop_m=0.02,
    )
    is_arm = np.isin(joints.names, arms)
    for state, phase in enumerate(TABLE, start=1):
        reaching, braced = schedule[state], schedule[state, True]
        assert schedule[state, False] is reaching
        assert braced.posture_hold[is_arm].all()
        np.testing.assert_array_equal(braced.posture_hold[~is_arm], reaching.posture_hold[~is_arm])
        np.testing.assert_array_equal(braced.posture_rad[~is_arm], reaching.posture_rad[~is_arm])
        assert reaching.com_height_offset_m == 0.0
        assert braced.com_height_offset_m == (-0.02 if phase.lean else 0.0)
    assert any(phase.lean for phase in TABLE)


def test_the_standing_height_follows_the_braced_com_target():
    """A run standing 2 cm below the erect height with the lean's z at -2 cm counts as
    standing; with the lean's z at 0 it does not (tolerance 1 cm)."""
    n = 200
    t = np.arange(n) * 0.01
    signals = {
        "time_s": t,
        "com_W": np.tile([0.1, 0.0, 0.555], (n, 1)),
        "com_reference_W": np.tile([0.1, 0.0, 0.575], (n, 1)),
        "pad_normal_force_N": np.zeros((n, 1)),
        "pad_groups": np.array(["soles"]),
        "com_lean_W": np.tile([0.0, 0.0, -0.02], (n, 1)),
    }
    entry = [0.0, 0.1, 0.2, 0.3]
    kwargs = dict(standing_height_m=0.575, height_tolerance_m=0.01, hold_s=0.5)
    braced = standup_metrics(signals, entry, **kwargs)
    assert braced["standing_at_end"] and braced["standup_time_s"] == pytest.approx(0.0, abs=0.01)
    signals["com_lean_W"] = np.zeros((n, 3))
    assert not standup_metrics(signals, entry, **kwargs)["standing_at_end"]
