"""End-to-end stand-ups under the helpers and robots that issue 21 found falling (slow)."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.config import SCENARIO_DIR, Pull, load_scenario
from drake_standup.config.rules import is_whole_multiple
from drake_standup.sim.runner import prepare
from drake_standup.sim.simulate import simulate

pytestmark = pytest.mark.slow


def _pulled(left, right, start_s, ramp_s, duration_s=4.0, name="unassisted", **settings):
    """The named scenario, the stand-up on time from 3 s, each hand pulled with its own
    force (N, world) from start_s; settings: dotted scenario fields."""
    scenario = load_scenario(SCENARIO_DIR / f"{name}.yaml")
    scenario.standup.trigger = "time"
    scenario.human.pulls = [
        Pull(hand=hand, start_s=start_s, duration_s=duration_s, ramp_s=ramp_s, force_N=force)
        for hand, force in (("left", list(left)), ("right", list(right)))
    ]
    scenario.duration_s = max(12.0, start_s + duration_s + 5.0)
    for key, value in settings.items():
        target = scenario
        *path, leaf = key.split("__")
        for part in path:
            target = getattr(target, part)
        setattr(target, leaf, value)
    return scenario


def _stands_erect(m):
    assert m["success"], m["failure_reason"]
    assert m["qp_failures"] == 0 and m["qp_relaxed_ticks"] == 0
    assert m["com_final_m"][2] == pytest.approx(m["standing_com_height_m"], abs=0.01)


@pytest.mark.parametrize(
    ("left", "right", "start_s", "ramp_s"),
    [
        ([0.0, 0.0, 15.0], [0.0, 0.0, 15.0], 4.0, 0.1),
        ([17.0, 0.0, 16.0], [3.0, 0.0, 24.0], 3.5, 0.5),
        ([12.0, 0.0, 18.0], [12.0, 0.0, 18.0], 3.5, 0.1),
        ([0.0, 25.0, 0.0], [0.0, 25.0, 0.0], 8.0, 0.1),
    ],
    ids=["lifted_abruptly_in_state_2", "lopsided_more_up", "more_up_than_forward", "sideways"],
)
def test_pulls_that_fell_before_stand_up(left, right, start_s, ramp_s):
    """Issue 21's falls: a pure lift of 15 N per hand begun abruptly in state 2 (it
    fell in state 3: the thighs' wrench planned while the plan lifted them); a lopsided
    pull more up than forward; 12 N forward + 18 N up per hand; 25 N per hand sideways on
    the standing robot. Each stands up erect, the QP never infeasible."""
    _stands_erect(
        simulate(_pulled(left, right, start_s, ramp_s), None, record=False, progress=False).metrics
    )


@pytest.mark.parametrize(("model", "force_N"), [("iCubGenova04", 0.0), ("iCubDarmstadt01", 15.0)])
def test_other_icubs_stand_up(model, force_N):
    """iCubGenova04 fell in state 2 with nobody pulling, iCubDarmstadt01 once standing
    under 15 + 15 N; both stand up erect with the pads and the seated pose of their own
    geometry and no settings of their own."""
    pull = [force_N, 0.0, force_N]
    scenario = _pulled(pull, pull, 3.0, 0.5, duration_s=8.0)
    scenario.robot.model = model
    _stands_erect(simulate(scenario, None, record=False, progress=False).metrics)


def test_the_authors_law_stands_up_helped():
    """advancement.law: interaction under 15 + 15 N per hand from 3.2 s with 1 s ramps
    fell in state 2 at 5.4 s; it stands up, psi ahead of time."""
    pull = [15.0, 0.0, 15.0]
    scenario = _pulled(pull, pull, 3.2, 1.0, duration_s=8.0, name="assisted")
    scenario.advancement.law = "interaction"
    m = simulate(scenario, None, record=False, progress=False).metrics
    _stands_erect(m)
    assert m["psi_final"] > scenario.duration_s


def test_the_qp_plans_what_the_plant_does_while_the_robot_leaves_the_seat():
    """The model behind the state-2 falls: the QP counted on the chair's forces while its
    plan pitched the pelvis off the buttocks pad and lifted the thighs, so the plant did
    something else (over 60 ms windows of state 2 the hips' planned velocity change was
    -1.1 rad/s, the plant's 0.01; the median error 98 %, measured before issue 21).
    With the seat held until its release is over and the thighs' pitch and normal held
    while they carry load, the velocity change the ticks plan (the sum of their vdot dt)
    of the base pitch, hips and torso is the plant's to 30 % (median over the windows
    while the pelvis pitches forward, until the hips near their stops: a stop is a
    constraint the plant has and the QP has not). With the arms and neck flat-weighed:
    weighed by the mass they carry (the default since issue 46) the plan asks the trunk
    for more and the median is 61 %, a cost docs/design.md records, open."""
    scenario = load_scenario(
        SCENARIO_DIR / "unassisted.yaml", [("controller.carried_limb_weight_by_mass", False)]
    )
    run = prepare(scenario)
    plant = run.built.station.plant
    standup = run.built.diagram.GetSubsystemByName("standup_controller")
    controller = standup.GetSubsystemByName("controller")  # the whole-body tick's system
    plant_context = plant.GetMyContextFromRoot(run.root_context)
    controller_context = controller.GetMyContextFromRoot(run.root_context)
    names = ("l_hip_pitch", "r_hip_pitch", "torso_pitch")
    rows = [1] + [plant.GetJointByName(n).velocity_start() for n in names]
    hip = plant.GetJointByName("l_hip_pitch")
    # The torques of a tick act over its whole period (the plant's steps within it).
    step = scenario.controller_period_s
    assert is_whole_multiple(step, plant.time_step())
    t = 3.0
    run.simulator.AdvanceTo(t)
    seated_hip = hip.get_angle(plant_context)
    errors = []
    while t < 4.5:
        v0 = plant.GetVelocities(plant_context)[rows].copy()
        planned = np.zeros(len(rows))
        for _ in range(15):
            tick, _ = controller.calc_tick(controller_context)
            planned += tick.solution.vdot[rows] * step
            t += step
            run.simulator.AdvanceTo(t)
        angle = hip.get_angle(plant_context)
        if angle > hip.position_upper_limits()[0] - 0.05:
            break
        if angle > seated_hip + 0.02:  # the pelvis pitches forward
            realised = plant.GetVelocities(plant_context)[rows] - v0
            errors.append(np.linalg.norm(planned - realised) / np.linalg.norm(planned))
    assert len(errors) >= 4
    assert np.median(errors) <= 0.3, np.round(errors, 2)


def test_a_pull_beyond_the_reaching_feet_braces_the_arms_and_stands_up():
    """25 N forward and 25 N up per hand held from 3 s (the assistance sweep's largest
    pull) needs more of the standing feet's hold than the limit with the arms reaching
    out. Braced (standup.brace_arms: the arms held as seated, a shorter lever) it stands
    up under the pull, state 4 before the pull ends at 8 s, erect once the arms reach out
    again. With the brace off it waits seated while the pull lasts, says why, and stands
    up once the helper lets go (issue 21's answer; standing up into it fell at psi_dot
    bounds 2.5 and 4)."""
    pull = [25.0, 0.0, 25.0]
    scenario = _pulled(pull, pull, 3.0, 0.5, duration_s=5.0, name="assisted")
    m = simulate(scenario, None, record=False, progress=False).metrics
    _stands_erect(m)
    assert m["state_entry_times_s"][3] < 8.0
    assert m["arms_braced_s"] > 2.0 and m["held_back_beyond_feet_s"] == 0.0
    assert m["sit_backs"] == 0
    scenario.standup.brace_arms = False
    m = simulate(scenario, None, record=False, progress=False).metrics
    _stands_erect(m)
    assert m["held_back_beyond_feet_s"] > 4.0
    assert m["state_entry_times_s"][1] > 8.0  # the stand-up began once the pull ended
    scenario.duration_s = 7.0  # while the pull lasts: waiting, and saying why
    m = simulate(scenario, None, record=False, progress=False).metrics
    assert m["failure_reason"] == "held back: a pull beyond what the standing feet can hold"
