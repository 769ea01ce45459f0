"""A helper that sways: a forward and upward pull on both hands whose size swings slowly,
as a person re-gripping would."""

import math

import numpy as np

from drake_standup.plugins import HandWrenchHelper

START_S, DURATION_S = 3.0, 6.0
MEAN_N, SWING_N, PERIOD_S = 15.0, 5.0, 1.5  # per hand, forward and up alike


class SwayingHelper(HandWrenchHelper):
    """From START_S for DURATION_S: MEAN_N +- SWING_N forward and up on each hand."""

    def hand_wrenches(self, time_s: float, robot_state: np.ndarray) -> np.ndarray:
        wrenches = np.zeros((2, 6))  # rows: left, right; [torque (3), force (3)]
        if START_S < time_s < START_S + DURATION_S:
            phase = 2.0 * math.pi * (time_s - START_S) / PERIOD_S
            size = MEAN_N + SWING_N * math.sin(phase)
            wrenches[:, 3] = size  # forward (world x)
            wrenches[:, 5] = size  # up (world z)
        return wrenches
