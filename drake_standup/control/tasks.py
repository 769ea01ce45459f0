"""The controller's least-squares tasks and the references they track.

Centroidal momentum (Nava et al., IROS 2016; SPEC 2), L = [L_ang about the CoM; m xdot]:

    xddot* = xd_ddot - K_D (xdot - xd_dot) - K_P (x - x_d)
    Ldot*  = [-K_D,ang L_ang - K_P,ang int L_ang;  m xddot* + f_par]

The contacts supply what gravity and the hands do not. The hands' measured wrench F_hand
acts on the robot in full (it is in the dynamics rows of the QP, and in the momentum
balance below), and the momentum target lets its helpful part f_par through, so the
contacts cancel everything else of it:

    sum_c X_Com,c F_c = Ldot* - [0; m g] - W_hand,Com

f_par is the component of the total hand force f_h along the desired CoM velocity when it
points along it (alpha > 0, SPEC 2), faded out as ||xd_dot|| -> 0 so that at the path's
end the whole pull is compensated, and as the CoM runs ahead of its reference:

    f_par = s(||xd_dot|| / v_fade) (1 - s(lead / lead_max)) max(0, f_h . u) u,
    u = xd_dot / ||xd_dot||,  lead = (x - x_d) . u,  s = smoothstep (3 r^2 - 2 r^3 on [0, 1]).
"""

import math

import numpy as np

from drake_standup.control.contacts import ContactSpec
from drake_standup.control.qp import QpLayout, Task
from drake_standup.control.spatial import cross, rotation_vector, skew


def com_acceleration_reference(
    p_WCom: np.ndarray,
    v_WCom: np.ndarray,
    com_reference: np.ndarray,
    kp_per_s2: np.ndarray,
    kd_per_s: np.ndarray,
) -> np.ndarray:
    """xddot* = xd_ddot - K_D (xdot - xd_dot) - K_P (x - x_d), m/s^2.

    com_reference = [x_d, xd_dot, xd_ddot] (9,), world frame.
    """
    x_d, xd_dot, xd_ddot = com_reference[:3], com_reference[3:6], com_reference[6:9]
    return xd_ddot - kd_per_s * (v_WCom - xd_dot) - kp_per_s2 * (p_WCom - x_d)


def _smoothstep(r: float) -> float:
    r = min(max(r, 0.0), 1.0)
    return r * r * (3.0 - 2.0 * r)


def helpful_force(
    f_hand_W: np.ndarray,
    xd_dot: np.ndarray,
    lead_m: float,
    fade_speed_mps: float,
    max_lead_m: float,
) -> np.ndarray:
    """f_par, the part of the total hand force f_hand_W (N) the controller lets act.

    lead_m = (x - x_d) . u is how far the CoM runs ahead of its reference along the path;
    the help fades out (smoothstep) between a lead of 0 and max_lead_m, so that with psi
    not advancing (or at its upper bound) a pull cannot carry the CoM past the reference.
    """
    speed = math.sqrt(float(xd_dot @ xd_dot))
    if speed == 0.0:
        return np.zeros(3)
    u = xd_dot / speed
    fade = _smoothstep(speed / fade_speed_mps) * (1.0 - _smoothstep(lead_m / max_lead_m))
    return fade * max(float(f_hand_W @ u), 0.0) * u


def momentum_task(
    layout: QpLayout,
    G_T: np.ndarray,
    p_BoCom: np.ndarray,
    Ldot_target: np.ndarray,
    W_hand_Bo: np.ndarray | None,
    W_gravity: np.ndarray,
    weight: float,
) -> Task:
    """sum_c X_Com,c F_c = Ldot_target - [0; m g] - W_hand_Com (module docstring;
    W_gravity = [0; m g]), with X_Com,c = [R, (p_C - p_Com) x R; 0, R] (R = R_WC) mapping
    [tau_C; f_C] to the wrench about the CoM in W (its force columns only for a point
    contact).

    The first six columns of G^T (control/qp.py: WholeBodyQp.contact_map) map the contact
    unknowns to their resultant wrench about the base origin Bo in W, and W_hand_Bo (the
    first six entries of J_h^T F_hand; None: no pull) is the hands' resultant there
    (control/terms.py); about the CoM, W_Com = [W_ang - p_BoCom x W_lin; W_lin].
    """
    A = G_T[:, :6].T.copy()
    A[:3] -= skew(p_BoCom) @ A[3:]
    b = Ldot_target - W_gravity
    if W_hand_Bo is not None:
        b -= W_hand_Bo
        b[:3] += cross(p_BoCom, W_hand_Bo[3:])
    return Task("momentum", weight, A, b, layout.wrenches)


def cop_centering_task(layout: QpLayout, contacts: list[ContactSpec], weight: float) -> Task:
    """Each 6-D contact's CoP at the centre c of its CoP box: [tau_x - c_y f_z;
    tau_y + c_x f_z] = 0, i.e. (CoP - c) f_z = 0. It settles how the load is shared, which
    the momentum task leaves free: away from the box edges, where a compliant pad starts
    to roll. Constant: the QP adds it once."""
    wrenches = [c for c, spec in enumerate(contacts) if not spec.point]
    A = np.zeros((2 * len(wrenches), layout.n_wrench))
    for row, c in enumerate(wrenches):
        wrench = layout.wrench(c)
        c_x, c_y = np.mean(contacts[c].cop_x_m), np.mean(contacts[c].cop_y_m)
        A[2 * row, wrench] = [1.0, 0.0, 0.0, 0.0, 0.0, -c_y]
        A[2 * row + 1, wrench] = [0.0, 1.0, 0.0, 0.0, 0.0, c_x]
    return Task("cop_centering", weight, A, np.zeros(len(A)), layout.wrenches)


def posture_task(layout: QpLayout, v_indices: np.ndarray, weights: np.ndarray) -> Task:
    """vdot[v_indices] = qddot*: joint accelerations in actuator order, row i weighted by
    weights[i]; a tracking task (b = qddot*, see posture_acceleration_reference). The task
    spans only the block of columns from the first to the last joint rate."""
    first, last = int(v_indices.min()), int(v_indices.max())
    A = np.zeros((len(v_indices), last - first + 1))
    A[np.arange(len(v_indices)), v_indices - first] = 1.0
    columns = slice(layout.vdot.start + first, layout.vdot.start + last + 1)
    return Task("posture", np.asarray(weights, dtype=float), A, None, columns)


def posture_acceleration_reference(
    q: np.ndarray, qdot: np.ndarray, q_reference: np.ndarray, kp_per_s2: float, kd_per_s: float
) -> np.ndarray:
    """qddot* = -K_P (q - q_ref) - K_D qdot, rad/s^2."""
    return -kp_per_s2 * (q - q_reference) - kd_per_s * qdot


def base_orientation_task(layout: QpLayout, weight: float) -> Task:
    """wdot_WB = wdot*: the base's angular acceleration, a tracking task (b = wdot*, see
    base_orientation_reference). The base comes first in v: vdot[:3] = wdot_WB
    (control/terms.py)."""
    base = slice(layout.vdot.start, layout.vdot.start + 3)
    return Task("base_orientation", weight, np.eye(3), None, base)


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


def joint_limit_acceleration_bounds(
    q: np.ndarray,
    qdot: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    horizon_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Joint accelerations that keep q in [q_min, q_max] over the next horizon_s at
    constant acceleration: q + T qdot + T^2/2 qddot in the limits,

    2 (q_min - q - T qdot) / T^2 <= qddot <= 2 (q_max - q - T qdot) / T^2."""
    scale = 2.0 / horizon_s**2
    q_coasting = q + horizon_s * qdot
    return scale * (q_min - q_coasting), scale * (q_max - q_coasting)
