"""Stand-up metrics on synthetic signals whose answers are known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.metrics import standup_metrics

PADS = {
    "l_sole_pad": "soles",
    "r_sole_pad": "soles",
    "l_thigh_pad": "thighs",
    "r_thigh_pad": "thighs",
    "buttocks_pad": "buttocks",
}
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
