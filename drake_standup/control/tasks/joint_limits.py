"""The joint limits as soft acceleration bounds (the QP's slack keeps it feasible)."""

import numpy as np

from drake_standup.control.qp_types import as_slice
from drake_standup.control.terms import RobotTerms


class JointLimitBounds:
    """vdot_min <= vdot[v_indices] <= vdot_max (joint_limit_acceleration_bounds) for the
    given joints, from their limits q_min, q_max and the horizon T (horizon_s)."""

    def __init__(
        self,
        q_indices: np.ndarray,
        v_indices: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        horizon_s: float,
    ):
        self.v_indices = v_indices
        self._q, self._v = as_slice(q_indices), as_slice(v_indices)
        self._q_min, self._q_max = q_min, q_max
        self._horizon_s = horizon_s

    def calc(self, terms: RobotTerms) -> tuple[np.ndarray, np.ndarray]:
        """(vdot_min, vdot_max) at terms' state."""
        return joint_limit_acceleration_bounds(
            terms.q[self._q], terms.v[self._v], self._q_min, self._q_max, self._horizon_s
        )


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
    way; re-evaluated each tick at the bound it is a spring of damping ratio 1/sqrt(2)."""
    scale = 2.0 / horizon_s**2
    q_coasting = q + horizon_s * qdot
    return scale * (q_min - q_coasting), scale * (q_max - q_coasting)
