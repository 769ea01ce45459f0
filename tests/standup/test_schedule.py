"""The contact schedule (standup/contact_schedule.py): the bounds, the unloading memory and the
seat's hold, from hand-computed cases; and the system's memory over ticks."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from drake_standup.config import ControllerConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.control.smooth import smoothstep
from drake_standup.standup.contact_schedule import (
    CONTACTS,
    ContactSchedule,
    contact_commands,
    next_unload_from,
    phase_seat_hold,
)
from drake_standup.standup.transitions import Measurements, _enter, _sit_back, initial_mode

CONFIG = ControllerConfig()
TABLE = PhaseTable()
NAN3 = np.full(3, math.nan)
F_MIN, SEAT_MAX, FOOT_MAX = 10.0, 400.0, 1000.0  # the defaults, N ([authors-code], [early-probe])
MARGIN = 20.0  # controller.seat_measured_margin_N


def _m(t: float) -> Measurements:
    # The CoM 6 cm ahead of the thigh pads: the buttocks' release begins at entry.
    return Measurements(t, t, np.array([0.06, 0.0, 0.38]), 0.1, (0.0, 0.0), (0.0, 0.0), 0.0)


def test_the_defaults_are_the_documented_bounds():
    assert (CONFIG.min_normal_force_N, CONFIG.seat_max_normal_force_N) == (F_MIN, SEAT_MAX)
    assert (CONFIG.foot_max_normal_force_N, CONFIG.seat_measured_margin_N) == (FOOT_MAX, MARGIN)


def test_seated_pads_get_the_seated_bounds_and_the_phase_hold():
    commands = contact_commands(CONFIG, NAN3, np.zeros(3), None, "held")
    assert commands.active == (True,) * 5
    np.testing.assert_array_equal(commands.min_normal_force_N, [F_MIN] * 5)
    np.testing.assert_array_equal(commands.max_normal_force_N, [SEAT_MAX] * 3 + [FOOT_MAX] * 2)
    assert commands.seat_hold == "held"


def test_a_seated_pad_is_counted_on_only_as_far_as_it_carries_load():
    """Every pad seated, measured: a thigh carrying nothing (a low seat, the thigh sloping
    up off it) gets [0, 20]; one carrying 4 N [4, 24]; the buttocks, 150 N, [10, 170];
    not measured, the seated bounds [10, 400]."""
    commands = contact_commands(CONFIG, NAN3, NAN3, np.array([150.0, 0.0, 4.0]), "held")
    np.testing.assert_array_equal(commands.min_normal_force_N[:3], [F_MIN, 0.0, 4.0])
    np.testing.assert_array_equal(
        commands.max_normal_force_N[:3], [150.0 + MARGIN, MARGIN, 4.0 + MARGIN]
    )
    np.testing.assert_array_equal(commands.min_normal_force_N[3:], [F_MIN, F_MIN])
    unmeasured = contact_commands(CONFIG, NAN3, NAN3, None, "held")
    np.testing.assert_array_equal(unmeasured.max_normal_force_N[:3], [SEAT_MAX] * 3)


def test_a_releasing_pad_is_bounded_by_what_is_left_and_by_what_it_carries():
    """The buttocks with half their load left, released from 120 N, carrying 30 N: at
    most min(0.5 x 120, 30 + 20) = 50 N, at least 0; the seated thighs, carrying 55 N,
    get [10, 55 + 20]; the seat keeps the phase's hold while the buttocks unload."""
    loads = np.array([0.5, math.nan, math.nan])
    commands = contact_commands(
        CONFIG, loads, np.array([120.0, 80.0, 80.0]), np.array([30.0, 55.0, 55.0]), "hinged"
    )
    assert commands.min_normal_force_N[0] == 0.0 and commands.max_normal_force_N[0] == 50.0
    np.testing.assert_array_equal(commands.min_normal_force_N[1:3], [F_MIN, F_MIN])
    np.testing.assert_array_equal(commands.max_normal_force_N[1:3], [55.0 + MARGIN] * 2)
    assert commands.seat_hold == "hinged" and commands.thighs_hold == "free"
    # Measured above what is left: the fraction binds (0.25 x 80 = 20 < 55 + 20).
    loads = np.array([0.0, 0.25, 0.25])
    commands = contact_commands(
        CONFIG, loads, np.array([120.0, 80.0, 80.0]), np.array([0.0, 55.0, 55.0]), "hinged"
    )
    np.testing.assert_array_equal(commands.max_normal_force_N[:3], [0.0, 20.0, 20.0])
    np.testing.assert_array_equal(commands.min_normal_force_N[:3], 0.0)
    # A negative measurement (a pad pulled off) counts as 0: margin only.
    commands = contact_commands(
        CONFIG, np.array([1.0, math.nan, math.nan]), np.array([200.0, 0, 0]), -np.ones(3), "held"
    )
    assert commands.max_normal_force_N[0] == MARGIN


def test_holds_follow_the_release_no_contact_is_counted_on_while_the_motion_lifts_it():
    """(buttocks, thighs) left -> (seat hold, thighs' hold): the seat keeps its phase's
    hold until the buttocks' release is over, then holds no rows; from then the thighs
    are held flat (pitch and normal) while seated and by their normal while they unload
    (a pad the QP still counts on is not lifted by the plan), then not at all."""
    cases = [
        ((math.nan, math.nan), ("hinged", "free")),  # seated
        ((0.4, math.nan), ("hinged", "free")),  # the buttocks unloading
        ((0.0, math.nan), ("free", "flat")),  # the buttocks off, the thighs seated
        ((0.0, 0.3), ("free", "normal")),  # the thighs unloading: still held down
        ((0.0, 0.0), ("free", "free")),  # all off: the chair leaves the QP
    ]
    for (buttocks, thighs), expected in cases:
        loads = np.array([buttocks, thighs, thighs])
        commands = contact_commands(CONFIG, loads, np.full(3, 100.0), None, "hinged")
        assert (commands.seat_hold, commands.thighs_hold) == expected, (buttocks, thighs)


def test_the_chair_leaves_the_qp_once_every_seat_pad_is_released():
    for loads, active in (([0.0, 0.0, 0.0], False), ([0.0, 1e-6, 1e-6], True)):
        commands = contact_commands(CONFIG, np.array(loads), np.ones(3), None, "hinged")
        assert commands.active == (active,) * 3 + (True, True)
        np.testing.assert_array_equal(commands.min_normal_force_N[3:], F_MIN)


def test_the_release_starts_from_the_last_commanded_load():
    """A seated pad, or one at the first ticks of its release (what is left >= 1),
    follows the last commanded load; a releasing pad keeps the load it started from."""
    last = np.array([100.0, 60.0, 61.0])
    before = np.array([90.0, 50.0, 51.0])
    got = next_unload_from(before, last, np.array([math.nan, 1.0, 0.4]))
    np.testing.assert_array_equal(got, [100.0, 60.0, 51.0])


def test_the_seat_hold_is_the_phases_and_after_a_sit_back_its_other():
    seated = initial_mode(np.zeros(3))
    assert phase_seat_hold(seated, TABLE) == TABLE.seated.seat_hold == "held"
    forward = _enter(seated, 2, _m(3.0), TABLE)
    assert phase_seat_hold(forward, TABLE) == "hinged"
    back = _sit_back(forward, _m(3.5), TABLE)
    assert back.state == 1 and back.sat_back
    assert phase_seat_hold(back, TABLE) == TABLE.seated.seat_hold_sat_back == "hinged"


# A period of 2^-7 s: its ticks' times are exact in binary, so a tick's time is never a
# rounding error away from the time the test asks for.
PERIOD_S = 2.0**-7


class _Schedule:
    """The ContactSchedule alone, its memory kept here as the controller keeps it."""

    def __init__(self):
        self.schedule = ContactSchedule(CONFIG, TABLE)
        self.memory = np.zeros(ContactSchedule.MEMORY_SIZE)
        self.tick(0.0, initial_mode(np.zeros(3)), np.zeros(5))  # the initialization tick

    def tick(self, t: float, mode, commanded) -> object:
        """The commands of the tick at t with mode and commanded (what the controller's
        last tick asked), the memory updated as after that tick."""
        commands, self.memory = self.schedule.tick(
            mode, t, self.memory, commanded, lambda: np.full(3, 1e3)
        )
        return commands


def test_the_scheduler_remembers_the_load_the_release_began_from():
    """Seated, the controller asks 100 N of the buttocks, also at the first tick of state
    2 (entered at 1 s); from there the buttocks' bound falls from those 100 N along the
    smoothstep over unload_s, whatever the controller asks later, and a failed tick
    (NaN) changes nothing."""
    schedule = _Schedule()
    seated = initial_mode(np.zeros(3))
    asked = np.array([100.0, 70.0, 70.0, 60.0, 60.0])
    for k in range(1, 128):
        commands = schedule.tick(k * PERIOD_S, seated, asked)
    assert commands.max_normal_force_N[0] == SEAT_MAX
    forward = _enter(seated, 2, _m(1.0), TABLE)
    over = TABLE.forward.unload_s
    for k in range(int(over / PERIOD_S)):
        t = 1.0 + k * PERIOD_S
        later = asked * (1.0 if k == 0 else 0.5 if k % 2 else 1.5)
        if k == 3:
            later[:] = np.nan
        commands = schedule.tick(t, forward, later)
        r = 1.0 - (t - 1.0) / over
        left = r * r * (3.0 - 2.0 * r)
        assert commands.max_normal_force_N[0] == pytest.approx(100.0 * left, abs=1e-9), t
    assert commands.min_normal_force_N[0] == 0.0


def test_a_failed_tick_keeps_the_last_successful_commands():
    schedule = _Schedule()
    seated = initial_mode(np.zeros(3))
    schedule.tick(4 * PERIOD_S, seated, np.array([80.0, 70.0, 70.0, 60.0, 60.0]))
    schedule.tick(8 * PERIOD_S, seated, np.full(5, np.nan))  # the QP failed meanwhile
    forward = _enter(seated, 2, _m(8 * PERIOD_S), TABLE)
    commands = schedule.tick(9 * PERIOD_S, forward, np.full(5, np.nan))
    left = 1.0 - PERIOD_S / TABLE.forward.unload_s
    assert commands.max_normal_force_N[0] == pytest.approx(80.0 * left * left * (3 - 2 * left))
    assert len(commands.active) == len(CONTACTS)


def test_a_landing_rises_to_the_seated_bound_so_that_seated_is_no_step():
    """A sit-down's settle lands the buttocks from their touch (land_s) over load_s: their
    bound is landed * max(F_0, F + margin), and never above F + margin. The release had
    begun from 20 N (they had lifted off), they carry 50 N: the bound rises to 70 N, the
    seated bound, where the release's 20 N would have stepped to 70 N at state 1."""
    schedule = ContactSchedule(CONFIG, TABLE)
    carried = np.array([50.0, 60.0, 60.0])
    touch, over = 10.0, TABLE.settle.load_s
    settle = dataclasses.replace(
        initial_mode(np.zeros(3)),
        state=7,
        release_s=(4.0, 5.0),
        land_s=(touch, 8.0),  # the thighs landed before: seated
    )
    memory = np.concatenate((np.full(3, 20.0), np.full(3, 20.0)))  # F_0 = 20 N each
    for k, t in enumerate((touch, touch + 0.25 * over, touch + 0.5 * over, touch + over)):
        commands, _ = schedule.tick(settle, t, memory, np.full(5, 20.0), lambda: carried)
        landed = smoothstep((t - touch) / over) if t < touch + over else math.nan
        high = commands.max_normal_force_N[0]
        if math.isnan(landed):  # seated
            assert high == pytest.approx(50.0 + MARGIN)
        else:
            assert high == pytest.approx(min(landed * (50.0 + MARGIN), 50.0 + MARGIN)), k
        assert commands.max_normal_force_N[1] == pytest.approx(60.0 + MARGIN)  # seated thighs
    # On the way up (state 2) the same memory bounds a release by its F_0, as before.
    forward = dataclasses.replace(settle, state=2, land_s=(math.nan, math.nan))
    commands, _ = schedule.tick(forward, 4.0, memory, np.full(5, 20.0), lambda: carried)
    assert commands.max_normal_force_N[0] <= 20.0
