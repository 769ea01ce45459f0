"""The scenario's sit-down (standup.sit_down, issue 62, docs/sit_down.md): its settings,
and what they must say of themselves, checked before anything simulates
(rules.validate)."""

from dataclasses import dataclass

from drake_standup.config.errors import ScenarioError
from drake_standup.config.phases import PHASES

# What starts a sit-down from standing (standup.sit_down.trigger): none (the robot stays
# up), hands (the helper's pull back and down, or the live page's Sit down button),
# time (standing stand_s).
SIT_DOWN_TRIGGERS = ("none", "hands", "time")


@dataclass
class SitDownConfig:
    """The sit-down after standing (states 5-7, phases.DESCENT), and standing again."""

    trigger: str = "none"
    # Standing this long (the rise's segment done) before the clock sits the robot down;
    # the hands' and the button's sit-down waits for standup.resume_after_s of standing. s.
    stand_s: float = 3.0
    # ... or the clock sits it down at this time of the run, once it stands (None:
    # stand_s after standing). Before the stand-up can have ended it is refused. s.
    at_s: float | None = None
    # Seated again, the robot balances this long before a stand-up may be asked again
    # (the seated phase's min_time_s is the first stand-up's). s.
    seated_s: float = 2.0
    # How many sit-downs a run makes at most.
    times: int = 1
    # A pad group has touched the seat once its pads' filtered normal force exceeds this
    # (the metrics' unloading level is 5 N: above the 1-3 N a compliant pad feels while
    # the thigh brushes it). N.
    touch_force_N: float = 10.0
    # ... or once the thigh pads' undersides are this near the seat's top (kinematics:
    # sensing's thigh_z_W against the chair's seat top), m.
    touch_gap_m: float = 0.005


def earliest_standing_s(scenario) -> float:
    """The earliest time of the run the robot can stand: the seated phase's balancing
    time, then the stand-up's segments at the fastest psi may run (psi_dot_upper with
    advancement, else the clock)."""
    phases = scenario.phases
    psi = sum(phases.phase(state).segment_psi for state in range(2, len(PHASES) + 1))
    advancing = scenario.advancement.enabled and scenario.response == "advancement"
    rate = scenario.advancement.psi_dot_upper if advancing else 1.0
    return phases.seated.exit.min_time_s + psi / rate


def check_sit_down(scenario) -> None:
    """standup.sit_down.at_s only with the clock's trigger, and not before the robot can
    have stood up."""
    sit = scenario.standup.sit_down
    if sit.at_s is None:
        return
    if sit.trigger != "time":
        raise ScenarioError(
            f"standup.sit_down.at_s: {sit.at_s:g}, but standup.sit_down.trigger is "
            f"'{sit.trigger}'; accepted: null, or trigger 'time'"
        )
    earliest = earliest_standing_s(scenario)
    if sit.at_s < earliest:
        raise ScenarioError(
            f"standup.sit_down.at_s: {sit.at_s:g} s is a sit-down before standing (the "
            f"robot stands at {earliest:.2f} s at the earliest: phases.seated's "
            f"{scenario.phases.seated.exit.min_time_s:g} s, then the stand-up's segments); "
            f"accepted: >= {earliest:.2f}"
        )
