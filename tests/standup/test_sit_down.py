"""The sit-down (states 5-7, standup/sit_down.py) on synthetic inputs: what asks for it,
the path back along the stand-up's own segment starts, the touch that begins a pad
group's landing and the load it may carry after, the creep to the seat, a pull against
the sit-down, and seated again."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from drake_standup.config import StandupConfig
from drake_standup.config.cycle import SitDownConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.control.smooth import smoothstep
from drake_standup.standup.guards import GuardSignals, Measurements, update_guards
from drake_standup.standup.sit_down import descent_end, descent_progress, next_cycle_mode
from drake_standup.standup.transitions import (
    _enter,
    initial_mode,
    seat_landings,
    seat_loads,
)

TABLE = PhaseTable()
TABLE.rise.com_height_m = 0.575  # the erect height, as the plan resolves it
COM0 = np.array([0.06, 0.0, 0.38])
STARTS = {2: [0.06, 0.0, 0.38], 3: [0.186, 0.0, 0.312], 4: [0.226, 0.0, 0.312]}
STANDING = np.array([0.226, 0.0, 0.575])


def _cfg(**sit) -> StandupConfig:
    return dataclasses.replace(StandupConfig(), sit_down=SitDownConfig(**sit))


def _m(t, psi=None, com=STANDING, hands=(0.0, 0.0), up=(0.0, 0.0), seat=(0.0, 0.0, 0.0), **kw):
    return Measurements(
        t,
        t if psi is None else psi,
        com,
        heel_x=0.1,
        foot_fz_N=(170.0, 170.0),
        hand_fx_N=hands,
        thigh_x=0.07,
        hand_fz_N=up,
        seat_fz_N=seat,
        **kw,
    )


def _standing(t: float = 6.0):
    """A mode in state 4 whose segments started at STARTS, its rise done at t."""
    mode = initial_mode(COM0)
    for k in (2, 3, 4):
        mode = _enter(mode, k, _m(t - 3.0 + k / 2, com=np.array(STARTS[k])), TABLE)
    return dataclasses.replace(
        mode,
        psi_entry=0.0,
        segment_psi=1.0,
        x_start_m=tuple(STANDING),
        delta_m=(0.0, 0.0, 0.0),
        standing_since_s=t,
    )


def _settled(mode, m, cfg):
    g = GuardSignals()
    for k in range(100, 0, -1):
        g = update_guards(g, dataclasses.replace(m, t=m.t - 0.01 * k), cfg, TABLE)
    return dataclasses.replace(mode, guards=g)


def _step(mode, m, cfg):
    return next_cycle_mode(_settled(mode, m, cfg), m, cfg, TABLE)


def _run(mode, m, cfg, until, dt=0.01):
    """Updates every dt from m.t to until (psi = t), the inputs otherwise m's."""
    t = m.t
    while t < until - 1e-9:
        mode = next_cycle_mode(mode, dataclasses.replace(m, t=t, psi=t), cfg, TABLE)
        t += dt
    return mode


def test_no_sit_down_is_asked_by_default():
    cfg = StandupConfig()
    mode = _run(_standing(), _m(6.0), cfg, until=20.0)
    assert mode.state == 4


def test_the_clock_sits_down_stand_s_after_the_rise_is_done():
    cfg = _cfg(trigger="time", stand_s=3.0)
    mode = _run(_standing(), _m(6.0), cfg, until=8.95)
    assert mode.state == 4 and mode.standing_since_s == pytest.approx(6.0)
    mode = _run(mode, _m(8.95), cfg, until=9.05)
    assert mode.state == 5


def test_at_s_sits_down_at_that_time_of_the_run():
    cfg = _cfg(trigger="time", at_s=7.5)
    assert _run(_standing(), _m(6.0), cfg, until=7.45).state == 4
    assert _run(_standing(), _m(6.0), cfg, until=7.55).state == 5


def test_a_pull_back_and_down_held_asks_for_it_and_a_pull_forward_does_not():
    cfg = _cfg(trigger="hands")
    down = _step(_standing(), _m(8.0, hands=(-8.0, -8.0), up=(-8.0, -8.0)), cfg)
    assert down.state == 5
    forward = _step(_standing(), _m(8.0, hands=(8.0, 8.0), up=(8.0, 8.0)), cfg)
    assert forward.state == 4
    weak = _step(_standing(), _m(8.0, hands=(-3.0, -3.0), up=(-3.0, -3.0)), cfg)
    assert weak.state == 4  # below standup.gentle_pull_force_N (6.5 N)


def test_the_live_page_asks_the_kth_sit_down_with_its_kth_click():
    cfg = _cfg(trigger="hands", times=2)
    assert _step(_standing(), _m(8.0, sit_down=1.0), cfg).state == 5
    once = dataclasses.replace(_standing(), sit_downs=1)
    assert _step(once, _m(8.0, sit_down=1.0), cfg).state == 4
    assert _step(once, _m(8.0, sit_down=2.0), cfg).state == 5


def test_times_bounds_the_sit_downs():
    cfg = _cfg(trigger="time", stand_s=0.0, times=1)
    done = dataclasses.replace(_standing(), sit_downs=1)
    assert _run(done, _m(6.0), cfg, until=9.0).state == 4


def test_the_descent_returns_along_the_stand_ups_own_starts():
    """lower ends where the rise began, land where the lift-off began, settle at the
    seated CoM but no further back than the thigh pads' line plus the release's
    unload_when (where the buttocks left the seat on the way up)."""
    mode = _standing()
    m = _m(9.0)
    rise, lift_off = mode.starts_m[3], mode.starts_m[2]  # as _enter recorded them
    assert rise[0] == pytest.approx(STARTS[2][0] + 0.1277 + 0.04)  # forward's, lift-off's
    np.testing.assert_allclose(descent_end(mode, 5, m, TABLE), rise)
    np.testing.assert_allclose(descent_end(mode, 6, m, TABLE), lift_off)
    settle = descent_end(mode, 7, m, TABLE)
    assert settle[0] == pytest.approx(0.07 + TABLE.forward.unload_when)
    lowered = _step(mode, dataclasses.replace(m, sit_down=1.0), _cfg(trigger="hands"))
    np.testing.assert_allclose(lowered.segment_end(), rise, atol=1e-12)
    np.testing.assert_allclose(lowered.x_start_m, STANDING)  # from the reference: no jump


def test_descent_progress_is_the_share_of_the_path_the_reference_has_gone():
    mode = _step(_standing(), _m(9.0, sit_down=1.0), _cfg(trigger="hands"))
    start, end = STANDING, np.array(mode.phase_to_m)
    assert descent_progress(mode, start, TABLE) == pytest.approx(0.0)
    assert descent_progress(mode, start + 0.25 * (end - start), TABLE) == pytest.approx(0.25)
    assert descent_progress(mode, end + [0, 0, -0.1], TABLE) == 1.0  # clamped
    assert math.isnan(descent_progress(_standing(), start, TABLE))


def test_a_landing_begins_at_the_touch_and_its_load_rises_over_load_s():
    cfg = _cfg(trigger="hands")
    land = dataclasses.replace(_step(_standing(), _m(9.0, sit_down=1.0), cfg), state=6)
    land = dataclasses.replace(land, release_s=(4.0, 5.0))  # both released on the way up
    brushed = next_cycle_mode(land, _m(10.0, seat=(0.0, 4.0, 4.0)), cfg, TABLE)
    assert math.isnan(brushed.land_s[1])  # 8 N in all: below touch_force_N
    touched = next_cycle_mode(land, _m(10.0, seat=(0.0, 6.0, 6.0)), cfg, TABLE)
    assert touched.land_s[1] == 10.0 and touched.height_follows
    landings = seat_landings(TABLE)
    loads = [seat_loads(touched, t, TABLE, landings) for t in (10.0, 10.35, 10.69, 10.71)]
    assert [row[0] for row in loads] == [0.0] * 4  # the buttocks stay released
    assert loads[0][1] == 0.0
    assert loads[1][1] == pytest.approx(smoothstep(0.5))
    assert 0.99 < loads[2][1] < 1.0
    assert math.isnan(loads[3][1]) and math.isnan(loads[3][2])  # seated once landed


@pytest.mark.parametrize("state, pads, k", [(6, "thigh", 1), (7, "buttocks", 0)])
def test_a_pad_group_within_touch_gap_of_the_seat_has_touched(state, pads, k):
    """The touch by kinematics, for the pad group the phase lands (no force yet: a landing
    the QP lowers exactly onto the seat rests on it with a few newtons, or hovers)."""
    cfg = _cfg(trigger="hands")
    gap = cfg.sit_down.touch_gap_m
    mode = dataclasses.replace(_step(_standing(), _m(9.0, sit_down=1.0), cfg), state=state)
    mode = dataclasses.replace(mode, release_s=(4.0, 5.0))
    if state == 7:
        mode = dataclasses.replace(mode, land_s=(math.nan, 8.0))  # the thighs landed
    far = next_cycle_mode(mode, _m(10.0, **{f"{pads}_gap_m": gap + 1e-3}), cfg, TABLE)
    assert math.isnan(far.land_s[k])
    near = next_cycle_mode(mode, _m(10.0, **{f"{pads}_gap_m": gap - 1e-3}), cfg, TABLE)
    assert near.land_s[k] == 10.0
    other = "buttocks" if pads == "thigh" else "thigh"  # the other group's gap: not this one's
    elsewhere = next_cycle_mode(mode, _m(10.0, **{f"{other}_gap_m": 0.0}), cfg, TABLE)
    assert math.isnan(elsewhere.land_s[k])


def test_an_untouched_pad_at_the_paths_end_creeps_down_from_rest():
    cfg = _cfg(trigger="hands")
    mode = dataclasses.replace(
        _step(_standing(), _m(9.0, sit_down=1.0), cfg), state=6, psi_entry=0.0, segment_psi=1.0
    )
    crept = next_cycle_mode(mode, _m(12.0), cfg, TABLE)
    assert crept.creeping and crept.state == 6
    assert crept.delta_m == (0.0, 0.0, -TABLE.land.sink_m)
    assert crept.segment_psi == TABLE.land.load_s and crept.psi_entry == 12.0


def test_a_pull_forward_and_up_stands_the_lowering_robot_back_up():
    cfg = _cfg(trigger="hands")
    lowering = _run(_step(_standing(), _m(9.0, sit_down=1.0), cfg), _m(9.01), cfg, until=9.5)
    assert lowering.state == 5
    up = _step(lowering, _m(9.6, hands=(10.0, 10.0), up=(10.0, 10.0)), cfg)
    assert up.state == 4
    assert up.segment_end()[2] == pytest.approx(TABLE.rise.com_height_m)
    assert math.isnan(up.standing_since_s)


def test_a_pull_against_the_landing_holds_the_reference_and_the_landing_goes_on_after():
    cfg = _cfg(trigger="hands")
    land = dataclasses.replace(_step(_standing(), _m(9.0, sit_down=1.0), cfg), state=6)
    held = _step(land, _m(9.5, hands=(10.0, 10.0), up=(10.0, 10.0)), cfg)
    assert held.state == 6 and held.stepped_back() and not any(held.delta_m)
    np.testing.assert_allclose(held.resume_end_m, land.segment_end())
    calm = _run(held, _m(9.6), cfg, until=10.6)
    assert calm.state == 6 and not calm.stepped_back()
    np.testing.assert_allclose(calm.segment_end(), land.segment_end(), atol=1e-12)


def _settling(cfg: StandupConfig):
    """A mode in state 7, its path done (psi 0-1) and both pad groups landed."""
    return dataclasses.replace(
        _step(_standing(), _m(9.0, sit_down=1.0), cfg),
        state=7,
        psi_entry=0.0,
        segment_psi=1.0,
        land_s=(11.0, 10.0),
        release_s=(4.0, 5.0),
    )


def test_settled_the_robot_is_seated_again_and_waits_seated_s_to_stand():
    cfg = _cfg(trigger="hands", seated_s=2.0)
    settle = _settling(cfg)
    seated = next_cycle_mode(settle, _m(12.0), cfg, TABLE)
    assert seated.state == 1 and seated.sit_downs == 1 and seated.sat_back
    assert all(math.isnan(v) for v in seated.release_s + seated.land_s)
    np.testing.assert_allclose(seated.segment_end(), COM0)  # back to where it sat
    pull = dict(hands=(20.0, 20.0), up=(20.0, 20.0), com=COM0)
    assert _run(seated, _m(12.0, **pull), cfg, until=13.9).state == 1
    assert _run(seated, _m(12.0, **pull), cfg, until=15.6).state == 2


def test_after_a_settle_its_posture_led_the_return_starts_where_the_com_is():
    """The settle's CoM rows are released (Phase.posture_leads), so its reference is not
    where the robot is: seated again, the return to where it sat starts at the CoM (and
    from the reference where the phase held the CoM to it)."""
    cfg = _cfg(trigger="hands", seated_s=2.0)
    settle = _settling(cfg)
    com = np.array([0.065, 0.0, 0.385])  # behind the settle's reference, which ends at 0.094
    assert TABLE.settle.posture_leads
    seated = next_cycle_mode(settle, _m(12.0, com=com), cfg, TABLE)
    np.testing.assert_allclose(seated.reference(12.0, com), com)
    np.testing.assert_allclose(seated.segment_end(), COM0)
    held = dataclasses.replace(TABLE, settle=dataclasses.replace(TABLE.settle, posture_leads=False))
    from_reference = next_cycle_mode(settle, _m(12.0, com=com), cfg, held)
    np.testing.assert_allclose(
        from_reference.reference(12.0, com)[:2], settle.reference(12.0, com)[:2]
    )
