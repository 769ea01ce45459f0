"""The posture tasks and their law: joint accelerations toward a filtered posture
reference,

    qddot* = -K_P (q - q_ref) - K_D qdot,
    q_ref  <- q_ref + (T / tau_f) (q_target - q_ref)      first-order filter, period T,

the target the stand-up state's posture, or, for the joints it does not name, the posture
held at the first tick (clamped inside the limits).
"""

import math

import numpy as np

from drake_standup.control.qp_types import QpLayout, Task, as_slice
from drake_standup.control.targets import TaskReferences
from drake_standup.control.terms import RobotTerms


class PostureTask(Task):
    """vdot[v_indices] = qddot* = -K_P (q - q_ref) - K_D qdot: joint accelerations in
    actuator order, row i weighted by weights[i], q_ref from TaskReferences. A spans only
    the block of columns from the first to the last joint rate."""

    name = "posture"
    constant_A = True

    def __init__(
        self,
        layout: QpLayout,
        q_indices: np.ndarray,
        v_indices: np.ndarray,
        weights: np.ndarray,
        kp_per_s2: float,
        damping_ratio: float,
        *,
        name: str = "posture",
        active_states: frozenset[int] | None = None,
    ):
        """name, active_states: a second posture task (e.g. extra weights in one state)."""
        self.name = name
        if active_states is not None:
            self.active_states = frozenset(active_states)
        first, last = int(v_indices.min()), int(v_indices.max())
        self.weight = np.asarray(weights, dtype=float)
        self.columns = slice(layout.vdot.start + first, layout.vdot.start + last + 1)
        self.A = np.zeros((len(v_indices), last - first + 1))
        self.A[np.arange(len(v_indices)), v_indices - first] = 1.0
        self.b = np.zeros(len(v_indices))
        self._q, self._v = as_slice(q_indices), as_slice(v_indices)
        self._kp = kp_per_s2
        self._kd = 2.0 * damping_ratio * math.sqrt(kp_per_s2)

    def update(self, terms: RobotTerms, references: TaskReferences) -> None:
        self.b = posture_acceleration_reference(
            terms.q[self._q], terms.v[self._v], references.q_reference, self._kp, self._kd
        )


class StancePostureTask(PostureTask):
    """A PostureTask whose weights grow with the stance factor (TaskReferences.stance,
    0 -> 1 over the end of the rise): joints held only once the legs end the rise."""

    name = "stance_posture"
    constant_A = False

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._full_weight = self.weight.copy()

    def update(self, terms: RobotTerms, references: TaskReferences) -> None:
        super().update(terms, references)
        self.weight = self._full_weight * references.stance


def posture_acceleration_reference(
    q: np.ndarray, qdot: np.ndarray, q_reference: np.ndarray, kp_per_s2: float, kd_per_s: float
) -> np.ndarray:
    """qddot* = -K_P (q - q_ref) - K_D qdot, rad/s^2."""
    return -kp_per_s2 * (q - q_reference) - kd_per_s * qdot


def next_posture_reference(
    q_initial: np.ndarray,
    q_reference: np.ndarray,
    hold: np.ndarray,
    target_rad: np.ndarray,
    q_target_min: np.ndarray,
    q_target_max: np.ndarray,
    *,
    blend: float,
) -> np.ndarray:
    """q_ref's next value: q_ref + blend (q_target - q_ref), q_target the state's posture
    where it names a joint and the first tick's (q_initial, within [q_target_min,
    q_target_max]) where hold."""
    q_next = np.where(
        hold, np.minimum(np.maximum(q_initial, q_target_min), q_target_max), target_rad
    )
    q_next -= q_reference
    q_next *= blend
    q_next += q_reference
    return q_next
