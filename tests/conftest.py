"""Shared fixtures: one seated run, simulated once per test session."""

from __future__ import annotations

import pytest

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.simulate import simulate


@pytest.fixture(scope="session")
def seated_run(tmp_path_factory):
    """scenarios/seated.yaml, 5 s, with recording, written to a tmp dir."""
    scenario = load_scenario(SCENARIO_DIR / "seated.yaml")
    scenario.duration_s = 5.0
    out = tmp_path_factory.mktemp("seated")
    result = simulate(scenario, out, record=True, progress=False)
    return scenario, result, out
