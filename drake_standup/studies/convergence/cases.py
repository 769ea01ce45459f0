"""The study's cases: which scenarios at which plant steps and controller periods, and what
a case's result depends on (its inputs and their hash, the cache's key)."""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass

SCENARIOS = ("assisted", "unassisted", "lateral", "seated")
# Seated, nothing happens after the settling: 5 s is enough (issue 11).
SEATED_DURATION_S = 5.0
STEPS_MS = (0.5, 1.0, 2.0, 4.0, 5.0, 8.0, 10.0)
# Issue 11's reference: every run is compared with the scenario's run here.
REFERENCE_STEP_MS = 1.0
# Plant steps also run with the controller at twice the step.
SLOW_CONTROLLER_STEPS_MS = (2.0, 4.0, 5.0)
SLOW_CONTROLLER_FACTOR = 2


@dataclass(frozen=True)
class Case:
    """One run of the study: a scenario, a plant step, the controller's multiple."""

    scenario: str
    step_ms: float
    factor: int = 1  # controller period = factor * plant step
    # The study's one controller period (--controller-ms), whatever the step: the robot's
    # own rate (robot.hardware: icub runs at 100 Hz). None: the period follows the step.
    rate_ms: float | None = None

    @property
    def base(self) -> bool:
        """The study's own configuration: the controller at the step, or at the study's
        fixed period (rate_ms) throughout; not the slower-controller variant."""
        return self.rate_ms is not None or self.factor == 1

    @property
    def name(self) -> str:
        return f"{self.scenario}_{self.step_ms:g}_{self.factor}"

    @property
    def step_s(self) -> float:
        return self.step_ms / 1000.0

    @property
    def controller_period_ms(self) -> float:
        return self.factor * self.step_ms

    @property
    def controller_period_s(self) -> float:
        return self.controller_period_ms / 1000.0


def study_cases(
    scenarios: list[str], steps_ms: list[float], controller_ms: float | None = None
) -> list[Case]:
    """Every scenario at every step (controller at the step), plus the
    slow-controller variants at the steps of SLOW_CONTROLLER_STEPS_MS; with
    controller_ms, the controller at that period at every step instead (each step a
    whole divisor of it: steps_divide)."""
    cases = []
    for name in scenarios:
        for step in sorted(steps_ms):
            if controller_ms is not None:
                cases.append(Case(name, step, round(controller_ms / step), controller_ms))
                continue
            cases.append(Case(name, step))
            if step in SLOW_CONTROLLER_STEPS_MS:
                cases.append(Case(name, step, SLOW_CONTROLLER_FACTOR))
    return cases


def steps_divide(steps_ms: list[float], controller_ms: float) -> float | None:
    """The first step that is not a whole divisor of controller_ms (None: all are)."""
    from drake_standup.config import is_whole_multiple

    return next((s for s in steps_ms if not is_whole_multiple(controller_ms, s)), None)


def same_family(a: Case, b: Case) -> bool:
    """b is one of the runs a is compared with: the same scenario and study, in the
    study's own configuration (Case.base)."""
    return a.scenario == b.scenario and a.rate_ms == b.rate_ms and b.base


def scenario_duration_s(name: str, text: str) -> float:
    """The scenario's own duration; the seated scenario's SEATED_DURATION_S."""
    from drake_standup.config import parse_scenario

    return SEATED_DURATION_S if name == "seated" else parse_scenario(text, name).duration_s


def case_inputs(
    case: Case, scenario_text: str, duration_s: float, overrides: list | tuple = ()
) -> dict:
    """What a run's result depends on (bar the code), and its hash; overrides: the
    study's --set (key path, value) pairs, applied to every run."""
    inputs = {
        "scenario": case.scenario,
        "scenario_sha256": hashlib.sha256(scenario_text.encode()).hexdigest(),
        "duration_s": duration_s,
        "plant_time_step_s": case.step_s,
        "controller_period_s": case.controller_period_s,
    }
    if overrides:  # absent otherwise: runs cached before --set keep their hash
        inputs["overrides"] = [[path, value] for path, value in overrides]
    inputs["hash"] = hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:16]
    return inputs
