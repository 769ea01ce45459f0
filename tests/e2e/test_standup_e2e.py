"""End-to-end stand-ups through the whole diagram (slow: ~40 s each)."""

from __future__ import annotations

import numpy as np
import pytest
from docs_check import undocumented_metrics

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.outputs.signals import load_signals
from drake_standup.sim.diagram import build_diagram
from drake_standup.sim.simulate import simulate

pytestmark = pytest.mark.slow


def _run(name: str, out_dir=None, **kw):
    scenario = load_scenario(SCENARIO_DIR / f"{name}.yaml")
    return scenario, simulate(scenario, out_dir, record=False, progress=False, **kw).metrics


@pytest.fixture(scope="module")
def unassisted_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("unassisted")
    scenario, metrics = _run("unassisted", out)
    return scenario, metrics, load_signals(out / "signals.npz")


@pytest.fixture(scope="module")
def unassisted(unassisted_run):
    return unassisted_run[:2]


@pytest.fixture(scope="module")
def assisted_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("assisted")
    scenario, metrics = _run("assisted", out, baseline=True)
    return scenario, metrics, load_signals(out / "signals.npz")


@pytest.fixture(scope="module")
def assisted(assisted_run):
    return assisted_run[:2]


def test_unassisted_stands_up_with_psi_equal_to_time(unassisted):
    scenario, m = unassisted
    assert m["success"], m["failure_reason"]
    assert m["standup_time_s"] is not None
    assert m["psi_final"] == pytest.approx(scenario.duration_s, abs=1e-9)
    assert m["psi_dot_min"] == 1.0 and m["psi_dot_max"] == 1.0
    assert m["qp_failures"] == 0
    assert m["com_final_m"][2] == pytest.approx(m["standing_com_height_m"], abs=0.01)
    assert m["contact_normal_force_N"]["thighs"] < 1.0
    assert m["contact_normal_force_N"]["buttocks"] < 1.0
    assert m["max_abs_torque_Nm"] <= scenario.robot.effort_limit_Nm + 1e-9


def test_every_metric_of_the_assisted_run_is_documented(assisted):
    """docs/outputs.md names each metrics.json key of the default scenario's run."""
    assert undocumented_metrics(assisted[1]) == []


def test_assisted_stands_up_sooner(assisted, unassisted):
    scenario, m = assisted
    _, u = unassisted
    assert m["success"], m["failure_reason"]
    assert m["psi_dot_max"] > 1.0
    assert m["psi_dot_max"] <= scenario.advancement.psi_dot_upper
    assert m["psi_final"] > scenario.duration_s  # psi ran ahead of time
    # Issue 12 asked 25 % sooner; issue 46 traded some of it for arms that do not whip
    # (the carried limbs weighed by their mass: 2.85 s against 2.76 s) and asks 20 %.
    assert m["standup_time_s"] <= 0.80 * u["standup_time_s"]
    # The same scenario with psi = t (the faded reference of the figure).
    assert m["standup_time_s"] < m["standup_time_s_without_advancement"]


def test_the_feet_take_the_load_without_slapping(assisted, unassisted):
    """Issue 30: from the stand-up's start the soles' summed normal force stays within
    40 N of its centred 0.1 s moving average (no heel or toe slapping down) alone, and the
    CoM reference moves at most 10 mm between logged samples, alone and helped."""
    assert unassisted[1]["sole_force_chatter_N"] <= 40.0
    for _, m in (assisted, unassisted):
        assert m["com_reference_max_step_m"] <= 0.010


@pytest.mark.xfail(
    strict=True,
    reason="issue 60: the buttocks' release slaps the helped run's soles (48.5 N at 3.77 s; "
    "40.5 N at the 4 ms step, which the force's samples read as 37.5 N)",
)
def test_the_helped_feet_take_the_load_without_slapping(assisted):
    """Issue 30's bound on the helped run, read from the soles' impulse (decision 017)."""
    assert assisted[1]["sole_force_chatter_N"] <= 40.0


@pytest.fixture(scope="module", params=["stiff", "compliant"])
def other_response(request, tmp_path_factory):
    """The assisted scenario's pull answered by stiff or compliant (config.RESPONSES)."""
    out = tmp_path_factory.mktemp(request.param)
    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml", [("response", request.param)])
    metrics = simulate(scenario, out, record=False, progress=False).metrics
    return scenario, metrics, load_signals(out / "signals.npz")


def test_stiff_and_compliant_keep_psi_equal_to_time(other_response, unassisted):
    """Under the assisted pull, stiff and compliant stand up with psi = t at every
    sample; stiff cancels the pull: its stand-up time is the unassisted one within
    0.05 s; compliant's reference yields, within its bound, and comes back: standing,
    the 15 + 15 N forward pull moves it F/K forward, and the upward pull not above the
    path (on the feet alone)."""
    scenario, m, sig = other_response
    assert m["success"], m["failure_reason"]
    assert m["response"] == scenario.response
    np.testing.assert_allclose(sig["psi"], sig["time_s"], rtol=0.0, atol=1e-9)
    assert (sig["psi_dot"] == 1.0).all()
    assert m["com_final_m"][2] == pytest.approx(m["standing_com_height_m"], abs=0.01)
    offset = sig["compliance_offset_W"]
    if scenario.response == "stiff":
        assert m["standup_time_s"] == pytest.approx(unassisted[1]["standup_time_s"], abs=0.05)
        assert not offset.any()
        return
    bound = np.array(scenario.compliance.max_offset_m)
    assert (np.abs(offset) <= bound + 1e-12).all()
    # The 15 + 15 N forward and up pull, standing at rest: F/K forward (inside the bound),
    # none up.
    K = scenario.compliance.stiffness_N_per_m
    plateau = (sig["time_s"] > 7.0) & (sig["time_s"] < 10.5)  # full pull 3.5-10.5 s
    assert (sig["state"][plateau] == 4).all()
    np.testing.assert_allclose(offset[plateau][:, 0], 30.0 / K, rtol=1e-3)
    np.testing.assert_allclose(offset[plateau][:, 2], 0.0, atol=1e-4)
    seated = sig["state"] <= 2
    assert offset[seated][:, 2].max() == pytest.approx(30.0 / K, rel=0.02)  # seated: up too
    assert np.abs(offset[-1]).max() < 1e-4  # back on the path 4 s after the pull ended


@pytest.fixture(scope="module")
def reactive(tmp_path_factory):
    out = tmp_path_factory.mktemp("reactive")
    scenario, metrics = _run("reactive", out, baseline=True)
    return scenario, metrics, load_signals(out / "signals.npz")


def test_reactive_helper_stands_up_sooner_and_lets_go(reactive, unassisted):
    """Issue 12: the person guiding the hands stands the robot up at least 15%
    sooner than alone; psi_dot within [1, upper], psi = t wherever nobody
    pulls; the pull within the cap, never sideways nor backwards, and none on
    the standing robot; the same helper at psi = t stands the robot up too."""
    scenario, m, sig = reactive
    _, u = unassisted
    assert m["success"], m["failure_reason"]
    assert m["qp_failures"] == 0
    assert m["standup_time_s"] <= 0.85 * u["standup_time_s"]
    assert 1.0 <= m["psi_dot_min"] and m["psi_dot_max"] <= scenario.advancement.psi_dot_upper
    assert m["standup_time_s_without_advancement"] is not None  # psi = t stood up too
    forces = sig["hand_wrenches_W"].reshape(-1, 2, 6)[:, :, 3:]
    assert np.linalg.norm(forces, axis=2).max() <= scenario.human.reactive.force_cap_N + 1e-9
    assert not forces[:, :, 1].any()
    assert forces[:, :, 0].min() >= 0.0 and forces[:, :, 2].min() >= 0.0
    # psi = t wherever nobody pulls: psi_dot follows the law (1 there) with a first-order
    # lag, so after the helper lets go its excess decays as exp(-dt / tau) (analytic bound).
    nobody = ~forces.any(axis=(1, 2))
    t = sig["time_s"]
    last_pull = np.maximum.accumulate(np.where(~nobody, t, -np.inf))
    bound = (scenario.advancement.psi_dot_upper - 1.0) * np.exp(
        -(t - last_pull) / scenario.advancement.psi_ddot_filter_s
    )
    assert np.all(sig["psi_dot"][nobody] - 1.0 <= bound[nobody] + 1e-12)
    assert np.all(sig["psi_dot"][nobody & (last_pull == -np.inf)] == 1.0)
    standing = sig["time_s"] >= sig["time_s"][np.argmax(sig["state"] >= 2)] + m["standup_time_s"]
    assert np.all(nobody[standing])


def test_a_hindering_pull_waits_seated_and_the_robot_stands_up_once_it_stops():
    """Issue 13: 10 N backwards on each hand from 3 s to 11 s. The stand-up starts at 3 s,
    sits back when the pull is felt, waits seated while it lasts (psi = t), and stands up
    erect once it stops; no fall, no QP failure."""
    scenario, m = _run("hindering")
    assert m["success"], m["failure_reason"]
    assert m["qp_failures"] == 0
    assert m["psi_dot_min"] == 1.0 and m["psi_dot_max"] == 1.0
    pull = scenario.human.pulls[0]
    end_of_pull = pull.start_s + pull.duration_s
    assert m["held_back_s"] > 0.8 * pull.duration_s
    assert m["state_entry_times_s"][1] >= end_of_pull - pull.ramp_s  # restarted after it
    assert m["com_final_m"][2] == pytest.approx(m["standing_com_height_m"], abs=0.01)


@pytest.mark.parametrize(
    ("start_s", "force_N"),
    [(1.0, 18.0), (3.5, 18.0), (4.5, 18.0), (4.6, 18.0), (5.2, 18.0), (8.0, 18.0), (3.2, 2.0)],
    ids=[
        "seated",
        "in_state_2",
        "as_state_3_begins",
        "in_state_3",
        "in_state_4",
        "standing",
        "2N_in_state_2",
    ],
)
def test_a_hindering_pull_in_any_state_does_not_topple_it(start_s, force_N):
    """Issues 13 and 21: the authors' opposing person (18 N backwards on each hand,
    [icub-logs]), abrupt (0.1 s ramps), for 4 s, started before the stand-up (1.0 s),
    inside state 2 (3.5 s: it sits back and waits), as state 3 begins (4.5 s) or inside
    it (4.6 s: it goes back onto its thighs in state 2),
    state 4 (5.2 s) or on the standing robot (8.0 s: it leans into the pull within its
    feet). No fall, psi = t throughout, and it ends standing erect (before the lean was
    bounded by the feet it fell when the pull stopped). 2 N per hand in state 2 toppled
    the robot under the first 8 N threshold of the hold; it now sits back too."""
    from drake_standup.config import Pull

    scenario = load_scenario(SCENARIO_DIR / "unassisted.yaml")
    scenario.human.pulls = [
        Pull(hand=hand, start_s=start_s, duration_s=4.0, ramp_s=0.1, force_N=[-force_N, 0.0, 0.0])
        for hand in ("left", "right")
    ]
    scenario.duration_s = max(scenario.duration_s, start_s + 4.0 + 5.0)
    m = simulate(scenario, None, record=False, progress=False).metrics
    assert m["success"], m["failure_reason"]
    assert m["qp_failures"] == 0
    assert m["psi_dot_max"] == 1.0
    assert m["com_final_m"][2] == pytest.approx(m["standing_com_height_m"], abs=0.01)


@pytest.mark.parametrize("mass_scale", [0.85, 1.15])
def test_a_robot_lighter_or_heavier_than_its_model_weighs_itself_and_stands_up(mass_scale):
    """Issue 13: the simulated robot 15 % lighter or heavier than the controller's model,
    under the default pull. Seated, the controller weighs it on its pads (m g = the pads'
    and hands' vertical forces): the estimate is the simulated mass within 1 %, and the
    robot stands up erect and stays standing."""
    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    scenario.duration_s = 8.0
    scenario.perturbation.mass_scale = mass_scale
    m = simulate(scenario, None, record=False, progress=False).metrics
    assert m["success"], m["failure_reason"]
    assert m["qp_failures"] == 0
    assert m["model_mass_kg"] == pytest.approx(m["simulated_mass_kg"], rel=0.01)
    assert m["com_final_m"][2] == pytest.approx(m["standing_com_height_m"], abs=0.01)


@pytest.mark.parametrize("name", ["hindering", "lateral"])
def test_unhelpful_pulls_never_advance_and_end_cleanly(name):
    scenario, m = _run(name)
    assert m["psi_dot_min"] == 1.0
    assert m["psi_dot_max"] == 1.0  # a hindering or perpendicular pull never helps
    assert m["psi_final"] == pytest.approx(m["sim_time_s"], abs=1e-9)
    assert m["success"] or m["failure_reason"]


def test_signals_npz_gives_the_metrics_back(unassisted_run):
    """The stand-up read straight off signals.npz, state array and time grid
    only: state entries to within one log sample of the state machine's own
    entry times, and the stand-up time (from the first sample in state 2 to the
    first sample from which, for 0.2 s, the CoM stays within 1 cm of the
    reference's final height and the thighs and the buttocks each carry < 5 N)
    to within two samples of the metric (each of its two ends is read to one sample)."""
    scenario, m, sig = unassisted_run
    t, state = sig["time_s"], sig["state"]
    dt = scenario.log_period_s
    for k in (2, 3, 4):
        t_k = t[np.argmax(state >= k)]
        assert t_k == pytest.approx(m["state_entry_times_s"][k - 1], abs=dt + 1e-9)
    groups = sig["pad_groups"]
    normal = sig["pad_normal_force_N"]
    off = np.ones(len(t), dtype=bool)
    for group in ("thighs", "buttocks"):
        off &= normal[:, groups == group].sum(axis=1) < 5.0
    # The erect height the metric used (checked against forward kinematics by
    # test_it_ends_standing_erect).
    up = off & (np.abs(sig["com_W"][:, 2] - m["standing_com_height_m"]) <= 0.01)
    window = int(round(0.2 / dt))
    held = [i for i in range(len(t) - window) if up[i : i + window + 1].all()]
    standup = t[held[0]] - t[np.argmax(state >= 2)]
    assert standup == pytest.approx(m["standup_time_s"], abs=2 * dt + 1e-9)


RUNS = ("assisted_run", "unassisted_run", "reactive")


@pytest.mark.parametrize("run", RUNS)
def test_it_ends_standing_erect(run, request):
    """Issue 12: both knees within 0.35 rad of straight and the CoM at least 0.55 m up at
    the end (read off signals.npz), and the CoM where forward kinematics puts it for the
    final joint angles with the soles flat (scene.standing): the simulated
    robot stands on flat feet, not tilted onto an edge."""
    scenario, m, sig = request.getfixturevalue(run)
    names = list(sig["joint_names"])
    q = sig["joint_positions_rad"][-1]
    for knee in ("l_knee", "r_knee"):
        assert abs(q[names.index(knee)]) <= 0.35
    assert sig["com_W"][-1, 2] >= 0.55
    built = build_diagram(scenario)
    final = dict(zip(names, q, strict=True))
    assert sig["com_W"][-1, 2] == pytest.approx(
        built.station.scene.standing.erect_com_height_m(final), abs=0.005
    )


@pytest.mark.parametrize("run", RUNS)
@pytest.mark.parametrize("group", ["thighs", "buttocks"])
def test_seat_pads_unload_once_and_stay_unloaded(run, group, request):
    """Issue 12: after the first second (the robot settling onto the chair), the group's
    total normal force crosses 5 N once, downwards, and never rises above 5 N again."""
    _, _, sig = request.getfixturevalue(run)
    t = sig["time_s"]
    force = sig["pad_normal_force_N"][:, sig["pad_groups"] == group].sum(axis=1)[t > 1.0]
    loaded = force > 5.0
    switches = np.flatnonzero(loaded[:-1] != loaded[1:])
    assert len(switches) == 1 and loaded[switches[0]], (group, t[t > 1.0][switches])
    assert force[switches[0] + 1 :].max() <= 5.0


def _hand_positions(scenario, sig) -> np.ndarray:
    """The hand frames' origins (N x 2 x 3) by forward kinematics of the logged poses."""
    from pydrake.common.eigen_geometry import Quaternion
    from pydrake.math import RigidTransform

    from drake_standup.standup.plan import feet_reach
    from drake_standup.world.station import make_station

    station = make_station(scenario, feet_reach(scenario.controller))
    plant, robot = station.plant, station.robot
    context = plant.CreateDefaultContext()
    base = plant.GetBodyByName("root_link", robot.model_instance)
    joints = [plant.GetJointByName(str(n), robot.model_instance) for n in sig["joint_names"]]
    hands = [robot.frame(plant, name) for name in ("l_hand", "r_hand")]
    out = np.empty((len(sig["time_s"]), 2, 3))
    for i in range(len(sig["time_s"])):
        q = sig["base_quaternion_wxyz"][i]
        pose = RigidTransform(Quaternion(q / np.linalg.norm(q)), sig["base_position_W"][i])
        plant.SetFreeBodyPose(context, base, pose)
        for joint, angle in zip(joints, sig["joint_positions_rad"][i], strict=True):
            joint.set_angle(context, float(angle))
        out[i] = [hand.CalcPoseInWorld(context).translation() for hand in hands]
    return out


def test_the_helpers_work_is_force_times_the_hands_displacement(assisted_run):
    """Over the pull's plateau (15 + 15 N per hand, constant from 3.5 to 10.5 s) the
    helper's work, summed on the plant's steps, is F . (p(t2) - p(t1)) for each hand,
    p from forward kinematics of the logged poses. The same work from the logged
    velocities (the trapezoid rule on 10 ms samples of a 4 ms plant) is within 5 %
    (test_advancement checks the velocities themselves)."""
    from drake_standup.outputs.metrics import helper_metrics

    scenario, m, sig = assisted_run
    t = sig["time_s"]
    assert m["helper_peak_force_N"] == pytest.approx(np.hypot(15.0, 15.0), rel=1e-9)
    # Both hands, the trapezoid's 8 s of which 7 at full force and two 0.5 s ramps.
    assert m["helper_impulse_Ns"] == pytest.approx(2 * np.hypot(15.0, 15.0) * 7.5, rel=2e-3)
    p = _hand_positions(scenario, sig)
    plateau = (t >= 3.5) & (t <= 10.5)
    i1, i2 = np.flatnonzero(plateau)[[0, -1]]
    F = np.array([15.0, 0.0, 15.0])
    by_displacement = float(F @ (p[i2] - p[i1]).sum(axis=0))
    assert by_displacement > 5.0  # the hands travelled forward and up with the robot
    work = sig["helper_work_J"]
    assert work[i2] - work[i1] == pytest.approx(by_displacement, rel=1e-5)  # 2e-6 seen
    assert m["helper_work_J"] == pytest.approx(work[-1])
    assert m["helper_positive_work_J"] >= m["helper_work_J"]
    window = slice(i1, i2 + 1)
    by_samples = helper_metrics(
        t[window], sig["hand_wrenches_W"][window], sig["hand_velocities_W"][window]
    )["helper_work_J"]
    assert by_samples == pytest.approx(by_displacement, rel=0.05)
    assert 0.0 < m["path_deviation_max_m"] < 0.1


def test_drakes_model_and_pinocchios_give_the_same_stand_up(assisted_run, tmp_path):
    """Issue 48: the controller's model by Pinocchio (controller.model_library:
    pinocchio) gives the default run Drake's model gives: the stand-up time and every
    state's entry within 0.02 s, the CoM within 1 mm at every logged sample."""
    import dataclasses

    scenario, metrics, signals = assisted_run
    assert scenario.controller.model_library == "drake"
    pinocchio = dataclasses.replace(
        scenario, controller=dataclasses.replace(scenario.controller, model_library="pinocchio")
    )
    other = simulate(pinocchio, tmp_path, record=False, progress=False).metrics
    other_signals = load_signals(tmp_path / "signals.npz")
    assert other["success"] and metrics["success"]
    assert other["standup_time_s"] == pytest.approx(metrics["standup_time_s"], abs=0.02)
    np.testing.assert_allclose(
        other["state_entry_times_s"], metrics["state_entry_times_s"], atol=0.02
    )
    np.testing.assert_array_equal(other_signals["time_s"], signals["time_s"])
    assert np.abs(other_signals["com_W"] - signals["com_W"]).max() < 1e-3
