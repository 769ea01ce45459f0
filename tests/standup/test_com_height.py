"""A phase whose CoM height follows the CoM (phases.com_height_follows, `forward` by
default): the reference's height is the measured CoM's there, and the segments that
follow it, a sit-back and a step back start from the reference actually used, so the
reference has no jump at state 3's entry (it had 37-66 mm in one 10 ms sample)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from drake_standup.config import StandupConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.ports.payloads import SEGMENT
from drake_standup.standup.com_path import CoMReferenceGenerator
from drake_standup.standup.transitions import (
    GuardSignals,
    Measurements,
    _enter,
    initial_mode,
    next_mode,
    update_guards,
)

COM0 = np.array([0.06, 0.0, 0.38])
CFG = StandupConfig(trigger="time")


def _min_jerk_position(x_start, delta, T, psi_entry, psi):
    """x_start + delta s(tau), written out here independently of com_path.py."""
    tau = min(max((psi - psi_entry) / T, 0.0), 1.0)
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    return np.asarray(x_start, float) + s * np.asarray(delta, float)


def _generator(segment, psi, com_W, psi_dot=1.3, psi_ddot=0.4):
    """(com_reference (9), x_d_W, path_tangent_W) of the generator on fixed inputs."""
    system = CoMReferenceGenerator()
    context = system.CreateDefaultContext()
    for name, value in (
        ("psi", [psi]),
        ("psi_dot", [psi_dot]),
        ("psi_ddot", [psi_ddot]),
        ("segment", segment),
        ("com_W", com_W),
    ):
        system.GetInputPort(name).FixValue(context, value)
    return tuple(
        system.GetOutputPort(name).Eval(context)
        for name in ("com_reference", "x_d_W", "path_tangent_W")
    )


def _segment(follows: bool) -> np.ndarray:
    return SEGMENT.pack(
        psi_entry=0.7,
        psi_length=1.5,
        x_start=[0.06, 0.0, 0.38],
        delta=[0.1277, -0.01, 0.03],
        height_follows=float(follows),
    )


@pytest.mark.parametrize("psi", [0.3, 1.2, 1.9, 5.0])  # before, inside, at the end, after
def test_the_height_is_the_measured_com_s_while_the_segment_follows_it(psi):
    com = np.array([0.5, 0.2, 0.3317])  # far from the path everywhere: only z may be read
    expected = _min_jerk_position([0.06, 0.0, 0.38], [0.1277, -0.01, 0.03], 1.5, 0.7, psi)
    reference, x_d, tangent = _generator(_segment(True), psi, com)
    np.testing.assert_allclose(reference[:2], expected[:2], atol=1e-12)
    assert reference[2] == com[2] and x_d[2] == com[2]
    np.testing.assert_allclose(x_d[:2], expected[:2], atol=1e-12)
    # Not tracked: no rate, no acceleration, no slope in z.
    assert reference[5] == 0.0 and reference[8] == 0.0 and tangent[2] == 0.0
    # Not following: the min-jerk path, whatever the CoM.
    reference, x_d, tangent = _generator(_segment(False), psi, com)
    np.testing.assert_allclose(reference[:3], expected, atol=1e-12)
    np.testing.assert_allclose(x_d, expected, atol=1e-12)
    if 0.7 < psi < 2.2:  # inside the segment the path rises
        assert reference[5] > 0.0 and tangent[2] > 0.0


def test_x_and_y_do_not_depend_on_the_flag():
    """The flag changes the height only: x, y, their rates and accelerations and the
    tangent's x, y are the path's either way."""
    com = np.array([0.5, 0.2, 0.3317])
    follow = _generator(_segment(True), 1.2, com)
    path = _generator(_segment(False), 1.2, com)
    for k in (0, 1, 3, 4, 6, 7):
        assert follow[0][k] == path[0][k] and path[0][k] != 0.0
    np.testing.assert_array_equal(follow[2][:2], path[2][:2])


def test_forward_follows_the_height_by_default():
    table = PhaseTable()
    assert [phase.com_height_follows for phase in table] == [False, True, False, False]


# --- Through the transitions --------------------------------------------------------


def _table(**lift_off) -> PhaseTable:
    table = PhaseTable()
    table.rise.com_height_m = 0.575
    for key, value in lift_off.items():
        setattr(table.lift_off, key, value)
    return table


def _m(t, psi, com, hands=(0.0, 0.0), feet=(300.0, 300.0)):
    # Heels and thigh pads far behind: the CoM is ahead of both.
    return Measurements(t, psi, np.asarray(com, float), -1.0, feet, hands, -1.0)


def _settled(mode, m, table):
    g = GuardSignals()
    for k in range(100, 0, -1):
        g = update_guards(g, dataclasses.replace(m, t=m.t - 0.01 * k), CFG, table)
    return dataclasses.replace(mode, guards=g)


def _in_state_2(table, t=3.0):
    mode = initial_mode(COM0)
    return _enter(mode, 2, _m(t, t, COM0), table)


def _used(mode, psi, com):
    """The reference the generator gives for mode's segment at psi and com (position)."""
    return _generator(mode.segment(), psi, np.asarray(com, float))[1]


@pytest.mark.parametrize("start_at_com_height", [True, False])
def test_state_3_starts_where_the_following_state_2_left_the_reference(start_at_com_height):
    """Entering state 3 after a state 2 whose height followed the CoM: the new segment
    starts at the reference of the instant before (the path's x, y end; the CoM's
    height, 5 cm below the seated one), whether or not lift_off asks for the CoM's
    height: the following alone makes the switch continuous."""
    table = _table(start_at_com_height=start_at_com_height)
    mode = _in_state_2(table)
    assert mode.height_follows
    forward = table.forward
    t = psi = 3.0 + forward.segment_psi + 0.01  # segment done
    com = np.array([0.25, 0.0, COM0[2] - 0.05])  # ahead of heels and thighs; dipped
    unloaded = dataclasses.replace(mode, release_s=(3.0, mode.release_s[1]))
    before = _used(unloaded, psi, com)
    end = _min_jerk_position(mode.x_start_m, mode.delta_m, forward.segment_psi, 3.0, psi)
    np.testing.assert_allclose(before, [end[0], end[1], com[2]], atol=1e-12)
    new = next_mode(_settled(unloaded, _m(t, psi, com), table), _m(t, psi, com), CFG, table)
    assert new.state == 3 and not new.height_follows
    np.testing.assert_allclose(new.x_start_m, before, atol=1e-12)
    np.testing.assert_allclose(_used(new, psi, com), before, atol=1e-12)
    # The jump the old table made: state 3 from the CoM's height, the path's at the
    # seated one.
    assert abs(before[2] - end[2]) == pytest.approx(0.05)


def _against(m):
    """m under a pull the feet could not hold: it moves the CoP back to the heels, 1 m
    behind here (_m)."""
    return dataclasses.replace(m, cop_shift_m=-(m.com_W[0] - m.heel_x))


def test_a_sit_back_starts_from_the_reference_actually_used():
    """A backward pull mid-way through the following state 2: state 1's return starts at
    the reference used then (the path's x, y; the CoM's height, not the path's) and ends
    at the seated CoM, its own height tracked again."""
    table = _table()
    mode = _in_state_2(table)
    t = psi = 3.0 + 0.4 * table.forward.segment_psi
    com = np.array([0.12, 0.0, COM0[2] - 0.03])
    back = (-10.0, -10.0)
    before = _used(mode, psi, com)
    x = _min_jerk_position(mode.x_start_m, mode.delta_m, table.forward.segment_psi, 3.0, psi)
    np.testing.assert_allclose(before, [x[0], x[1], com[2]], atol=1e-12)
    m = _against(_m(t, psi, com, hands=back))
    new = next_mode(_settled(mode, m, table), m, CFG, table)
    assert new.state == 1 and not new.height_follows
    np.testing.assert_allclose(new.x_start_m, before, atol=1e-12)
    np.testing.assert_allclose(_used(new, psi, com), before, atol=1e-12)
    np.testing.assert_allclose(new.segment_end(), COM0, atol=1e-12)
    # The height returns along the path, not with the CoM.
    later = _used(new, psi + new.segment_psi, com + [0.0, 0.0, -0.02])
    np.testing.assert_allclose(later, COM0, atol=1e-12)


def test_a_step_back_holds_the_reference_used():
    """A backward pull while the thighs unload in state 3: the state-2 hold starts at the
    reference used then and keeps it (its height is not the CoM's, though state 2's is
    by default), so the step back does not jump."""
    table = _table()
    mode = _in_state_2(table)
    mode = _enter(mode, 3, _m(5.0, 5.0, [0.2, 0.0, 0.33]), table)
    assert not mode.height_follows
    t = psi = 5.0 + 0.5 * table.lift_off.unload_s
    com = np.array([0.21, 0.0, 0.325])
    back = (-10.0, -10.0)
    before = _used(mode, psi, com)
    x = _min_jerk_position(mode.x_start_m, mode.delta_m, table.lift_off.segment_psi, 5.0, psi)
    np.testing.assert_allclose(before, x, atol=1e-12)
    m = _against(_m(t, psi, com, hands=back))
    held = next_mode(_settled(mode, m, table), m, CFG, table)
    assert held.state == 2 and not held.height_follows
    np.testing.assert_allclose(_used(held, psi, com), before, atol=1e-12)
    np.testing.assert_allclose(_used(held, psi + 1.0, com - [0.0, 0.0, 0.01]), before, atol=1e-12)


def test_entered_again_after_a_step_back_it_starts_where_the_hold_was():
    """Once the pull has stopped, state 3 starts again from the held reference, not from
    the CoM's height (which sank meanwhile under state 2's gains): no jump."""
    table = _table()
    mode = _in_state_2(table)
    mode = _enter(mode, 3, _m(5.0, 5.0, [0.2, 0.0, 0.33]), table)
    t = psi = 5.0 + 0.5 * table.lift_off.unload_s
    back = (-10.0, -10.0)
    m = _against(_m(t, psi, [0.21, 0.0, 0.325], hands=back))
    held = next_mode(_settled(mode, m, table), m, CFG, table)
    assert held.state == 2
    x_held = _used(held, psi, m.com_W)
    held = dataclasses.replace(held, hindered_until_s=t + 1.0)
    go = t + 1.0 + CFG.resume_after_s + 0.01
    sunk = np.array([0.21, 0.0, 0.314])  # 11 mm lower
    m = _m(go, go, sunk)
    again = next_mode(_settled(held, m, table), m, CFG, table)
    assert again.state == 3
    np.testing.assert_allclose(_used(again, go, sunk), x_held, atol=1e-12)
    assert abs(x_held[2] - sunk[2]) > 0.01
