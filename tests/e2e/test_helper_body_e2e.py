"""Issue 32 end to end (slow): people of 1.55 and 1.90 m, 50 and 100 kg, their arms
relaxed or firm, stand the robot up, none falls; their logged torques never exceed
their strength, and a relaxed person keeps strength to spare; with the default person
advancement stands up at least 15 % sooner than the stiff response (issue 32), the grip
peaks at most at twice what they mean to pull, they do no negative work on the robot, its
arms stay under 3 rad/s and the person's back straightens at their own pace (issue 46)."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.helper.body_control import TRUNK_RATE_RAD_PER_S
from drake_standup.sim.simulate import simulate

pytestmark = pytest.mark.slow

BODY = SCENARIO_DIR / "body.yaml"
PEOPLE = [
    (height, mass, tone)
    for height in (1.55, 1.90)
    for mass in (50.0, 100.0)
    for tone in ("relaxed", "firm")
]


def _run(overrides: list):
    scenario = load_scenario(BODY, overrides)
    return simulate(scenario, None, record=False, progress=False)


def _metrics(overrides: list) -> dict:
    return _run(overrides).metrics


@pytest.mark.parametrize(("height_m", "mass_kg", "tone"), PEOPLE)
def test_any_person_stands_the_robot_up_within_their_strength(height_m, mass_kg, tone):
    m = _metrics(
        [
            ("human.body.height_m", height_m),
            ("human.body.mass_kg", mass_kg),
            ("human.body.tone", tone),
        ]
    )
    assert m["success"], m["failure_reason"]
    assert m["standing_at_end"] and m["qp_failures"] == 0
    # The plant clamps each joint to its strength; a relaxed person never needs it all
    # (a firm one reaches their back's strength: docs/design.md).
    assert m["helper_peak_strength_fraction"] <= 1.0 + 1e-9
    if tone == "relaxed":
        assert m["helper_peak_strength_fraction"] < 0.95
    assert 0.0 < m["helper_peak_shoulder_torque_Nm"] and 0.0 < m["helper_peak_lumbar_torque_Nm"]


def test_advancement_stands_up_15_percent_sooner_than_stiff_with_the_default_person():
    run = _run([])
    advancement = run.metrics
    stiff = _metrics([("response", "stiff")])
    assert advancement["success"] and stiff["success"]
    assert advancement["standing_at_end"] and stiff["standing_at_end"]
    # 2.96 s against 3.71 s here (docs/results.md).
    assert advancement["standup_time_s"] <= 0.85 * stiff["standup_time_s"], (
        advancement["standup_time_s"],
        stiff["standup_time_s"],
    )
    # Issue 46: a grip a person can hold (at most twice what they mean per hand), no work
    # against the robot, no whip; 36 N for 20 N, +7 J, 2.5 rad/s here (docs/results.md).
    meant_N = load_scenario(BODY).human.reactive.force_cap_N
    assert advancement["helper_peak_force_N"] <= 2.0 * meant_N
    assert advancement["helper_work_J"] >= 0.0
    assert advancement["peak_joint_speed_arms_rad_per_s"] <= 3.0
    assert advancement["peak_joint_speed_neck_rad_per_s"] <= 3.0
    # The back straightens at a person's pace: its set-point moves at most at
    # TRUNK_RATE_RAD_PER_S and the joint follows it without overshooting far (0.87 rad/s
    # here; 3.5 rad/s with an unbounded set-point).
    s = run.signals
    lumbar = list(s["helper_joint_names"]).index("lumbar_flexion")
    speed = np.abs(s["helper_joint_velocities_rad_per_s"][:, lumbar])
    assert 0.3 * TRUNK_RATE_RAD_PER_S < speed.max() <= 1.2 * TRUNK_RATE_RAD_PER_S
