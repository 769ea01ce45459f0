"""What the robot estimated of itself (robot.hardware: icub), judged against the truth:
metrics.json's "estimation", each estimate's RMS error over the run (signals.npz's
estimated_* beside the true signals), and figure_estimation.png."""

from __future__ import annotations

import numpy as np


def _rms(error: np.ndarray) -> float:
    """The RMS of the error vectors' norms (rows = samples)."""
    error = np.asarray(error, dtype=float).reshape(len(error), -1)
    return float(np.sqrt(np.mean(np.sum(error**2, axis=1)))) if len(error) else 0.0


def orientation_error_rad(q_wxyz: np.ndarray, p_wxyz: np.ndarray) -> np.ndarray:
    """The angle between two unit quaternions' rotations, row by row (q and -q alike)."""
    dot = np.abs(np.sum(q_wxyz * p_wxyz, axis=1))
    norms = np.linalg.norm(q_wxyz, axis=1) * np.linalg.norm(p_wxyz, axis=1)
    return 2.0 * np.arccos(np.clip(dot / norms, 0.0, 1.0))


def estimation_metrics(signals: dict[str, np.ndarray]) -> dict:
    """{"estimation": {...}} with the RMS errors (m, rad, m/s, N) of the base's position and
    orientation, the CoM's position and velocity, the hands' forces and the pads' forces;
    empty without estimates (robot.hardware: ideal)."""
    if "estimated_robot_state" not in signals and "estimated_com_W" not in signals:
        return {}
    s = signals
    angle = orientation_error_rad(s["base_quaternion_wxyz"], s["estimated_base_quaternion_wxyz"])
    hands = s["hand_wrenches_W"] - s["estimated_hand_wrenches_W"]
    return {
        "estimation": {
            "base_position_rms_m": _rms(s["base_position_W"] - s["estimated_base_position_W"]),
            "base_orientation_rms_rad": _rms(angle[:, None]),
            "com_position_rms_m": _rms(s["com_W"] - s["estimated_com_W"]),
            "com_velocity_rms_mps": _rms(s["com_velocity_W"] - s["estimated_com_velocity_W"]),
            "hand_force_rms_N": _rms(np.c_[hands[:, 3:6], hands[:, 9:12]]),
            "pad_force_rms_N": _rms(s["pad_forces_W"] - s["estimated_pad_forces_W"]),
        }
    }


def figure_estimation(signals: dict[str, np.ndarray], entry_times_s, path) -> None:
    """figure_estimation.png (robot.hardware: icub): each estimate against the truth
    (the base, the CoM's velocity, the hands' forces, the pads' loads), and the
    advancement's law on the estimates against the same law on the truth."""
    from drake_standup.outputs.figures import _mark_states, _plt

    plt = _plt()
    s, t = signals, signals["time_s"]
    fig, axes = plt.subplots(3, 2, figsize=(12, 10), sharex=True)
    ax = axes[0, 0]
    error = 1e3 * (s["estimated_base_position_W"] - s["base_position_W"])
    for k, color in enumerate(("tab:red", "tab:green", "tab:blue")):
        ax.plot(t, error[:, k], color=color, label=f"{'xyz'[k]}")
    ax.set_ylabel("error [mm]")
    ax.set_title("(a) base position: estimate - truth")
    ax.legend(fontsize=8, ncol=3)
    ax = axes[0, 1]
    angle = orientation_error_rad(s["base_quaternion_wxyz"], s["estimated_base_quaternion_wxyz"])
    ax.plot(t, np.degrees(angle), color="tab:purple")
    ax.set_ylabel("error [deg]")
    ax.set_title("(b) base orientation: angle between estimate and truth")
    ax = axes[1, 0]
    for k, color in ((0, "tab:red"), (2, "tab:blue")):
        ax.plot(t, s["com_velocity_W"][:, k], color=color, lw=1.0, label=f"true v_{'xyz'[k]}")
        ax.plot(t, s["estimated_com_velocity_W"][:, k], "--", color=color, lw=1.0, label="estimate")
    ax.set_ylabel("CoM velocity [m/s]")
    ax.set_title("(c) CoM velocity")
    ax.legend(fontsize=8, ncol=2)
    ax = axes[1, 1]
    for col, hand in ((3, "left"), (9, "right")):
        for k, color in ((0, "tab:red"), (2, "tab:blue")):
            ls = "-" if hand == "left" else ":"
            ax.plot(
                t,
                s["hand_wrenches_W"][:, col + k],
                ls,
                color=color,
                lw=1.0,
                label=f"{hand} f_{'xyz'[k]}",
            )
            ax.plot(t, s["estimated_hand_wrenches_W"][:, col + k], ls, color="k", lw=0.6)
    ax.set_ylabel("hand force [N]")
    ax.set_title("(d) hands: truth (colour), estimate (black)")
    ax.legend(fontsize=7, ncol=2)
    ax = axes[2, 0]
    groups = [str(g) for g in s["pad_groups"]]
    for group, color in zip(dict.fromkeys(groups), ("tab:blue", "tab:orange", "tab:green")):
        rows = [i for i, g in enumerate(groups) if g == group]
        ax.plot(t, s["pad_forces_W"][:, rows, 2].sum(axis=1), color=color, label=group)
        ax.plot(t, s["estimated_pad_forces_W"][:, rows, 2].sum(axis=1), "--", color=color)
    ax.set_ylabel("normal force [N]")
    ax.set_title("(e) pads: truth (solid), estimate (dashed)")
    ax.legend(fontsize=8)
    ax = axes[2, 1]
    ax.plot(t, s["psi_dot_law_from_truth"], color="tab:gray", lw=1.5, label="law on the truth")
    ax.plot(t, s["psi_dot_law"], color="tab:green", lw=1.0, label="law on the estimates")
    ax.plot(t, s["psi_dot"], "--", color="k", lw=0.8, label="psi_dot (filtered)")
    ax.set_ylabel("psi_dot [-]")
    ax.set_title("(f) the advancement's law")
    ax.legend(fontsize=8)
    for ax in axes.ravel():
        _mark_states(ax, entry_times_s)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle("What the robot knew of itself (robot.hardware: icub)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
