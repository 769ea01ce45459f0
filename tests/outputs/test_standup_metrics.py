"""Stand-up metrics on synthetic signals whose answers are known by construction."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_pads import PADS

from drake_standup.outputs.metrics import (
    helper_metrics,
    path_deviation_max_m,
    seated_rest_metrics,
    sit_backs,
    smoothness_metrics,
    standup_metrics,
    torso_twist,
)

DT = 0.004


def _signals(t_stand, t_thighs_off, t_buttocks_off=4.0, height=0.56, end_s=12.0):
    """State 2 at 3 s, 3 at 5 s, 4 at 6 s with the last segment (T = 1.8) ending at
    psi = 7.8 = t; the reference rises to `height`. The CoM is 3 cm below that height
    before t_stand and 5 mm below from then on; the thighs (2 x 30 N) and the buttocks
    (40 N) unload at their times. Laid out as signals.npz, on a 4 ms grid."""
    t = np.arange(0.0, end_s, DT)
    state = np.select([t >= 6.0, t >= 5.0, t >= 3.0], [4, 3, 2], 1)
    ref = np.zeros((len(t), 3))
    ref[:, 2] = np.interp(t, [6.0, 7.8], [0.40, height])
    com = ref.copy()
    com[:, 2] = np.where(t < t_stand, height - 0.03, height - 0.005)
    normal = np.zeros((len(t), 5))
    normal[:, :2] = 160.0
    normal[:, 2:4] = np.where(t < t_thighs_off, 30.0, 0.0)[:, None]
    normal[:, 4] = np.where(t < t_buttocks_off, 40.0, 0.0)
    return {
        "time_s": t,
        "com_W": com,
        "com_reference_W": ref,
        "psi": t.copy(),
        "state": state,
        "segment_psi_entry": np.where(t >= 6.0, 6.0, 0.0),
        "segment_psi_length": np.where(t >= 6.0, 1.8, 100.0),
        "pad_names": np.array(list(PADS)),
        "pad_groups": np.array(list(PADS.values())),
        "pad_normal_force_N": normal,
    }


ENTRIES = [0.0, 3.0, 5.0, 6.0]


def _time(signals):
    return standup_metrics(signals, ENTRIES)["standup_time_s"]


def test_standup_ends_when_the_com_is_up_and_the_seat_off():
    # The later of the two outcomes decides, counted from entering state 2.
    assert _time(_signals(t_stand=9.0, t_thighs_off=6.5)) == pytest.approx(6.0, abs=DT)
    assert _time(_signals(t_stand=7.0, t_thighs_off=8.2)) == pytest.approx(5.2, abs=DT)
    assert _time(_signals(t_stand=7.0, t_thighs_off=5.0, t_buttocks_off=9.5)) == (
        pytest.approx(6.5, abs=DT)
    )
    m = standup_metrics(_signals(t_stand=9.0, t_thighs_off=6.5), ENTRIES)
    assert m["standing_at_end"] is True
    assert m["standing_com_height_m"] == pytest.approx(0.56)


def test_not_a_guard_instant_but_the_height_reached():
    """The CoM reaches its height 3 s after state 4 began (no guard fires then): the
    time follows the CoM, not the state machine."""
    assert _time(_signals(t_stand=9.0, t_thighs_off=5.5)) == pytest.approx(9.0 - 3.0, abs=DT)


def test_the_standing_height_is_the_runs_own():
    # An erect stance (0.56 m) or a crouch (0.526 m): read off the reference's end.
    for height in (0.526, 0.56, 0.58):
        m = standup_metrics(_signals(t_stand=8.0, t_thighs_off=6.5, height=height), ENTRIES)
        assert m["standing_com_height_m"] == pytest.approx(height)
        assert m["standup_time_s"] == pytest.approx(5.0, abs=DT)


def test_height_tolerance_is_one_centimetre():
    sig = _signals(t_stand=8.0, t_thighs_off=6.5)
    t = sig["time_s"]
    sig["com_W"][t >= 8.0, 2] = 0.56 - 0.0105
    assert _time(sig) is None
    sig["com_W"][t >= 8.0, 2] = 0.56 + 0.0095
    assert _time(sig) == pytest.approx(5.0, abs=DT)


def test_a_reload_inside_the_hold_restarts_it():
    """The thighs touch again for 0.1 s (6 N) 0.15 s after the CoM got up: standing
    counts from after the reload; a 4.9 N touch changes nothing."""
    sig = _signals(t_stand=8.0, t_thighs_off=6.5)
    t = sig["time_s"]
    touch = (t >= 8.15) & (t < 8.25)
    sig["pad_normal_force_N"][touch, 2] = 4.9
    assert _time(sig) == pytest.approx(5.0, abs=DT)
    sig["pad_normal_force_N"][touch, 2] = 6.0
    assert _time(sig) == pytest.approx(8.25 - 3.0, abs=DT)


def test_standing_must_hold_for_the_hold_time():
    # The CoM gets up 0.1 s before the run ends: not held 0.2 s, not stood up.
    sig = _signals(t_stand=11.9, t_thighs_off=6.5)
    assert _time(sig) is None
    assert standup_metrics(sig, ENTRIES)["standing_at_end"] is True


def test_no_standing_height_before_the_path_is_done():
    sig = _signals(t_stand=6.5, t_thighs_off=6.5, end_s=7.5)  # last segment unfinished
    m = standup_metrics(sig, ENTRIES)
    assert m["standup_time_s"] is None and m["standing_com_height_m"] is None
    assert m["standing_at_end"] is False


def test_tracking_rms():
    sig = _signals(t_stand=0.0, t_thighs_off=6.5)
    m = standup_metrics(sig, ENTRIES)
    # 5 mm below the reference's height from 7.8 s on; during the rise the CoM sits at
    # 0.555 and the reference below it.
    error = np.abs(sig["com_W"][:, 2] - sig["com_reference_W"][:, 2])
    assert m["com_tracking_rms_m"] == pytest.approx(np.sqrt(np.mean(error**2)))


def test_a_given_erect_height_replaces_the_references_end():
    sig = _signals(t_stand=8.0, t_thighs_off=6.5, height=0.56)
    m = standup_metrics(sig, ENTRIES, standing_height_m=0.575)
    assert m["standing_com_height_m"] == pytest.approx(0.575)
    # The CoM stands 5 mm below 0.56, i.e. 2 cm below 0.575: never standing.
    assert m["standup_time_s"] is None
    sig["com_W"][sig["time_s"] >= 8.0, 2] = 0.570
    assert standup_metrics(sig, ENTRIES, standing_height_m=0.575)["standup_time_s"] == (
        pytest.approx(5.0, abs=DT)
    )


def test_leaning_against_a_pull_lowers_the_standing_height():
    """A robot tilted about its feet by a lean d stands at sqrt(H^2 - d^2): with a 12 cm
    lean from t = 8 s an erect 0.575 m becomes 0.5623 m, so a CoM at 0.5625 m stands (it
    would be 1.25 cm low against the untilted height)."""
    sig = _signals(t_stand=8.0, t_thighs_off=6.5)
    t = sig["time_s"]
    sig["com_W"][t >= 8.0, 2] = 0.5625
    assert standup_metrics(sig, ENTRIES, standing_height_m=0.575)["standup_time_s"] is None
    lean = np.zeros((len(t), 3))
    lean[t >= 8.0, 0] = -0.12
    sig["com_lean_W"] = lean
    tilted = np.sqrt(0.575**2 - 0.12**2)
    assert abs(0.5625 - tilted) < 0.01 < abs(0.5625 - 0.575)
    m = standup_metrics(sig, ENTRIES, standing_height_m=0.575)
    assert m["standup_time_s"] == pytest.approx(5.0, abs=DT)


# --- What the helper spends, and the path deviation, against closed forms --------------


def _hands(t, f_left, f_right, v_left, v_right):
    """hand_wrenches_W (N x 12) and hand_velocities_W (N x 6) from per-sample arrays."""
    n = len(t)
    wrenches = np.zeros((n, 12))
    wrenches[:, 3:6], wrenches[:, 9:12] = f_left, f_right
    return wrenches, np.hstack([v_left, v_right])


def test_helper_work_impulse_and_peak_of_constant_forces_on_moving_hands():
    """F_l = (10, 0, 5) N on a hand accelerating along x at a = 0.3 m/s^2 from rest, so
    its power 3 t W is linear and the trapezoid rule exact: 0.15 T^2 J; F_r = (-2, 0, 0)
    N on a hand moving at 0.1 m/s along x: -0.2 T J. Impulse (|F_l| + |F_r|) T."""
    T, a = 2.0, 0.3
    t = np.linspace(0.0, T, 201)
    zeros = np.zeros((len(t), 3))
    v_left = zeros.copy()
    v_left[:, 0] = a * t
    v_right = zeros.copy()
    v_right[:, 0] = 0.1
    wrenches, velocities = _hands(t, [10.0, 0.0, 5.0], [-2.0, 0.0, 0.0], v_left, v_right)
    m = helper_metrics(t, wrenches, velocities)
    assert m["helper_work_J"] == pytest.approx(10.0 * a * T**2 / 2 - 0.2 * T, rel=1e-12)
    assert m["helper_peak_force_N"] == pytest.approx(np.hypot(10.0, 5.0))
    assert m["helper_impulse_Ns"] == pytest.approx((np.hypot(10.0, 5.0) + 2.0) * T, rel=1e-12)


def test_positive_work_is_the_part_where_the_helper_puts_power_in():
    """Power 3 (t - 1) W over [0, 2] s: no net work, 1.5 J put in after t = 1 s."""
    t = np.linspace(0.0, 2.0, 201)  # a sample at t = 1
    v = np.zeros((len(t), 3))
    v[:, 0] = t - 1.0
    wrenches, velocities = _hands(t, [3.0, 0.0, 0.0], [0.0, 0.0, 0.0], v, np.zeros_like(v))
    m = helper_metrics(t, wrenches, velocities)
    assert m["helper_work_J"] == pytest.approx(0.0, abs=1e-12)
    assert m["helper_positive_work_J"] == pytest.approx(1.5, rel=1e-12)


def test_path_deviation_is_the_distance_to_the_curve_not_to_the_point_at_time_t():
    """A reference along a quarter circle of radius 0.3 m, the CoM 1 cm outside it
    (radially) and lagging it by a tenth of the arc: 1 cm from the path (to the polyline
    through 2001 samples: within R (1 - cos(dtheta / 2)) = 5.8e-8 m), while it is 4.7 cm
    from where the reference is at the same instant."""
    R, d = 0.3, 0.01
    theta = np.linspace(0.0, np.pi / 2, 2001)
    path = np.stack([R * np.cos(theta), np.zeros_like(theta), R * np.sin(theta)], axis=1)
    lag = np.clip(theta - 0.1 * np.pi / 2, 0.0, None)
    com = np.stack([(R + d) * np.cos(lag), np.zeros_like(lag), (R + d) * np.sin(lag)], axis=1)
    assert path_deviation_max_m(com, path) == pytest.approx(d, abs=1e-7)
    assert np.linalg.norm(com - path, axis=1).max() > 4 * d


def test_path_deviation_of_a_straight_path_held_still_in_places():
    """Repeated samples (psi held, a segment of zero length) are no segment: the distance
    to a straight path is the perpendicular one, or to its end beyond it."""
    path = np.array([[0.0, 0, 0], [0.0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.2, 0, 0]])
    com = np.array([[0.05, 0.02, 0.0], [0.25, 0.0, 0.0]])
    assert path_deviation_max_m(com, path) == pytest.approx(0.05)
    assert path_deviation_max_m(com[:1], path) == pytest.approx(0.02)
    assert path_deviation_max_m(com, path[:1]) == pytest.approx(0.25)  # a reference held


def _smooth_signals(sole_total, reference=None, dt=0.01):
    """Two soles sharing sole_total (N,) equally, a thigh pad unloaded; state 2 from 1 s."""
    t = np.arange(len(sole_total)) * dt
    normal = np.zeros((len(t), 3))
    normal[:, :2] = sole_total[:, None] / 2.0
    return {
        "time_s": t,
        "pad_groups": np.array(["soles", "soles", "thighs"]),
        "pad_normal_force_N": normal,
        "com_reference_W": np.zeros((len(t), 3)) if reference is None else reference,
    }


SMOOTH_ENTRIES = (0.0, 1.0, 2.0, 3.0)


def test_chatter_is_zero_for_a_load_rising_linearly():
    """A centred moving average reproduces a straight line: a ramp is no chatter."""
    signals = _smooth_signals(np.linspace(0.0, 320.0, 400))
    assert smoothness_metrics(signals, SMOOTH_ENTRIES)["sole_force_chatter_N"] == pytest.approx(
        0.0, abs=1e-9
    )


def test_chatter_of_one_slap_is_its_size_less_its_share_of_the_average():
    """One sample A above a constant load departs from the 11-sample (0.1 s at 10 ms)
    centred average by A (1 - 1/11)."""
    load = np.full(400, 280.0)
    load[250] += 110.0
    chatter = smoothness_metrics(_smooth_signals(load), SMOOTH_ENTRIES)["sole_force_chatter_N"]
    assert chatter == pytest.approx(110.0 * (1.0 - 1.0 / 11.0))


def test_chatter_counts_from_the_standup_start_only():
    """A slap while seated (before state 2's entry at 1 s) is not the stand-up's; a run
    that never left the seat has no figure."""
    load = np.full(400, 280.0)
    load[50] += 300.0  # at 0.5 s
    assert smoothness_metrics(_smooth_signals(load), SMOOTH_ENTRIES)["sole_force_chatter_N"] == (
        pytest.approx(0.0)
    )
    seated = smoothness_metrics(_smooth_signals(load), (0.0, None, None, None))
    assert seated["sole_force_chatter_N"] is None


def test_reference_step_is_the_largest_sample_to_sample_distance():
    """A reference moving 2 mm per sample with one 3-4-0 mm jump: 5 mm."""
    reference = np.zeros((100, 3))
    reference[:, 0] = 0.002 * np.arange(100)
    reference[60:, 0] += 0.003
    reference[60:, 1] += 0.004
    reference[60:, 0] -= 0.002  # the jump replaces that sample's 2 mm step
    metrics = smoothness_metrics(_smooth_signals(np.full(100, 280.0), reference), SMOOTH_ENTRIES)
    assert metrics["com_reference_max_step_m"] == pytest.approx(0.005)


def test_seated_rest_measures_the_slide_and_the_drop_before_the_standup_only():
    """A base that sinks 1 mm and slides 3-4 mm sideways and forward while seated (5 mm),
    then moves 0.3 m once state 2 has begun (at 1 s): 5 mm of slide, 1 mm of drop, the
    pads' loads at 1 s; the window ends at 3 s when the stand-up never starts."""
    signals = _smooth_signals(np.full(400, 280.0))
    t = signals["time_s"]
    base = np.zeros((len(t), 3))
    base[:, 2] = 0.39
    base[t >= 0.5, 2] -= 0.001
    base[t >= 0.6, 0] += 0.003
    base[t >= 0.7, 1] += 0.004
    base[t > 1.0, 0] += 0.3
    signals["base_position_W"] = base
    signals["pad_normal_force_N"][:, 2] = np.where(t <= 1.0, 120.0, 0.0)
    rest = seated_rest_metrics(signals, SMOOTH_ENTRIES)
    assert rest["seated_slide_m"] == pytest.approx(0.005)
    assert rest["seated_drop_m"] == pytest.approx(0.001)
    assert rest["seated_normal_force_N"] == pytest.approx({"soles": 280.0, "thighs": 120.0})
    never = seated_rest_metrics(signals, (0.0, None, None, None))
    # The 0.3 m move at 1 s lies inside the 3 s window.
    assert never["seated_slide_m"] == pytest.approx(np.hypot(0.303, 0.004))
    assert never["seated_normal_force_N"]["thighs"] == 0.0


def test_sit_backs_count_the_returns_to_state_1():
    """State 1 again after 2 or 3 counts; staying in 1, and a step back from 3 to 2, do not."""
    assert sit_backs(np.array([1, 1, 2, 2, 1, 1, 2, 3, 2, 3, 1, 2, 3, 4])) == 2
    assert sit_backs(np.array([1, 1, 1])) == 0


def _twisting(t, yaw_of_t, roll0=0.1):
    """Joint signals: torso_roll sat at roll0 and stays; torso_yaw follows yaw_of_t(t)."""
    q = np.zeros((len(t), 3))
    q[:, 0] = roll0
    q[:, 1] = yaw_of_t(t)
    q[:, 2] = 0.3  # a knee, not judged
    return {
        "time_s": t,
        "joint_names": np.array(["torso_roll", "torso_yaw", "l_knee"]),
        "joint_positions_rad": q,
    }


LIMITS = {"torso_roll": (-0.5, 0.5), "torso_yaw": (-0.9, 0.6), "l_knee": (-2.0, 0.0)}


def test_the_twist_is_judged_half_way_to_each_stop():
    t = np.arange(0.0, 4.0, 0.5)
    # The yaw sat at 0: its stops are 0.6 up and 0.9 down, half-way 0.3 and 0.45.
    yaw = {0.0: 0.0, 0.5: 0.29, 1.0: 0.31, 1.5: -0.44, 2.0: -0.46, 2.5: 0.0, 3.0: 0.7, 3.5: 0.1}
    m, twisted = torso_twist(_twisting(t, lambda t: np.array([yaw[x] for x in t])), LIMITS)
    assert twisted.tolist() == [False, False, True, False, True, False, True, False]
    assert m["peak_torso_twist_rad"] == pytest.approx(0.7)
    assert m["torso_twist_at_end_rad"] == pytest.approx(0.1)
    # The roll is judged from where it sat (0.1): 0.3 is 0.2 of its 0.4 to the stop.
    sig = _twisting(t, lambda t: 0.0 * t)
    sig["joint_positions_rad"][3:, 0] = 0.3
    assert not torso_twist(sig, LIMITS)[1].any()
    sig["joint_positions_rad"][3:, 0] = 0.31
    assert torso_twist(sig, LIMITS)[1].tolist() == [False] * 3 + [True] * 5


def test_a_model_without_the_trunk_joints_is_not_judged():
    sig = _twisting(np.arange(0.0, 1.0, 0.5), lambda t: t)
    sig["joint_names"] = np.array(["a", "b", "l_knee"])
    m, twisted = torso_twist(sig, LIMITS)
    assert twisted is None and m["peak_torso_twist_rad"] is None


def test_a_twisted_trunk_is_not_standing():
    sig = _signals(t_stand=7.0, t_thighs_off=6.5)
    t = sig["time_s"]
    assert standup_metrics(sig, ENTRIES, trunk_twisted=np.zeros(len(t), bool))[
        "standup_time_s"
    ] == pytest.approx(4.0, abs=DT)
    # Twisted from 6.9 s to 8.0 s: standing begins at 8.0 s, 5.0 s after state 2.
    twisted = (t >= 6.9) & (t < 8.0)
    m = standup_metrics(sig, ENTRIES, trunk_twisted=twisted)
    assert m["standup_time_s"] == pytest.approx(5.0, abs=DT)
    assert m["standing_at_end"] is True
    m = standup_metrics(sig, ENTRIES, trunk_twisted=t >= 9.0)
    assert m["standing_at_end"] is False
