"""End-to-end: the iCub stays seated under the joint-space hold (issue 2)."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from drake_standup.robot.urdf import original_urdf

pytestmark = pytest.mark.slow

G = 9.81


def _urdf_mass_kg(model: str) -> float:
    """Robot mass summed straight from the URDF, independently of Drake."""
    root = ET.parse(original_urdf(model)).getroot()
    return sum(float(m.get("value")) for m in root.iter("mass"))


def test_run_completes_and_writes_outputs(seated_run):
    """Nobody pulls and the stand-up waits for a pull: the robot balances on
    the chair for the whole run. "success" means stood up, so it is false with
    exactly that reason, not a fall or a solver failure."""
    _, result, out = seated_run
    assert result.metrics["success"] is False
    assert result.metrics["failure_reason"] == "did not stand up"
    assert result.metrics["qp_failures"] == 0
    for name in ("recording.html", "metrics.json", "diagrams/standup.dot"):
        assert (out / name).is_file(), name
    metrics = json.loads((out / "metrics.json").read_text())
    for key in ("success", "failure_reason", "sim_time_s", "wall_time_s", "realtime_factor"):
        assert key in metrics
    assert metrics["sim_time_s"] == pytest.approx(5.0, abs=1e-6)
    assert metrics["realtime_factor"] > 0


def test_com_stays_put_after_settling(seated_run):
    """After the first 0.5 s the CoM moves less than 1 cm."""
    _, result, _ = seated_run
    after = result.times_s >= 0.5
    com = result.com_W[after]
    drift = np.linalg.norm(com - com[:1], axis=1).max()
    assert drift < 0.01
    assert result.metrics["com_drift_after_settle_m"] == pytest.approx(drift)


def test_contact_forces_carry_the_robot_weight(seated_run):
    """Soles, thighs and buttocks together carry m g (URDF mass) within 2%,
    with no net horizontal force, and each group carries part of it."""
    scenario, result, _ = seated_run
    weight = _urdf_mass_kg(scenario.robot.model) * G
    late = result.times_s >= 1.0
    total = result.pad_forces_W.sum(axis=1)[late]  # (N, 3)
    assert np.all(np.abs(total[:, 2] - weight) < 0.02 * weight)
    assert np.all(np.abs(total[:, :2]) < 0.02 * weight)
    groups = result.metrics["contact_normal_force_N"]
    assert set(groups) == {"soles", "thighs", "buttocks"}
    for name, fz in groups.items():
        assert fz > 0.05 * weight, name


def test_the_pads_impulse_is_the_weight_times_the_time(seated_run):
    """At rest the pads' impulse over the plant's steps is m g T (the robot's momentum
    does not change): over 1-5 s within 0.5 % of the URDF's weight times 4 s, and the
    mean force over every 10 ms interval within 2 % of the weight (no interval counts
    two or three of the 4 ms steps: 10 ms is 2.5 of them)."""
    scenario, result, _ = seated_run
    weight = _urdf_mass_kg(scenario.robot.model) * G
    t = result.signals["time_s"]
    vertical = result.signals["pad_impulses_Ns"][:, :, 2].sum(axis=1)
    i, j = np.searchsorted(t, [1.0, 5.0])
    assert vertical[j] - vertical[i] == pytest.approx(weight * (t[j] - t[i]), rel=0.005)
    mean = np.diff(vertical[i : j + 1]) / np.diff(t[i : j + 1])
    assert np.all(np.abs(mean - weight) < 0.02 * weight)


def test_only_the_pads_touch_anything(seated_run):
    """The robot's only collision geometries are the five pads, and every one
    of them is in contact at the end (the pose really rests on chair and floor)."""
    _, result, _ = seated_run
    final = result.pad_forces_W[-1, :, 2]
    assert set(result.pad_names) == {
        "l_sole_pad",
        "r_sole_pad",
        "l_thigh_pad",
        "r_thigh_pad",
        "buttocks_pad",
    }
    assert np.all(final > 1.0)


def test_psi_equals_time_without_a_pull(seated_run):
    """Nobody pulls: psi(t) = t to 1e-9 over the whole run, psi_dot = 1."""
    _, result, _ = seated_run
    assert result.metrics["psi_final"] == pytest.approx(5.0, abs=1e-9)
    assert result.metrics["psi_dot_min"] == 1.0 and result.metrics["psi_dot_max"] == 1.0
    assert result.metrics["state_entry_times_s"] == [0.0, None, None, None]


def test_psi_equals_time_with_advancement_disabled():
    """A pull from t = 0.5 s, advancement off: psi = t, psi_dot = 1 exactly."""
    from drake_standup.config import SCENARIO_DIR, load_scenario
    from drake_standup.sim.simulate import simulate

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    scenario.advancement.enabled = False
    scenario.duration_s = 1.5
    for pull in scenario.human.pulls:
        pull.start_s = 0.5
    result = simulate(scenario, None, record=False, progress=False)
    assert result.metrics["psi_final"] == pytest.approx(1.5, abs=1e-9)
    assert result.metrics["psi_dot_min"] == 1.0 and result.metrics["psi_dot_max"] == 1.0


def test_the_default_standing_height_is_the_erect_posture():
    """The rise ends, by default, at the CoM height of the authors' state-4 posture
    with the soles flat (forward kinematics: phases.rise.com_height_erect, resolved per
    robot), 0.575 m on iCubGazeboV2_5, and that posture has flat soles: the sagittal leg
    angles sum to zero, so each sole's z axis is vertical."""
    from pydrake.systems.framework import DiagramBuilder

    from drake_standup.config import Scenario
    from drake_standup.world.scene import add_scene

    scenario = Scenario()
    scene = add_scene(DiagramBuilder(), scenario, pd_gains=None, visuals=False)
    posture = scenario.phases.rise.posture_rad
    for side in "lr":
        legs = [posture[f"{side}_{joint}"] for joint in ("hip_pitch", "knee", "ankle_pitch")]
        assert abs(sum(legs)) < 1e-9
    height = scene.standing.erect_com_height_m(posture)
    assert scenario.phases.rise.com_height_erect and scenario.phases.rise.com_height_m is None
    assert height == pytest.approx(0.575, abs=1e-3)
    # Straighter knees stand higher; a crouch lower (monotone in the knee).
    straighter = dict(posture, l_knee=-0.05, r_knee=-0.05, l_hip_pitch=0.05, r_hip_pitch=0.05)
    assert scene.standing.erect_com_height_m(straighter) > height
