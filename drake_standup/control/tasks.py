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

import numpy as np

from drake_standup.control.contacts import ContactSpec
from drake_standup.control.qp import QpLayout, Task
from drake_standup.control.spatial import rotation_vector, skew
from drake_standup.control.terms import RobotTerms


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
    speed = float(np.linalg.norm(xd_dot))
    if speed == 0.0:
        return np.zeros(3)
    u = xd_dot / speed
    fade = _smoothstep(speed / fade_speed_mps) * (1.0 - _smoothstep(lead_m / max_lead_m))
    return fade * max(float(f_hand_W @ u), 0.0) * u


def hand_wrench_about_com(
    terms: RobotTerms, hand_frames: list[str], F_hand_W: np.ndarray
) -> np.ndarray:
    """W_hand,Com (6,): the hands' wrenches [tau; f] (each at its frame's origin, in W)
    shifted to the CoM and summed."""
    total = np.zeros(6)
    for k, name in enumerate(hand_frames):
        tau_W, f_W = F_hand_W[6 * k : 6 * k + 3], F_hand_W[6 * k + 3 : 6 * k + 6]
        total[:3] += tau_W + skew(terms.frames[name].p_WF - terms.p_WCom) @ f_W
        total[3:] += f_W
    return total


def momentum_task(
    terms: RobotTerms,
    layout: QpLayout,
    contacts: list[ContactSpec],
    Ldot_target: np.ndarray,
    W_hand_Com: np.ndarray,
    gravity_W: np.ndarray,
    weight: float,
) -> Task:
    """sum_c X_Com,c F_c = Ldot_target - [0; m g] - W_hand_Com (module docstring),
    X_Com,c = [R, (p_C - p_Com) x R; 0, R] (R = R_WC) mapping [tau_C; f_C] to the wrench
    about the CoM in W (its force columns only for a point contact).
    """
    A = np.zeros((6, layout.n_wrench))
    for c, spec in enumerate(contacts):
        frame = terms.frames[spec.frame]
        force = slice(layout.wrench(c).stop - 3, layout.wrench(c).stop)
        if not spec.point:
            A[:3, force.start - 3 : force.start] = frame.R_WF
        A[:3, force] = skew(frame.p_WF - terms.p_WCom) @ frame.R_WF
        A[3:, force] = frame.R_WF
    gravity_wrench = np.concatenate([np.zeros(3), terms.mass_kg * gravity_W])
    b = Ldot_target - gravity_wrench - W_hand_Com
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


def posture_task(
    layout: QpLayout,
    v_indices: np.ndarray,
    qddot_target: np.ndarray,
    weights: np.ndarray,
) -> Task:
    """vdot[v_indices] = qddot_target: joint accelerations in actuator order, each row
    weighted by weights (a row scaled by sqrt(w_i) in a unit-weight task). The task spans
    only the block of columns from the first to the last joint rate."""
    first, last = int(v_indices.min()), int(v_indices.max())
    sqrt_w = np.sqrt(weights)
    A = np.zeros((len(v_indices), last - first + 1))
    A[np.arange(len(v_indices)), v_indices - first] = sqrt_w
    columns = slice(layout.vdot.start + first, layout.vdot.start + last + 1)
    return Task("posture", 1.0, A, sqrt_w * qddot_target, columns)


def base_orientation_task(
    terms: RobotTerms,
    layout: QpLayout,
    R_WB_target: np.ndarray,
    kp_per_s2: float,
    kd_per_s: float,
    weight: float,
) -> Task:
    """wdot_WB = -K_P theta k - K_D w_WB, with theta k the rotation from target to R_WB.

    The base comes first in v: vdot[:3] = wdot_WB, v[:3] = w_WB (control/terms.py).
    """
    error = rotation_vector(terms.R_WB @ R_WB_target.T)
    w_WB = terms.v[:3]
    base = slice(layout.vdot.start, layout.vdot.start + 3)
    return Task("base_orientation", weight, np.eye(3), -kp_per_s2 * error - kd_per_s * w_WB, base)


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
    return (
        scale * (q_min - q - horizon_s * qdot),
        scale * (q_max - q - horizon_s * qdot),
    )
