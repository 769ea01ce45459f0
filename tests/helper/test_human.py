"""The human: scripted pulls reach the plant exactly; physics agrees; the
reactive helper pulls toward its target within its force cap, follows a hand
that outruns it, lets go, and acts on what it saw its reaction time ago; the path guide
walks the hand at its pace, never yanks, never pulls backwards or sideways,
and eases off (each against numbers written out by hand)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drake_standup.config import (
    SCENARIO_DIR,
    HumanConfig,
    Pull,
    ReactiveHumanConfig,
    Scenario,
    ScenarioError,
    load_scenario,
    parse_scenario,
)
from drake_standup.helper.hands import HumanWrenchSource
from drake_standup.helper.partner import Path, path_force, reactive_force, trapezoid
from drake_standup.sim.diagram import build_diagram

PULLS = [
    Pull(hand="left", start_s=1.0, duration_s=2.0, ramp_s=0.5, force_N=[20.0, 0.0, 10.0]),
    Pull(hand="right", start_s=1.5, duration_s=1.0, ramp_s=0.25, force_N=[5.0, -3.0, 8.0]),
]


def _expected(t: float) -> np.ndarray:
    """(2, 3) scripted forces written out by hand from PULLS."""

    def ramp(t, start, dur, r):
        if t <= start or t >= start + dur:
            return 0.0
        return min(1.0, (t - start) / r, (start + dur - t) / r)

    return np.array(
        [
            ramp(t, 1.0, 2.0, 0.5) * np.array([20.0, 0.0, 10.0]),
            ramp(t, 1.5, 1.0, 0.25) * np.array([5.0, -3.0, 8.0]),
        ]
    )


def test_trapezoid_values():
    assert trapezoid(0.99, 1.0, 2.0, 0.5) == 0.0
    assert trapezoid(1.25, 1.0, 2.0, 0.5) == pytest.approx(0.5)
    assert trapezoid(2.0, 1.0, 2.0, 0.5) == 1.0
    assert trapezoid(2.9, 1.0, 2.0, 0.5) == pytest.approx(0.2)
    assert trapezoid(3.0, 1.0, 2.0, 0.5) == 0.0
    assert trapezoid(1.5, 1.0, 2.0, 0.0) == 1.0


def test_plant_receives_exactly_the_scripted_force():
    """Read the applied_spatial_force the plant sees, at times on the ramps."""
    scenario = Scenario()
    scenario.human = HumanConfig(pulls=PULLS)
    built = build_diagram(scenario)
    plant = built.station.scene.plant
    robot = built.station.scene.robot
    root = built.diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(root)
    hand_bodies = [robot.frame(plant, h).body().index() for h in ("l_hand", "r_hand")]
    for t in (0.5, 1.1, 1.3, 1.6, 1.7, 2.2, 2.6, 2.9, 3.2):
        root.SetTime(t)
        applied = plant.get_applied_spatial_force_input_port().Eval(plant_context)
        got = np.zeros((2, 3))
        for f in applied:
            assert not f.F_Bq_W.rotational().any()
            got[hand_bodies.index(f.body_index)] += f.F_Bq_W.translational()
        np.testing.assert_allclose(got, _expected(t), atol=1e-12)
        measured = built.diagram.GetSubsystemByName("human").GetOutputPort("hand_wrenches_W")
        w = measured.Eval(built.diagram.GetSubsystemByName("human").GetMyContextFromRoot(root))
        np.testing.assert_allclose(w.reshape(2, 6)[:, 3:], _expected(t), atol=1e-12)


def test_pulls_change_linear_momentum_by_their_impulse(limp_robot_rig):
    """Zero gravity, no contact, a limp floating robot: its linear momentum
    changes by the pulls' impulse sum F(t_n) dt (Newton's second law). The
    discrete plant updates velocities with the mass matrix of the step's start
    while the limp robot spins, an O(dt) error: 0.6% at 1 ms, hence 1%; a
    wrong hand, sign, body or ramp is off by far more."""
    simulator, plant, plant_context = limp_robot_rig(
        lambda plant, robot, dt: HumanWrenchSource(plant, robot, HumanConfig(pulls=PULLS))
    )
    mass = plant.CalcTotalMass(plant_context)
    t_end = 3.5
    simulator.AdvanceTo(t_end)
    momentum = mass * plant.CalcCenterOfMassTranslationalVelocityInWorld(plant_context)
    steps = np.arange(0.0, t_end - 1e-9, 1e-3)
    impulse = sum(_expected(t).sum(axis=0) for t in steps) * 1e-3
    assert np.linalg.norm(momentum - impulse) < 0.01 * np.linalg.norm(impulse)
    assert np.linalg.norm(impulse) > 10.0  # the check is not vacuous


def test_reactive_human_pulls_toward_target_within_cap():
    # The pace alone (no lead kept ahead of the hand: lead_min_m 0).
    cfg = ReactiveHumanConfig(
        start_s=1.0, duration_s=5.0, ramp_s=0.5, force_cap_N=20.0, lead_min_m=0.0
    )
    start = np.array([0.24, 0.01, 0.31])
    assert not reactive_force(cfg, 0.9, start, np.zeros(3), start).any()
    # Mid-pull, hand still at the start: pulled along the pace's direction u, by the
    # spring to the pace point (0.5 s of it: 10.6 N) and the damping to its speed.
    f = reactive_force(cfg, 1.5, start, np.zeros(3), start)
    v_pace = np.array(cfg.target_velocity_mps)
    direction = v_pace / np.linalg.norm(v_pace)
    travel = np.linalg.norm(v_pace) * 0.5
    expected = cfg.stiffness_N_per_m * travel * direction + cfg.damping_Ns_per_m * v_pace
    np.testing.assert_allclose(f, expected, rtol=1e-12)
    # Far behind the target: capped.
    f = reactive_force(cfg, 5.5, start - 1.0, np.zeros(3), start)
    assert np.linalg.norm(f) == pytest.approx(20.0 * trapezoid(5.5, 1.0, 5.0, 0.5))
    # Hand moving along with the target: only the spring is left.
    f_moving = reactive_force(cfg, 1.5, start, v_pace, start)
    np.testing.assert_allclose(f_moving, cfg.stiffness_N_per_m * travel * direction, rtol=1e-12)


# --- the velocity guide is a person (issue 31) -----------------------------------
# Pace along u = (0.6, 0, 0.8) at 0.1 m/s from t = 1 s, K 100 N/m, D 10 N s/m, cap 50 N.
U = np.array([0.6, 0.0, 0.8])
P0 = np.array([0.24, 0.11, 0.31])


# The pull's timing and the arm's impedance both guides' tests share.
_ARM = dict(
    start_s=1.0, duration_s=10.0, ramp_s=0.5, stiffness_N_per_m=100.0, damping_Ns_per_m=10.0
)


def _person(**kw) -> ReactiveHumanConfig:
    values = dict(
        **_ARM,
        force_cap_N=50.0,
        target_velocity_mps=list(0.1 * U),
        travel_m=0.3,
        lead_min_m=0.0,  # the pace alone; test_person_keeps_pulling_a_hand_that_outruns_them
    )
    values.update(kw)
    return ReactiveHumanConfig(**values)


def test_person_follows_a_hand_that_outruns_them():
    """At t = 2 s the pace is 0.1 m along u. A hand seen 0.2 m along u, moving at 0.5
    m/s, is not pulled back: the target is where it was seen, moving as it was."""
    cfg, v = _person(), 0.5 * U
    seen = P0 + 0.2 * U
    assert not reactive_force(cfg, 2.0, seen, v, P0, seen=(seen, v)).any()
    # Seen 0.15 s ago, it has moved on 0.075 m since: the person lags by as much, and
    # their arm pulls it back by K 0.075 (7.5 N), the damping adding nothing.
    now = seen + 0.075 * U
    np.testing.assert_allclose(
        reactive_force(cfg, 2.0, now, v, P0, seen=(seen, v)), -7.5 * U, atol=1e-12
    )


def test_person_keeps_pulling_a_hand_that_outruns_them():
    """lead_min_m 0.05: at t = 2 s the pace is 0.1 m along u. A hand seen 0.2 m along u,
    moving at 0.5 m/s, is led 0.05 m ahead, the target moving with it: K 0.05 = 5 N
    along u, no damping. Seen 0.15 s ago it has moved on 0.075 m: K (0.05 - 0.075)."""
    cfg, v = _person(lead_min_m=0.05), 0.5 * U
    seen = P0 + 0.2 * U
    np.testing.assert_allclose(reactive_force(cfg, 2.0, seen, v, P0), 5.0 * U, atol=1e-12)
    now = seen + 0.075 * U
    np.testing.assert_allclose(
        reactive_force(cfg, 2.0, now, v, P0, seen=(seen, v)), -2.5 * U, atol=1e-12
    )
    # Behind the pace the pace leads (0.02 m along u: K 0.08 + D (0.1 - 0)), ...
    np.testing.assert_allclose(
        reactive_force(cfg, 2.0, P0 + 0.02 * U, np.zeros(3), P0), 9.0 * U, atol=1e-12
    )
    # ... and the lead ends with the person's reach (travel 0.3 m): 0.02 m short of it,
    # K 0.02; beyond it the hand is followed, never pulled back.
    np.testing.assert_allclose(reactive_force(cfg, 2.0, P0 + 0.28 * U, v, P0), 2.0 * U, atol=1e-12)
    assert not reactive_force(cfg, 2.0, P0 + 0.4 * U, v, P0).any()


def test_a_person_leading_a_fast_hand_speeds_up_with_it():
    """At t = 2 s the pace is 0.1 m along u; a hand 0.08 m along u moving at 0.5 m/s
    along u (seen now): the person leads it by 0.02 m and moves at its speed, not their
    pace, so only the spring acts, K 0.02 (2 N) along u; the damping about the pace
    (D (0.1 - 0.5) = -4 N) would have pulled it back."""
    cfg, v = _person(), 0.5 * U
    np.testing.assert_allclose(reactive_force(cfg, 2.0, P0 + 0.08 * U, v, P0), 2.0 * U, atol=1e-12)
    # Slower than the pace, the person still pulls at their pace: D (0.1 - 0.05) more.
    slow = reactive_force(cfg, 2.0, P0 + 0.08 * U, 0.05 * U, P0)
    np.testing.assert_allclose(slow, (2.0 + 10.0 * 0.05) * U, atol=1e-12)


def test_person_guides_along_u_not_back_to_a_line():
    """A hand at rest 0.1 m sideways of the start, at t = 1.5 s (pace 0.05 m): pulled
    K 0.05 + D 0.1 along u and nothing sideways (the first model pulled it back in y)."""
    hand = P0 + np.array([0.0, 0.1, 0.0])
    f = reactive_force(_person(), 1.5, hand, np.zeros(3), P0)
    np.testing.assert_allclose(f, (100.0 * 0.05 + 10.0 * 0.1) * U, atol=1e-12)


def test_person_stops_at_their_travel_and_lets_go_once_the_robot_is_up():
    cfg = _person()
    # After 0.3 m (t = 4 s) the person stops: a hand 0.1 m short is pulled K 0.1 along
    # u, the damping holding it (the target still); a hand beyond is followed.
    np.testing.assert_allclose(
        reactive_force(cfg, 5.0, P0 + 0.2 * U, np.zeros(3), P0), 10.0 * U, atol=1e-12
    )
    assert not reactive_force(cfg, 5.0, P0 + 0.4 * U, np.zeros(3), P0).any()
    # The CoM's rise: full pull below 0.07 m, half at 0.105 m, none from 0.14 m.
    full = reactive_force(cfg, 2.0, P0, np.zeros(3), P0, com_rise_m=0.05)
    half = reactive_force(cfg, 2.0, P0, np.zeros(3), P0, com_rise_m=0.105)
    np.testing.assert_allclose(half, 0.5 * full, atol=1e-12)
    assert not reactive_force(cfg, 2.0, P0, np.zeros(3), P0, com_rise_m=0.14).any()


# --- guide: path ---------------------------------------------------------------
# A straight path 1 m long along (0.6, 0.8) in (forward, up): a 3-4-5 triangle,
# so every number below is written out by hand.
START = np.array([0.24, 0.11, 0.31])
DIR = np.array([0.6, 0.0, 0.8])


def _path_cfg(**kw) -> ReactiveHumanConfig:
    values = dict(
        **_ARM,
        guide="path",
        force_cap_N=100.0,
        path_xz_m=[[0.6, 0.8]],
        pace_mps=0.2,
        lead_min_m=0.0,
        lead_max_m=1.0,
        ease_com_rise_m=[0.10, 0.14],
    )
    values.update(kw)
    return ReactiveHumanConfig(**values)


def _pull(cfg, t, s_hand=0.0, v_along=0.0, rise=0.0, sideways=0.0, v_sideways=0.0):
    """The force on a hand s_hand along the straight path, moving v_along."""
    side = np.array([0.0, 1.0, 0.0])
    p = START + s_hand * DIR + sideways * side
    v = v_along * DIR + v_sideways * side
    return path_force(cfg, Path(cfg.path_xz_m), t, p, v, START, com_rise_m=rise)


def test_path_arc_length_and_closest_point():
    path = Path([[0.3, 0.4], [0.3, 1.4]])  # 0.5 m up-forward, then 1 m straight up
    assert path.length == pytest.approx(1.5)
    np.testing.assert_allclose(path.point(0.25), [0.15, 0.2])
    np.testing.assert_allclose(path.point(1.0), [0.3, 0.9])
    np.testing.assert_allclose(path.point(9.0), [0.3, 1.4])  # clamped to the end
    s, tangent = path.project(np.array([0.5, 1.0]))  # 0.2 m in front of the upright leg
    assert s == pytest.approx(0.5 + 0.6)
    np.testing.assert_allclose(tangent, [0.0, 1.0])
    s, tangent = path.project(np.array([-0.1, -0.1]))  # behind the start
    assert s == 0.0
    np.testing.assert_allclose(tangent, [0.6, 0.8])


def test_rounded_corner_arc_length_and_continuous_progress():
    """A right-angle corner rounded to 0.2 m: the path is 2 - 2 r + pi r / 2
    long (its 1-degree chords 0.001% shorter), and the closest point of a hand
    passing the corner's inside, 0.1 m from the path, moves continuously: by
    under 4 mm per mm of the hand (r / (r - 0.1) = 2 mm on the arc, plus at
    most a vertex's 1.7 mm) where at the sharp corner it jumps by 0.2 m."""
    r = 0.2
    path = Path([[1.0, 0.0], [1.0, 1.0]], corner_radius_m=r)
    assert path.length == pytest.approx(2.0 - 2.0 * r + math.pi * r / 2, rel=2e-5)
    np.testing.assert_allclose(path.point(0.5), [0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(path.point(path.length - 0.5), [1.0, 0.5], atol=1e-12)
    hand_z = np.linspace(0.05, 0.3, 251)  # along x = 0.9, past the corner, 1 mm apart
    s = np.array([path.project(np.array([0.9, z]))[0] for z in hand_z])
    assert np.all(np.diff(s) >= 0.0) and np.diff(s).max() < 0.004
    sharp = Path([[1.0, 0.0], [1.0, 1.0]])
    s = np.array([sharp.project(np.array([0.9, z]))[0] for z in hand_z])
    assert np.diff(s).max() > 0.15  # the sharp corner's jump, for contrast


def test_path_target_travels_at_the_pace():
    """Hand still at its start: the target is pace (t - start) along the path,
    moving at the pace, so F = K pace (t - start) + D pace along the path."""
    cfg = _path_cfg()
    for elapsed in (0.5, 1.5, 2.5):
        f = _pull(cfg, 1.0 + elapsed)
        expected = 100.0 * 0.2 * elapsed + 10.0 * 0.2
        np.testing.assert_allclose(f, expected * DIR, atol=1e-12)
    # Nothing before the start nor after the pull's end.
    assert not _pull(cfg, 0.9).any()
    assert not _pull(cfg, 11.0).any()
    # On the ramp: scaled by it (0.25 s into 0.5 s: one half).
    np.testing.assert_allclose(_pull(cfg, 1.25), 0.5 * (100 * 0.05 + 2.0) * DIR, atol=1e-12)


def test_path_never_more_than_lead_max_ahead_no_yank():
    """The person waits for a hand left behind: the target is lead_max ahead of
    it and moves with it, however far the pace has gone."""
    cfg = _path_cfg(lead_max_m=0.25)
    for v_along in (0.0, 0.3):
        f = _pull(cfg, 5.0, s_hand=0.1, v_along=v_along)  # pace: 0.8 m
        np.testing.assert_allclose(f, 100.0 * 0.25 * DIR, atol=1e-12)


def test_path_follows_a_hand_that_outruns_the_pace():
    """A hand ahead of the pace keeps lead_min of pull, not more, not less."""
    cfg = _path_cfg(lead_min_m=0.1)
    f = _pull(cfg, 2.0, s_hand=0.5, v_along=0.8)  # pace: 0.2 m
    np.testing.assert_allclose(f, 100.0 * 0.1 * DIR, atol=1e-12)


def test_path_never_pulls_backwards():
    """A hand moving faster than the pace toward the target: the damping
    would pull it back; the person lets go instead (zero, never negative)."""
    cfg = _path_cfg()
    f = _pull(cfg, 2.0, s_hand=0.15, v_along=2.0)  # K 0.05 + D (0.2 - 2) < 0
    assert not f.any()


def test_path_force_cap():
    cfg = _path_cfg(force_cap_N=25.0)
    f = _pull(cfg, 5.0)  # K 0.8 + D 0.2 = 82 N uncapped
    assert np.linalg.norm(f) == pytest.approx(25.0)
    np.testing.assert_allclose(f / 25.0, DIR, atol=1e-12)


def test_path_no_sideways_force():
    """Out of the sagittal plane, and moving sideways: no sideways force, and
    the same pull as on the path."""
    cfg = _path_cfg()
    on_path = _pull(cfg, 2.0, s_hand=0.1)
    aside = _pull(cfg, 2.0, s_hand=0.1, sideways=0.12, v_sideways=0.5)
    assert aside[1] == 0.0
    np.testing.assert_allclose(aside, on_path, atol=1e-12)


def test_path_pull_turns_through_a_corner_along_the_path():
    """Hand 0.1 m before a corner, target 0.1 m after it: the pull points from
    the hand's point on the path to the target's point."""
    cfg = _path_cfg(path_xz_m=[[0.4, 0.3], [0.4, 1.3]], lead_min_m=0.2, lead_max_m=0.2)
    path = Path(cfg.path_xz_m)
    p = START + np.array([0.32, 0.0, 0.24])  # 0.4 m along the first leg (0.8, 0.6)
    f = path_force(cfg, path, 2.0, p, np.zeros(3), START, com_rise_m=0.0)
    chord = np.array([0.4, 0.4]) - np.array([0.32, 0.24])
    direction = chord / np.linalg.norm(chord)
    np.testing.assert_allclose(f, 100.0 * 0.2 * np.array([direction[0], 0.0, direction[1]]))
    assert f[0] > 0.0 and f[2] > 0.0


def test_path_eases_off_at_the_end_and_once_the_robot_is_up():
    cfg = _path_cfg(lead_min_m=0.1)
    # At the path's end the target stops there: no pull on a hand that is there.
    assert not _pull(cfg, 9.0, s_hand=1.0).any()
    # 0.04 m before it: K 0.04 toward the end, no more (the target has stopped).
    np.testing.assert_allclose(_pull(cfg, 9.0, s_hand=0.96), 4.0 * DIR, atol=1e-12)
    # The CoM's rise: full pull below 0.10 m, half at 0.12 m, none from 0.14 m.
    full = _pull(cfg, 2.0, rise=0.05)
    np.testing.assert_allclose(_pull(cfg, 2.0, rise=0.12), 0.5 * full, atol=1e-12)
    assert not _pull(cfg, 2.0, rise=0.14).any()
    assert not _pull(cfg, 2.0, rise=0.3).any()


def test_reactive_scenarios_load():
    """The shipped reactive scenario uses the path guide; a file written before
    it (mode: reactive and the first keys only) loads with guide: velocity."""
    shipped = load_scenario(SCENARIO_DIR / "reactive.yaml").human
    assert shipped.mode == "reactive" and shipped.reactive.guide == "path"
    assert shipped.reactive.force_cap_N <= 25.0  # [authors-code]: 10-25 N per hand
    old = parse_scenario(
        "human:\n  mode: reactive\n  reactive:\n    force_cap_N: 15.0\n"
        "    target_velocity_mps: [0.1, 0.0, 0.2]\n",
        "old",
    ).human.reactive
    assert old.guide == "velocity" and old.force_cap_N == 15.0
    assert old.path_xz_m == ReactiveHumanConfig().path_xz_m


@pytest.mark.parametrize(
    "body, key",
    [
        ("guide: spring", "human.reactive.guide"),
        ("path_xz_m: []", "human.reactive.path_xz_m"),
        ("path_xz_m: [[0.3, 0.2, 0.1]]", "human.reactive.path_xz_m[0]"),
        ("path_xz_m: [[0.3, 0.2], [0.3, 0.2]]", "human.reactive.path_xz_m[1]"),
        ("pace_mps: 0.0", "human.reactive.pace_mps"),
        ("path_corner_radius_m: -0.1", "human.reactive.path_corner_radius_m"),
        ("lead_min_m: -0.1", "human.reactive.lead_min_m"),
        ("{lead_min_m: 0.2, lead_max_m: 0.1}", "human.reactive.lead_max_m"),
        ("ease_com_rise_m: [0.14, 0.10]", "human.reactive.ease_com_rise_m"),
        ("ease_com_rise_m: [0.1]", "human.reactive.ease_com_rise_m"),
    ],
)
def test_bad_path_keys_are_one_line_errors_naming_the_key(body, key):
    if body.startswith("{"):
        text = f"human:\n  mode: reactive\n  reactive: {body}\n"
    else:
        text = f"human:\n  mode: reactive\n  reactive:\n    {body}\n"
    with pytest.raises(ScenarioError) as err:
        parse_scenario(text, "test")
    message = str(err.value)
    assert "\n" not in message and message.startswith(key) and "accepted" in message


def test_person_acts_on_what_they_saw_their_reaction_time_ago():
    """The person's decisions read the hands as they were reaction_time_s (0.2 s) ago:
    the arms move at t = 0 (the robot's state switched from A to B); until 0.2 s the
    force is the person's answer to A's hands acting on B's, from then on to B's."""
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder

    from drake_standup.robot.icub import ContactModel, add_icub

    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    robot = add_icub(plant, visuals=False, contact=ContactModel())
    plant.Finalize()
    cfg = _person(start_s=0.0, ramp_s=0.0, reaction_time_s=0.2)
    human = HumanWrenchSource(plant, robot, HumanConfig(mode="reactive", reactive=cfg))
    context = plant.CreateDefaultContext()
    x_a = plant.GetPositionsAndVelocities(context, robot.model_instance)
    x_b = x_a.copy()
    for name in ("l_shoulder_pitch", "r_shoulder_pitch", "l_elbow", "r_elbow"):
        x_b[plant.GetJointByName(name, robot.model_instance).position_start()] += 0.3

    def hands(x):
        plant.SetPositionsAndVelocities(context, robot.model_instance, x)
        frames = [robot.frame(plant, name) for name in ("l_hand", "r_hand")]
        com = plant.CalcCenterOfMassPositionInWorld(context, [robot.model_instance])[2]
        return [f.CalcPoseInWorld(context).translation() for f in frames], com

    (p_a, com_a), (p_b, com_b) = hands(x_a), hands(x_b)
    simulator = Simulator(human)
    root = simulator.get_mutable_context()
    port = human.GetInputPort("robot_state")
    port.FixValue(root, x_a)
    simulator.Initialize()  # the hands at the start, and all the person has seen: A
    port.FixValue(root, x_b)

    def force(t):
        simulator.AdvanceTo(t)
        return human.GetOutputPort("hand_wrenches_W").Eval(root).reshape(2, 6)[:, 3:]

    zero = np.zeros(3)

    def expected(t, seen, rise):
        return [
            reactive_force(cfg, t, p_b[i], zero, p_a[i], rise, seen=(seen[i], zero)) for i in (0, 1)
        ]

    np.testing.assert_allclose(force(0.19), expected(0.19, p_a, 0.0), atol=1e-12)
    late = force(0.21)
    np.testing.assert_allclose(late, expected(0.21, p_b, com_b - com_a), atol=1e-12)
    # Not vacuous: what the person saw changes the pull (along u: the arms move mostly
    # across it) by far more than the tolerance.
    assert np.abs(late - np.array(expected(0.21, p_a, 0.0))).max() > 0.1


def test_a_steady_motion_is_tracked_without_the_reaction_times_lag():
    """A hand moving steadily at 0.5 m/s along u, seen 0.2 s ago: the person carries what
    they saw on to now (predicted) and pulls exactly as a person who sees it now; a
    hand that has just stopped where they expect it is pulled on by their damping about
    the speed they still expect, D v = 10 x 0.5 = 5 N along u."""
    from drake_standup.helper.hands import PERCEIVED, predicted

    cfg, v, lag = _person(), 0.5 * U, 0.2
    now = P0 + 0.3 * U
    sample = np.zeros(PERCEIVED)
    sample[3:6], sample[9:12] = now - lag * v, v  # the right hand, 0.2 s ago
    seen = predicted(sample, 1, lag)
    np.testing.assert_allclose(seen[0], now, atol=1e-15)
    at_once = reactive_force(cfg, 3.0, now, v, P0)
    np.testing.assert_allclose(reactive_force(cfg, 3.0, now, v, P0, seen=seen), at_once)
    braked = reactive_force(cfg, 3.0, now, np.zeros(3), P0, seen=seen)
    np.testing.assert_allclose(braked - reactive_force(cfg, 3.0, now, np.zeros(3), P0), 5.0 * U)
