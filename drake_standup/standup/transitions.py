"""The stand-up's mode and its transitions, as the phase table declares them: pure
functions on an immutable StandupMode (state_machine.py wraps them in a Drake system).

What each state does and the guard that leaves it are the phase table's (phases.py);
this module is its mechanism:

- update_guards (guards.py): the forces the guards read, filtered, through Schmitt
  triggers.
- next_mode: one update. A phase is left for the next one when every condition of its
  Guard holds and no pull against the stand-up has been felt for standup.resume_after_s;
  one switch per update at most, so no state is ever skipped. "Segment done" (psi past
  the segment's end) keeps the reference's slope continuous across switches.
- seat_loads: what is left of each seat pad's load while the phases release it (NaN
  while the pad is seated): the contact schedule's input (contact_schedule.py).
- A pull against the stand-up (one the feet could not hold: more than
  standup.standing_pull_usage_limit of the CoM's reach back over the heels, guards.
  heel_usage; or beyond the standing feet; through the same filter and trigger) is answered
  by the phase's when_hindered: wait (the guards wait for calm), sit_back (_sit_back: the
  reference returns to the seated CoM, state 1 again), step_back (while the pads this
  phase releases still carry more than reseat_above_thigh_load of their load: sit back;
  while they unload: back to the previous phase, _step_back; once off: wait) or stand
  (the standing robot leans against it; not waiting).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from drake_standup.config import StandupConfig
from drake_standup.config.phases import (
    EVERY_PHASE,
    SEAT_PAD_ROWS,
    SEAT_PADS,
    Guard,
    Phase,
    PhaseTable,
)
from drake_standup.control.smooth import smoothstep
from drake_standup.standup.com_path import reference_at
from drake_standup.standup.guards import (  # noqa: F401 (the mode's parts, re-exported)
    N_STATES,
    GuardSignals,
    Measurements,
    SchmittTrigger,
    update_guards,
)

_NAN3 = (math.nan, math.nan, math.nan)
# The states a run can be in: the stand-up's (1-4) and the sit-down's (5-7).
N_MODES = len(EVERY_PHASE)


@dataclass(frozen=True)
class StandupMode:
    """The machine's abstract state: where it is, the active CoM segment, the guards'
    filtered signals, and what a pull against the stand-up has done."""

    state: int = 1
    # When each state (1-7) was last entered (NaN: not yet).
    entry_times_s: tuple[float, ...] = (0.0,) + (math.nan,) * (N_MODES - 1)
    psi_entry: float = 0.0
    segment_psi: float = 1.0
    x_start_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    delta_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    # The segment's reference height is the measured CoM's (the phase's
    # com_height_follows; com_path.py), not x_start + delta s.
    height_follows: bool = False
    guards: GuardSignals = GuardSignals()
    held_back_s: float = 0.0  # time spent waiting for a pull against it to stop
    held_beyond_feet_s: float = 0.0  # of which a pull beyond what the feet can hold
    # Where the CoM sat at the start: a sit-back returns there, so that the next
    # forward segment starts where the first one did.
    x_seated_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    hindered_until_s: float = -math.inf  # the last time a hindering pull was felt
    # A step back from a phase: where its segment was to end (NaN: none). The phase,
    # entered again, ends there.
    resume_end_m: tuple[float, float, float] = _NAN3
    sat_back: bool = False  # a hindering pull has sat the robot back since the start
    # When the release of each seat pad group (phases.SEAT_PADS) began (NaN: seated).
    release_s: tuple[float, ...] = (math.nan,) * len(SEAT_PADS)
    # Where each stand-up state's segment last started: the sit-down returns along them.
    starts_m: tuple[tuple[float, float, float], ...] = (_NAN3,) * N_STATES
    # When each seat pad group touched the seat in the sit-down that lands it (NaN: not).
    land_s: tuple[float, ...] = (math.nan,) * len(SEAT_PADS)
    sit_downs: int = 0  # sit-downs completed (back in state 1)
    standing_since_s: float = math.nan  # state 4's segment done since (NaN: not)
    # Where the reference was when the sit-down's phase began (its path's start; a hold
    # keeps it): how far along that path the CoM reference is moves the posture.
    phase_from_m: tuple[float, float, float] = _NAN3
    phase_to_m: tuple[float, float, float] = _NAN3  # ... and where it ends
    creeping: bool = False  # the phase's path done, creeping down to the seat's touch

    def __copy__(self) -> StandupMode:
        return self

    def __deepcopy__(self, memo: dict) -> StandupMode:
        """Itself: the mode is immutable. Drake clones the abstract state (a Python
        deepcopy) into and out of its scratch state at every unrestricted update of the
        diagram, i.e. at every plant step: real copies cost ~15 us a step (measured)."""
        return self

    def segment(self) -> np.ndarray:
        """[psi_entry, T, x_start, delta, height_follows] (payloads.SEGMENT)."""
        return np.array(
            [
                self.psi_entry,
                self.segment_psi,
                *self.x_start_m,
                *self.delta_m,
                float(self.height_follows),
            ]
        )

    def reference(self, psi: float, com_W: np.ndarray) -> np.ndarray:
        """Where the CoM reference is at psi with the CoM at com_W (com_path.reference_at:
        the segment's path, its height the CoM's where it follows the CoM)."""
        return reference_at(self.segment(), psi, com_W)

    def segment_end(self) -> np.ndarray:
        return np.array(self.x_start_m) + np.array(self.delta_m)

    def stepped_back(self) -> bool:
        return not math.isnan(self.resume_end_m[0])


def initial_mode(com0_W: np.ndarray, t: float = 0.0) -> StandupMode:
    """State 1 at t, holding the CoM where it starts."""
    com0 = tuple(float(c) for c in com0_W)
    entry = (t,) + (math.nan,) * (N_MODES - 1)
    starts = (com0,) + (_NAN3,) * (N_STATES - 1)
    return StandupMode(entry_times_s=entry, x_start_m=com0, x_seated_m=com0, starts_m=starts)


def next_mode(
    mode: StandupMode, m: Measurements, cfg: StandupConfig, table: PhaseTable
) -> StandupMode:
    """The mode after one update: its guards' signals updated, in the same, the next or
    (under a pull against the stand-up) an earlier state."""
    g = update_guards(mode.guards, m, cfg, table)
    phase = table.phase(mode.state)
    against = g.against()
    held, beyond = mode.held_back_s, mode.held_beyond_feet_s
    if against and phase.when_hindered != "stand" and not math.isnan(mode.guards.t):
        held += m.t - mode.guards.t
        if g.beyond_feet.on:
            beyond += m.t - mode.guards.t
    hindered_until = m.t if against else mode.hindered_until_s
    mode = dataclasses.replace(
        mode,
        guards=g,
        held_back_s=held,
        held_beyond_feet_s=beyond,
        hindered_until_s=hindered_until,
    )
    if against:
        if phase.when_hindered == "step_back":
            loads = np.nan_to_num(seat_loads(mode, m.t, table), nan=1.0)  # NaN: seated
            left = max(loads[_released(phase)], default=0.0)
            if left > cfg.reseat_above_thigh_load:  # the pads still carry the robot
                return _sit_back(mode, m, table)
            if left > 0.0:  # unloading: back onto them
                return _step_back(mode, m, table)
        elif phase.when_hindered == "sit_back" and not mode.stepped_back():
            return _sit_back(mode, m, table)
    mode = _begin_releases(mode, phase, m)
    calm = not against and m.t - mode.hindered_until_s >= cfg.resume_after_s
    if mode.state == N_STATES or not (calm and guard_holds(phase, mode, m, cfg)):
        return mode
    return _enter(mode, mode.state + 1, m, table)


def _begin_releases(mode: StandupMode, phase: Phase, m: Measurements) -> StandupMode:
    """The release of the pads phase unloads begins, where it has not yet: at once, or
    once the CoM has passed the thigh pads by phase.unload_when."""
    waiting = [
        k
        for k, pads in enumerate(SEAT_PADS)
        if pads in phase.unload and math.isnan(mode.release_s[k])
    ]
    if not waiting:
        return mode
    if phase.unload_when is not None and not m.com_W[0] >= m.thigh_x + phase.unload_when:
        return mode
    release = list(mode.release_s)
    for k in waiting:
        release[k] = m.t
    return dataclasses.replace(mode, release_s=tuple(release))


def released_for_s(mode: StandupMode, phase: Phase, t: float) -> float:
    """How long the release of every pad group phase unloads has been going on at t (inf:
    it unloads none; NaN: one has not begun)."""
    since = [t - mode.release_s[k] for k, pads in enumerate(SEAT_PADS) if pads in phase.unload]
    return math.nan if any(map(math.isnan, since)) else min(since, default=math.inf)


def guard_holds(phase: Phase, mode: StandupMode, m: Measurements, cfg: StandupConfig) -> bool:
    """Every condition of phase.exit (phases.Guard) holds for mode at m."""
    guard: Guard = phase.exit
    k = mode.state - 1
    dwell = m.t - mode.entry_times_s[k]
    g = mode.guards
    # Seated again after a sit-down, the robot balances sit_down.seated_s.
    min_time_s = cfg.sit_down.seated_s if k == 0 and mode.sit_downs else guard.min_time_s
    if dwell < min_time_s:
        return False
    pulled = g.hands_pulled.on or g.hands_held.on
    button = m.stand_up > mode.sit_downs  # the button's k-th click after k - 1 sit-downs
    if guard.asked and not (cfg.trigger == "time" or pulled or button):
        return False
    if guard.segment_done and not (
        m.psi - mode.psi_entry >= mode.segment_psi or not any(mode.delta_m)
    ):
        return False
    if guard.unloaded and not released_for_s(mode, phase, m.t) >= phase.unload_s:
        return False
    if guard.feet_force_N is not None and not g.feet_loaded[k].on:
        return False
    if guard.each_foot_force_N is not None and not g.each_foot_loaded[k].on:
        return False
    ahead = guard.com_ahead_of_heels_m
    return ahead is None or m.com_W[0] >= m.heel_x + ahead


def _released(phase: Phase) -> list[int]:
    """The entries of seat_loads that phase releases."""
    return [i for i, pads in enumerate(SEAT_LOADS) if pads in phase.unload]


def _sit_back(
    mode: StandupMode, m: Measurements, table: PhaseTable, start_m: np.ndarray | None = None
) -> StandupMode:
    """Back to state 1: a pull against the stand-up waits seated (the paper: psi = t,
    nothing advances). The state-1 segment starts where the reference is now (no jump)
    and returns to where the CoM sat at the start, over phases.seated.segment_psi; state
    1's balancing time runs again from now, and its exit waits for the return. Held where
    it was instead, each later forward segment ended its offset further on and the
    robot stood up past its toes (docs/design.md, "Hindering pulls"). "Where
    the reference is" is the one used: its height the CoM's where the segment followed
    it; the return holds its own height (height_follows off). start_m: where the return
    starts instead (a sit-down's settle led by its posture: where the CoM is)."""
    x_now = mode.reference(m.psi, m.com_W) if start_m is None else np.asarray(start_m)
    entry = [m.t] + [math.nan] * (N_MODES - 1)
    return dataclasses.replace(
        mode,
        state=1,
        entry_times_s=tuple(entry),
        psi_entry=m.psi,
        segment_psi=table.seated.segment_psi,
        x_start_m=tuple(float(v) for v in x_now),
        delta_m=tuple(float(a - b) for a, b in zip(mode.x_seated_m, x_now, strict=True)),
        height_follows=False,
        resume_end_m=_NAN3,
        sat_back=True,
        release_s=(math.nan,) * len(SEAT_PADS),
    )


def _step_back(mode: StandupMode, m: Measurements, table: PhaseTable) -> StandupMode:
    """Back to the previous phase while this one's pads unload: they are seated again
    (they carry what the chair gives) and the reference stops where it is (psi = t,
    nothing advances). Once the pull has stopped, the previous phase's guard (calm among
    them) enters this phase again, whose segment then ends where the interrupted one
    would have (docs/design.md, "Hindering pulls"). The hold keeps the height
    of the reference used when it began (height_follows off)."""
    entry = list(mode.entry_times_s)
    entry[mode.state - 1] = math.nan
    left = table.phase(mode.state).unload
    release = [math.nan if pads in left else s for pads, s in zip(SEAT_PADS, mode.release_s)]
    held = held_here(mode, m)
    return dataclasses.replace(
        held, release_s=tuple(release), state=mode.state - 1, entry_times_s=tuple(entry)
    )


def held_here(mode: StandupMode, m: Measurements) -> StandupMode:
    """The reference held where it is (psi = t, nothing advances, at the height it has),
    remembering where its segment was to end (resume_end_m)."""
    x_now = mode.reference(m.psi, m.com_W)
    return dataclasses.replace(
        mode,
        psi_entry=m.psi,
        segment_psi=1.0,
        x_start_m=tuple(float(v) for v in x_now),
        delta_m=(0.0, 0.0, 0.0),
        height_follows=False,
        resume_end_m=tuple(float(v) for v in mode.segment_end()),
    )


def _enter(mode: StandupMode, state: int, m: Measurements, table: PhaseTable) -> StandupMode:
    """state's phase entered: its segment starts where the previous one ended (that one
    is done, or holds still), at the CoM's height where the previous segment's height
    followed the CoM (that is where the reference is) or where the phase says so
    (bumpless: a stiffer height gain would otherwise see the lean's 1-3 cm drop as a
    step), toward its displacement (its absolute x and height where given), or where a
    step back left it to end; its height follows the CoM where the phase says so. Entered
    again after a step back, it starts where the step back held the reference, at any
    height: from the CoM's it jumped by the height the CoM lost meanwhile (11 mm in one
    10 ms sample, measured)."""
    phase = table.phase(state)
    x_start = mode.segment_end()
    if mode.height_follows or (phase.start_at_com_height and not mode.stepped_back()):
        x_start[2] = float(m.com_W[2])
    delta = np.array(phase.com_delta_m, dtype=float)
    if phase.com_x_m is not None:
        delta[0] = phase.com_x_m - x_start[0]
    if phase.com_height_m is not None:
        delta[2] = phase.com_height_m - x_start[2]
    if mode.stepped_back():
        delta[:2] = np.array(mode.resume_end_m[:2]) - x_start[:2]
    starts = list(mode.starts_m)
    starts[state - 1] = tuple(float(v) for v in x_start)
    entered = phase_segment(mode, state, phase, m, x_start, delta, starts_m=tuple(starts))
    return _begin_releases(entered, phase, m)


def phase_segment(
    mode: StandupMode,
    state: int,
    phase: Phase,
    m: Measurements,
    x_start: np.ndarray,
    delta: np.ndarray,
    *,
    entry: list[float] | None = None,
    **more,
) -> StandupMode:
    """mode in state with the phase's segment from x_start by delta, from now (psi) over
    phase.segment_psi, its height following the CoM where the phase says so; entry: the
    states' entry times (None: mode's, state's entered now); more: other fields to set."""
    if entry is None:
        entry = list(mode.entry_times_s)
        entry[state - 1] = m.t
    return dataclasses.replace(
        mode,
        state=state,
        entry_times_s=tuple(entry),
        psi_entry=m.psi,
        segment_psi=phase.segment_psi,
        x_start_m=tuple(float(v) for v in x_start),
        delta_m=tuple(float(v) for v in delta),
        height_follows=phase.com_height_follows,
        resume_end_m=_NAN3,
        **more,
    )


# The seat pads, as seat_loads orders them, and their pad group (phases.SEAT_PADS).
SEAT_LOADS = tuple(group for _, group in SEAT_PAD_ROWS)


def _seat_ramps(table: PhaseTable, phase_of, duration: str) -> list[tuple]:
    """(state, the phase's duration attribute, s, the entries of SEAT_LOADS, its index in
    SEAT_PADS) of each pad group phase_of(pads) names a state for."""
    ramps = []
    for k, pads in enumerate(SEAT_PADS):
        state = phase_of(pads)
        if state is not None:
            rows = [i for i, name in enumerate(SEAT_LOADS) if name == pads]
            ramps.append((state, getattr(table.phase(state), duration), rows, k))
    return ramps


def seat_releases(table: PhaseTable) -> list[tuple[int, float, list[int], int]]:
    """(the state that releases it, over how long, s, the entries of SEAT_LOADS, its index
    in SEAT_PADS) of each pad group the table releases."""
    return _seat_ramps(table, table.unloading_phase, "unload_s")


def seat_landings(table: PhaseTable) -> list[tuple[int, float, list[int], int]]:
    """seat_releases' entries for the pad groups a sit-down phase lands (phase.load)."""
    return _seat_ramps(table, table.landing_phase, "load_s")


def seat_loads(
    mode: StandupMode,
    t: float,
    table: PhaseTable | list[tuple[int, float, list[int]]],
    landings: list[tuple[int, float, list[int], int]] = (),
) -> np.ndarray:
    """What is left of the load of the buttocks and of each thigh (SEAT_LOADS), as a
    fraction of their load when their release began; NaN while the pad is seated. A pad
    group is released from mode.release_s (in the phase that lists it in unload, at its
    entry or once its unload_when holds; until the robot is back in an earlier phase),
    smoothstep from 1 to 0 over its unload_s; in a sit-down, from its touch (mode.land_s)
    from 0 to 1 over the landing phase's load_s, then seated. table: the phase table, or
    its seat_releases; landings: seat_landings(table), none by default."""
    releases = seat_releases(table) if isinstance(table, PhaseTable) else table
    loads = np.full(len(SEAT_LOADS), math.nan)
    for _, over_s, rows, k in releases:
        began = mode.release_s[k]
        if not math.isnan(began):
            loads[rows] = 0.0 if over_s <= 0 else smoothstep(1.0 - (t - began) / over_s)
    # A sit-down's landing pads (seat_landings): from their touch their load rises back
    # to what it was when their release began, over the phase's load_s; seated then.
    for _, over_s, rows, k in landings:
        landed_for = t - mode.land_s[k]
        if landed_for < over_s:
            loads[rows] = smoothstep(landed_for / over_s)
        elif landed_for >= over_s:
            loads[rows] = math.nan
    return loads
