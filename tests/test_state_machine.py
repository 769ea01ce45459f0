"""The stand-up state machine on synthetic inputs: thresholds, dwell times,
one state at a time; and the LeafSystem's timing on its update grid."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_standup.config import StandupConfig
from drake_standup.state_machine import (
    Measurements,
    StandupStateMachine,
    initial_mode,
    next_mode,
    seat_scale,
)

# The authors' dwell times (SPEC 3; our defaults leave the dwell to psi), so
# the dwell guards are exercised too.
CFG = StandupConfig(min_time_state2_s=1.5, min_time_state3_s=0.5)
COM0 = np.array([0.06, 0.0, 0.38])
AHEAD = np.array([0.30, 0.0, 0.40])  # CoM far in front of the heels


def _m(t, psi=None, com=AHEAD, heel_x=0.1, feet=(200.0, 200.0), hands=(20.0, 20.0)):
    return Measurements(t, t if psi is None else psi, com, heel_x, feet, hands)


def _in_state(state: int, t_entry: float, cfg=CFG):
    """A mode that entered `state` at t_entry with psi = t_entry."""
    mode = initial_mode(COM0)
    for k in range(2, state + 1):
        mode = _force_enter(mode, k, t_entry, cfg)
    return mode


def _force_enter(mode, state, t, cfg):
    from drake_standup.state_machine import _enter

    return _enter(mode, state, _m(t), cfg)


def test_1_to_2_needs_balance_time_and_both_hands_over_threshold():
    mode = initial_mode(COM0)
    thr = CFG.hand_force_threshold_N
    assert next_mode(mode, _m(2.999, hands=(50, 50)), CFG).state == 1  # too early
    assert next_mode(mode, _m(3.5, hands=(thr, 50)), CFG).state == 1  # exactly at: not >
    assert next_mode(mode, _m(3.5, hands=(50, thr - 1)), CFG).state == 1  # one hand only
    assert next_mode(mode, _m(3.0, hands=(thr + 1e-9, thr + 1e-9)), CFG).state == 2


def test_1_to_2_with_time_trigger_ignores_hands():
    cfg = dataclasses.replace(CFG, trigger="time")
    mode = initial_mode(COM0)
    assert next_mode(mode, _m(2.999, hands=(0, 0)), cfg).state == 1
    new = next_mode(mode, _m(3.0, hands=(0, 0)), cfg)
    assert new.state == 2 and new.entry_times_s[1] == 3.0


def test_2_to_3_guards():
    mode = _in_state(2, 3.0)
    t_ok = 3.0 + CFG.min_time_state2_s
    thr = CFG.feet_force_2to3_N
    heel = 0.1
    com_ok = np.array([heel + CFG.com_ahead_of_heels_m, 0.0, 0.4])
    ok = {"feet": (thr / 2 + 1e-9, thr / 2 + 1e-9), "com": com_ok, "heel_x": heel}
    assert next_mode(mode, _m(t_ok, **ok), CFG).state == 3  # all at their thresholds
    assert next_mode(mode, _m(t_ok - 1e-6, **ok), CFG).state == 2  # dwell
    assert next_mode(mode, _m(t_ok, **{**ok, "feet": (thr / 2, thr / 2)}), CFG).state == 2
    com_behind = com_ok - np.array([1e-6, 0.0, 0.0])
    assert next_mode(mode, _m(t_ok, **{**ok, "com": com_behind}), CFG).state == 2
    # Segment not finished (psi behind): no switch, whatever the forces.
    assert next_mode(mode, _m(t_ok, psi=t_ok - 1e-6, **ok), CFG).state == 2


def test_3_to_4_needs_each_foot():
    mode = _in_state(3, 5.0)
    t_ok = 5.0 + CFG.min_time_state3_s
    thr = CFG.foot_force_3to4_N
    assert next_mode(mode, _m(t_ok, feet=(thr + 1e-9, thr + 1e-9)), CFG).state == 4
    assert next_mode(mode, _m(t_ok, feet=(thr, 500.0)), CFG).state == 3
    assert next_mode(mode, _m(t_ok, feet=(500.0, thr)), CFG).state == 3
    assert next_mode(mode, _m(t_ok - 1e-6, feet=(500.0, 500.0)), CFG).state == 3


def test_state_4_is_final():
    mode = _in_state(4, 6.0)
    assert next_mode(mode, _m(100.0), CFG) is mode


def test_never_skips_a_state_even_when_every_guard_holds():
    mode = initial_mode(COM0)
    states = [mode.state]
    t = 10.0  # every dwell satisfied; psi far past every segment
    for _ in range(5):
        mode = next_mode(mode, _m(t, psi=10.0 * t), CFG)
        states.append(mode.state)
        t += 10.0
    assert states == [1, 2, 3, 4, 4, 4]


def test_seat_release_ramp():
    mode = _in_state(3, 5.0)
    assert seat_scale(_in_state(2, 3.0), 9.0, CFG) == 1.0
    assert seat_scale(mode, 5.0, CFG) == 1.0
    assert seat_scale(mode, 5.0 + CFG.seat_release_s / 4, CFG) == pytest.approx(0.75)
    assert seat_scale(mode, 5.0 + CFG.seat_release_s, CFG) == 0.0
    assert seat_scale(mode, 50.0, CFG) == 0.0


def test_leaf_system_switches_on_its_update_grid():
    """Fixed synthetic inputs with trigger 'time': the system enters 2 at the
    first update at or after balance_time_s, then 3 after min_time_state2_s,
    then 4 after min_time_state3_s, exactly on the update grid."""
    cfg = dataclasses.replace(CFG, trigger="time", update_period_s=0.01)
    n_pads = 5
    system = StandupStateMachine(cfg, n_pads=n_pads, sole_rows=(0, 1))
    context = system.CreateDefaultContext()
    pads = np.zeros((n_pads, 3))
    pads[0, 2] = pads[1, 2] = 200.0
    system.GetInputPort("com_W").FixValue(context, AHEAD)
    system.GetInputPort("heel_x_W").FixValue(context, [0.1])
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
    t2 = cfg.balance_time_s
    t3 = t2 + max(cfg.min_time_state2_s, cfg.segment_psi[0])
    t4 = t3 + max(cfg.min_time_state3_s, cfg.segment_psi[1])
    np.testing.assert_allclose(entries, [0.0, t2, t3, t4], atol=cfg.update_period_s + 1e-9)
    assert system.GetOutputPort("standup_state").Eval(context)[0] == 4
    plan = system.GetOutputPort("contact_plan").Eval(context)
    assert plan[0] == 4 and plan[1] == 0.0  # seat released by t = 8 s


def test_entry_times_are_nan_until_reached():
    system = StandupStateMachine(CFG, n_pads=5, sole_rows=(0, 1))
    context = system.CreateDefaultContext()
    entries = system.GetOutputPort("entry_times_s").Eval(context)
    assert entries[0] == 0.0 and all(math.isnan(e) for e in entries[1:])
