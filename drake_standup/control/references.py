"""What the tasks track: the per-state schedule and each tick's references (SPEC 3, 7).

StandupSchedule is the one place for what changes with the standup state (defaults of
ControllerConfig):

    state   CoM K_P            posture target               base pitch   seat
    1       com_kp_seated      the first tick's posture     0.0 rad      held
    2       com_kp_seated      posture_state2_rad           0.4 rad      hinged
    3       com_kp_standing    posture_state3_rad           0.3 rad      hinged
    4       com_kp_standing    posture_state4_rad           0.0 rad      hinged

with K_D = 2 zeta sqrt(K_P); joints a table does not name hold the first tick's posture;
targets lie posture_limit_margin_rad inside the joint limits; the seat lets the pelvis
pitch about the hip axis from seat_hinge_from_state on.

ReferenceGenerator turns the schedule, the CoM reference and the measured pull into one
tick's TaskReferences. Centroidal momentum (Nava et al., IROS 2016; SPEC 2),
L = [L_ang about the CoM; m xdot]:

    xddot* = xd_ddot - K_D (xdot - xd_dot) - K_P (x - x_d)
    Ldot*  = [-K_D,ang L_ang - K_P,ang int L_ang;  m xddot* + f_par]

The hands' measured wrench acts on the robot in full (control/tasks.py: MomentumTask);
the momentum target lets its helpful part f_par through: the component of the total hand
force f_h along the desired CoM velocity when it points along it (alpha > 0, SPEC 2),
faded out as ||xd_dot|| -> 0 so that at the path's end the whole pull is compensated, and
as the CoM runs ahead of its reference:

    f_par = s(||xd_dot|| / v_fade) (1 - s(lead / lead_max)) max(0, f_h . u) u,
    u = xd_dot / ||xd_dot||,  lead = (x - x_d) . u,  s = smoothstep (3 r^2 - 2 r^3 on [0, 1]).

The robot's response to the pull (scenario response, config.RESPONSES) sets what of it
acts: advancement lets f_par through (above); stiff and compliant compensate the whole pull
(f_par = 0), and compliant moves the CoM reference by the offset x of an admittance,

    M xddot + D xdot + K x = f_h,   each axis of x within compliance.max_offset_m,

integrated each tick (semi-implicit Euler), its rate and acceleration added to the
reference's; it returns to zero when the pull, or the compliant response, stops.
Horizontally it settles only as far as the standing feet could still hold the pull, and
on the feet alone not above the path (ReferenceGenerator._offset_bounds).

The posture reference and the base's target orientation:

    q_ref  <- q_ref + (T / tau_f) (q_target - q_ref)      first-order filter, period T
    R_WB*  = R(yaw_0, pitch): the first tick's yaw, the state's forward pitch
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import Value
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from drake_standup.caching import declare_cached
from drake_standup.config import RESPONSES, ComplianceConfig, ControllerConfig
from drake_standup.control.spatial import cross, yaw_pitch_rotation
from drake_standup.control.terms import RobotTerms
from drake_standup.payloads import COM_REFERENCE, HAND_WRENCHES
from drake_standup.phases import PhaseTable
from drake_standup.reference import smoothstep

STATES = (1, 2, 3, 4)
# The response codes (the index in config.RESPONSES) the controller's systems read.
ADVANCEMENT, STIFF, COMPLIANT = (RESPONSES.index(name) for name in RESPONSES)


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


def joint_values(
    names: list[str], table: dict[str, float], key: str, default: float = math.nan
) -> np.ndarray:
    """table (joint name -> value) in the order of names, default where a joint is not
    named; an unknown name is an error that names the config field key."""
    unknown = sorted(set(table) - set(names))
    if unknown:
        raise ValueError(f"controller.{key}: unknown joint(s) {', '.join(unknown)}")
    return np.array([table.get(name, default) for name in names])


@dataclass(frozen=True)
class StateReferences:
    """What one standup state asks of the tasks and the seat."""

    com_kp_per_s2: np.ndarray  # K_P (x, y, z), 1/s^2
    com_kd_per_s: np.ndarray  # K_D = 2 zeta sqrt(K_P), 1/s
    # Posture target, actuator order, clamped inside the joint limits; NaN where hold.
    posture_rad: np.ndarray
    posture_hold: np.ndarray  # True: the joint holds the first tick's posture
    base_pitch_rad: float  # forward pitch of the base target
    seat_hinged: bool  # the seat leaves the pelvis' pitch about the hip axis free
    lean: bool  # the CoM target leans against the pull (the feet alone carry the robot)
    stance: bool  # the legs' posture, not the CoM height, ends the segment (state 4)


class StandupSchedule:
    """StateReferences of states 1-4 from the phase table (phases.py)."""

    def __init__(
        self,
        table: PhaseTable,
        config: ControllerConfig,
        joint_names: list[str],
        q_min: np.ndarray,
        q_max: np.ndarray,
    ):
        margin = config.posture_limit_margin_rad
        self.q_target_min = q_min + margin
        self.q_target_max = q_max - margin
        self._by_state = {}
        for state, phase in enumerate(table, start=1):
            target = joint_values(joint_names, phase.posture_rad, "posture_rad")
            kp = np.array(phase.com_kp_per_s2)
            self._by_state[state] = StateReferences(
                kp,
                2.0 * config.com_damping_ratio * np.sqrt(kp),
                np.clip(target, self.q_target_min, self.q_target_max),
                np.isnan(target),
                phase.base_pitch_rad,
                phase.seat_hold == "hinged",
                phase.lean,
                phase.stance,
            )

    def __getitem__(self, standup_state: int) -> StateReferences:
        return self._by_state[standup_state]


@dataclass(slots=True)
class TaskReferences:
    """One tick's references, computed upstream of the QP: what Task.update reads."""

    standup_state: int
    state: StateReferences
    Ldot_star: np.ndarray  # (6,) [Ldot_ang*; m xddot* + f_par], N m / N
    tau_hand: np.ndarray | None  # J_h^T F_hand, both hands (None: no pull)
    q_reference: np.ndarray  # (nu,) filtered posture reference, rad
    R_WB_target: np.ndarray  # (3, 3) base target orientation
    helpful_force_W: np.ndarray  # f_par, N (zero: no pull)
    lean_W: np.ndarray  # (3,) the CoM target's lean against the pull this tick, m
    # The momentum task's vertical row weight, a fraction of its weight (state 4's end).
    vertical_weight_scale: float
    # How far the legs have taken over the end of the rise, 0-1 (state 4).
    stance: float
    next_height_integral: float  # the stance's CoM height integral after this tick, m s
    # int L_ang dt after this tick (+ T L_ang of this tick's state), N m s^2.
    next_momentum_integral: np.ndarray
    # The posture state after this tick: [latched flag, first tick's posture (nu),
    # q_ref's next value (nu), first tick's base yaw].
    next_posture: np.ndarray
    # The admittance's [offset (3), rate (3)] after this tick (response compliant), m, m/s.
    next_compliance: np.ndarray = field(default_factory=lambda: np.zeros(6))


def static_lean(
    hand_wrench_Com: np.ndarray, com_height_m: float, weight_N: float, max_lean_m: float
) -> np.ndarray:
    """(3,) CoM shift (x, y; z = 0) that keeps the feet's centre of pressure where it is
    without the pull, in static balance.

    hand_wrench_Com = [tau; f], the hands' resultant about the CoM (W, N m / N). With the
    CoM at height h above the soles and the ground reaction R = -(f + m g) acting at the
    CoP p, the moments about the CoM balance when

        p_x - c_x = (tau_y + h f_x) / (m g - f_z),   p_y - c_y = -(tau_x - h f_y) / (m g - f_z):

    so the CoM moves by -(tau_y + h f_x) / (m g - f_z) in x and (tau_x - h f_y) / (m g - f_z)
    in y for the CoP to stay put. Clipped to max_lean_m (each axis); zero if the pull
    would lift the robot."""
    tau, f = hand_wrench_Com[:3], hand_wrench_Com[3:]
    support = weight_N - f[2]
    if support <= 0.0:
        return np.zeros(3)
    lean = np.array(
        [-(tau[1] + com_height_m * f[0]) / support, (tau[0] - com_height_m * f[1]) / support, 0.0]
    )
    return np.clip(lean, -max_lean_m, max_lean_m)


class ReferenceGenerator:
    """The module docstring's references for each tick, from the schedule and the
    controller's state (momentum integral, posture state)."""

    def __init__(
        self,
        config: ControllerConfig,
        schedule: StandupSchedule,
        q_joints: slice | np.ndarray,
        period_s: float,
        gravity_mps2: float = 0.0,
        compliance: ComplianceConfig | None = None,
        standing_need: Callable | None = None,
        usage_limit: float = 1.0,
    ):
        """q_joints: the actuated joints' entries of q, in the schedule's order;
        gravity_mps2: g, the plant's. The robot's weight is that of the model the terms
        are computed with (terms.mass_kg g: the controller's estimate once it has
        weighed the robot), for the lean against the pull and the height integral's
        bound. compliance: the admittance of the compliant response (default: its
        defaults); standing_need(F_hand_W, weight_N): what the pull asks of the standing
        feet, (d, reach) or None (sensing.standing_lean), and usage_limit the share of
        their reach the compliant offset may use (None: the box alone)."""
        self._standing_need = standing_need
        self._usage_limit = usage_limit
        compliance = compliance or ComplianceConfig()
        mass, stiffness = compliance.virtual_mass_kg, compliance.stiffness_N_per_m
        self._admittance = (
            mass,
            2.0 * compliance.damping_ratio * math.sqrt(stiffness * mass),
            stiffness,
            np.array(compliance.max_offset_m),
        )
        self._config = config
        self.schedule = schedule
        self._q_joints = q_joints
        self._nu = len(schedule.q_target_min)
        self._blend = min(period_s / config.posture_filter_time_constant_s, 1.0)
        self._latched = np.ones(1)  # the posture state's latched flag
        # The base's target orientation for the last (yaw, pitch), rad.
        self._base_target = (None, None), None
        self._gravity_mps2 = gravity_mps2
        self._period_s = period_s
        self._lean_blend = min(period_s / config.lean_filter_time_constant_s, 1.0)

    def _lean(
        self,
        terms: RobotTerms,
        state: StateReferences,
        tau_hand: np.ndarray | None,
        lean_W: np.ndarray | None,
    ) -> np.ndarray:
        """tau_hand: the hands' generalized force J_h^T F_hand (None: no pull), whose first
        six entries are their resultant about the base origin (control/terms.py).

        The lean's next value: static_lean of the measured pull, bounded forward and
        back by the feet (lean_max_forward_m, lean_max_back_m; lean_max_m sideways),
        first-order filtered (lean_filter_time_constant_s), in the states that stand on
        the feet alone; it decays back to zero in the others and when the pull stops."""
        lean = np.zeros(3) if lean_W is None else lean_W
        target = np.zeros(3)
        if state.lean and tau_hand is not None:
            wrench = tau_hand[:6].copy()
            wrench[:3] -= cross(terms.p_BoCom, wrench[3:])
            target = static_lean(
                wrench,
                float(terms.p_WCom[2]),
                terms.mass_kg * self._gravity_mps2,
                self._config.lean_max_m,
            )
            target[0] = min(
                max(target[0], -self._config.lean_max_back_m), self._config.lean_max_forward_m
            )
        # count_nonzero: .any() of a 3-vector costs ~5x more (NaN counts in both).
        if not (np.count_nonzero(target) or np.count_nonzero(lean)):
            return lean
        return lean + self._lean_blend * (target - lean)

    def _offset_bounds(
        self, state: StateReferences, F_hand_W: np.ndarray, weight_N: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) of where the compliant offset may settle this tick (the anchor of
        _yield): within compliance.max_offset_m; horizontally, only as far as the
        standing feet could hold the pull with the CoM moved by x: the lean the pull then
        needs, d - x (standing_need: d and the feet's reach, judged on the robot standing
        whatever its posture now, as the stand-up's wait is), within standup.
        standing_pull_usage_limit of their reach, or x settles at 0 on that side; and, on
        the feet alone (the states that lean), not above the path: the legs carry the rise
        on the path's own timing (an upward yield ran the CoM 1.2 cm past the erect height
        at the rise's end, at a 1 ms step; measured)."""
        box = self._admittance[3]
        low, high = -box.copy(), box.copy()
        need = None if self._standing_need is None else self._standing_need(F_hand_W, weight_N)
        if need is not None:
            d, (forward, back, side) = need
            limit = self._usage_limit
            high[:2] = np.minimum(high[:2], np.maximum(0.0, d[:2] + limit * np.array([back, side])))
            low[:2] = np.maximum(
                low[:2], np.minimum(0.0, d[:2] - limit * np.array([forward, side]))
            )
        if state.lean:
            high[2] = 0.0
        return low, high

    def _yield(self, anchor: np.ndarray, compliance: np.ndarray) -> np.ndarray:
        """The admittance's next [offset, rate] (6,) from this tick's [offset, rate], by
        semi-implicit Euler, pulled toward anchor (3: where the pull alone would hold the
        offset, f / K within _offset_bounds; 0 with no pull): so the offset follows a
        bound that moves as smoothly as it follows a pull, critically damped, instead of
        jumping to it. compliance.max_offset_m holds it in any case, with no rate outward
        there."""
        mass, damping, stiffness, box = self._admittance
        x, v = compliance[:3], compliance[3:]
        force = -damping * v - stiffness * (x - anchor)
        v_next = v + (self._period_s / mass) * force
        x_next = x + self._period_s * v_next
        held = np.clip(x_next, -box, box)
        outward = (held != x_next) & (v_next * x_next > 0.0)
        v_next[outward] = 0.0
        return np.concatenate((held, v_next))

    def calc(
        self,
        terms: RobotTerms,
        standup_state: int,
        com_reference: np.ndarray,
        F_hand_W: np.ndarray | None,
        momentum_integral: np.ndarray,
        posture: np.ndarray,
        lean_W: np.ndarray | None = None,
        path_progress: float = 1.0,
        height_integral: float = 0.0,
        response: int = ADVANCEMENT,
        compliance: np.ndarray | None = None,
    ) -> TaskReferences:
        """com_reference = [x_d, xd_dot, xd_ddot] (9,); F_hand_W = [tau_l, f_l, tau_r, f_r]
        (None: no pull); momentum_integral = int L_ang dt; posture: the posture state
        before this tick (TaskReferences.next_posture); lean_W: the lean's filtered value
        before this tick (None: zero); path_progress: how far along its segment the CoM
        reference is, 0-1; height_integral: the stance's integral of the CoM height
        error before this tick, m s; response: ADVANCEMENT, STIFF or COMPLIANT (which of
        the pull acts, module docstring); compliance: the admittance's [offset, rate]
        before this tick (None: at rest)."""
        config = self._config
        state = self.schedule[standup_state]
        tau_hand = None if F_hand_W is None else terms.J_W.reshape(len(F_hand_W), -1).T @ F_hand_W
        lean = self._lean(terms, state, tau_hand, lean_W)
        if np.count_nonzero(lean):
            # Leaning is tilting about the feet: the CoM target keeps its distance from
            # the floor point below the unleaned target, so it drops as it leans (2 cm at
            # a 15 cm lean); an unchanged height asked for legs longer than straight.
            com_reference = com_reference.copy()
            height = com_reference[2]
            com_reference[:2] += lean[:2]
            com_reference[2] = math.sqrt(max(height * height - lean[0] ** 2 - lean[1] ** 2, 0.0))
        compliance = np.zeros(6) if compliance is None else compliance
        pulled = F_hand_W is not None and response == COMPLIANT
        next_compliance = compliance
        if pulled or np.count_nonzero(compliance):
            anchor = np.zeros(3)
            if pulled:
                bounds = self._offset_bounds(state, F_hand_W, terms.mass_kg * self._gravity_mps2)
                anchor = np.clip((F_hand_W[3:6] + F_hand_W[9:12]) / self._admittance[2], *bounds)
            next_compliance = self._yield(anchor, compliance)
            com_reference = com_reference + np.concatenate(
                (
                    next_compliance,
                    (next_compliance[3:] - compliance[3:]) / self._period_s,
                )
            )
        xddot_star = com_acceleration_reference(
            terms.p_WCom, terms.v_WCom, com_reference, state.com_kp_per_s2, state.com_kd_per_s
        )
        Ldot_star = np.empty(6)
        Ldot_star[:3] = -config.angular_momentum_kd_per_s * terms.L_WCom[:3]
        Ldot_star[:3] -= config.angular_momentum_kp_per_s2 * momentum_integral
        Ldot_star[3:] = terms.mass_kg * xddot_star
        vertical_weight_scale = 1.0
        stance = 0.0
        if state.stance:
            stance = smoothstep(
                (path_progress - config.stance_from_progress) / (1.0 - config.stance_from_progress)
            )
            vertical_weight_scale -= stance * (1.0 - config.stance_vertical_weight_scale)
        # Integral action on the CoM height in the stance: the legs' posture, at the
        # acceleration level, sagged under an unmodelled weight (10 % heavier: knees
        # -0.73 rad, 2.2 cm low, measured); the integral asks the soles for the missing
        # force. Bounded to 20 % of the weight; zero outside the stance.
        next_height_integral = 0.0
        if stance > 0.0:
            ki = config.stance_height_ki_per_s3
            limit = 0.2 * self._gravity_mps2 / ki  # 20 % of g, the plant's
            next_height_integral = min(
                max(
                    height_integral
                    + self._period_s * stance * (com_reference[2] - terms.p_WCom[2]),
                    -limit,
                ),
                limit,
            )
            Ldot_star[5] += terms.mass_kg * ki * next_height_integral
        f_par = np.zeros(3)
        if F_hand_W is not None and response == ADVANCEMENT:
            xd_dot = com_reference[3:6]
            speed = math.sqrt(float(xd_dot @ xd_dot))
            lead_m = (terms.p_WCom - com_reference[:3]) @ xd_dot / speed if speed > 0.0 else 0.0
            f_par = helpful_force(
                F_hand_W[3:6] + F_hand_W[9:12],
                xd_dot,
                lead_m,
                config.help_fade_speed_mps,
                config.help_max_lead_m,
            )
            # The legs end the rise (stance): the whole pull is compensated there, or
            # the help carried the CoM onto straight, locked knees (measured).
            f_par *= 1.0 - stance
            Ldot_star[3:] += f_par

        nu = self._nu
        if posture[0] > 0.5:
            q_initial, q_reference = posture[1 : 1 + nu], posture[1 + nu : 1 + 2 * nu]
            base_yaw = posture[-1]
        else:
            q_initial = q_reference = terms.q[self._q_joints]
            base_yaw = math.atan2(terms.R_WB[1, 0], terms.R_WB[0, 0])
        schedule = self.schedule
        q_next = np.where(
            state.posture_hold,
            np.minimum(np.maximum(q_initial, schedule.q_target_min), schedule.q_target_max),
            state.posture_rad,
        )
        # The reference's next value: q_ref + blend (q_target - q_ref).
        q_next -= q_reference
        q_next *= self._blend
        q_next += q_reference
        # root_link's x axis points backwards: a forward pitch is about its -y.
        key = (base_yaw, state.base_pitch_rad)
        if key != self._base_target[0]:
            self._base_target = key, yaw_pitch_rotation(key[0], -key[1])
        return TaskReferences(
            standup_state=standup_state,
            state=state,
            Ldot_star=Ldot_star,
            tau_hand=tau_hand,
            q_reference=q_reference,
            R_WB_target=self._base_target[1],
            helpful_force_W=f_par,
            lean_W=lean,
            vertical_weight_scale=vertical_weight_scale,
            stance=stance,
            next_height_integral=next_height_integral,
            next_compliance=next_compliance,
            next_momentum_integral=momentum_integral + self._period_s * terms.L_WCom[:3],
            next_posture=np.concatenate((self._latched, q_initial, q_next, (base_yaw,))),
        )


class TaskReferenceGenerator(LeafSystem):
    """Each tick's TaskReferences (ReferenceGenerator.calc) as a system, every period_s.

    Inputs: terms (abstract RobotTerms, control/model.py), standup_state (1),
    com_reference (9, payloads.COM_REFERENCE), hand_wrenches_W (12), path_progress (1:
    how far along its segment the CoM reference is, 0-1), response (1: the response code,
    ADVANCEMENT, STIFF or COMPLIANT). Outputs: task_references (abstract TaskReferences),
    lean_W (3: the CoM target's lean after the last tick, m) and compliance_W (6: the
    admittance's offset and rate after the last tick, m, m/s). Discrete state: the angular
    momentum's integral (3, N m s^2), the posture state (TaskReferences.next_posture), the
    lean (3, m), the stance's height integral (1, m s), the admittance (6).
    """

    def __init__(self, generator: ReferenceGenerator, period_s: float):
        super().__init__()
        self._generator = generator
        self._period_s = period_s
        nu = len(generator.schedule.q_target_min)
        self._terms = self.DeclareAbstractInputPort("terms", Value[object](None))
        self._state_input = self.DeclareVectorInputPort("standup_state", 1)
        self._reference = self.DeclareVectorInputPort("com_reference", COM_REFERENCE.size)
        self._hands = self.DeclareVectorInputPort("hand_wrenches_W", HAND_WRENCHES.size)
        self._progress = self.DeclareVectorInputPort("path_progress", 1)
        self._response = self.DeclareVectorInputPort("response", 1)
        self._integral = self.DeclareDiscreteState(3)
        # [latched flag, state-1 posture (nu), filtered posture reference (nu), base yaw].
        self._posture = self.DeclareDiscreteState(2 + 2 * nu)
        self._lean = self.DeclareDiscreteState(3)
        self._height_integral = self.DeclareDiscreteState(1)
        self._compliance = self.DeclareDiscreteState(6)
        self._references = declare_cached(
            self, "task references", self._calc, {self.all_sources_ticket()}
        )
        self.DeclareAbstractOutputPort(
            "task_references",
            lambda: Value[object](None),
            self._CalcReferences,
            {self._references.ticket()},
        )
        self.DeclareStateOutputPort("lean_W", self._lean)
        self.DeclareStateOutputPort("compliance_W", self._compliance)
        self.DeclareInitializationDiscreteUpdateEvent(self._Update)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._Update)

    def _calc(self, context: Context) -> TaskReferences:
        state = context.get_discrete_state()
        F_hand_W = self._hands.Eval(context)
        progress = float(self._progress.Eval(context)[0])
        standup_state = min(max(int(round(self._state_input.Eval(context)[0])), 1), 4)
        return self._generator.calc(
            self._terms.Eval(context),
            standup_state,
            self._reference.Eval(context),
            F_hand_W if np.count_nonzero(F_hand_W) else None,
            state.get_value(self._integral),
            state.get_value(self._posture),
            state.get_value(self._lean),
            progress,
            float(state.get_value(self._height_integral)[0]),
            int(round(self._response.Eval(context)[0])),
            state.get_value(self._compliance),
        )

    def _CalcReferences(self, context: Context, output: Value) -> None:
        output.set_value(self._references.Eval(context))

    def _Update(self, context: Context, discrete_state: DiscreteValues) -> None:
        references = self._references.Eval(context)
        discrete_state.set_value(self._integral, references.next_momentum_integral)
        discrete_state.set_value(self._posture, references.next_posture)
        discrete_state.set_value(self._lean, references.lean_W)
        discrete_state.set_value(self._height_integral, [references.next_height_integral])
        discrete_state.set_value(self._compliance, references.next_compliance)
