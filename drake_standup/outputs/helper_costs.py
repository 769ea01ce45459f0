"""What helping costs the person (human.mode: body): metrics.json's helper_* entries from
their joint torques in signals.npz (helper_joint_torques_Nm, one column per joint of
helper_joint_names; the torque their muscles applied, own weight included)."""

from __future__ import annotations

import numpy as np

# The joints each cost sums, by the name's ending (helper_body.py's joint names).
SHOULDER = ("shoulder_flexion", "shoulder_abduction", "shoulder_rotation")
LUMBAR = ("lumbar_flexion", "lumbar_bending", "lumbar_rotation")


def _trapezoid(y: np.ndarray, t: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t))) if len(t) > 1 else 0.0


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
