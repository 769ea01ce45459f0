"""The stand-sit-stand cycle through the whole diagram (slow: ~40 s each): the shipped
scenarios/cycle.yaml, and a pull against the sit-down while the robot lowers."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from docs_check import undocumented_metrics

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.outputs.signals import group_normal_forces, load_signals
from drake_standup.sim.simulate import simulate

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cycle(tmp_path_factory):
    out = tmp_path_factory.mktemp("cycle")
    scenario = load_scenario(SCENARIO_DIR / "cycle.yaml")
    metrics = simulate(scenario, out, record=False, progress=False).metrics
    return metrics, load_signals(out / "signals.npz")


def test_the_cycle_stands_sits_and_stands_again(cycle):
    m, signals = cycle
    assert m["success"], m["failure_reason"]
    assert m["qp_failures"] == 0
    state = signals["state"]
    changes = state[np.r_[True, state[1:] != state[:-1]]].tolist()
    assert changes == [1, 2, 3, 4, 5, 6, 7, 1, 2, 3, 4]
    (record,) = m["sit_downs"]
    assert record["stood_again"] and m["standing_at_end"]
    # The seat lands without a slap: its peak within 1.3 times the load it settles at.
    assert m["landing_peak_ratio"] <= 1.3
    assert m["thighs_landing_peak_ratio"] <= 1.3
    # Seated again as it sat at first: the CoM back over the seat, the seat loaded.
    i_seated = int(np.searchsorted(signals["time_s"], record["seated_s"] + 1.5))
    assert abs(signals["com_W"][i_seated, 0] - signals["com_W"][0, 0]) < 0.01
    assert record["seated_load_N"] > 0.5 * m["weight_N"]


def test_every_metric_of_the_cycle_is_documented(cycle):
    assert undocumented_metrics(cycle[0]) == []


def test_a_pull_against_the_lowering_stands_the_robot_back_up(tmp_path):
    """From 9.8 s, 10 N forward and 10 N up per hand while the clock's sit-down (at 9.5 s)
    lowers the robot: it rises again and waits standing, then sits down once the pull
    has eased; it never drops into the chair."""
    scenario = load_scenario(SCENARIO_DIR / "cycle.yaml")
    pulls = scenario.human.pulls[:2] + [
        dataclasses.replace(pull, start_s=9.8, duration_s=2.0, ramp_s=0.2, force_N=[10.0, 0, 10.0])
        for pull in scenario.human.pulls[2:4]
    ]
    sit = dataclasses.replace(scenario.standup.sit_down, trigger="time", at_s=9.5)
    scenario = dataclasses.replace(
        scenario,
        duration_s=18.0,
        human=dataclasses.replace(scenario.human, pulls=pulls),
        standup=dataclasses.replace(scenario.standup, sit_down=sit),
    )
    m = simulate(scenario, tmp_path, record=False, progress=False).metrics
    signals = load_signals(tmp_path / "signals.npz")
    assert m["success"], m["failure_reason"]
    first, second = m["sit_downs"]
    assert first["seated_s"] is None and 9.8 < first["stood_back_up_s"] < 11.0
    # While it was stood back up, the seat carried nothing: it did not fall into the chair.
    forces = group_normal_forces(signals)
    t, seat = signals["time_s"], forces["thighs"] + forces["buttocks"]
    waiting = (t > first["stood_back_up_s"]) & (t < second["start_s"])
    assert seat[waiting].max() < 1.0
    assert second["start_s"] > 11.8 and second["seated_s"] is not None
    # The second sit-down returns along the way up, not to where the first one turned
    # back (that half-lowered pose landed the thighs at 3 times their load).
    assert second["landing_peak_ratio"] <= 1.3
    assert second["thighs_landing_peak_ratio"] <= 1.3
