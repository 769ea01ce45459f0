"""The guards' signals: the forces the stand-up's guards read, low-pass filtered (first
order, standup.force_filter_time_constant_s), through Schmitt triggers: a condition turns
on once its filtered force has stayed above the threshold for guard_dwell_s, and off once
it has stayed below guard_off_ratio times the threshold as long, so noise around a
threshold cannot flip it back and forth. Pure functions; transitions.py's next_mode reads
them, state_machine.py wraps both in a Drake system.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drake_standup.config import StandupConfig
from drake_standup.config.phases import PHASES, PhaseTable

N_STATES = len(PHASES)


@dataclass(frozen=True)
class SchmittTrigger:
    """A condition with hysteresis and dwell: on after the value has stayed above the on
    threshold for the dwell, off after it has stayed below the off threshold as long."""

    on: bool = False
    # Since when the value has been past the threshold that would flip the trigger
    # (NaN: it is not).
    pending_since_s: float = math.nan

    def update(
        self, value: float, t: float, on_above: float, off_below: float, dwell_s: float
    ) -> SchmittTrigger:
        crossing = value < off_below if self.on else value > on_above
        if not crossing:
            return self if math.isnan(self.pending_since_s) else SchmittTrigger(self.on)
        since = t if math.isnan(self.pending_since_s) else self.pending_since_s
        if t - since >= dwell_s - 1e-9:
            return SchmittTrigger(not self.on)
        return SchmittTrigger(self.on, since)


_OFF = SchmittTrigger()


@dataclass(frozen=True)
class GuardSignals:
    """Filtered forces and the triggers the guards read; feet_loaded[k] and
    each_foot_loaded[k] are phase k+1's exit conditions (off where it has none)."""

    t: float = math.nan  # time of the last update (NaN: none yet)
    foot_fz_N: tuple[float, float] = (0.0, 0.0)  # filtered, left, right
    hand_fx_N: tuple[float, float] = (0.0, 0.0)  # filtered, left, right
    hand_help_N: tuple[float, float] = (0.0, 0.0)  # filtered helping_pull_N, left, right
    hands_pulled: SchmittTrigger = _OFF  # both hands > hand_force_threshold_N
    # both hands' helping pull (forward and up) > gentle_pull_force_N for
    # gentle_pull_time_s
    hands_held: SchmittTrigger = _OFF
    # both hands pulled the sit-down's way (back and down, lowering_pull_N) by more than
    # gentle_pull_force_N for gentle_pull_time_s: the helper asks for the sit-down.
    hand_lower_N: tuple[float, float] = (0.0, 0.0)  # filtered lowering_pull_N
    hands_lowered: SchmittTrigger = _OFF
    feet_loaded: tuple[SchmittTrigger, ...] = (_OFF,) * N_STATES  # the feet together
    each_foot_loaded: tuple[SchmittTrigger, ...] = (_OFF,) * N_STATES  # each foot
    # A pull against the stand-up: one needing more than standing_pull_usage_limit of
    # the CoM's reach back over the heels (heel_usage), or, where a scenario sets
    # hindering_force_threshold_N, both hands together pulled back by more than it.
    hindered: SchmittTrigger = _OFF
    heel_usage: float = 0.0  # filtered
    # The largest filtered backward force on both hands while hindered; kept until the
    # backward force falls below guard_off_ratio of it (0: none). The same pull looks
    # smaller seated, its lever shorter: it is still against the stand-up. N.
    hindering_back_N: float = 0.0
    # A pull needing more than standing_pull_usage_limit of what the standing robot's
    # feet can hold (filtered usage; the trigger).
    pull_usage: float = 0.0
    # The arms braced (held as seated, hands near the body) while the pull needs more
    # than standing_pull_usage_limit of the feet's hold with the arms reaching out
    # (standup.brace_arms); beyond_feet then judges the usage braced (filtered).
    brace: SchmittTrigger = _OFF
    braced_usage: float = 0.0
    beyond_feet: SchmittTrigger = _OFF

    def hindering(self) -> bool:
        """A pull against the stand-up: the trigger, or the pull that set it not yet eased."""
        return self.hindered.on or self.hindering_back_N > 0.0

    def against(self) -> bool:
        """A pull the stand-up cannot go on under: hindering, or beyond the feet."""
        return self.hindering() or self.beyond_feet.on


@dataclass(frozen=True)
class Measurements:
    """What the guards read: time, psi, CoM, heel edge, feet and hand forces."""

    t: float
    psi: float
    com_W: np.ndarray
    heel_x: float
    foot_fz_N: tuple[float, float]  # left, right
    hand_fx_N: tuple[float, float]  # left, right
    # The x of the thigh pads' centres (NaN: not measured; a release waiting for the CoM
    # to pass them never begins).
    thigh_x: float = math.nan
    # sensing.standing_pull_usage of the measured pull (0: not measured), and the same
    # with the arms braced (NaN: not measured; the arms never brace).
    pull_usage: float = 0.0
    braced_usage: float = math.nan
    # The hands' z forces, left, right (0: not measured). N.
    hand_fz_N: tuple[float, float] = (0.0, 0.0)
    # sensing.pull_cop_shift_m: how far the pull moves the centre of pressure under the
    # robot at its posture now (negative: back; 0: not measured). m.
    cop_shift_m: float = 0.0
    # How often someone asked for the stand-up (live mode's "Stand up" button): with
    # trigger 'hands', as good as the pull; after k sit-downs the (k+1)-th counts.
    stand_up: float = 0.0
    # The seat pads' normal forces, buttocks, left and right thigh (phases.SEAT_PAD_ROWS;
    # NaN: not measured): what tells the sit-down its thighs and buttocks have touched. N.
    seat_fz_N: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    # How often someone asked for the sit-down (live mode's "Sit down" button).
    sit_down: float = 0.0
    # How high the thigh pads' undersides, and the buttocks pad's, are above the seat's
    # top (kinematics: on the iCub, the encoders and the base estimate; NaN: not known). m.
    thigh_gap_m: float = math.nan
    buttocks_gap_m: float = math.nan


# A pull that lifts the robot uses its reach this many times over (it stays finite
# through the filter).
_LIFTED_USAGE = 10.0


def heel_usage(m: Measurements, table: PhaseTable) -> float:
    """The share of the CoM's reach back over the heels that the pull's backward shift of
    the centre of pressure needs (1: the CoP at the heels' edge). The reach is the CoM's
    lead over the heels now, at least the lead with which the phases hand the robot to
    its feet (their exits' com_ahead_of_heels_m): before then the seat holds the pull,
    and what counts is whether the feet will."""
    if m.cop_shift_m >= 0.0:
        return 0.0
    lead = max((p.exit.com_ahead_of_heels_m or 0.0 for p in table), default=0.0)
    reach = max(float(m.com_W[0]) - m.heel_x, lead)
    if reach <= 0.0 or math.isinf(m.cop_shift_m):
        return _LIFTED_USAGE
    return min(-m.cop_shift_m / reach, _LIFTED_USAGE)


def helping_pull_N(fx_N: float, fz_N: float) -> float:
    """The part of a hand's pull that goes the stand-up's way, forward and up: a grip of
    9 N along a 45-degree pace pulls 6.4 N forward, no less a request to stand."""
    return math.hypot(max(fx_N, 0.0), max(fz_N, 0.0))


def lowering_pull_N(fx_N: float, fz_N: float) -> float:
    """The part of a hand's pull that goes the sit-down's way, back and down."""
    return math.hypot(max(-fx_N, 0.0), max(-fz_N, 0.0))


def _low_pass(previous: tuple[float, ...], raw: tuple[float, ...], gain: float) -> tuple:
    return tuple(float(y + gain * (x - y)) for y, x in zip(previous, raw, strict=True))


def update_guards(
    g: GuardSignals, m: Measurements, cfg: StandupConfig, table: PhaseTable
) -> GuardSignals:
    """The guards' signals after a measurement: forces filtered (first order, exact for a
    step held over the update: gain 1 - exp(-dt / tau); the first measurement starts the
    filters), then the triggers of every phase's exit."""
    can_brace = cfg.brace_arms and not math.isnan(m.braced_usage)
    braced_raw = m.braced_usage if can_brace else 0.0
    heel_raw = heel_usage(m, table)
    help_raw = tuple(helping_pull_N(x, z) for x, z in zip(m.hand_fx_N, m.hand_fz_N, strict=True))
    lower_raw = tuple(lowering_pull_N(x, z) for x, z in zip(m.hand_fx_N, m.hand_fz_N, strict=True))
    if math.isnan(g.t):
        feet, hands, helping = tuple(m.foot_fz_N), tuple(m.hand_fx_N), help_raw
        lowering = lower_raw
        usage, braced, heel = m.pull_usage, braced_raw, heel_raw
    else:
        tau = cfg.force_filter_time_constant_s
        gain = 1.0 if tau <= 0 else 1.0 - math.exp(-max(m.t - g.t, 0.0) / tau)
        feet = _low_pass(g.foot_fz_N, m.foot_fz_N, gain)
        hands = _low_pass(g.hand_fx_N, m.hand_fx_N, gain)
        helping = _low_pass(g.hand_help_N, help_raw, gain)
        lowering = _low_pass(g.hand_lower_N, lower_raw, gain)
        usage, braced, heel = _low_pass(
            (g.pull_usage, g.braced_usage, g.heel_usage), (m.pull_usage, braced_raw, heel_raw), gain
        )
    off, dwell = cfg.guard_off_ratio, cfg.guard_dwell_s
    limit = cfg.standing_pull_usage_limit
    brace = g.brace.update(usage, m.t, limit, off * limit, dwell) if can_brace else _OFF

    def trigger(trigger: SchmittTrigger, value: float, threshold: float | None):
        if threshold is None:
            return trigger
        return trigger.update(value, m.t, threshold, off * threshold, dwell)

    hand_on, back_on = cfg.hand_force_threshold_N, cfg.hindering_force_threshold_N
    back = -sum(hands)
    # The backward force itself counts only where a scenario sets its threshold (older
    # files); judged by its effect, a pull is against the stand-up if the feet cannot
    # hold it.
    against = heel / limit
    if back_on is not None:
        against = max(against, back / back_on if back_on > 0 else (math.inf if back > 0 else 0.0))
    gentle = cfg.gentle_pull_force_N
    exits = [phase.exit for phase in table]
    hindered = g.hindered.update(against, m.t, 1.0, off, dwell)
    remembered = max(g.hindering_back_N, back) if hindered.on else g.hindering_back_N
    if not hindered.on and back < off * remembered:
        remembered = 0.0
    return GuardSignals(
        t=m.t,
        foot_fz_N=feet,
        hand_fx_N=hands,
        hand_help_N=helping,
        hands_pulled=g.hands_pulled.update(min(hands), m.t, hand_on, off * hand_on, dwell),
        hands_held=g.hands_held.update(
            min(helping), m.t, gentle, off * gentle, max(dwell, cfg.gentle_pull_time_s)
        ),
        hand_lower_N=lowering,
        hands_lowered=g.hands_lowered.update(
            min(lowering), m.t, gentle, off * gentle, max(dwell, cfg.gentle_pull_time_s)
        ),
        feet_loaded=tuple(
            trigger(k, sum(feet), e.feet_force_N) for k, e in zip(g.feet_loaded, exits)
        ),
        each_foot_loaded=tuple(
            trigger(k, min(feet), e.each_foot_force_N) for k, e in zip(g.each_foot_loaded, exits)
        ),
        hindered=hindered,
        heel_usage=heel,
        hindering_back_N=remembered,
        pull_usage=usage,
        brace=brace,
        braced_usage=braced,
        beyond_feet=g.beyond_feet.update(
            braced if brace.on else usage, m.t, limit, off * limit, dwell
        ),
    )
