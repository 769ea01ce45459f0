"""The base orientation task and its law: the pelvis toward a target orientation,

    wdot* = -K_P theta k - K_D w_WB,   R_WB* = R(yaw_0, pitch),

theta k the rotation from the target to R_WB; the target keeps the first tick's yaw and
takes the stand-up state's forward pitch.
"""

import math

import numpy as np

from drake_standup.control.qp_types import QpLayout, Task
from drake_standup.control.targets import TaskReferences
from drake_standup.control.terms import RobotTerms
from drake_standup.robot.spatial import rotation_vector, yaw_pitch_rotation


class BaseOrientationTask(Task):
    """wdot_WB = wdot* (base_orientation_reference) toward TaskReferences.R_WB_target. The
    base comes first in v: vdot[:3] = wdot_WB (control/terms.py)."""

    name = "base_orientation"
    constant_A = True

    def __init__(self, layout: QpLayout, weight: float, kp_per_s2: float, damping_ratio: float):
        self.weight = weight
        self.columns = slice(layout.vdot.start, layout.vdot.start + 3)
        self.A = np.eye(3)
        self.b = np.zeros(3)
        self._kp = kp_per_s2
        self._kd = 2.0 * damping_ratio * math.sqrt(kp_per_s2)

    def update(self, terms: RobotTerms, references: TaskReferences) -> None:
        self.b = base_orientation_reference(
            terms.R_WB, terms.v[:3], references.R_WB_target, self._kp, self._kd
        )


def base_orientation_reference(
    R_WB: np.ndarray,
    w_WB: np.ndarray,
    R_WB_target: np.ndarray,
    kp_per_s2: float,
    kd_per_s: float,
) -> np.ndarray:
    """wdot* = -K_P theta k - K_D w_WB, rad/s^2, with theta k the rotation from target to
    R_WB."""
    wdot = rotation_vector(R_WB @ R_WB_target.T)
    wdot *= -kp_per_s2
    wdot -= kd_per_s * w_WB
    return wdot


class BaseTarget:
    """R_WB* for a (yaw, forward pitch), remembering the last one (it changes only at a
    state's entry)."""

    def __init__(self):
        self._last = (None, None), None

    def __call__(self, yaw_rad: float, pitch_rad: float) -> np.ndarray:
        key = (yaw_rad, pitch_rad)
        if key != self._last[0]:
            # root_link's x axis points backwards: a forward pitch is about its -y.
            self._last = key, yaw_pitch_rotation(key[0], -key[1])
        return self._last[1]
