"""End-to-end stand-ups through the whole diagram (slow: ~40 s each)."""

from __future__ import annotations

import pytest

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.simulate import simulate

pytestmark = pytest.mark.slow


def _run(name: str, **kw):
    scenario = load_scenario(SCENARIO_DIR / f"{name}.yaml")
    return scenario, simulate(scenario, None, record=False, progress=False, **kw).metrics


@pytest.fixture(scope="module")
def unassisted():
    return _run("unassisted")


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
