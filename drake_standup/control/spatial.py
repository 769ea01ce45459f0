"""Small SO(3) and spatial-vector helpers in numpy (cheaper than pydrake's objects, and
than np.cross, at 1 kHz in Python)."""

import math

import numpy as np


def skew(p: np.ndarray) -> np.ndarray:
    """[p]x: skew(p) @ f == np.cross(p, f)."""
    x, y, z = p
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """theta k with R = exp([theta k]x), theta in [0, pi) (log map of SO(3))."""
    vee = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    sin_theta = float(np.linalg.norm(vee))
    theta = math.atan2(sin_theta, 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0))
    # vee = sin(theta) k; theta / sin(theta) -> 1 as theta -> 0.
    return vee * (theta / sin_theta if sin_theta > 1e-9 else 1.0)


def yaw_pitch_rotation(yaw_rad: float, pitch_rad: float) -> np.ndarray:
    """R = Rz(yaw) Ry(pitch)."""
    cy, sy = math.cos(yaw_rad), math.sin(yaw_rad)
    cp, sp = math.cos(pitch_rad), math.sin(pitch_rad)
    return np.array([[cy * cp, -sy, cy * sp], [sy * cp, cy, sy * sp], [-sp, 0.0, cp]])


def block_rotation(R: np.ndarray) -> np.ndarray:
    """(6 x 6) diag(R, R): re-expresses a spatial vector [angular; linear] (a wrench or a
    spatial velocity at the same point) from frame C to W when R = R_WC."""
    X = np.zeros((6, 6))
    X[:3, :3] = R
    X[3:, 3:] = R
    return X
