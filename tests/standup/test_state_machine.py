"""The stand-up state machine on synthetic inputs: thresholds, dwell times,
one state at a time, filtered forces through Schmitt triggers, the seat's
unloading plan; and the LeafSystem's timing on its update grid."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_standup.config import StandupConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.standup.guards import heel_usage
from drake_standup.standup.state_machine import StandupStateMachine
from drake_standup.standup.transitions import (
    GuardSignals,
    Measurements,
    SchmittTrigger,
    _enter,
    _sit_back,
    initial_mode,
    next_mode,
    released_for_s,
    seat_loads,
    update_guards,
)

CFG = StandupConfig()
CFG_TIME = dataclasses.replace(CFG, trigger="time")


def _table(**exits) -> PhaseTable:
    """The default phase table with the authors' dwell times ([authors-code]; our defaults leave
    the dwell to psi), so the dwell guards are exercised too; exits: more of it, as
    {phase: {field: value}} (a field of Phase, or exit.<field> of its Guard)."""
    table = PhaseTable()
    table.rise.com_height_m = 0.575  # the erect height, as the stand-up controller resolves it
    table.forward.exit.min_time_s = 1.5
    table.lift_off.exit.min_time_s = 0.5
    for name, fields in exits.items():
        phase = getattr(table, name)
        for key, value in fields.items():
            target, _, leaf = key.rpartition(".")
            setattr(phase.exit if target else phase, leaf, value)
    return table


TABLE = _table()
SEATED, FORWARD, LIFT_OFF = TABLE.seated, TABLE.forward, TABLE.lift_off
COM0 = np.array([0.06, 0.0, 0.38])
AHEAD = np.array([0.30, 0.0, 0.40])  # CoM far in front of the heels


def _m(t, psi=None, com=AHEAD, heel_x=0.1, feet=(200.0, 200.0), hands=(20.0, 20.0), thigh_x=0.0):
    return Measurements(t, t if psi is None else psi, com, heel_x, feet, hands, thigh_x)


def _settled(mode, m, cfg=CFG, table=TABLE):
    """mode with its guards' signals as if m's forces had been measured for the last
    second (every 10 ms): filters settled, triggers past their dwell."""
    g = GuardSignals()
    for k in range(100, 0, -1):
        g = update_guards(g, dataclasses.replace(m, t=m.t - 0.01 * k), cfg, table)
    return dataclasses.replace(mode, guards=g)


def _next(mode, m, cfg=CFG, table=TABLE):
    """next_mode on a mode whose guards have settled on m's forces: the thresholds, as if
    the forces had held long enough."""
    return next_mode(_settled(mode, m, cfg, table), m, cfg, table)


def _in_state(state: int, t_entry: float, table=TABLE):
    """A mode that entered `state` at t_entry with psi = t_entry."""
    mode = initial_mode(COM0)
    for k in range(2, state + 1):
        mode = _enter(mode, k, _m(t_entry), table)
    return mode


def test_1_to_2_needs_balance_time_and_both_hands_over_threshold():
    """The firm pull (both hands over hand_force_threshold_N, the gentle trigger off)."""
    mode = initial_mode(COM0)
    cfg = dataclasses.replace(CFG, gentle_pull_force_N=1e3)
    thr = cfg.hand_force_threshold_N
    assert _next(mode, _m(2.999, hands=(50, 50)), cfg).state == 1  # too early
    assert _next(mode, _m(3.5, hands=(thr, 50)), cfg).state == 1  # exactly at: not >
    assert _next(mode, _m(3.5, hands=(50, thr - 1)), cfg).state == 1  # one hand only
    assert _next(mode, _m(3.0, hands=(thr + 1e-9, thr + 1e-9)), cfg).state == 2


def _first_state_2(force_N: float, cfg=CFG, up_N: float = 0.0) -> float:
    """When the stand-up starts (NaN: within 2 s it does not) under a pull of force_N
    forward and up_N up on both hands from 3 s, the guards updated every 10 ms."""
    mode = initial_mode(COM0)
    for k in range(500):
        t = 0.01 * k
        on = t >= 3.0
        m = dataclasses.replace(
            _m(t, hands=(force_N,) * 2 if on else (0.0, 0.0)),
            hand_fz_N=(up_N,) * 2 if on else (0.0, 0.0),
        )
        mode = next_mode(mode, m, cfg, TABLE)
        if mode.state == 2:
            return mode.entry_times_s[1]
    return math.nan


def test_a_gentle_pull_starts_the_stand_up_once_held_for_a_reaction_time():
    """A firm pull (12 N per hand) starts it within the filter and the dwell (50 + 50 ms);
    a gentle one (8 N, under 10 N but over [icub-logs]' 6.5 N of nobody helping) only once it
    has been over 6.5 N, through the filter, for gentle_pull_time_s; 6 N never does."""
    firm, gentle = _first_state_2(12.0), _first_state_2(8.0)
    assert 3.0 < firm <= 3.0 + 0.05 + 3 * CFG.force_filter_time_constant_s
    # The filtered 8 N passes 6.5 N after tau ln(8 / 1.5) = 84 ms; then the hold.
    crossed = 3.0 + CFG.force_filter_time_constant_s * math.log(8.0 / 1.5)
    assert gentle == pytest.approx(crossed + CFG.gentle_pull_time_s, abs=0.021)
    assert math.isnan(_first_state_2(6.0))


def test_a_gentle_grip_counts_forward_and_up():
    """A 9 N grip along a 45-degree pace pulls 6.4 N forward and 6.4 N up: below 6.5 N
    forward, yet a request to stand, held as the 9 N it is (the same start as 9 N
    forward); 6 N each way never starts it; a press down is not counted (8 N forward
    pressed down starts as 8 N forward, 8 N down alone never), nor is a pull back (one
    up as much as it is back starts as its lift; its effect is the hindering guard's)."""
    side = 9.0 / math.sqrt(2.0)
    assert _first_state_2(side, up_N=side) == pytest.approx(_first_state_2(9.0), abs=1e-9)
    assert not math.isnan(_first_state_2(side, up_N=side))
    assert math.isnan(_first_state_2(6.0 / math.sqrt(2.0), up_N=6.0 / math.sqrt(2.0)))
    assert _first_state_2(8.0, up_N=-8.0) == pytest.approx(_first_state_2(8.0), abs=1e-9)
    assert math.isnan(_first_state_2(0.0, up_N=-8.0))
    assert _first_state_2(-8.0, up_N=8.0) == pytest.approx(_first_state_2(0.0, up_N=8.0))


def test_1_to_2_with_time_trigger_ignores_hands():
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = initial_mode(COM0)
    assert _next(mode, _m(2.999, hands=(0, 0)), cfg).state == 1
    new = _next(mode, _m(3.0, hands=(0, 0)), cfg)
    assert new.state == 2 and new.entry_times_s[1] == 3.0


def test_2_to_3_guards():
    mode = _in_state(2, 3.0)
    t_ok = 3.0 + FORWARD.exit.min_time_s
    thr = FORWARD.exit.feet_force_N
    heel = 0.1
    com_ok = np.array([heel + FORWARD.exit.com_ahead_of_heels_m, 0.0, 0.4])
    ok = {"feet": (thr / 2 + 1e-9, thr / 2 + 1e-9), "com": com_ok, "heel_x": heel}
    assert _next(mode, _m(t_ok, **ok), CFG).state == 3  # all at their thresholds
    assert _next(mode, _m(t_ok - 1e-6, **ok), CFG).state == 2  # dwell
    assert _next(mode, _m(t_ok, **{**ok, "feet": (thr / 2, thr / 2)}), CFG).state == 2
    com_behind = com_ok - np.array([1e-6, 0.0, 0.0])
    assert _next(mode, _m(t_ok, **{**ok, "com": com_behind}), CFG).state == 2
    # Segment not finished (psi behind): no switch, whatever the forces.
    assert _next(mode, _m(t_ok, psi=t_ok - 1e-6, **ok), CFG).state == 2


def test_3_to_4_needs_each_foot():
    mode = _in_state(3, 5.0)
    # The latest of: the phase's minimum time, the thighs' release, the segment's end.
    t_ok = 5.0 + max(LIFT_OFF.exit.min_time_s, LIFT_OFF.unload_s, LIFT_OFF.segment_psi)
    thr = LIFT_OFF.exit.each_foot_force_N
    assert _next(mode, _m(t_ok, feet=(thr + 1e-9, thr + 1e-9)), CFG).state == 4
    assert _next(mode, _m(t_ok, feet=(thr, 500.0)), CFG).state == 3
    assert _next(mode, _m(t_ok, feet=(500.0, thr)), CFG).state == 3
    assert _next(mode, _m(t_ok - 1e-6, feet=(500.0, 500.0)), CFG).state == 3


def test_state_4_is_final():
    mode = _in_state(4, 6.0)
    assert _next(mode, _m(100.0), CFG).state == 4


def test_never_skips_a_state_even_when_every_guard_holds():
    mode = initial_mode(COM0)
    states = [mode.state]
    t = 10.0  # every dwell satisfied; psi far past every segment
    for _ in range(5):
        mode = _next(mode, _m(t, psi=10.0 * t), CFG)
        states.append(mode.state)
        t += 10.0
    assert states == [1, 2, 3, 4, 4, 4]


def test_leaf_system_switches_on_its_update_grid():
    """Fixed synthetic inputs with trigger 'time': the system enters 2 at the
    first update at or after balance_time_s, then 3 after min_time_state2_s,
    then 4 after min_time_state3_s, exactly on the update grid."""
    cfg = dataclasses.replace(CFG, trigger="time", update_period_s=0.01)
    n_pads = 5
    system = StandupStateMachine(cfg, TABLE, n_pads=n_pads, sole_rows=(0, 1))
    context = system.CreateDefaultContext()
    pads = np.zeros((n_pads, 3))
    pads[0, 2] = pads[1, 2] = 200.0
    system.GetInputPort("com_W").FixValue(context, AHEAD)
    system.GetInputPort("heel_x_W").FixValue(context, [0.1])
    system.GetInputPort("thigh_x_W").FixValue(context, [0.0])
    system.GetInputPort("pad_forces_W").FixValue(context, pads.reshape(-1))
    system.GetInputPort("hand_wrenches_W").FixValue(context, np.zeros(12))
    psi_port = system.GetInputPort("psi")
    simulator = Simulator(system, context)
    simulator.Initialize()
    # psi = t, updated by hand each 1 ms (as the advancement would).
    t = 0.0
    while t < 8.0:
        psi_port.FixValue(context, [t])
        t = round(t + 0.001, 9)
        simulator.AdvanceTo(t)
    entries = system.GetOutputPort("entry_times_s").Eval(context)
    t2 = SEATED.exit.min_time_s
    t3 = t2 + max(FORWARD.exit.min_time_s, FORWARD.segment_psi)
    t4 = t3 + max(LIFT_OFF.exit.min_time_s, LIFT_OFF.segment_psi)
    np.testing.assert_allclose(entries, [0.0, t2, t3, t4], atol=cfg.update_period_s + 1e-9)
    assert system.GetOutputPort("standup_state").Eval(context)[0] == 4
    loads = seat_loads(system.GetOutputPort("mode").Eval(context), 8.0, TABLE)
    np.testing.assert_array_equal(loads, 0.0)  # the seat released by t = 8 s


def test_the_buttocks_release_waits_for_the_com_to_pass_the_thigh_pads():
    """State 2's release begins at the first update with the CoM unload_when in front of
    the thigh pads' centres (not at entry: behind them, the chair still carries the
    robot), the pads unload over unload_s from then, and the exit waits for that."""
    ahead = FORWARD.unload_when
    assert ahead is not None and FORWARD.exit.unloaded
    thigh = 0.2
    behind = np.array([thigh + ahead - 1e-6, 0.0, 0.40])
    mode = _enter(initial_mode(COM0), 2, _m(3.0, com=behind, thigh_x=thigh), TABLE)
    assert np.isnan(seat_loads(mode, 3.0, TABLE)).all()  # entered: still seated
    t = 3.0 + 2 * FORWARD.segment_psi  # segment done, feet loaded, CoM ahead of the heels
    mode = _next(mode, _m(t, com=behind, thigh_x=thigh), CFG)
    assert mode.state == 2 and np.isnan(seat_loads(mode, t, TABLE)).all()
    passed = behind + np.array([2e-6, 0.0, 0.0])
    mode = _next(mode, _m(t, com=passed, thigh_x=thigh), CFG)
    assert mode.state == 2 and mode.release_s[0] == t  # the release begins, no exit yet
    np.testing.assert_allclose(seat_loads(mode, t, TABLE)[0], 1.0)
    np.testing.assert_allclose(seat_loads(mode, t + FORWARD.unload_s / 2, TABLE)[0], 0.5)
    assert np.isnan(seat_loads(mode, t + 1.0, TABLE)[1:]).all()  # the thighs stay seated
    early = t + FORWARD.unload_s - 0.01
    assert _next(mode, _m(early, com=passed, thigh_x=thigh), CFG).state == 2
    done = t + FORWARD.unload_s
    assert _next(mode, _m(done, com=passed, thigh_x=thigh), CFG).state == 3
    # Unmeasured (NaN) thighs: a release that waits for them never begins.
    blind = _next(mode, _m(t, com=passed, thigh_x=math.nan), CFG)
    assert blind.release_s == mode.release_s  # begun releases stay begun
    unseen = _enter(initial_mode(COM0), 2, _m(3.0, thigh_x=math.nan), TABLE)
    assert math.isnan(_next(unseen, _m(t, thigh_x=math.nan), CFG).release_s[0])


def test_a_phase_releasing_two_pad_groups_is_released_once_both_have_begun():
    """released_for_s over both groups: the shorter release, or NaN (not released)
    while either has not begun, whichever group that is."""
    both = dataclasses.replace(PhaseTable().lift_off, unload=["buttocks", "thighs"])
    mode = initial_mode(COM0)
    for release in ((math.nan, 1.0), (1.0, math.nan)):
        assert math.isnan(released_for_s(dataclasses.replace(mode, release_s=release), both, 3.0))
    begun = dataclasses.replace(mode, release_s=(1.0, 2.0))
    assert released_for_s(begun, both, 3.0) == 1.0
    none = dataclasses.replace(both, unload=[])
    assert released_for_s(mode, none, 3.0) == math.inf


def test_a_sit_back_seats_every_pad_again():
    mode = _enter(initial_mode(COM0), 2, _m(3.0), TABLE)
    assert mode.release_s[0] == 3.0
    back = _sit_back(mode, _m(3.1), TABLE)
    assert back.state == 1 and np.isnan(back.release_s).all()
    assert np.isnan(seat_loads(back, 3.2, TABLE)).all()


def test_an_unresolved_erect_height_is_refused():
    with pytest.raises(ValueError, match="com_height_erect"):
        StandupStateMachine(CFG, PhaseTable(), n_pads=5, sole_rows=(0, 1))


def test_entry_times_are_nan_until_reached():
    system = StandupStateMachine(CFG, TABLE, n_pads=5, sole_rows=(0, 1))
    context = system.CreateDefaultContext()
    entries = system.GetOutputPort("entry_times_s").Eval(context)
    assert entries[0] == 0.0 and all(math.isnan(e) for e in entries[1:])


# --- Filtered forces, Schmitt triggers, dwell ------------------------------------------


def _feet_trace(t, total_N):
    """Measurements every 10 ms with the feet carrying total_N (split evenly)."""
    return [
        Measurements(float(tk), float(tk), AHEAD, 0.1, (f / 2, f / 2), (0.0, 0.0))
        for tk, f in zip(t, total_N, strict=True)
    ]


def test_noisy_force_around_the_threshold_switches_once():
    """The feet's load ramps through the 2 -> 3 threshold (150 N) with +-40 N of white
    noise: the raw force crosses it dozens of times, the trigger turns on once and stays."""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 3.0, 0.01)
    mean = np.interp(t, [0.0, 3.0], [100.0, 220.0])
    total = mean + rng.uniform(-40.0, 40.0, len(t))
    thr = FORWARD.exit.feet_force_N
    raw_crossings = np.count_nonzero(np.diff((total > thr).astype(int)) != 0)
    assert raw_crossings > 10  # the noise would flip a bare threshold
    g, on = GuardSignals(), []
    for m in _feet_trace(t, total):
        g = update_guards(g, m, CFG, TABLE)
        on.append(g.feet_loaded[1].on)
    switches = np.flatnonzero(np.diff(np.array(on, dtype=int)))
    assert len(switches) == 1 and on[-1]
    # ... near where the mean crosses the threshold (1.25 s), within the filter's lag
    # and the dwell.
    assert 0.9 < t[switches[0] + 1] < 1.7


def test_dwell_rejects_a_short_spike_and_accepts_a_held_load():
    thr = FORWARD.exit.feet_force_N
    t = np.arange(0.0, 1.0, 0.01)
    # A 300 N spike for 20 ms: the filtered force passes 150 N (166 N), but not for the
    # dwell.
    spike = np.where((t >= 0.5) & (t < 0.52), 300.0, 100.0)
    g = GuardSignals()
    for m in _feet_trace(t, spike):
        g = update_guards(g, m, CFG, TABLE)
        assert not g.feet_loaded[1].on
    # Held: on at the first update at least guard_dwell_s after the filtered force
    # passed the threshold, i.e. after the filter's lag tau ln(2) (step 100 -> 200 N).
    held = np.where(t >= 0.5, 200.0, 100.0)
    g, t_on = GuardSignals(), None
    for m in _feet_trace(t, held):
        g = update_guards(g, m, CFG, TABLE)
        if g.feet_loaded[1].on and t_on is None:
            t_on = m.t
    lag = CFG.force_filter_time_constant_s * math.log((200.0 - 100.0) / (200.0 - thr))
    assert t_on == pytest.approx(0.5 + lag + CFG.guard_dwell_s, abs=0.011)


def test_schmitt_trigger_hysteresis():
    """Off only below the off threshold, held for the dwell; values between the two
    thresholds change nothing."""
    trig = SchmittTrigger()
    trig = trig.update(11.0, 0.0, 10.0, 8.0, 0.05)
    assert not trig.on
    trig = trig.update(11.0, 0.05, 10.0, 8.0, 0.05)
    assert trig.on
    for k, value in enumerate([9.0, 8.5, 9.9, 8.1] * 5):  # between: stays on
        trig = trig.update(value, 0.06 + 0.01 * k, 10.0, 8.0, 0.05)
        assert trig.on
    trig = trig.update(7.0, 1.0, 10.0, 8.0, 0.05)
    trig = trig.update(9.0, 1.03, 10.0, 8.0, 0.05)  # back between: the dwell restarts
    trig = trig.update(7.0, 1.06, 10.0, 8.0, 0.05)
    assert trig.on
    trig = trig.update(7.0, 1.11, 10.0, 8.0, 0.05)
    assert not trig.on


def test_filter_is_first_order():
    """A step seen every 10 ms: the filtered force after time t is 1 - exp(-t / tau)."""
    g = update_guards(GuardSignals(), _m(0.0, feet=(0.0, 0.0)), CFG, TABLE)
    for k in range(1, 11):
        g = update_guards(g, _m(0.01 * k, feet=(100.0, 100.0)), CFG, TABLE)
    expected = 100.0 * (1.0 - math.exp(-0.1 / CFG.force_filter_time_constant_s))
    assert g.foot_fz_N[0] == pytest.approx(expected)


# --- The seat's unloading plan -----------------------------------------------------------


def test_seat_unloading_plan():
    """The phase table's release: the buttocks from state 2 over its unload_s, the thighs
    from state 3 over theirs, smoothstep from 1 to 0 (3 r^2 - 2 r^3 of the time left)."""
    assert np.isnan(seat_loads(_in_state(1, 0.0), 1.0, TABLE)).all()
    mode = _in_state(2, 3.0)
    half = 3.0 + FORWARD.unload_s / 2
    np.testing.assert_allclose(seat_loads(mode, 3.0, TABLE)[0], 1.0)
    np.testing.assert_allclose(seat_loads(mode, half, TABLE)[0], 0.5)  # smoothstep
    assert seat_loads(mode, 3.0 + FORWARD.unload_s, TABLE)[0] == 0.0
    assert np.isnan(seat_loads(mode, 4.0, TABLE)[1:]).all()  # thighs still seated
    mode = _in_state(3, 5.0)
    quarter = 5.0 + LIFT_OFF.unload_s / 4  # seat_scale 0.75
    np.testing.assert_allclose(seat_loads(mode, quarter, TABLE)[1:], 0.75**2 * 1.5)
    np.testing.assert_allclose(seat_loads(mode, 5.0 + LIFT_OFF.unload_s, TABLE), 0.0)


def test_3_to_4_waits_for_the_release():
    table = _table(lift_off={"exit.min_time_s": 0.0, "unload_s": 0.8})
    mode = _in_state(3, 5.0, table)
    assert _next(mode, _m(5.79, psi=20.0), table=table).state == 3
    assert _next(mode, _m(5.801, psi=20.0), table=table).state == 4


def test_state_3_starts_at_the_com_height():
    """Bumpless: the state-3 segment starts at the measured CoM height (x, y continue
    the state-2 segment), and state 4 rises from there to the standing height."""
    mode = _in_state(2, 3.0)
    com = np.array([0.3, 0.01, 0.355])
    new = _next(mode, _m(3.0 + FORWARD.exit.min_time_s, com=com, feet=(200.0, 200.0)))
    assert new.state == 3
    assert new.x_start_m[2] == pytest.approx(0.355)
    np.testing.assert_allclose(new.x_start_m[:2], mode.segment_end()[:2])


# --- Issue 13: a pull against the stand-up holds it ------------------------------------

LIMIT = CFG.standing_pull_usage_limit
# The CoM's lead over the heels with which the phases hand the robot to its feet.
LEAD = max(p.exit.com_ahead_of_heels_m or 0.0 for p in TABLE)


def _reach(m: Measurements) -> float:
    return max(m.com_W[0] - m.heel_x, LEAD)


def _pulled(m: Measurements, usage: float, hands=(-10.0, -10.0)) -> Measurements:
    """m under a backward pull that needs `usage` of the CoM's reach back over the heels."""
    return dataclasses.replace(m, hand_fx_N=hands, cop_shift_m=-usage * _reach(m))


def _back(t, usage=1.5 * LIMIT, **kwargs) -> Measurements:
    """A pull against the stand-up at t: 1.5 times what the feet may be asked."""
    return _pulled(_m(t, **kwargs), usage)


def test_heel_usage_is_the_share_of_the_reach_back_over_the_heels():
    """Behind the heels' lead the reach is the phases' lead (the seat holds the pull until
    the feet take the robot with that lead); further ahead, the CoM's own lead."""
    seated = dataclasses.replace(_m(3.0, com=COM0, heel_x=0.2), cop_shift_m=-0.012)
    assert heel_usage(seated, TABLE) == pytest.approx(0.012 / LEAD)
    ahead = dataclasses.replace(_m(3.0, com=AHEAD, heel_x=0.1), cop_shift_m=-0.05)
    assert heel_usage(ahead, TABLE) == pytest.approx(0.05 / 0.2)
    forward = dataclasses.replace(ahead, cop_shift_m=0.05)  # toward the toes: not this
    assert heel_usage(forward, TABLE) == 0.0
    lifted = dataclasses.replace(ahead, cop_shift_m=-math.inf)
    assert heel_usage(lifted, TABLE) == 10.0


def test_a_pull_the_feet_could_not_hold_keeps_the_robot_seated():
    """Judged by its effect: seated, a backward pull that would need more than the limit
    of the reach over the heels waits; one that needs less starts, however hard the
    hands are pulled back."""
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = initial_mode(COM0)
    seated = _m(3.5, com=COM0, heel_x=0.2)
    assert _next(mode, _pulled(seated, 1.05 * LIMIT), cfg).state == 1
    assert _next(mode, _pulled(seated, 0.95 * LIMIT, hands=(-30.0, -30.0)), cfg).state == 2


def test_a_pull_that_sat_the_robot_back_holds_it_until_it_eases():
    """A backward pull too much for the feet in state 2 sits the robot back; seated, the
    same pull needs less of the reach (its lever shorter), but it is still the pull that
    was against the stand-up: the robot waits until the backward force falls below
    guard_off_ratio of the largest it felt while hindered, then resume_after_s."""
    cfg = CFG_TIME
    mode = _in_state(2, 3.0)
    sat = _next(mode, _back(3.2, psi=3.2), cfg)  # 2 x 10 N back, 1.5 x the limit
    assert sat.state == 1 and sat.guards.hindering_back_N == pytest.approx(20.0)
    seated = _pulled(_m(8.0, com=COM0, heel_x=0.2), 0.3 * LIMIT)  # the same force seated
    t, mode = 8.0, sat
    for k in range(100):  # a second of it: still waiting
        t = 8.0 + 0.01 * k
        mode = next_mode(mode, dataclasses.replace(seated, t=t, psi=t), cfg, TABLE)
    assert mode.state == 1 and mode.guards.against()
    eased = _pulled(seated, 0.1 * LIMIT, hands=(-0.3 * 10.0, -0.3 * 10.0))
    for k in range(1, 100):  # the pull eased to 30 %: calm, then the stand-up goes on
        t = 9.0 + 0.01 * k
        mode = next_mode(mode, dataclasses.replace(eased, t=t, psi=t + 10.0), cfg, TABLE)
    assert mode.guards.hindering_back_N == 0.0 and mode.state == 2


def test_a_backward_force_counts_where_a_scenario_sets_its_threshold():
    """Older files set standup.hindering_force_threshold_N: both hands together pulled
    back by more than it hold the stand-up too, whatever the pull's effect."""
    back_N = 2.5
    cfg = dataclasses.replace(CFG, trigger="time", hindering_force_threshold_N=back_N)
    mode = initial_mode(COM0)
    back = (-(back_N / 2 + 1.0), -(back_N / 2 + 1.0))
    assert _next(mode, _m(3.5, hands=back), cfg).state == 1
    weak = (-(back_N / 2 - 0.5), -(back_N / 2 - 0.5))
    assert _next(mode, _m(3.5, hands=weak), cfg).state == 2
    assert _next(mode, _m(3.5, hands=back), CFG_TIME).state == 2  # the default: by effect


@pytest.mark.parametrize("state", [2, 3])
def test_a_backward_pull_with_the_thighs_on_the_chair_sits_back_without_a_jump(state):
    """In state 2, or in state 3 while the thighs still carry most of their load: back to
    state 1, the reference starting where its segment had brought it (the path evaluated
    independently here; in state 2 at the CoM's height, which the reference follows) and
    returning to the seated CoM, the balancing time running again; state 2 waits for the
    return and then starts from the seated CoM, so that it ends where the first attempt's
    would have."""
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = _in_state(state, 3.0)
    assert mode.x_seated_m == tuple(COM0)
    # A tenth into the thighs' release: they carry 97 % of their load (smoothstep).
    t = psi = 3.0 + 0.1 * min(LIFT_OFF.unload_s, mode.segment_psi)
    new = _next(mode, _back(t, psi=psi), cfg)
    assert new.state == 1 and new.entry_times_s[0] == t
    assert all(math.isnan(e) for e in new.entry_times_s[1:])
    tau = (psi - mode.psi_entry) / mode.segment_psi
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    expected = np.array(mode.x_start_m) + s * np.array(mode.delta_m)
    if state == 2:  # forward's reference height is the CoM's (com_height_follows)
        expected[2] = AHEAD[2]
    np.testing.assert_allclose(new.x_start_m, expected, atol=1e-12)
    np.testing.assert_allclose(new.segment_end(), COM0, atol=1e-12)
    # The balancing time has run but the return has not: still seated.
    late = t + SEATED.exit.min_time_s + 0.01
    calm = (0.0, 0.0)
    assert _next(new, _m(late, psi=t + 0.5 * new.segment_psi, hands=calm), cfg).state == 1
    again = _next(new, _m(late, psi=t + new.segment_psi + 0.01, hands=calm), cfg)
    assert again.state == 2
    np.testing.assert_allclose(again.x_start_m, COM0, atol=1e-12)


@pytest.mark.parametrize("into_release", [0.25, 0.6])
def test_state_3_goes_back_onto_the_thighs_while_they_unload(into_release):
    """A quarter or 0.6 into the thighs' release (they carry 84 % or 35 % of their load,
    smoothstep: below reseat_above_thigh_load) a backward pull sends state 3 back to
    state 2, the reference held where the state-3 segment had brought it (the path
    evaluated independently here) and the thighs planned seated; it stays there while
    pulled, however the guards read; once the pull has stopped for resume_after_s, state
    3 again, whose segment ends where the interrupted one was to end."""
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = _in_state(3, 5.0)
    end = mode.segment_end()
    t = psi = 5.0 + into_release * LIFT_OFF.unload_s
    feet = (500.0, 500.0)
    held = _next(mode, _back(t, psi=psi, feet=feet), cfg)
    assert held.state == 2 and math.isnan(held.entry_times_s[2])
    tau = min((psi - mode.psi_entry) / mode.segment_psi, 1.0)
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    x_held = np.array(mode.x_start_m) + s * np.array(mode.delta_m)
    np.testing.assert_allclose(held.x_start_m, x_held, atol=1e-12)
    assert held.delta_m == (0.0, 0.0, 0.0)
    assert math.isnan(seat_loads(held, t, TABLE)[1])  # the thighs seated again
    later = t + 5.0  # still pulled: feet loaded, CoM ahead, segment done; still state 2
    assert _next(held, _back(later, psi=later, feet=feet), cfg).state == 2
    held = dataclasses.replace(held, hindered_until_s=later)
    calm = (0.0, 0.0)
    soon = later + 0.9 * cfg.resume_after_s
    assert _next(held, _m(soon, psi=soon, feet=feet, hands=calm), cfg).state == 2
    go = later + cfg.resume_after_s + 0.01
    again = _next(held, _m(go, psi=go, feet=feet, hands=calm), cfg)
    assert again.state == 3
    np.testing.assert_allclose(again.segment_end()[:2], end[:2], atol=1e-12)


def test_state_3_holds_once_the_thighs_are_off_the_chair():
    """After the thighs' release a backward pull no longer takes the robot back: state 3
    holds."""
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = _in_state(3, 5.0)
    t = 5.0 + 1.01 * LIFT_OFF.unload_s
    feet = (500.0, 500.0)
    held = _next(mode, _back(t, feet=feet), cfg)
    assert held.state == 3 and held.x_start_m == mode.x_start_m
    assert _next(held, _back(t + 0.1, feet=feet), cfg).state == 3


def test_the_stand_up_resumes_only_a_while_after_the_pull_stops():
    """Seated, balanced long enough, a hindering pull felt until t = 5 s: the stand-up
    starts resume_after_s later, not before."""
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = dataclasses.replace(initial_mode(COM0), hindered_until_s=5.0)
    early = 5.0 + 0.9 * cfg.resume_after_s
    assert _next(mode, _m(early, psi=early, hands=(0.0, 0.0)), cfg).state == 1
    late = 5.0 + cfg.resume_after_s + 0.01
    assert _next(mode, _m(late, psi=late, hands=(0.0, 0.0)), cfg).state == 2


def test_state_3_goes_on_once_the_pull_has_stopped_for_a_while():
    mode = _in_state(3, 5.0)
    t_ok = 5.0 + max(LIFT_OFF.exit.min_time_s, LIFT_OFF.unload_s) + 0.01
    feet = (500.0, 500.0)
    mode = dataclasses.replace(mode, hindered_until_s=t_ok)
    assert _next(mode, _m(t_ok + 0.9 * CFG.resume_after_s, feet=feet, hands=(0.0, 0.0))).state == 3
    assert _next(mode, _m(t_ok + CFG.resume_after_s + 0.01, feet=feet, hands=(0, 0))).state == 4


def test_time_held_back_accumulates_while_hindered():
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = initial_mode(COM0)
    t = 0.0
    usage = 2.0 * LIMIT
    for k in range(400):  # 4 s of updates every 10 ms: pulled back from 1 to 3 s
        t = 0.01 * k
        m = _m(t, hands=(0.0, 0.0), com=COM0)
        mode = next_mode(mode, _pulled(m, usage) if 1.0 <= t < 3.0 else m, cfg, TABLE)
    # On once the filtered usage (first order, tau) crosses the limit and the dwell has
    # passed, off likewise once it decays below guard_off_ratio of it: the 2 s shifted
    # by the difference of the two delays (within an update, 10 ms).
    tau, dwell = cfg.force_filter_time_constant_s, cfg.guard_dwell_s
    on = tau * math.log(usage / (usage - LIMIT)) + dwell
    off = tau * math.log(usage / (cfg.guard_off_ratio * LIMIT)) + dwell
    assert mode.held_back_s == pytest.approx(2.0 + off - on, abs=0.02)
    assert not mode.guards.hindered.on


def test_a_pull_beyond_the_standing_feet_is_waited_out_as_a_hindering_one():
    """A forward pull the standing robot's feet could not hold (standing_pull_usage above
    its limit, through the guards' filter and trigger): seated, the stand-up does not
    start; in state 2 it sits back; standing (state 4) it leans and goes on; the time it
    held the stand-up back is counted apart; below the limit nothing of this."""
    cfg = dataclasses.replace(CFG, trigger="time")
    limit = cfg.standing_pull_usage_limit
    helpful = (20.0, 20.0)  # forward: not hindering
    over = dataclasses.replace(_m(3.5, hands=helpful), pull_usage=limit * 1.05)
    under = dataclasses.replace(over, pull_usage=limit * 0.95)
    mode = initial_mode(COM0)
    waited = _next(mode, over, cfg)
    assert waited.state == 1 and waited.guards.beyond_feet.on and not waited.guards.hindered.on
    assert _next(mode, under, cfg).state == 2
    forward = _in_state(2, 3.0)
    sat = _next(forward, dataclasses.replace(over, t=3.2, psi=3.2), cfg)
    assert sat.state == 1 and sat.sat_back
    standing = _in_state(4, 3.0)
    assert _next(standing, dataclasses.replace(over, t=8.0, psi=8.0), cfg).state == 4
    t, held = 0.0, initial_mode(COM0)
    for k in range(300):  # 3 s of updates: beyond the feet from 1 to 2 s
        t = 0.01 * k
        usage = 2 * limit if 1.0 <= t < 2.0 else 0.0
        m = dataclasses.replace(_m(t, hands=helpful, com=COM0), pull_usage=usage)
        held = next_mode(held, m, cfg, TABLE)
    assert held.held_beyond_feet_s == pytest.approx(held.held_back_s)
    assert 0.9 < held.held_beyond_feet_s < 1.2


def test_stand_up_request_starts_like_the_pull_after_the_balance_time():
    """The live page's "Stand up" (Measurements.stand_up) with trigger 'hands' and no
    pull: state 2 once the balance time is over, not before; without the request the
    robot stays seated; a pull against the stand-up still holds it."""
    mode = initial_mode(COM0)
    t = SEATED.exit.min_time_s
    asked = dataclasses.replace(_m(t, hands=(0.0, 0.0)), stand_up=True)
    assert _next(mode, asked).state == 2
    assert _next(mode, dataclasses.replace(asked, t=t - 0.1)).state == 1
    assert _next(mode, dataclasses.replace(asked, stand_up=False)).state == 1
    assert _next(mode, _pulled(asked, 1.5 * LIMIT)).state == 1
