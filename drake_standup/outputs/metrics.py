"""The run's metrics (metrics.json) from its signals: seated balance, advancement, the
stand-up and how it ended."""

from __future__ import annotations

import numpy as np

from drake_standup.helper.work import HELPER_SPENT
from drake_standup.outputs.cycle import (
    first_entry_times,
    moving_average_departure,
    sit_down_metrics,
)
from drake_standup.outputs.estimation import estimation_metrics
from drake_standup.outputs.signals import group_mean_normal_forces, group_normal_forces
from drake_standup.robot.limbs import (
    JOINT_GROUPS,
    TRUNK_TWIST_JOINTS,
    joint_group,
    joint_limits_rad,
    shoulder_tendon_margin_rad,
)


def seated_metrics(signals: dict[str, np.ndarray], weight_N: float, settle_s: float = 0.5) -> dict:
    """CoM drift after settling and the contact forces at the end of the run."""
    t = signals["time_s"]
    com = signals["com_W"]
    metrics: dict = {"weight_N": weight_N}
    if len(t) == 0:
        return metrics
    after = t >= settle_s
    if after.any():
        drift = np.linalg.norm(com[after] - com[np.argmax(after)], axis=1)
        metrics["com_drift_after_settle_m"] = float(drift.max())
    metrics["com_final_m"] = com[-1]
    final = signals["pad_forces_W"][-1]  # (pads, 3)
    metrics["contact_force_N"] = {str(n): final[i] for i, n in enumerate(signals["pad_names"])}
    metrics["contact_normal_force_N"] = {
        g: float(fz[-1]) for g, fz in group_normal_forces(signals).items()
    }
    metrics["contact_force_total_N"] = final.sum(axis=0)
    return metrics


def advancement_metrics(
    psi_final: float, psi_dot: np.ndarray, entry_times_s: tuple[float, ...]
) -> dict:
    """psi at the end, the range of psi_dot, when each state was entered."""
    if len(psi_dot) == 0:
        return {"psi_final": float(psi_final)}
    return {
        "psi_final": float(psi_final),
        "psi_dot_min": float(np.min(psi_dot)),
        "psi_dot_max": float(np.max(psi_dot)),
        "state_entry_times_s": [None if np.isnan(t) else float(t) for t in entry_times_s],
    }


def standup_metrics(
    signals: dict[str, np.ndarray],
    entry_times_s,
    *,
    standing_height_m: float | None = None,
    height_tolerance_m: float = 0.01,
    unloaded_N: float = 5.0,
    hold_s: float = 0.2,
    trunk_twisted: np.ndarray | None = None,
) -> dict:
    """Stand-up time, CoM tracking and whether the robot is standing at the end.

    The stand-up is measured from its outcome, not from a guard's instant. Standing at a
    sample: the CoM within height_tolerance_m of the standing height, and every pad group
    but the soles (thighs, buttocks) carrying less than unloaded_N in all. The standing
    height is standing_height_m, the erect height (simulate.py: the CoM height of the
    state-4 posture, scene.standing); without it, the run's own: the CoM
    reference's height at the end of the run, once its last segment (state 4) has run
    through (None otherwise: the run never set it). Where the controller leans the CoM
    against a pull (signals com_lean_W, a horizontal shift d), the standing height is
    that of the posture tilted about the feet, sqrt(height^2 - |d|^2), lowered by the
    lean's z where the arms are braced against a strong pull.
    standup_time_s runs from entering state 2 to the first standing sample from which
    the robot stays standing for hold_s (None if never); standing_at_end: standing at
    the last sample. 5 N is the unloading level of issue 12's chatter count: 1.5 % of
    the robot's weight, above the 1-3 N a pad still feels while it lifts off a
    compliant seat, far below the 50-170 N the thighs carry seated. trunk_twisted (one
    bool a sample, torso_twist): a sample whose trunk is twisted is not standing either.
    """
    t = signals["time_s"]
    error = np.linalg.norm(signals["com_W"] - signals["com_reference_W"], axis=1)
    metrics: dict = {
        "com_tracking_rms_m": float(np.sqrt(np.mean(error**2))) if len(t) else None,
        "standing_at_end": False,
        "standing_com_height_m": None,
        "standup_time_s": None,
    }
    if not len(t):
        return metrics
    if standing_height_m is None:
        done = signals["psi"] - signals["segment_psi_entry"] >= signals["segment_psi_length"]
        if not (signals["state"][-1] == len(entry_times_s) and done[-1]):
            return metrics
        height = float(signals["com_reference_W"][-1, 2])
    else:
        height = float(standing_height_m)
    metrics["standing_com_height_m"] = height
    seat = [f for g, f in group_normal_forces(signals).items() if g != "soles"]
    unloaded = np.all(np.array(seat) < unloaded_N, axis=0) if seat else np.ones(len(t), bool)
    if "com_lean_W" in signals:
        # Leaning against a pull tilts the standing robot about its feet: the erect
        # height is then that of the tilted posture (the controller's own target).
        lean = signals["com_lean_W"]
        height = np.sqrt(np.maximum(height**2 - lean[:, 0] ** 2 - lean[:, 1] ** 2, 0.0))
        height = height + lean[:, 2]  # lower with the arms braced against a strong pull
    standing = (np.abs(signals["com_W"][:, 2] - height) <= height_tolerance_m) & unloaded
    if trunk_twisted is not None:
        standing &= ~trunk_twisted
    metrics["standing_at_end"] = bool(standing[-1])
    # Standing from sample i through t[i] + hold_s: no non-standing sample up to the
    # last sample within the hold, and the run lasts that long.
    not_standing = np.r_[0, np.cumsum(~standing)]
    last = np.searchsorted(t, t + hold_s - 1e-9, side="right") - 1
    held = (not_standing[last + 1] - not_standing[:-1] == 0) & (t[-1] >= t + hold_s - 1e-9)
    t2 = standup_start_s(entry_times_s)
    if t2 is not None:
        held &= t >= t2
        if held.any():
            metrics["standup_time_s"] = float(t[np.argmax(held)] - t2)
    return metrics


def _trapezoid(y: np.ndarray, t: np.ndarray) -> float:
    """int y dt by the trapezoid rule (numpy < 2 has no np.trapezoid)."""
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def helper_metrics(
    time_s: np.ndarray, hand_wrenches_W: np.ndarray, hand_velocities_W: np.ndarray
) -> dict:
    """What the helper spent, from the hands' measured forces (hand_wrenches_W: N x 12,
    [tau_l, f_l, tau_r, f_r]) and the velocities of the points they pull
    (hand_velocities_W: N x 6, [v_l, v_r]), by the trapezoid rule on the samples:
    helper_work_J = int F . v dt over both hands; helper_positive_work_J its positive
    part, int max(F . v, 0) dt; helper_peak_force_N the larger hand's peak |f|;
    helper_impulse_Ns = int (|f_l| + |f_r|) dt."""
    f = np.stack([hand_wrenches_W[:, 3:6], hand_wrenches_W[:, 9:12]], axis=1)  # N x 2 x 3
    v = hand_velocities_W.reshape(len(time_s), 2, 3)
    power_W = np.einsum("nhk,nhk->n", f, v)
    magnitude_N = np.linalg.norm(f, axis=2)  # N x 2
    return {  # the trapezoid rule gives 0 on fewer than two samples
        "helper_work_J": _trapezoid(power_W, time_s),
        "helper_positive_work_J": _trapezoid(np.maximum(power_W, 0.0), time_s),
        "helper_peak_force_N": float(magnitude_N.max()) if magnitude_N.size else 0.0,
        "helper_impulse_Ns": _trapezoid(magnitude_N.sum(axis=1), time_s),
    }


# What helping costs the person (human.mode: body), from their joint torques in
# signals.npz (own weight included): the joints each peak sums, by the name's ending.
SHOULDER = ("shoulder_flexion", "shoulder_abduction", "shoulder_rotation")
LUMBAR = ("lumbar_flexion", "lumbar_bending", "lumbar_rotation")


def _peak_norm(torques: np.ndarray, names: list[str], group: tuple[str, ...], side: str) -> float:
    """The largest over time of the group's joint torques' Euclidean norm on one side."""
    columns = [i for i, n in enumerate(names) if n.startswith(side) and n.endswith(group)]
    return float(np.linalg.norm(torques[:, columns], axis=1).max()) if columns else 0.0


def helper_body_metrics(signals: dict[str, np.ndarray]) -> dict:
    """helper_peak_shoulder_torque_Nm (the larger shoulder's, the norm of its three
    joints' torques), helper_peak_lumbar_torque_Nm (the same of the lumbar joint's three),
    helper_peak_elbow_torque_Nm, helper_effort_Nm2s (int sum_j tau_j^2 dt: the
    joint-effort integral), helper_relative_effort_s (the same of tau_j / strength_j) and
    helper_peak_strength_fraction (the largest |tau_j| / strength_j: 1 is a joint at its
    limit), over the logged samples."""
    t = signals["time_s"]
    tau = signals["helper_joint_torques_Nm"]
    names = [str(n) for n in signals["helper_joint_names"]]
    limits = np.asarray(signals["helper_effort_limits_Nm"], dtype=float)
    if len(t) == 0:
        return {}
    elbows = [i for i, n in enumerate(names) if n.endswith("elbow")]
    relative = tau / limits
    return {
        "helper_peak_shoulder_torque_Nm": max(
            _peak_norm(tau, names, SHOULDER, side) for side in ("left", "right")
        ),
        "helper_peak_lumbar_torque_Nm": _peak_norm(tau, names, LUMBAR, "lumbar"),
        "helper_peak_elbow_torque_Nm": float(np.abs(tau[:, elbows]).max()),
        "helper_effort_Nm2s": _trapezoid(np.sum(tau**2, axis=1), t),
        "helper_relative_effort_s": _trapezoid(np.sum(relative**2, axis=1), t),
        "helper_peak_strength_fraction": float(np.abs(relative).max()),
    }


def path_deviation_max_m(points_W: np.ndarray, path_W: np.ndarray) -> float | None:
    """The largest distance from a point (N x 3: the CoM) to a path given by its samples
    in order (M x 3: the CoM reference x_d(psi) as psi ran), the polyline through them:
    how far the CoM strays from the path, not from where the reference is at time t."""
    if not len(points_W) or not len(path_W):
        return None
    a = path_W[:-1]
    ab = path_W[1:] - a
    length2 = np.einsum("mk,mk->m", ab, ab)
    keep = length2 > 0.0  # repeated samples (psi held) are no segment
    a, ab, length2 = a[keep], ab[keep], length2[keep]
    if not len(a):  # the reference never moved: the distance to its one point
        return float(np.linalg.norm(points_W - path_W[0], axis=1).max())
    worst = 0.0
    for chunk in np.array_split(points_W, max(1, len(points_W) // 256)):
        ap = chunk[:, None, :] - a[None, :, :]  # n x m x 3
        u = np.clip(np.einsum("nmk,mk->nm", ap, ab) / length2, 0.0, 1.0)
        nearest = a[None] + u[..., None] * ab[None]
        d = np.linalg.norm(chunk[:, None, :] - nearest, axis=2).min(axis=1)
        worst = max(worst, float(d.max()))
    return worst


def standup_start_s(entry_times_s) -> float | None:
    """State 2's entry time, the stand-up's start (None: the run never left the seat)."""
    t2 = entry_times_s[1] if entry_times_s is not None and len(entry_times_s) > 1 else None
    return float(t2) if t2 is not None and np.isfinite(t2) else None


def seated_rest_metrics(
    signals: dict[str, np.ndarray], entry_times_s, window_s: float = 3.0
) -> dict:
    """Whether the robot sat at rest before it stood up (issue 30): over the first
    window_s, or until the stand-up's start (state 2's entry) if sooner, the base's
    largest horizontal distance from where the run started (seated_slide_m) and its
    largest drop below it (seated_drop_m); and the normal force on each pad group (soles,
    thighs, buttocks) at the window's last sample (seated_normal_force_N). Empty without
    samples."""
    t = signals["time_s"]
    if not len(t) or "base_position_W" not in signals:
        return {}
    t2 = standup_start_s(entry_times_s)
    end = window_s if t2 is None else min(window_s, t2)
    seated = t <= end + 1e-9
    base = signals["base_position_W"][seated]
    slide = np.linalg.norm(base[:, :2] - base[0, :2], axis=1)
    last = int(np.count_nonzero(seated)) - 1
    return {
        "seated_slide_m": float(slide.max()),
        "seated_drop_m": float(max(0.0, (base[0, 2] - base[:, 2]).max())),
        "seated_normal_force_N": {
            group: float(fz[last]) for group, fz in group_normal_forces(signals).items()
        },
    }


def smoothness_metrics(
    signals: dict[str, np.ndarray], entry_times_s, window_s: float = 0.1
) -> dict:
    """How smoothly the feet take the load, and whether the CoM reference jumps.

    sole_force_chatter_N: the soles' summed normal force, each sample the mean over the
    log period before it (the plant's impulse: signals.group_mean_normal_forces), its
    largest departure from its centred window_s moving average, from the stand-up's start
    (state 2's entry) to the end; a heel or toe slapping down shows as one sample far off
    the average, a load rising smoothly as none. com_reference_max_step_m: the largest
    distance between consecutive logged samples of the CoM reference (log_period_s
    apart). None where the run never left the seat or has too few samples."""
    t = signals["time_s"]
    metrics: dict = {"sole_force_chatter_N": None, "com_reference_max_step_m": None}
    if len(t) < 2:
        return metrics
    reference = signals["com_reference_W"]
    metrics["com_reference_max_step_m"] = float(
        np.linalg.norm(np.diff(reference, axis=0), axis=1).max()
    )
    t2 = standup_start_s(entry_times_s)
    if t2 is None:
        return metrics
    period = float(np.median(np.diff(t)))
    window = int(round(window_s / period)) | 1  # odd: centred
    soles = group_mean_normal_forces(signals).get("soles")
    if soles is None:
        return metrics
    departure = moving_average_departure(soles, window)
    centre = t[window // 2 : len(t) - window // 2]
    after = centre >= t2 - 1e-9
    if after.any():
        metrics["sole_force_chatter_N"] = float(departure[after].max())
    return metrics


def limb_metrics(signals: dict[str, np.ndarray]) -> dict:
    """peak_joint_speed_<limb>_rad_per_s: the fastest |qdot| of any joint of each limb
    (robot/limbs.py: JOINT_GROUPS) over the logged samples (a whip shows as a light limb
    faster than the trunk that carries it); shoulder_tendon_margin_min_rad: the shoulders'
    least distance to their tendon bound (negative: past it; None without shoulders)."""
    names = [str(name) for name in signals["joint_names"]]
    limbs = np.array([joint_group(name) for name in names])
    speeds = np.abs(signals["joint_velocities_rad_per_s"])
    metrics: dict = {}
    for limb in JOINT_GROUPS:
        columns = limbs == limb
        peak = float(speeds[:, columns].max()) if columns.any() and len(speeds) else None
        metrics[f"peak_joint_speed_{limb}_rad_per_s"] = peak
    margin = signals.get("shoulder_tendon_margin_rad")
    if margin is None:  # signals.npz before issue 46
        margin = shoulder_tendon_margin_rad(signals["joint_positions_rad"], names)
    finite = margin[np.isfinite(margin)] if len(margin) else margin
    metrics["shoulder_tendon_margin_min_rad"] = float(finite.min()) if len(finite) else None
    return metrics


def torso_twist(
    signals: dict[str, np.ndarray], limits_rad: dict[str, tuple[float, float]]
) -> tuple[dict, np.ndarray | None]:
    """(metrics, twisted): peak_torso_twist_rad and torso_twist_at_end_rad, the largest
    |q - q_0| of TRUNK_TWIST_JOINTS (q_0: the first sample, where the robot sits); twisted, one
    bool a sample: a joint more than half-way from q_0 to its stop (limits_rad: name ->
    (lower, upper)), a trunk no roboticist calls erect (issue 60: under a strong pull
    the QP drove the torso's yaw and roll onto their stops while the CoM stood tall).
    None where the model has none of the joints."""
    names = [str(name) for name in signals["joint_names"]]
    columns = [names.index(j) for j in TRUNK_TWIST_JOINTS if j in names and j in limits_rad]
    if not columns or not len(signals["time_s"]):
        return {"peak_torso_twist_rad": None, "torso_twist_at_end_rad": None}, None
    q = signals["joint_positions_rad"][:, columns]
    d = q - q[0]
    lower = np.array([limits_rad[names[c]][0] for c in columns]) - q[0]
    upper = np.array([limits_rad[names[c]][1] for c in columns]) - q[0]
    to_stop = np.where(d >= 0.0, np.maximum(upper, 1e-9), np.minimum(lower, -1e-9))
    twisted = np.any(d / to_stop > 0.5, axis=1)
    deviation = np.abs(d).max(axis=1)
    metrics = {
        "peak_torso_twist_rad": float(deviation.max()),
        "torso_twist_at_end_rad": float(deviation[-1]),
    }
    return metrics, twisted


def sit_backs(state: np.ndarray) -> int:
    """How often the stand-up went back to state 1 once it had left it (a pull against
    it sat it back), from the state's samples."""
    state = np.asarray(state)
    # From the stand-up's states only: a sit-down (5-7) ends in state 1 as asked.
    return int(np.count_nonzero((state[1:] == 1) & (state[:-1] > 1) & (state[:-1] <= 4)))


def run_metrics(
    signals: dict[str, np.ndarray],
    station,
    *,
    station_context,
    scenario,
    psi_final: float | None,
    entry_times_s: tuple[float, ...],
    standing_height_m: float | None = None,
) -> dict:
    """metrics.json's entries of a run from its signals: the seated balance and the final
    contact forces, the robot's mass (the model's, and the simulated one with
    perturbation.mass_scale), and with the stand-up controller (psi_final given) the
    advancement, the stand-up against the erect height (scene.standing of the
    rise's posture) and the controller's QP, joint-limit, mass-estimate and waiting
    figures; the peak joint torque."""
    plant, instance = station.plant, station.robot.model_instance
    mass_kg = plant.CalcTotalMass(plant.CreateDefaultContext(), [instance])
    simulated_mass_kg = plant.CalcTotalMass(station_context, [instance])
    g = -plant.gravity_field().gravity_vector()[2]
    metrics = seated_metrics(signals, weight_N=simulated_mass_kg * g)
    metrics["robot_mass_kg"] = mass_kg
    metrics["simulated_mass_kg"] = simulated_mass_kg
    samples = len(signals["time_s"])
    twist, twisted = torso_twist(signals, joint_limits_rad(plant, instance, TRUNK_TWIST_JOINTS))
    metrics.update(twist)
    cycle = sit_down_metrics(signals) if psi_final is not None and samples else {}
    if cycle:  # a cycle's stand-up is its first (the state machine's entries are its last)
        entry_times_s = first_entry_times(signals["state"], signals["time_s"])
    if psi_final is not None:
        metrics.update(advancement_metrics(psi_final, signals["psi_dot"], entry_times_s))
        metrics.update(
            standup_metrics(
                signals,
                metrics["state_entry_times_s"],
                standing_height_m=standing_height_m,
                trunk_twisted=twisted,
            )
        )
        metrics["qp_failures"] = int(signals["qp_failures"][-1]) if samples else 0
        metrics.update(smoothness_metrics(signals, metrics["state_entry_times_s"]))
        metrics.update(seated_rest_metrics(signals, metrics["state_entry_times_s"]))
    if samples and "qp_ok" in signals:
        slack = signals["joint_limit_slack"]
        metrics["joint_limit_slack_peak"] = float(slack.max())
        step = signals["time_s"][1] - signals["time_s"][0] if len(slack) > 1 else 0.0
        metrics["joint_limit_slack_integral"] = float(np.sum(slack) * step) if step else 0.0
        # Ticks the QP was solved only with its contacts relaxed (control/qp.py).
        metrics["qp_relaxed_ticks"] = int(signals["qp_relaxed"][-1])
        if "qp_fallback" in signals:  # ticks daqp failed and Clarabel solved (issue 46)
            metrics["qp_fallback_ticks"] = int(signals["qp_fallback"][-1])
        # The robot's mass as the controller estimated it (weighing itself seated).
        metrics["model_mass_kg"] = float(signals["model_mass_scale"][-1] * mass_kg)
        # How long the stand-up waited for a pull against it to stop (state machine).
        metrics["held_back_s"] = float(signals["held_back_s"][-1])
        if "held_back_beyond_feet_s" in signals:  # signals.npz before issue 21 lack it
            metrics["held_back_beyond_feet_s"] = float(signals["held_back_beyond_feet_s"][-1])
        metrics["sit_backs"] = sit_backs(signals["state"])
        if "arms_braced" in signals:  # how long the arms were braced against a pull
            metrics["arms_braced_s"] = float(np.count_nonzero(signals["arms_braced"]) * step)
    if samples and "helper_work_J" in signals:  # the plant's steps' totals (HelperWork)
        metrics.update({name: float(signals[name][-1]) for name in HELPER_SPENT})
    elif "hand_velocities_W" in signals:  # the logged samples only
        metrics.update(
            helper_metrics(
                signals["time_s"], signals["hand_wrenches_W"], signals["hand_velocities_W"]
            )
        )
    if "helper_joint_torques_Nm" in signals:  # the helper's body (human.mode: body)
        metrics.update(helper_body_metrics(signals))
    if "com_reference_W" in signals:
        metrics["path_deviation_max_m"] = path_deviation_max_m(
            signals["com_W"], signals["com_reference_W"]
        )
    metrics.update(limb_metrics(signals))
    metrics.update(cycle)
    metrics.update(estimation_metrics(signals))
    torques = signals["joint_torques_Nm"]
    metrics["max_abs_torque_Nm"] = float(np.abs(torques).max()) if torques.size else None
    return metrics
