"""End-to-end stand-ups through the whole diagram (slow: ~40 s each)."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.outputs import load_signals
from drake_standup.simulate import simulate

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
def assisted():
    return _run("assisted", baseline=True)


def test_unassisted_stands_up_with_psi_equal_to_time(unassisted):
    scenario, m = unassisted
    assert m["success"], m["failure_reason"]
    assert m["standup_time_s"] is not None
    assert m["psi_final"] == pytest.approx(scenario.duration_s, abs=1e-9)
    assert m["psi_dot_min"] == 1.0 and m["psi_dot_max"] == 1.0
    assert m["qp_failures"] == 0
    assert m["com_final_m"][2] == pytest.approx(scenario.standup.standing_com_height_m, abs=0.02)
    assert m["contact_normal_force_N"]["thighs"] < 1.0
    assert m["contact_normal_force_N"]["buttocks"] < 1.0
    assert m["max_abs_torque_Nm"] <= scenario.robot.effort_limit_Nm + 1e-9


def test_assisted_stands_up_sooner(assisted, unassisted):
    scenario, m = assisted
    _, u = unassisted
    assert m["success"], m["failure_reason"]
    assert m["psi_dot_max"] > 1.0
    assert m["psi_dot_max"] <= scenario.advancement.psi_dot_upper
    assert m["psi_final"] > scenario.duration_s  # psi ran ahead of time
    assert m["standup_time_s"] <= 0.8 * u["standup_time_s"]
    # The same scenario with psi = t (the faded reference of the figure).
    assert m["standup_time_s"] < m["standup_time_s_without_advancement"]


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
    up = off & (np.abs(sig["com_W"][:, 2] - sig["com_reference_W"][-1, 2]) <= 0.01)
    window = int(round(0.2 / dt))
    held = [i for i in range(len(t) - window) if up[i : i + window + 1].all()]
    standup = t[held[0]] - t[np.argmax(state >= 2)]
    assert standup == pytest.approx(m["standup_time_s"], abs=2 * dt + 1e-9)
