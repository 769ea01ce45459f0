"""The sit-down's metrics (issue 62) from a run's signals: each sit-down's time, how its
thighs landed, how the CoM tracked the descent, and whether the robot stood again.

A sit-down runs from state 5's entry (lower) to state 1's (seated, the buttocks landed).
Its landing is judged on the seat pads' force, each sample the mean over the log period
before it (the plant's impulse: signals.group_mean_normal_forces), from state 6's entry
(land) to landing_window_s after seated; the load the pads settle at is their mean over
the last settle_window_s of the seated stay (before the next stand-up's state 2, or the
run's end).
"""

from __future__ import annotations

import numpy as np

from drake_standup.outputs.signals import group_mean_normal_forces

# The sit-down's states (standup/sit_down.py): lower, land, settle; seated is state 1.
LOWER, LAND, SEATED = 5, 6, 1
STAND_UP_STATES = 4


def first_entry_times(state: np.ndarray, time_s: np.ndarray) -> tuple[float, ...]:
    """When each stand-up state (1-4) was first entered (NaN: never), from the state's
    samples: a cycle's first stand-up (the state machine's entry times are its last)."""
    entries = []
    for k in range(1, STAND_UP_STATES + 1):
        hits = np.flatnonzero(state == k)
        entries.append(float(time_s[hits[0]]) if len(hits) else float("nan"))
    return tuple(entries)


def _entries(state: np.ndarray, k: int, after: int = 0) -> np.ndarray:
    """The sample indices where state k begins, from sample after on."""
    begins = np.flatnonzero((state[1:] == k) & (state[:-1] != k)) + 1
    return begins[begins >= after]


def _rate_N_per_s(force: np.ndarray, t: np.ndarray, span_s: float) -> float:
    """The largest rise of force over span_s (its samples' mean over each log period)."""
    if len(t) < 2:
        return 0.0
    n = max(1, int(round(span_s / float(np.median(np.diff(t))))))
    if len(force) <= n:
        return 0.0
    return float(((force[n:] - force[:-n]) / (t[n:] - t[:-n])).max())


def _one_sit_down(signals: dict, start: int, *, landing_window_s: float, settle_window_s: float):
    t, state = signals["time_s"], signals["state"]
    forces = group_mean_normal_forces(signals)
    thighs = forces.get("thighs", np.zeros(len(t)))
    seat = thighs + forces.get("buttocks", np.zeros(len(t)))
    record: dict = {"start_s": float(t[start]), "seated_s": None, "sit_down_time_s": None}
    seated = _entries(state, SEATED, start)
    land = _entries(state, LAND, start)
    descent = (np.arange(len(t)) >= start) & (state > STAND_UP_STATES)
    if descent.any():
        error = signals["com_W"][descent] - signals["com_reference_W"][descent]
        error = np.linalg.norm(error, axis=1)
        record["descent_com_tracking_rms_m"] = float(np.sqrt(np.mean(error**2)))
    if not len(seated):
        return record
    i_seated = seated[0]
    record["seated_s"] = float(t[i_seated])
    record["sit_down_time_s"] = float(t[i_seated] - t[start])
    again = _entries(state, 2, i_seated)
    stay_end = again[0] if len(again) else len(t)
    stay = (np.arange(len(t)) < stay_end) & (t >= t[stay_end - 1] - settle_window_s)
    stay &= np.arange(len(t)) >= i_seated
    i_land = land[0] if len(land) else i_seated
    window = (np.arange(len(t)) >= i_land) & (t <= t[i_seated] + landing_window_s)
    window &= np.arange(len(t)) < stay_end
    settled_thighs, settled_seat = float(thighs[stay].mean()), float(seat[stay].mean())
    record |= {
        "thighs_landing_peak_N": float(thighs[window].max()),
        "thighs_seated_N": settled_thighs,
        "thighs_landing_peak_ratio": float(thighs[window].max() / max(settled_thighs, 1e-9)),
        "seat_landing_peak_N": float(seat[window].max()),
        "seat_seated_N": settled_seat,
        "seat_landing_peak_ratio": float(seat[window].max() / max(settled_seat, 1e-9)),
        "seat_load_rate_N_per_s": _rate_N_per_s(seat[window], t[window], 0.05),
        "soles_unload_rate_N_per_s": _rate_N_per_s(
            -forces.get("soles", np.zeros(len(t)))[window], t[window], 0.05
        ),
        "stood_again": bool(len(again)) and bool(np.any(state[again[0] :] == STAND_UP_STATES)),
    }
    return record


def sit_down_metrics(
    signals: dict[str, np.ndarray], *, landing_window_s: float = 1.0, settle_window_s: float = 0.5
) -> dict:
    """{} where the run never sat down; else sit_downs (one record a sit-down, as the
    module docstring measures it) and the first's figures at the top level:
    sit_down_time_s, thighs_landing_peak_N and _ratio, seat_load_rate_N_per_s,
    descent_com_tracking_rms_m."""
    state = np.asarray(signals["state"])
    if len(state) < 2 or not np.any(state == LOWER):
        return {}
    starts = _entries(state, LOWER)
    records = [
        _one_sit_down(
            signals, int(i), landing_window_s=landing_window_s, settle_window_s=settle_window_s
        )
        for i in starts
    ]
    first = records[0]
    keys = (
        "sit_down_time_s",
        "thighs_landing_peak_N",
        "thighs_landing_peak_ratio",
        "seat_landing_peak_ratio",
        "seat_load_rate_N_per_s",
        "descent_com_tracking_rms_m",
    )
    return {"sit_downs": records} | {key: first.get(key) for key in keys}
