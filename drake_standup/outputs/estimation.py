"""metrics.json's "estimation" (robot.hardware: icub): each estimate's RMS error over the
run against the truth it is judged on (signals.npz's estimated_* beside the true signals)."""

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
