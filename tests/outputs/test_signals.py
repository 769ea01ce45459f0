"""signals.npz: the logged time series every run writes beside metrics.json.

Checked against what is known independently of the logging: the seated pose
the scenario starts from, psi = t when nobody helps, the robot's weight on its
pads, and the run's own metrics (computed before the file was written).
"""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.config.chair import SEATED_JOINTS
from drake_standup.outputs.signals import load_signals, write_signals

pytestmark = pytest.mark.slow

LISTED = {  # issue 11: the arrays a user can rely on, with their shapes
    "time_s": ("N",),
    "com_W": ("N", 3),
    "com_reference_W": ("N", 3),
    "psi": ("N",),
    "psi_dot": ("N",),
    "state": ("N",),
    "hand_wrenches_W": ("N", 12),
    "pad_normal_force_N": ("N", "P"),
    "pad_names": ("P",),
    "pad_groups": ("P",),
    "joint_positions_rad": ("N", "J"),
    "joint_names": ("J",),
    "joint_torques_Nm": ("N", "J"),
}


@pytest.fixture(scope="module")
def seated(seated_run):
    scenario, result, out = seated_run
    return scenario, result, load_signals(out / "signals.npz")


def test_every_listed_array_with_its_shape(seated):
    scenario, _, sig = seated
    # The whole run, every log period: up to its end (the end itself logged or not).
    n = len(sig["time_s"])
    assert sig["time_s"][-1] > scenario.duration_s - scenario.log_period_s - 1e-9
    sizes = {"N": n, "P": 5, "J": 32}
    for name, shape in LISTED.items():
        assert name in sig, name
        assert sig[name].shape == tuple(sizes.get(d, d) for d in shape), name
    # One time grid, the loggers' period, from 0.
    np.testing.assert_allclose(np.diff(sig["time_s"]), scenario.log_period_s, atol=1e-12)
    assert sig["time_s"][0] == 0.0


def test_names_and_groups_match_the_model(seated):
    scenario, _, sig = seated
    names = [str(n) for n in sig["joint_names"]]
    assert len(set(names)) == 32 and set(SEATED_JOINTS) <= set(names)
    groups = dict(zip(sig["pad_names"], sig["pad_groups"]))
    assert groups == {
        "l_sole_pad": "soles",
        "r_sole_pad": "soles",
        "l_thigh_pad": "thighs",
        "r_thigh_pad": "thighs",
        "buttocks_pad": "buttocks",
    }


def test_joint_positions_start_in_the_scenarios_seated_pose(seated):
    """Column j at t = 0 is the seated angle of joint_names[j] (by name, so a column
    mix-up fails; joints the pose leaves out start at 0): the pose solved on the shipped
    chair, the authors' to 1 mrad (test_seating.py)."""
    _, _, sig = seated
    expected = np.array([SEATED_JOINTS.get(str(n), 0.0) for n in sig["joint_names"]])
    np.testing.assert_allclose(sig["joint_positions_rad"][0], expected, atol=2e-3)


def test_psi_is_time_and_the_pads_carry_the_weight(seated):
    _, result, sig = seated
    np.testing.assert_allclose(sig["psi"], sig["time_s"], atol=1e-9)
    assert np.all(sig["psi_dot"] == 1.0) and np.all(sig["state"] == 1)
    late = sig["time_s"] >= 1.0
    total = sig["pad_normal_force_N"][late].sum(axis=1)
    np.testing.assert_allclose(total, result.metrics["weight_N"], rtol=0.02)
    # The normal forces are the z column of the full pad forces.
    np.testing.assert_array_equal(sig["pad_normal_force_N"], sig["pad_forces_W"][:, :, 2])


def test_arrays_agree_with_the_metrics(seated):
    _, result, sig = seated
    m = result.metrics
    np.testing.assert_allclose(sig["com_W"][-1], m["com_final_m"], atol=0)
    assert np.abs(sig["joint_torques_Nm"]).max() == pytest.approx(m["max_abs_torque_Nm"])
    assert int(sig["qp_failures"][-1]) == m["qp_failures"]
    assert sig["psi"][-1] == pytest.approx(m["psi_final"], abs=2 * 0.01)


def test_round_trip_keeps_every_array(tmp_path, seated):
    _, result, sig = seated
    write_signals(tmp_path / "again.npz", result.signals)
    again = load_signals(tmp_path / "again.npz")
    assert again.keys() == sig.keys()
    for name in sig:
        np.testing.assert_array_equal(again[name], sig[name])
    # Plain numpy.load reads it without pickle (strings are unicode arrays).
    with np.load(tmp_path / "again.npz", allow_pickle=False) as data:
        assert str(data["pad_names"][0]) == str(sig["pad_names"][0])


def test_a_recording_does_not_change_the_simulation():
    """Meshcat's publishes sit on the plant's step grid (diagram.on_step_grid),
    so the same 0.6 s of the assisted scenario, with the pull from 0.1 s, is
    bitwise the same with and without the recording."""
    from drake_standup.config import SCENARIO_DIR, load_scenario
    from drake_standup.sim.simulate import simulate

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    scenario.duration_s = 0.6
    for pull in scenario.human.pulls:
        pull.start_s = 0.1
    plain = simulate(scenario, None, record=False, progress=False).signals
    recorded = simulate(scenario, None, record=True, progress=False).signals
    assert plain.keys() == recorded.keys()
    for name in plain:
        np.testing.assert_array_equal(recorded[name], plain[name], err_msg=name)


@pytest.mark.slow
def test_a_recording_does_not_change_the_default_run():
    """The whole default run (15 s, the stand-up and the pull), recorded and not: every
    logged signal bitwise the same. The contact forces' publishes at 0.1 s once landed
    an ulp off the plant's step at 3.9 s and split psi's integrator step: the two runs
    parted there by 1e-10."""
    from drake_standup.config import SCENARIO_DIR, load_scenario
    from drake_standup.sim.simulate import simulate

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    plain = simulate(scenario, None, record=False, progress=False).signals
    recorded = simulate(scenario, None, record=True, progress=False).signals
    assert plain["time_s"][-1] == pytest.approx(scenario.duration_s, abs=0.02)
    for name in plain:
        np.testing.assert_array_equal(recorded[name], plain[name], err_msg=name)


@pytest.mark.parametrize(
    ("period", "step", "expected"),
    [
        (1 / 30, 0.004, 0.032),
        (0.04, 0.004, 0.04),
        (0.1, 0.004, 0.096),  # 25 steps land off the grid (below); 24 on it
        (0.1, 0.001, 0.096),
        (0.04, 0.01, 0.04),
        (0.001, 0.004, 0.004),
    ],
)
def test_publish_periods_land_on_the_plant_steps_themselves(period, step, expected):
    """Every event k of the period is the plant's step k n in floating point, as Drake
    computes both (k * period, m * step), over the horizon."""
    from drake_standup.sim.diagram import ON_GRID_HORIZON_S, on_step_grid

    result = on_step_grid(period, step)
    assert result == pytest.approx(expected, rel=1e-12)
    n = round(result / step)
    assert result == step * n
    k = np.arange(1, int(ON_GRID_HORIZON_S / result) + 1)
    assert np.array_equal(k * result, (k * n) * step)


def test_a_whole_number_of_steps_is_not_enough():
    """Why on_step_grid checks the products: 25 steps of 4 ms, 39 times, is not the
    plant's 975th step (one ulp apart)."""
    assert 39 * (0.004 * 25) != 975 * 0.004


def test_the_psi_equals_t_run_in_its_own_process_equals_one_run_here(monkeypatch, capsys):
    """run_diagram's psi = t run goes to a second process as YAML; the same
    run simulated in this process (the fallback, forced by a Python that fails
    at once) gives bitwise the same signals, so the YAML round trip loses
    nothing of the scenario."""
    import sys

    from drake_standup.config import SCENARIO_DIR, load_scenario
    from drake_standup.sim.baseline import Baseline

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    scenario.duration_s = 0.8
    for pull in scenario.human.pulls:
        pull.start_s = 0.1
    there = Baseline(scenario, "whole_body", 0.05).result()
    monkeypatch.setattr(sys, "executable", "/bin/false")
    here = Baseline(scenario, "whole_body", 0.05).result()
    assert "simulating it here" in capsys.readouterr().err
    assert there.signals.keys() == here.signals.keys()
    for name in here.signals:
        np.testing.assert_array_equal(there.signals[name], here.signals[name], err_msg=name)
