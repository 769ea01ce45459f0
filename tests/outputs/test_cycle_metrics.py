"""The sit-down's metrics (outputs/cycle.py) on synthetic signals whose answers are known
by construction."""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_pads import PADS

from drake_standup.outputs.cycle import first_entry_times, sit_down_metrics
from drake_standup.outputs.metrics import sit_backs

DT = 0.01
# Stand-up 2 at 3 s, 3 at 4 s, 4 at 5 s; lower at 9, land at 10, settle at 11, seated at
# 12; the next stand-up's state 2 at 15 s, 3 at 16, 4 at 17.
TIMES = [(0.0, 1), (3.0, 2), (4.0, 3), (5.0, 4), (9.0, 5), (10.0, 6), (11.0, 7), (12.0, 1)]
TIMES += [(15.0, 2), (16.0, 3), (17.0, 4)]


def _state(t, times=TIMES):
    state = np.ones(len(t), dtype=np.int8)
    for start, k in times:
        state[t >= start - 1e-9] = k
    return state


def _signals(end_s=20.0, times=TIMES, slap=False):
    """Seated: 70 N on each thigh, 60 N on the buttocks. The thighs land from 10.2 s over
    0.5 s to 50 N each (100 N) and carry 80 N each once the buttocks are down from 11.5 s
    (60 N); with slap, a 10 ms spike of 100 N more on each thigh at 10.3 s (10 N each
    then). The CoM is
    1 cm off its reference in x through the sit-down, on it elsewhere."""
    t = np.arange(0.0, end_s, DT)
    state = _state(t, times)
    normal = np.zeros((len(t), 5))
    seated = (t < 3.0) | (t >= 12.0) & (t < 15.0)
    landing = np.clip((t - 10.2) / 0.5, 0.0, 1.0) * 50.0
    thigh = np.where(seated, 70.0, np.where((t >= 10.2) & (t < 11.5), landing, 0.0))
    thigh = np.where((t >= 11.5) & (t < 12.0), 80.0, thigh)
    if slap:
        thigh = np.where(np.abs(t - 10.3) < DT / 2, thigh + 100.0, thigh)
    normal[:, 2] = normal[:, 3] = thigh
    normal[:, 4] = np.where(seated | (t >= 11.5) & (t < 12.0), 60.0, 0.0)
    normal[:, :2] = (330.0 - normal[:, 2:].sum(axis=1))[:, None] / 2
    ref = np.zeros((len(t), 3))
    com = ref.copy()
    com[(state >= 5), 0] = 0.01
    return {
        "time_s": t,
        "state": state,
        "com_W": com,
        "com_reference_W": ref,
        "pad_names": np.array(list(PADS)),
        "pad_groups": np.array(list(PADS.values())),
        "pad_normal_force_N": normal,
    }


def test_no_sit_down_no_metrics():
    t = np.arange(0.0, 8.0, DT)
    signals = _signals(end_s=8.0)
    assert sit_down_metrics(signals) == {}
    assert first_entry_times(signals["state"], t) == (0.0, 3.0, 4.0, 5.0)


def test_a_cycles_times_and_landing_by_construction():
    m = sit_down_metrics(_signals())
    assert m["sit_down_time_s"] == pytest.approx(3.0)  # lower at 9 s, seated at 12 s
    record = m["sit_downs"][0]
    assert record["stood_again"]
    assert record["seated_load_N"] == pytest.approx(200.0)  # 2 x 70 + 60, the stay's end
    assert m["landing_peak_N"] == pytest.approx(220.0)  # 2 x 80 + 60 before seated
    assert m["landing_peak_ratio"] == pytest.approx(1.1)
    assert record["thighs_landing_peak_N"] == pytest.approx(100.0)
    assert m["thighs_landing_peak_ratio"] == pytest.approx(1.0)
    assert m["descent_com_tracking_rms_m"] == pytest.approx(0.01)
    # The thighs rise 100 N over 0.5 s: 200 N/s over any 50 ms inside it.
    assert record["seat_load_rate_N_per_s"] >= 200.0 - 1e-6
    assert record["seated_normal_force_N"]["buttocks"] == pytest.approx(60.0)


def test_a_slap_shows_in_the_landing_and_the_soles():
    quiet, slap = sit_down_metrics(_signals()), sit_down_metrics(_signals(slap=True))
    assert slap["sit_downs"][0]["thighs_landing_peak_N"] == pytest.approx(220.0)
    assert slap["thighs_landing_peak_ratio"] == pytest.approx(2.2)
    assert slap["sit_down_sole_chatter_N"] > quiet["sit_down_sole_chatter_N"] + 80.0


def test_a_lowering_stood_back_up_is_no_sit_down():
    times = [(0.0, 1), (3.0, 2), (4.0, 3), (5.0, 4), (8.0, 5), (8.5, 4)] + TIMES[4:]
    m = sit_down_metrics(_signals(times=times))
    first, second = m["sit_downs"]
    assert first["stood_back_up_s"] == pytest.approx(8.5) and first["seated_s"] is None
    assert m["sit_down_time_s"] == pytest.approx(second["sit_down_time_s"]) == pytest.approx(3.0)


def test_a_cycles_stand_up_is_its_first_and_its_return_to_state_1_no_sit_back():
    signals = _signals()
    assert first_entry_times(signals["state"], signals["time_s"]) == (0.0, 3.0, 4.0, 5.0)
    assert sit_backs(signals["state"]) == 0
    assert math.isclose(sit_down_metrics(signals)["sit_downs"][0]["seated_s"], 12.0, abs_tol=1e-9)
