"""The momentum task and its law: the rate of change of the centroidal momentum the
contacts must give (Nava et al., IROS 2016: [nava2016]), L = [L_ang about the CoM; m xdot]:

    xddot* = xd_ddot - K_D (xdot - xd_dot) - K_P (x - x_d)
    Ldot*  = [-K_D,ang L_ang - K_P,ang int L_ang;  m xddot* + f_par  (+ m K_I int e_z)]

(controller.angular_momentum_integral_axes "pitch": int L_ang about the heading's pitch
axis only, the base orientation task holding the roll and yaw.)

The hands' measured wrench acts on the robot in full (the task's b, and the QP's dynamics
rows); Ldot* lets its helpful part f_par through (helpful_force), so the contacts cancel
everything else of it. In the stance (the legs end the rise) an integral of the CoM height
error asks the soles for the force an unmodelled weight needs, bounded to 20 % of it.
"""

import math
from dataclasses import dataclass

import numpy as np

from drake_standup.config import ControllerConfig
from drake_standup.control.qp_types import ContactMap, QpLayout, Task
from drake_standup.control.smooth import smoothstep
from drake_standup.control.targets import TaskReferences
from drake_standup.control.terms import RobotTerms
from drake_standup.robot.spatial import cross, skew


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
        com = self._weight * references.com_weight_scale
        self.weight[3:5] = com
        self.weight[5] = com * references.vertical_weight_scale
        A[:] = self._contact_map(terms)[:, :6].T
        A[:3] -= skew(terms.p_BoCom) @ A[3:]
        self._W_gravity[3:] = terms.mass_kg * self._gravity_W
        np.subtract(references.Ldot_star, self._W_gravity, out=b)
        if references.tau_hand is not None:
            W_hand_Bo = references.tau_hand[:6]
            b -= W_hand_Bo
            b[:3] += cross(terms.p_BoCom, W_hand_Bo[3:])


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
    fade = smoothstep(speed / fade_speed_mps) * (1.0 - smoothstep(lead_m / max_lead_m))
    return fade * max(float(f_hand_W @ u), 0.0) * u


@dataclass(frozen=True)
class MomentumTarget:
    """One tick of the momentum law."""

    Ldot_star: np.ndarray  # (6,) [Ldot_ang*; m xddot* + f_par], N m / N
    helpful_force_W: np.ndarray  # f_par, N (zero: no help let through)
    next_height_integral: float  # the stance's CoM height integral after the tick, m s
    next_momentum_integral: np.ndarray  # int L_ang dt after the tick, N m s^2


class MomentumLaw:
    """Ldot* of the module docstring, once a tick of period_s; the gains are the config's
    (angular momentum, the stance's height integral, the help's fades), the CoM's K_P and
    K_D the caller's (they change with the stand-up state)."""

    def __init__(self, config: ControllerConfig, period_s: float, gravity_mps2: float):
        self._config = config
        self._period_s = period_s
        self._gravity_mps2 = gravity_mps2

    def target(
        self,
        terms: RobotTerms,
        com_target: np.ndarray,
        kp_per_s2: np.ndarray,
        kd_per_s: np.ndarray,
        momentum_integral: np.ndarray,
        stance: float,
        *,
        height_integral: float,
        pull_W: np.ndarray | None,
        heading_rad: float = 0.0,
        trunk_Ldot: np.ndarray | None = None,
    ) -> MomentumTarget:
        """com_target = [x_d, xd_dot, xd_ddot] (9,); momentum_integral: int L_ang dt and
        height_integral: the stance's, before the tick; stance: how far the legs have taken
        over, 0-1 (0: no integral); pull_W: the hands' total force whose helpful part goes
        through (None: none does); heading_rad: the yaw the robot faces (the base target's),
        whose pitch axis keeps the integral where config.angular_momentum_integral_axes
        is "pitch"; trunk_Ldot: an angular momentum rate added to Ldot_ang* (the trunk's
        posture standing: task_references.py), N m (None: none)."""
        config = self._config
        xddot_star = com_acceleration_reference(
            terms.p_WCom, terms.v_WCom, com_target, kp_per_s2, kd_per_s
        )
        Ldot_star = np.empty(6)
        Ldot_star[:3] = -config.angular_momentum_kd_per_s * terms.L_WCom[:3]
        Ldot_star[:3] -= config.angular_momentum_kp_per_s2 * momentum_integral
        if trunk_Ldot is not None:
            Ldot_star[:3] += trunk_Ldot
        Ldot_star[3:] = terms.mass_kg * xddot_star
        next_height_integral = 0.0
        if stance > 0.0:
            ki = config.stance_height_ki_per_s3
            limit = 0.2 * self._gravity_mps2 / ki  # 20 % of g, the plant's
            next_height_integral = min(
                max(
                    height_integral + self._period_s * stance * (com_target[2] - terms.p_WCom[2]),
                    -limit,
                ),
                limit,
            )
            Ldot_star[5] += terms.mass_kg * ki * next_height_integral
        f_par = np.zeros(3)
        if pull_W is not None:
            xd_dot = com_target[3:6]
            speed = math.sqrt(float(xd_dot @ xd_dot))
            lead_m = (terms.p_WCom - com_target[:3]) @ xd_dot / speed if speed > 0.0 else 0.0
            f_par = helpful_force(
                pull_W, xd_dot, lead_m, config.help_fade_speed_mps, config.help_max_lead_m
            )
            # The legs end the rise (stance): the whole pull is compensated there, or
            # the help carried the CoM onto straight, locked knees (measured).
            f_par *= 1.0 - stance
            Ldot_star[3:] += f_par
        next_momentum_integral = momentum_integral + self._period_s * terms.L_WCom[:3]
        if config.angular_momentum_integral_axes == "pitch":
            axis = np.array([-math.sin(heading_rad), math.cos(heading_rad), 0.0])
            next_momentum_integral = (next_momentum_integral @ axis) * axis
        return MomentumTarget(Ldot_star, f_par, next_height_integral, next_momentum_integral)
