"""The sit-down's metrics (issue 62) from a run's signals: each sit-down's time, how it
landed, how the CoM tracked the descent, the soles' chatter on the way down, and whether
the robot stood again.

A sit-down runs from state 5's entry (lower) to state 1's (seated, the buttocks landed).
Forces are each sample's mean over the log period before it (the plant's impulse:
signals.group_mean_normal_forces).
- The landing (landing_peak_ratio): the seat pads' force (thighs and buttocks) from state
  6's entry (land) to landing_window_s after seated, its peak over the load the pads
  settle at (their mean over the last settle_window_s of the seated stay, before the next
  stand-up's state 2 or the run's end). The seat as a whole: how the load shares between
  thighs and buttocks is the seat's geometry's (on a 0.18 m seat the thighs slope up off
  it and settle at nearly nothing).
- The thighs' own landing (thighs_landing_peak_ratio): their peak in state 6 over their
  load at its end (the last 0.1 s).
- seat_load_rate_N_per_s, soles_unload_rate_N_per_s: the seat's fastest rise and the
  soles' fastest fall over 50 ms in the landing's window.
- sit_down_sole_chatter_N: metrics.smoothness_metrics' chatter over the sit-down (state
  5's entry to landing_window_s after seated).
"""

from __future__ import annotations

import numpy as np

from drake_standup.outputs.signals import group_mean_normal_forces


def moving_average_departure(x: np.ndarray, window: int) -> np.ndarray:
    """|x - its centred moving average over window samples (odd)| where the window is
    full (metrics.py's, here to keep the import one way)."""
    half = window // 2
    if len(x) < window:
        return np.zeros(0)
    mean = np.convolve(x, np.ones(window) / window, mode="valid")
    return np.abs(x[half : len(x) - half] - mean)


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
    back_up = _entries(state, STAND_UP_STATES, start)
    if len(back_up) and (not len(seated) or back_up[0] < seated[0]):
        # A pull against it stood the robot back up while it lowered: not a sit-down.
        record["stood_back_up_s"] = float(t[back_up[0]])
        seated = seated[:0]
    land = _entries(state, LAND, start)
    idx = np.arange(len(t))
    stop = seated[0] if len(seated) else (back_up[0] if len(back_up) else len(t))
    descent = (idx >= start) & (idx < stop) & (state > STAND_UP_STATES)
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
    stay = (idx < stay_end) & (t >= t[stay_end - 1] - settle_window_s) & (idx >= i_seated)
    i_land = land[0] if len(land) else i_seated
    window = (idx >= i_land) & (t <= t[i_seated] + landing_window_s) & (idx < stay_end)
    settled_seat = float(seat[stay].mean())
    own = (idx >= i_land) & (idx < i_seated) & (state == LAND)
    own_end = own & (t >= t[own].max() - 0.1) if own.any() else own
    landed = float(thighs[own_end].mean()) if own.any() else float("nan")
    record |= {
        "landing_peak_N": float(seat[window].max()),
        "seated_load_N": settled_seat,
        "landing_peak_ratio": float(seat[window].max() / max(settled_seat, 1e-9)),
        "thighs_landing_peak_N": float(thighs[own].max()) if own.any() else None,
        "thighs_landed_N": landed,
        "thighs_landing_peak_ratio": float(thighs[own].max() / max(landed, 1e-9))
        if own.any()
        else None,
        "seated_normal_force_N": {g: float(f[stay].mean()) for g, f in forces.items()},
        "seat_load_rate_N_per_s": _rate_N_per_s(seat[window], t[window], 0.05),
        "soles_unload_rate_N_per_s": _rate_N_per_s(
            -forces.get("soles", np.zeros(len(t)))[window], t[window], 0.05
        ),
        "stood_again": bool(len(again)) and bool(np.any(state[again[0] :] == STAND_UP_STATES)),
        "sit_down_sole_chatter_N": _chatter(forces.get("soles"), t, start, window),
    }
    return record


def _chatter(soles: np.ndarray | None, t: np.ndarray, start: int, window: np.ndarray):
    """The soles' chatter (metrics.moving_average_departure over 0.1 s) from start to the
    landing window's end."""
    if soles is None or len(t) < 2:
        return None
    n = int(round(0.1 / float(np.median(np.diff(t))))) | 1
    departure = moving_average_departure(soles, n)
    centre = np.arange(n // 2, len(t) - n // 2)
    last = int(np.flatnonzero(window)[-1]) if window.any() else len(t) - 1
    inside = (centre >= start) & (centre <= last)
    return float(departure[inside].max()) if inside.any() else None


def sit_down_metrics(
    signals: dict[str, np.ndarray], *, landing_window_s: float = 1.0, settle_window_s: float = 0.5
) -> dict:
    """{} where the run never sat down; else sit_downs (one record a sit-down begun, as
    the module docstring measures it; one a pull stood back up has stood_back_up_s and no
    seated_s) and the first completed one's figures at the top level (keys)."""
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
    done = [r for r in records if r["seated_s"] is not None]
    first = done[0] if done else records[-1]
    keys = (
        "sit_down_time_s",
        "landing_peak_N",
        "landing_peak_ratio",
        "thighs_landing_peak_ratio",
        "seat_load_rate_N_per_s",
        "descent_com_tracking_rms_m",
        "sit_down_sole_chatter_N",
    )
    return {"sit_downs": records} | {key: first.get(key) for key in keys}
