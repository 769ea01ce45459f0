"""StandupStateMachine: the four states of the stand-up and their guards.

    1 balance seated     -> 2 after balance_time_s, and with trigger 'hands'
                              once both hands feel a forward pull > threshold
                              or the stand_up input says go (live mode's button)
    2 CoM forward, the buttocks unloaded over seat_unload_s
                         -> 3 after min_time_state2_s, the state-2 segment done,
                              feet normal forces together > feet_force_2to3_N,
                              the CoM >= com_ahead_of_heels_m in front of the heels
    3 CoM forward, the thighs unloaded over seat_release_s
                         -> 4 after min_time_state3_s and the release, the
                              segment done, each foot's normal force >
                              foot_force_3to4_N
    4 CoM up to standing (final)
(SPEC 3 and 7.) "Segment done" (psi past the segment's end) keeps the
reference's slope continuous across switches; with psi_dot >= 1 it costs
nothing when the dwell time is at least the segment length. One switch per
update at most, so no state is ever skipped.

The force guards read low-pass filtered forces (first order,
force_filter_time_constant_s) through Schmitt triggers: a condition turns on
once its filtered force has stayed above the threshold for guard_dwell_s, and
off once it has stayed below guard_off_ratio times the threshold for as long,
so noise around a threshold cannot flip a guard back and forth. The filters
and triggers live in the mode: next_mode stays a pure function.

The contact plan says what is left of each seat pad's load while it unloads
(NaN while seated): the buttocks from 1 to 0 over seat_unload_s from state 2,
each thigh over seat_release_s from state 3 (smoothstep in both).

A pull against the stand-up (both hands together pulled backwards by more than
hindering_force_threshold_N, through the same filter and trigger) waits: state 1
does not start; state 2, and state 3 while the thighs carry more than
reseat_above_thigh_load of their load, sit back into state 1 (_reseat: the
reference returns to the seated CoM); later in state 3, the thighs unloading, the
robot goes back onto them in state 2 (_back_to_state_2: the reference held); once
they are off the chair state 3 holds. The stand-up goes on resume_after_s after
the pull stops.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from pydrake.common.value import Value
from pydrake.systems.framework import BasicVector, Context, LeafSystem, State

from drake_standup.config import StandupConfig
from drake_standup.reference import SEGMENT_SIZE, path, smoothstep

N_STATES = 4


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


@dataclass(frozen=True)
class GuardSignals:
    """Filtered forces and the triggers the guards read."""

    t: float = math.nan  # time of the last update (NaN: none yet)
    foot_fz_N: tuple[float, float] = (0.0, 0.0)  # filtered, left, right
    hand_fx_N: tuple[float, float] = (0.0, 0.0)  # filtered, left, right
    hands_pulled: SchmittTrigger = SchmittTrigger()  # both hands > hand threshold
    feet_loaded: SchmittTrigger = SchmittTrigger()  # the feet together > feet_force_2to3_N
    each_foot_loaded: SchmittTrigger = SchmittTrigger()  # each foot > foot_force_3to4_N
    # Both hands together pulled backwards (against the stand-up) by more than
    # hindering_force_threshold_N.
    hindered: SchmittTrigger = SchmittTrigger()


@dataclass(frozen=True)
class StandupMode:
    """The machine's abstract state: where it is, the active CoM segment, the guards'
    filtered signals and the seat pads' loads when their unloading began."""

    state: int = 1
    entry_times_s: tuple[float, ...] = (0.0,) + (math.nan,) * (N_STATES - 1)
    psi_entry: float = 0.0
    segment_psi: float = 1.0
    x_start_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    delta_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    guards: GuardSignals = GuardSignals()
    held_back_s: float = 0.0  # time spent waiting for a hindering pull to stop
    # Where the CoM sat at the start: a stand-up sat back by a hindering pull returns
    # there, so that its next state-2 segment starts where the first one did.
    x_seated_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    hindered_until_s: float = -math.inf  # the last time a hindering pull was felt
    # State 3 sent back to state 2 by a hindering pull: where its segment was to end
    # (NaN: not sent back). The next state 3 ends there.
    state3_end_m: tuple[float, float, float] = (math.nan, math.nan, math.nan)

    def __copy__(self) -> StandupMode:
        return self

    def __deepcopy__(self, memo: dict) -> StandupMode:
        """Itself: the mode is immutable. Drake clones the abstract state (a
        Python deepcopy) into and out of its scratch state at every
        unrestricted update of the diagram, i.e. at every plant step: real
        copies cost ~15 us a step (measured)."""
        return self

    def segment(self) -> np.ndarray:
        return np.array([self.psi_entry, self.segment_psi, *self.x_start_m, *self.delta_m])

    def segment_end(self) -> np.ndarray:
        return np.array(self.x_start_m) + np.array(self.delta_m)


@dataclass(frozen=True)
class Measurements:
    """What the guards read: time, psi, CoM, heel edge, feet and hand forces."""

    t: float
    psi: float
    com_W: np.ndarray
    heel_x: float
    foot_fz_N: tuple[float, float]  # left, right
    hand_fx_N: tuple[float, float]  # left, right
    # Someone asked for the stand-up (live mode's "Stand up" button): with
    # trigger 'hands', as good as the pull.
    stand_up: bool = False


def initial_mode(com0_W: np.ndarray) -> StandupMode:
    """State 1 at t = 0, holding the CoM where it starts."""
    com0 = tuple(float(c) for c in com0_W)
    return StandupMode(x_start_m=com0, x_seated_m=com0)


def _low_pass(previous: tuple[float, ...], raw: tuple[float, ...], gain: float) -> tuple:
    return tuple(float(y + gain * (x - y)) for y, x in zip(previous, raw, strict=True))


def update_guards(g: GuardSignals, m: Measurements, cfg: StandupConfig) -> GuardSignals:
    """The guards' signals after a measurement: forces filtered (first order, exact for a
    step held over the update: gain 1 - exp(-dt / tau); the first measurement starts the
    filters), then the triggers."""
    if math.isnan(g.t):
        feet, hands = tuple(m.foot_fz_N), tuple(m.hand_fx_N)
    else:
        tau = cfg.force_filter_time_constant_s
        gain = 1.0 if tau <= 0 else 1.0 - math.exp(-max(m.t - g.t, 0.0) / tau)
        feet = _low_pass(g.foot_fz_N, m.foot_fz_N, gain)
        hands = _low_pass(g.hand_fx_N, m.hand_fx_N, gain)
    off, dwell = cfg.guard_off_ratio, cfg.guard_dwell_s
    hand_on, feet_on, foot_on, back_on = (
        cfg.hand_force_threshold_N,
        cfg.feet_force_2to3_N,
        cfg.foot_force_3to4_N,
        cfg.hindering_force_threshold_N,
    )
    return GuardSignals(
        t=m.t,
        foot_fz_N=feet,
        hand_fx_N=hands,
        hands_pulled=g.hands_pulled.update(min(hands), m.t, hand_on, off * hand_on, dwell),
        feet_loaded=g.feet_loaded.update(sum(feet), m.t, feet_on, off * feet_on, dwell),
        each_foot_loaded=g.each_foot_loaded.update(min(feet), m.t, foot_on, off * foot_on, dwell),
        hindered=g.hindered.update(-sum(hands), m.t, back_on, off * back_on, dwell),
    )


def next_mode(mode: StandupMode, m: Measurements, cfg: StandupConfig) -> StandupMode:
    """The mode after one update: its guards' signals updated, in the same or the next
    state."""
    g = update_guards(mode.guards, m, cfg)
    held = mode.held_back_s
    if g.hindered.on and mode.state < 4 and not math.isnan(mode.guards.t):
        held += m.t - mode.guards.t
    hindered_until = m.t if g.hindered.on else mode.hindered_until_s
    mode = dataclasses.replace(mode, guards=g, held_back_s=held, hindered_until_s=hindered_until)
    dwell = m.t - mode.entry_times_s[mode.state - 1]
    segment_done = m.psi - mode.psi_entry >= mode.segment_psi
    hindered = g.hindered.on
    calm = not hindered and m.t - mode.hindered_until_s >= cfg.resume_after_s
    if hindered and mode.state == 3:
        thighs = seat_unloading(mode, m.t, cfg)[1]
        if thighs > cfg.reseat_above_thigh_load:  # the thighs still carry the robot
            return _reseat(mode, m, cfg)
        if thighs > 0.0:  # the thighs unloading: back onto them
            return _back_to_state_2(mode, m)
    if hindered and mode.state == 2 and math.isnan(mode.state3_end_m[0]):
        return _reseat(mode, m, cfg)
    if mode.state == 1:
        asked = cfg.trigger == "time" or g.hands_pulled.on or m.stand_up
        go = dwell >= cfg.balance_time_s and asked
        go = go and calm and (segment_done or not any(mode.delta_m))
    elif mode.state == 2:
        go = (
            dwell >= cfg.min_time_state2_s
            and segment_done
            and g.feet_loaded.on
            and m.com_W[0] >= m.heel_x + cfg.com_ahead_of_heels_m
            and calm
        )
    elif mode.state == 3:
        go = (
            dwell >= cfg.min_time_state3_s
            and dwell >= cfg.seat_release_s  # the thighs unloaded
            and segment_done
            and g.each_foot_loaded.on
            and calm
        )
    else:
        go = False
    if not go:
        return mode
    return _enter(mode, mode.state + 1, m, cfg)


def _reseat(mode: StandupMode, m: Measurements, cfg: StandupConfig) -> StandupMode:
    """Back to state 1 from state 2, or from state 3 while the thighs still carry more
    than reseat_above_thigh_load of their load: a pull against
    the stand-up waits seated (the paper: psi = t, nothing advances). The state-1
    segment starts where the reference is now (no jump) and returns to where the CoM
    sat at the start, at the pace of the state-2 segment; state 1's balancing time runs
    again from now, and state 2 waits for the return. Held where it was instead, the
    next state-2 segment started from there and every later one ended its offset (6 cm
    forward) further on: the robot stood up past its toes and fell (measured)."""
    x_now = path(mode.segment(), m.psi)[0]
    entry = [m.t] + [math.nan] * (N_STATES - 1)
    return dataclasses.replace(
        mode,
        state=1,
        entry_times_s=tuple(entry),
        psi_entry=m.psi,
        segment_psi=cfg.segment_psi[0],
        x_start_m=tuple(float(v) for v in x_now),
        delta_m=tuple(float(a - b) for a, b in zip(mode.x_seated_m, x_now, strict=True)),
        state3_end_m=(math.nan, math.nan, math.nan),
    )


def _back_to_state_2(mode: StandupMode, m: Measurements) -> StandupMode:
    """From state 3, the thighs unloading, back to state 2 under a hindering pull: the
    thighs are planned seated again (they carry what the chair gives) and the reference
    stops where the state-3 segment had brought it (psi = t, nothing advances). Once the
    pull has stopped, state 2's guards (calm among them) go on to state 3 again, whose
    segment then ends where the interrupted one would have. Holding state 3 instead, the
    thighs went on unloading under the pull and a 15 N per hand pull caught with them at
    70-90 % of their load tipped the robot back; sat back into state 1 from there, it
    ended up further forward on the chair and its next attempt fell back (measured)."""
    x_now = path(mode.segment(), m.psi)[0]
    entry = list(mode.entry_times_s)
    entry[2] = math.nan
    return dataclasses.replace(
        mode,
        state=2,
        entry_times_s=tuple(entry),
        psi_entry=m.psi,
        segment_psi=1.0,
        x_start_m=tuple(float(v) for v in x_now),
        delta_m=(0.0, 0.0, 0.0),
        state3_end_m=tuple(float(v) for v in mode.segment_end()),
    )


def _enter(mode: StandupMode, state: int, m: Measurements, cfg: StandupConfig) -> StandupMode:
    # State 1 holds its start, so its "end" is x_start; later segments have
    # finished (segment_done), so they end at x_start + delta exactly.
    x_start = mode.segment_end()
    if state == 3:
        # Bumpless: state 3 stiffens the CoM's height (com_kp_standing: 30 against 5
        # seated), and the forward lean of state 2 leaves the CoM 1-3 cm below the
        # seated height. Kept, that error became a step in the demanded lift that
        # unloaded the thighs at once (48 -> 20 N in 20 ms, measured) and they landed
        # again; the segment starts at the CoM's height instead, and state 4 rises
        # from there.
        x_start[2] = float(m.com_W[2])
    if state == 2:
        delta = np.array(cfg.state2_com_delta_m)
    elif state == 3:
        delta = np.array(cfg.state3_com_delta_m)
        if not math.isnan(mode.state3_end_m[0]):  # once more, after a hindering pull
            delta[:2] = np.array(mode.state3_end_m[:2]) - x_start[:2]
    else:
        delta = np.array([0.0, 0.0, cfg.standing_com_height_m - x_start[2]])
    entry = list(mode.entry_times_s)
    entry[state - 1] = m.t
    return dataclasses.replace(
        mode,
        state=state,
        entry_times_s=tuple(entry),
        psi_entry=m.psi,
        segment_psi=cfg.segment_psi[state - 2],
        x_start_m=tuple(float(v) for v in x_start),
        delta_m=tuple(float(v) for v in delta),
        state3_end_m=(math.nan, math.nan, math.nan),
    )


def seat_scale(mode: StandupMode, t: float, cfg: StandupConfig) -> float:
    """1 while seated; from state 3 it ramps to 0 over seat_release_s."""
    if mode.state < 3:
        return 1.0
    if cfg.seat_release_s <= 0:
        return 0.0
    return max(0.0, 1.0 - (t - mode.entry_times_s[2]) / cfg.seat_release_s)


def seat_unloading(mode: StandupMode, t: float, cfg: StandupConfig) -> np.ndarray:
    """What is left of the load of the buttocks (seat contact) and of each thigh, as a
    fraction of their load when their unloading began; NaN while the pad is seated (the
    controller's choice). Smoothstep from 1 to 0: the buttocks over seat_unload_s from
    state 2 (the pelvis pitching forward about the hips lifts them), the thighs over
    seat_release_s from state 3 (smoothstep of seat_scale)."""
    fractions = np.full(3, math.nan)
    if mode.state >= 2:
        if cfg.seat_unload_s <= 0:
            fractions[0] = 0.0
        else:
            fractions[0] = smoothstep(1.0 - (t - mode.entry_times_s[1]) / cfg.seat_unload_s)
    if mode.state >= 3:
        fractions[1:] = smoothstep(seat_scale(mode, t, cfg))
    return fractions


class StandupStateMachine(LeafSystem):
    """Periodic (update_period_s) state machine with the mode as abstract state.

    Inputs: psi (1), com_W (3), heel_x_W (1), pad_forces_W (3 per pad, rows of
    the soles given as sole_rows = (left, right)), hand_wrenches_W (12), and
    stand_up (1; > 0.5: go; unconnected: never), which only the live helper has.
    Outputs: standup_state (1), segment (8: [psi_entry, T, x_start, delta]),
    contact_plan (6: [state, seat_scale, feet_scale, then what is left of the
    load of the seat, left thigh, right thigh (seat_unloading; NaN: seated)]),
    entry_times_s (4, NaN for states not reached), held_back (2: [a pull against
    the stand-up holds it (1/0), the time it has waited so far, s]).
    """

    PLAN_SIZE = 6

    def __init__(self, config: StandupConfig, n_pads: int, sole_rows: tuple[int, int]):
        super().__init__()
        self._cfg = config
        self._sole_rows = sole_rows
        self._mode_index = self.DeclareAbstractState(Value[object](StandupMode()))
        self._psi = self.DeclareVectorInputPort("psi", 1)
        self._com = self.DeclareVectorInputPort("com_W", 3)
        self._heel = self.DeclareVectorInputPort("heel_x_W", 1)
        self._pads = self.DeclareVectorInputPort("pad_forces_W", 3 * n_pads)
        self._hands = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        self._stand_up = self.DeclareVectorInputPort("stand_up", 1)
        self.DeclareInitializationUnrestrictedUpdateEvent(self._Initialize)
        self.DeclarePeriodicUnrestrictedUpdateEvent(config.update_period_s, 0.0, self._Update)
        mode_only = {self.abstract_state_ticket(self._mode_index)}
        self.DeclareVectorOutputPort(
            "standup_state", 1, self._CalcState, prerequisites_of_calc=mode_only
        )
        self.DeclareVectorOutputPort(
            "segment", SEGMENT_SIZE, self._CalcSegment, prerequisites_of_calc=mode_only
        )
        self.DeclareVectorOutputPort(
            "contact_plan",
            self.PLAN_SIZE,
            self._CalcContactPlan,
            prerequisites_of_calc={
                self.abstract_state_ticket(self._mode_index),
                self.time_ticket(),
            },
        )
        self.DeclareVectorOutputPort(
            "entry_times_s", N_STATES, self._CalcEntryTimes, prerequisites_of_calc=mode_only
        )
        # [hindered (1/0), time held back so far, s]
        self.DeclareVectorOutputPort(
            "held_back", 2, self._CalcHeldBack, prerequisites_of_calc=mode_only
        )

    def mode(self, context: Context) -> StandupMode:
        return context.get_abstract_state(self._mode_index).get_value()

    def _Initialize(self, context: Context, state: State) -> None:
        mode = initial_mode(self._com.Eval(context))
        mode = dataclasses.replace(
            mode, entry_times_s=(context.get_time(),) + (math.nan,) * (N_STATES - 1)
        )
        state.get_mutable_abstract_state(self._mode_index).set_value(mode)

    def _measure(self, context: Context) -> Measurements:
        pads = self._pads.Eval(context).reshape(-1, 3)
        hands = self._hands.Eval(context).reshape(2, 6)
        left, right = self._sole_rows
        return Measurements(
            t=context.get_time(),
            psi=float(self._psi.Eval(context)[0]),
            com_W=self._com.Eval(context),
            heel_x=float(self._heel.Eval(context)[0]),
            foot_fz_N=(float(pads[left, 2]), float(pads[right, 2])),
            hand_fx_N=(float(hands[0, 3]), float(hands[1, 3])),
            stand_up=self._stand_up.HasValue(context) and self._stand_up.Eval(context)[0] > 0.5,
        )

    def _Update(self, context: Context, state: State) -> None:
        mode = self.mode(context)
        new = next_mode(mode, self._measure(context), self._cfg)
        state.get_mutable_abstract_state(self._mode_index).set_value(new)

    def _CalcState(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self.mode(context).state)

    def _CalcSegment(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self.mode(context).segment())

    def _CalcContactPlan(self, context: Context, output: BasicVector) -> None:
        mode = self.mode(context)
        t = context.get_time()
        output.SetFromVector(
            np.r_[
                mode.state, seat_scale(mode, t, self._cfg), 1.0, seat_unloading(mode, t, self._cfg)
            ]
        )

    def _CalcHeldBack(self, context: Context, output: BasicVector) -> None:
        mode = self.mode(context)
        output.SetFromVector([float(mode.guards.hindered.on), mode.held_back_s])

    def _CalcEntryTimes(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(np.array(self.mode(context).entry_times_s))
