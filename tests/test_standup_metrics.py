"""Stand-up metrics on synthetic signals whose answers are known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.outputs import standup_metrics

PADS = {
    "l_sole_pad": "soles",
    "r_sole_pad": "soles",
    "l_thigh_pad": "thighs",
    "r_thigh_pad": "thighs",
    "buttocks_pad": "buttocks",
}


def _signals(t_stand: float, t_seat_off: float, com_offset: float = 0.0):
    """State 2 at 3 s, 3 at 5 s, 4 at 6 s with the last segment (T = 1.8)
    ending at psi = 7.8 = t; CoM on the reference after t_stand (offset
    before); seat pads unloaded after t_seat_off. Laid out as signals.npz."""
    t = np.arange(0.0, 12.0, 0.01)
    state = np.select([t >= 6.0, t >= 5.0, t >= 3.0], [4, 3, 2], 1)
    ref = np.zeros((len(t), 3))
    ref[:, 2] = 0.5
    com = ref.copy()
    com[:, 0] += np.where(t < t_stand, 0.05, com_offset)
    normal = np.zeros((len(t), 5))
    normal[:, :2] = 160.0
    normal[:, 2:] = np.where(t < t_seat_off, 30.0, 0.0)[:, None]
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


def test_standup_time_is_first_standing_sample_after_state_2():
    m = standup_metrics(_signals(t_stand=9.0, t_seat_off=6.5), ENTRIES)
    assert m["standup_time_s"] == pytest.approx(9.0 - 3.0)
    assert m["standing_at_end"] is True


def test_reference_must_have_reached_its_end():
    # CoM and seat ready at 6.5 s, but the last segment ends at psi = 7.8.
    m = standup_metrics(_signals(t_stand=6.5, t_seat_off=6.5), ENTRIES)
    assert m["standup_time_s"] == pytest.approx(7.8 - 3.0, abs=0.011)


def test_seat_contact_prevents_standing():
    m = standup_metrics(_signals(t_stand=8.0, t_seat_off=99.0), ENTRIES)
    assert m["standup_time_s"] is None and m["standing_at_end"] is False


def test_com_tolerance():
    m = standup_metrics(_signals(8.0, 6.5, com_offset=0.021), ENTRIES)
    assert m["standup_time_s"] is None
    m = standup_metrics(_signals(8.0, 6.5, com_offset=0.019), ENTRIES)
    assert m["standup_time_s"] == pytest.approx(5.0)


def test_tracking_rms():
    m = standup_metrics(_signals(t_stand=6.0, t_seat_off=6.5), ENTRIES)
    # 5 cm error for 600 of the 1200 samples.
    assert m["com_tracking_rms_m"] == pytest.approx(0.05 * np.sqrt(0.5))
