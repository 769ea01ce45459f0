"""Small SO(3) and spatial-vector helpers in numpy (cheaper than pydrake's objects, and
than np.cross, at 1 kHz in Python)."""

import math

import numpy as np


def skew(p: np.ndarray) -> np.ndarray:
    """[p]x: skew(p) @ f == np.cross(p, f)."""
    x, y, z = p.tolist()
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for 3-vectors (np.cross costs ~25 us a call)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def rotation_from_quaternion(wxyz: np.ndarray) -> np.ndarray:
    """R of the unit quaternion q / |q| (as Drake's RotationMatrix(Quaternion))."""
    w, x, y, z = wxyz.tolist()
    s = 2.0 / (w * w + x * x + y * y + z * z)
    wx, wy, wz = s * w * x, s * w * y, s * w * z
    xx, xy, xz = s * x * x, s * x * y, s * x * z
    yy, yz, zz = s * y * y, s * y * z, s * z * z
    return np.array(
        [
            [1.0 - yy - zz, xy - wz, xz + wy],
            [xy + wz, 1.0 - xx - zz, yz - wx],
            [xz - wy, yz + wx, 1.0 - xx - yy],
        ]
    )


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """theta k with R = exp([theta k]x), theta in [0, pi) (log map of SO(3))."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()
    x, y, z = 0.5 * (r21 - r12), 0.5 * (r02 - r20), 0.5 * (r10 - r01)
    sin_theta = math.sqrt(x * x + y * y + z * z)
    theta = math.atan2(sin_theta, 0.5 * (r00 + r11 + r22 - 1.0))
    # [x, y, z] = sin(theta) k; theta / sin(theta) -> 1 as theta -> 0.
    scale = theta / sin_theta if sin_theta > 1e-9 else 1.0
    return np.array([scale * x, scale * y, scale * z])


def exp_rotation(w: np.ndarray) -> np.ndarray:
    """The rotation matrix of axis-angle vector w (Rodrigues)."""
    angle = float(np.linalg.norm(w))
    if angle < 1e-12:
        return np.eye(3)
    K = skew(w / angle)
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


def yaw_pitch_rotation(yaw_rad: float, pitch_rad: float) -> np.ndarray:
    """R = Rz(yaw) Ry(pitch)."""
    cy, sy = math.cos(yaw_rad), math.sin(yaw_rad)
    cp, sp = math.cos(pitch_rad), math.sin(pitch_rad)
    return np.array([[cy * cp, -sy, cy * sp], [sy * cp, cy, sy * sp], [-sp, 0.0, cp]])
