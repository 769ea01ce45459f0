"""The sit-down after standing, and standing again: states 5-7 (phases.DESCENT), pure
functions on the StandupMode as transitions.py's are (state_machine.py calls next_cycle_mode).

Each sit-down phase is a stand-up phase reversed, along the path this robot took out of
this chair: its segment starts where the reference is and ends where the stand-up phase
it names (returns_to) started (StandupMode.starts_m), or at the seated CoM. So the
descent is planned from the chair's geometry as the stand-up read it: over the feet
down to where the thighs left the seat (lower), back to where the buttocks had left it
(land: the thighs touch), back to the seated CoM (settle: the buttocks touch). From a
pad group's measured touch (sit_down.touch_force_N) its load rises over the phase's
load_s (transitions.seat_loads): the contact schedule lets the QP ask no more of it.

    from   to   when (every one, and no pull against the sit-down for resume_after_s)
    4      5    standing (the rise's segment done), sit_down.times not used up, and
                asked: trigger time after stand_s standing; trigger hands: the helper's
                pull back and down (guards.hands_lowered) or the live page's button
    5      6    segment done
    6      7    segment done, the thighs landed (load_s after their touch)
    7      1    segment done, the buttocks landed: seated, sit_down.seated_s before the
                stand-up may be asked again

A pull against the sit-down is one the stand-up's way (forward and up: guards.hands_held,
the same gate that starts a stand-up). While lowering (when_hindered: stand) it stands
the robot back up (state 4, the rise from where the reference is); landing or settling
(hold) it holds the reference where it is until the pull has eased, then goes on.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_standup.config import StandupConfig
from drake_standup.config.phases import PHASES, SEAT_PADS, PhaseTable
from drake_standup.standup.guards import Measurements, update_guards
from drake_standup.standup.transitions import (
    N_STATES,
    SEAT_LOADS,
    StandupMode,
    _sit_back,
    held_here,
    next_mode,
    phase_segment,
)


def next_cycle_mode(
    mode: StandupMode, m: Measurements, cfg: StandupConfig, table: PhaseTable
) -> StandupMode:
    """The mode after one update: transitions.next_mode in the stand-up (bitwise the same
    where no sit-down is asked: sit_down.trigger none), the module docstring's sit-down
    around it."""
    if mode.state > N_STATES:
        return _next_descent(mode, m, cfg, table)
    new = next_mode(mode, m, cfg, table)
    if cfg.sit_down.trigger == "none" or new.state != N_STATES:
        return new
    return _maybe_sit_down(new, m, cfg, table)


def _segment_done(mode: StandupMode, psi: float) -> bool:
    return psi - mode.psi_entry >= mode.segment_psi or not any(mode.delta_m)


def _maybe_sit_down(
    mode: StandupMode, m: Measurements, cfg: StandupConfig, table: PhaseTable
) -> StandupMode:
    """In state 4: note since when it stands, and begin the sit-down once asked."""
    if math.isnan(mode.standing_since_s):
        if not _segment_done(mode, m.psi):
            return mode
        mode = dataclasses.replace(mode, standing_since_s=m.t)
    sit = cfg.sit_down
    standing = m.t - mode.standing_since_s
    calm = not mode.guards.against() and m.t - mode.hindered_until_s >= cfg.resume_after_s
    if mode.sit_downs >= sit.times or not calm or mode.guards.hands_held.on:
        return mode
    if sit.trigger == "time":
        asked = standing >= sit.stand_s if sit.at_s is None else m.t >= sit.at_s
    else:
        button = m.sit_down > mode.sit_downs  # the k-th click asks for the k-th sit-down
        asked = standing >= cfg.resume_after_s and (mode.guards.hands_lowered.on or button)
    return _enter_descent(mode, N_STATES + 1, m, table) if asked else mode


def _next_descent(
    mode: StandupMode, m: Measurements, cfg: StandupConfig, table: PhaseTable
) -> StandupMode:
    """One update in states 5-7."""
    g = update_guards(mode.guards, m, cfg, table)
    against = g.hands_held.on  # a pull the stand-up's way: against the sit-down
    mode = dataclasses.replace(
        mode, guards=g, hindered_until_s=m.t if against else mode.hindered_until_s
    )
    phase = table.phase(mode.state)
    if against:
        if phase.when_hindered == "stand":
            return _stand_again(mode, m, table)
        if not mode.stepped_back():  # held until the pull eases, then on to the segment's end
            return held_here(mode, m)
        return mode
    mode = _touches(mode, m, cfg, table)
    calm = m.t - mode.hindered_until_s >= cfg.resume_after_s
    if not calm:
        return mode
    if mode.stepped_back():  # a hold is over: the phase goes on to where it was to end
        return _enter_descent(mode, mode.state, m, table)
    landed = all(
        m.t - mode.land_s[k] >= phase.load_s
        for k, pads in enumerate(SEAT_PADS)
        if pads in phase.load
    )
    near = phase.exit.thighs_within_m
    done = _segment_done(mode, m.psi) or (near is not None and m.thigh_gap_m <= near)
    if done and not landed and _untouched(mode, phase):
        return _creep(mode, m, phase)  # again after each creep, until the touch
    if not (done and (landed or not phase.exit.unloaded)):
        return mode
    if mode.state == len(table.every()):
        return _seated(mode, m, table)
    return _enter_descent(mode, mode.state + 1, m, table)


def _untouched(mode: StandupMode, phase) -> bool:
    """Some pad group the phase lands has not touched the seat yet."""
    return any(math.isnan(mode.land_s[k]) for k, pads in enumerate(SEAT_PADS) if pads in phase.load)


def _creep(mode: StandupMode, m: Measurements, phase) -> StandupMode:
    """The phase's path is done and a pad it lands has not touched: the reference creeps
    down by phase.sink_m more over the phase's load_s (min jerk: it starts at rest), until
    the touch takes the height (_touches). Back on the path the robot took up, the
    posture converges on the pose the pads left the seat in only slowly: the thighs hung
    a few millimetres above it for 1.7 s (measured)."""
    if phase.sink_m <= 0.0:
        return mode
    x_now = mode.reference(m.psi, m.com_W)
    return dataclasses.replace(
        mode,
        psi_entry=m.psi,
        segment_psi=max(phase.load_s, 0.1),
        x_start_m=tuple(float(v) for v in x_now),
        delta_m=(0.0, 0.0, -phase.sink_m),
        height_follows=False,
        creeping=True,
    )


def _touches(
    mode: StandupMode, m: Measurements, cfg: StandupConfig, table: PhaseTable
) -> StandupMode:
    """The pad groups this phase lands that have touched the seat now: their landing
    begins (their pads together carry more than sit_down.touch_force_N, or their
    undersides are within sit_down.touch_gap_m of the seat's top: a landing the QP
    lowers exactly onto the seat rests there with 2-6 N, measured; a settle led by its
    posture left the buttocks hovering over it, 0 N)."""
    phase = table.phase(mode.state)
    land = list(mode.land_s)
    gaps = {"thighs": m.thigh_gap_m, "buttocks": m.buttocks_gap_m}
    for k, pads in enumerate(SEAT_PADS):
        if pads not in phase.load or not math.isnan(land[k]):
            continue
        force = sum(f for f, name in zip(m.seat_fz_N, SEAT_LOADS, strict=True) if name == pads)
        near = gaps[pads] <= cfg.sit_down.touch_gap_m
        if force > cfg.sit_down.touch_force_N or near:
            land[k] = m.t
    if tuple(land) == mode.land_s:
        return mode
    # Touched: the seat takes the height (the reference's height is the CoM's from now).
    return dataclasses.replace(mode, land_s=tuple(land), height_follows=True)


def descent_end(mode: StandupMode, state: int, m: Measurements, table: PhaseTable) -> np.ndarray:
    """Where sit-down state's segment ends (phases.RETURNS_TO): where the named stand-up
    phase's segment last started; toward the seated CoM, no further back than the seat's
    support line where the buttocks left the seat on the way up (the thigh pads' x plus
    the release's unload_when: behind it, with the buttocks not yet seated, the robot tips
    back onto the chair, 195 N). Seated (state 1), the CoM returns the rest of the way."""
    phase = table.phase(state)
    target = phase.returns_to
    if target != "seated":
        return np.array(mode.starts_m[PHASES.index(target)])
    end = np.array(mode.x_seated_m)
    line = table.phase(table.unloading_phase("buttocks") or 2).unload_when
    if line is not None and not math.isnan(m.thigh_x):
        end[0] = max(end[0], m.thigh_x + line)
    return end


def descent_progress(mode: StandupMode, x_d: np.ndarray, table: PhaseTable) -> float:
    """How far along its sit-down phase's path (phase_from_m to descent_end) the CoM
    reference x_d is, 0-1, horizontally where the phase's height follows the CoM; NaN
    outside the sit-down. The posture moves with it (task_references.py), so that the
    body's shape and the CoM's height stay as they were on the way up at each point of
    the path (the posture's own filter alone led the CoM: the thighs met the seat 5 cm
    of CoM height early, at 0.3 m/s, 234 N)."""
    if mode.state <= N_STATES:
        return math.nan
    start = np.array(mode.phase_from_m)
    path = np.array(mode.phase_to_m) - start
    along = x_d - start
    if mode.height_follows:
        path[2] = along[2] = 0.0
    length2 = float(path @ path)
    if length2 <= 1e-12:
        return 1.0
    return min(max(float(along @ path) / length2, 0.0), 1.0)


def _enter_descent(
    mode: StandupMode, state: int, m: Measurements, table: PhaseTable
) -> StandupMode:
    """state's phase entered (or, after a hold, re-entered): its segment from where the
    reference is (no jump) to descent_end, or to where the hold left it to end."""
    phase = table.phase(state)
    x_start = mode.reference(m.psi, m.com_W)
    resuming = mode.stepped_back() and mode.state == state
    end = np.array(mode.resume_end_m) if resuming else descent_end(mode, state, m, table)
    delta = end - x_start
    if phase.com_height_follows:
        delta[2] = 0.0
    entry = list(mode.entry_times_s)
    start, to = mode.phase_from_m, mode.phase_to_m
    if not resuming:
        entry[state - 1] = m.t
        start, to = tuple(float(v) for v in x_start), tuple(float(v) for v in end)
    return phase_segment(
        mode,
        state,
        phase,
        m,
        x_start,
        delta,
        entry=entry,
        phase_from_m=start,
        phase_to_m=to,
        creeping=False,
    )


def _stand_again(mode: StandupMode, m: Measurements, table: PhaseTable) -> StandupMode:
    """Back to state 4 from the lowering: the rise again from where the reference is to
    the erect height; the sit-down waits to be asked again."""
    x_now = mode.reference(m.psi, m.com_W)
    rise = table.rise
    end = np.array(mode.starts_m[N_STATES - 1], dtype=float)
    end[2] = rise.com_height_m if rise.com_height_m is not None else x_now[2]
    return phase_segment(mode, N_STATES, rise, m, x_now, end - x_now, standing_since_s=math.nan)


def _seated(mode: StandupMode, m: Measurements, table: PhaseTable) -> StandupMode:
    """State 1 again, every pad seated (no release, no landing), the seat's hold as after
    a sit-back (transitions._sit_back: the reference returns from where it is to where the
    CoM sat at the start over phases.seated.segment_psi); the stand-up may be asked again
    after sit_down.seated_s. After a phase its posture led (the settle), the return starts
    where the CoM is: its reference had run on ahead of the CoM (3 cm, the full-weight
    CoM rows then pulled the body forward onto the buttocks' edge: 54 N on the soles)."""
    posture_led = table.phase(mode.state).posture_leads
    return dataclasses.replace(
        _sit_back(mode, m, table, m.com_W if posture_led else None),
        land_s=(math.nan,) * len(SEAT_PADS),
        creeping=False,
        sit_downs=mode.sit_downs + 1,
        standing_since_s=math.nan,
    )
