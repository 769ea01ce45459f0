"""The controller's least-squares tasks (control/qp_types.py: Task) and their feedback laws.

Each task is w ||A z[columns] - b||^2 over the QP's unknowns z = [F_1 .. F_nc, vdot],
refreshed by update(terms, references) from one tick's TaskReferences
(standup/task_references.py):

    momentum          sum_c X_Com,c F_c = Ldot* - [0; m g] - W_hand,Com
    posture           qddot = qddot* = -K_P (q - q_ref) - K_D qdot
    base orientation  wdot_WB = wdot* = -K_P theta k - K_D w_WB
    CoP centering     (CoP_c - c) f_z,c = 0 for each 6-D contact (constant)

The hands' measured wrench F_hand acts on the robot in full (it is in the dynamics rows of
the QP, and in the momentum balance above); Ldot* lets its helpful part f_par through, so
the contacts cancel everything else of it.
"""

import math

import numpy as np

from drake_standup.control.contacts import ContactSpec
from drake_standup.control.qp import ContactMap, QpLayout, Task, as_slice
from drake_standup.control.spatial import cross, rotation_vector, skew
from drake_standup.control.targets import TaskReferences
from drake_standup.control.terms import RobotTerms


class MomentumTask(Task):
    """sum_c X_Com,c F_c = Ldot* - [0; m g] - W_hand_Com (module docstring), with
    X_Com,c = [R, (p_C - p_Com) x R; 0, R] (R = R_WC) mapping [tau_C; f_C] to the wrench
    about the CoM in W (its force columns only for a point contact).

    The first six columns of G^T (control/qp_types.py: ContactMap) map the contact unknowns to
    their resultant wrench about the base origin Bo in W, and the first six entries of
    J_h^T F_hand are the hands' resultant there (control/terms.py); about the CoM,
    W_Com = [W_ang - p_BoCom x W_lin; W_lin]."""

    name = "momentum"

    def __init__(
        self,
        layout: QpLayout,
        contact_map: ContactMap,
        gravity_W: np.ndarray,
        weight: float,
    ):
        """gravity_W: g (3,), m/s^2; the weight m g is the model's, terms.mass_kg."""
        self._weight = weight
        self.weight = np.full(6, weight)
        self.columns = layout.wrenches
        self.A = np.empty((6, layout.n_wrench))
        self.b = np.empty(6)
        self._contact_map = contact_map
        self._gravity_W = gravity_W
        self._W_gravity = np.zeros(6)  # [0; m g], N

    def update(self, terms: RobotTerms, references: TaskReferences) -> None:
        A, b = self.A, self.b
        self.weight[5] = self._weight * references.vertical_weight_scale
        A[:] = self._contact_map(terms)[:, :6].T
        A[:3] -= skew(terms.p_BoCom) @ A[3:]
        self._W_gravity[3:] = terms.mass_kg * self._gravity_W
        np.subtract(references.Ldot_star, self._W_gravity, out=b)
        if references.tau_hand is not None:
            W_hand_Bo = references.tau_hand[:6]
            b -= W_hand_Bo
            b[:3] += cross(terms.p_BoCom, W_hand_Bo[3:])


class CopCenteringTask(Task):
    """Each 6-D contact's CoP at the centre c of its CoP box: [tau_x - c_y f_z;
    tau_y + c_x f_z] = 0, i.e. (CoP - c) f_z = 0. It settles how the load is shared, which
    the momentum task leaves free: away from the box edges, where a compliant pad starts
    to roll. Constant: the QP adds it once."""

    name = "cop_centering"
    constant_A = constant_b = True

    def __init__(self, layout: QpLayout, contacts: list[ContactSpec], weight: float):
        wrenches = [c for c, spec in enumerate(contacts) if not spec.point]
        self.weight = weight
        self.columns = layout.wrenches
        self.A = np.zeros((2 * len(wrenches), layout.n_wrench))
        for row, c in enumerate(wrenches):
            wrench = layout.wrench(c)
            c_x, c_y = np.mean(contacts[c].cop_x_m), np.mean(contacts[c].cop_y_m)
            self.A[2 * row, wrench] = [1.0, 0.0, 0.0, 0.0, 0.0, -c_y]
            self.A[2 * row + 1, wrench] = [0.0, 1.0, 0.0, 0.0, 0.0, c_x]
        self.b = np.zeros(len(self.A))


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
