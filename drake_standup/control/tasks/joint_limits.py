"""The joint limits as soft acceleration bounds (the QP's slack keeps it feasible): each
joint's box [q_min, q_max], and linear limits a^T q + b >= 0 over several joints (the
iCub's shoulder tendons: robot/limbs.py), each a row of the QP on a^T qddot."""

import numpy as np

from drake_standup.control.qp_types import as_slice
from drake_standup.control.terms import RobotTerms


class JointLimitBounds:
    """vdot_min <= vdot[v_indices] <= vdot_max for the given joints, from their limits
    q_min, q_max and the horizon T (horizon_s): joint_limit_acceleration_bounds, tightened
    by braking_bounds where braking_rad_per_s2 is given. With linear_limits (a, b): rows
    a q_joints + b >= 0 (a: k x joints, unit-norm rows, so that a braking rate in rad/s^2
    reads the same as a joint's), bounded alike from below on a qddot, as combined_rows
    (k x num_velocities) after the joints' rows."""

    def __init__(
        self,
        q_indices: np.ndarray,
        v_indices: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        horizon_s: float,
        braking_rad_per_s2: float | None = None,
        *,
        linear_limits: tuple[np.ndarray, np.ndarray] | None = None,
        num_velocities: int | None = None,
        speed_limit_rad_per_s: np.ndarray | None = None,
        speed_time_constant_s: float | None = None,
    ):
        """speed_limit_rad_per_s: each joint's speed limit (inf: none; None: none), held
        by speed_bounds with speed_time_constant_s (required with a limit)."""
        self.v_indices = v_indices
        self._speed = None
        if speed_limit_rad_per_s is not None and np.isfinite(speed_limit_rad_per_s).any():
            if speed_time_constant_s is None:
                raise ValueError("a speed limit needs its speed_time_constant_s")
            self._speed = np.asarray(speed_limit_rad_per_s, dtype=float)
        self._speed_tau = speed_time_constant_s
        self._q, self._v = as_slice(q_indices), as_slice(v_indices)
        self._q_min, self._q_max = q_min, q_max
        self._horizon_s = horizon_s
        self._braking = braking_rad_per_s2
        self.combined_rows = None
        if linear_limits is not None and len(linear_limits[0]):
            a, b = linear_limits
            self._a, self._minus_b = np.asarray(a, dtype=float), -np.asarray(b, dtype=float)
            self.combined_rows = np.zeros((len(a), num_velocities))
            self.combined_rows[:, v_indices] = self._a

    def calc(self, terms: RobotTerms) -> tuple[np.ndarray, np.ndarray]:
        """(vdot_min, vdot_max) at terms' state."""
        q, qdot = terms.q[self._q], terms.v[self._v]
        low, high = self._bounds(q, qdot, self._q_min, self._q_max)
        if self._speed is not None:
            low, high = speed_bounds(qdot, self._speed, self._speed_tau, low, high)
        if self.combined_rows is None:
            return low, high
        s, sdot = self._a @ q, self._a @ qdot
        s_low, s_high = self._bounds(s, sdot, self._minus_b, np.full(len(s), np.inf))
        return np.concatenate((low, s_low)), np.concatenate((high, s_high))

    def _bounds(self, q, qdot, q_min, q_max) -> tuple[np.ndarray, np.ndarray]:
        low, high = joint_limit_acceleration_bounds(q, qdot, q_min, q_max, self._horizon_s)
        if self._braking is None:
            return low, high
        brake_low, brake_high = braking_bounds(
            q, qdot, q_min, q_max, self._braking, self._horizon_s
        )
        return np.maximum(low, brake_low), np.minimum(high, brake_high)


def joint_limit_acceleration_bounds(
    q: np.ndarray,
    qdot: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    horizon_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Joint accelerations that put q inside [q_min, q_max] at the end of the next
    horizon_s at constant acceleration: q + T qdot + T^2/2 qddot in the limits,

    2 (q_min - q - T qdot) / T^2 <= qddot <= 2 (q_max - q - T qdot) / T^2.

    Only the horizon's end is bounded: a joint running at its limit may pass it on the
    way; re-evaluated each tick at the bound it is a spring of damping ratio 1/sqrt(2).
    braking_bounds is what stops a fast joint before its limit."""
    scale = 2.0 / horizon_s**2
    q_coasting = q + horizon_s * qdot
    return scale * (q_min - q_coasting), scale * (q_max - q_coasting)


def speed_bounds(
    qdot: np.ndarray,
    speed_limit: np.ndarray,
    time_constant_s: float,
    low: np.ndarray,
    high: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) tightened so that each joint's speed stays within speed_limit: the
    margin m = v_max - |qdot| kept with dm/dt >= -m / T (a control barrier function of time
    constant T), i.e. (-v_max - qdot) / T <= qddot <= (v_max - qdot) / T. A joint already
    faster is brought back at that rate. The position bounds win where the two conflict (a
    joint at its limit must stop whatever its speed)."""
    speed_low = (-speed_limit - qdot) / time_constant_s
    speed_high = (speed_limit - qdot) / time_constant_s
    new_low = np.minimum(np.maximum(low, speed_low), high)
    new_high = np.maximum(np.minimum(high, speed_high), new_low)
    return new_low, new_high


def braking_bounds(
    q: np.ndarray,
    qdot: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    braking_rad_per_s2: float,
    time_constant_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Joint accelerations that keep every joint able to stop before its limit braking at
    a = braking_rad_per_s2: toward q_max, with d = q_max - q and qdot > 0, the margin
    h = d - qdot^2 / (2 a) stays >= 0 if dh/dt >= -h / T (a control barrier function of
    time constant T = time_constant_s), i.e.

        qddot <= a (h / (T qdot) - 1),

    -a where h = 0 (braking as hard as reserved), and no bound moving away from the limit
    or at rest. It never asks for more than min(a, qdot / T), the reserve or a stop within
    T: a joint already too fast (h < 0, the reserve was not delivered) is not asked for
    more than it can get, and the bound goes to 0 as qdot does, so that a joint resting
    at (or just past) its limit, its velocity jittering about 0, sees no step between a
    braking and a free bound (such a step toggled the bound's slack 0 <-> 20 rad/s^2 tick
    by tick and rang the feet; measured). The same mirrored toward q_min."""
    a, T = braking_rad_per_s2, time_constant_s
    low = np.full(q.shape, -np.inf)
    high = np.full(q.shape, np.inf)
    up, down = qdot > 0.0, qdot < 0.0
    v_up = qdot[up]
    h_up = (q_max[up] - q[up]) - v_up * v_up / (2.0 * a)
    high[up] = np.maximum(a * (h_up / (T * v_up) - 1.0), -np.minimum(a, v_up / T))
    v_down = -qdot[down]
    h_down = (q[down] - q_min[down]) - v_down * v_down / (2.0 * a)
    low[down] = np.minimum(-a * (h_down / (T * v_down) - 1.0), np.minimum(a, v_down / T))
    return low, high
