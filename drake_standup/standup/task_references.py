"""What the tasks track: the phase table's references per state, and each tick's.

PhaseReferences is the one place for what changes with the stand-up state (the phase
table, config/phases.py, with ControllerConfig's defaults):

    state   CoM K_P            posture target               base pitch   seat
    1       com_kp_seated      the first tick's posture     0.0 rad      held
    2       com_kp_seated      posture_state2_rad           0.4 rad      hinged
    3       com_kp_standing    posture_state3_rad           0.3 rad      hinged
    4       com_kp_standing    posture_state4_rad           0.0 rad      hinged

with K_D = 2 zeta sqrt(K_P); joints a table does not name hold the first tick's posture;
targets lie posture_limit_margin_rad inside the joint limits.

TaskReferenceGenerator makes one tick's TaskReferences in the order the paper's objective
reads, each law where its task is:

    the CoM target     x_d(psi) leaned against the pull, yielded by the compliant
                       response's admittance (standup/com_path.py: CoMTarget)
    the stance         how far the legs end the rise (0-1), from the path's progress
    momentum           xddot*, Ldot*, f_par, the stance's height integral
                       (control/tasks/momentum.py: MomentumLaw)
    posture            q_ref <- q_ref + (T / tau_f) (q_target - q_ref), in
                       posture_filter_stages such stages in series
                       (control/tasks/posture.py: next_posture_reference)
    base orientation   R_WB* = R(yaw_0, pitch) (control/tasks/base.py: BaseTarget)

The robot's response to the pull (scenario response, config/responses.py) sets what of
it acts: a response that lets the help through (advancement) lets f_par through, the others
compensate the whole pull (f_par = 0); one that yields (compliant) moves the CoM target by
the admittance's offset.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drake_standup.config import RESPONSES, ComplianceConfig, ControllerConfig
from drake_standup.config.phases import PHASES, PhaseTable
from drake_standup.config.responses import SHIPPED, Response
from drake_standup.control.smooth import psi_clock_blend, smoothstep
from drake_standup.control.targets import StateReferences, TaskReferences, joint_values
from drake_standup.control.tasks import BaseTarget, MomentumLaw, next_posture_reference
from drake_standup.control.tasks.base import base_orientation_reference
from drake_standup.control.tasks.posture import posture_acceleration_reference
from drake_standup.control.terms import RobotTerms
from drake_standup.robot.spatial import skew
from drake_standup.standup.com_path import CoMTarget
from drake_standup.standup.return_path import base_pitch, next_memory, returning, with_pitch

# The response codes (the index in config.RESPONSES) the controller's systems read.
ADVANCEMENT, STIFF, COMPLIANT = (RESPONSES.index(name) for name in RESPONSES)


@dataclass(frozen=True)
class TickInputs:
    """What one tick of the references reads now (standup/whole_body.py gives them)."""

    standup_state: int
    com_reference: np.ndarray  # [x_d, xd_dot, xd_ddot] (9,), world
    # [tau_l, f_l, tau_r, f_r] (12,), world; None: no pull
    F_hand_W: np.ndarray | None = None
    path_progress: float = 1.0  # how far along its segment the CoM reference is, 0-1
    response: int = ADVANCEMENT  # ADVANCEMENT, STIFF or COMPLIANT (module docstring)
    psi_dot: float = 1.0  # the advancement's rate (the posture filter's clock)
    braced: bool = False  # the arms braced against a strong pull (PhaseReferences)
    # How far along its sit-down phase's path the CoM reference is (sit_down.py
    # descent_progress; NaN: not sitting down): the posture returns along with it.
    descent_progress: float = math.nan


@dataclass(frozen=True)
class CarriedState:
    """What the references carry from one tick to the next (the whole-body system's
    discrete state); CarriedState.after(references) is the next tick's."""

    momentum_integral: np.ndarray  # int L_ang dt (3,)
    posture: np.ndarray  # the posture filter's state (TaskReferences.next_posture)
    lean_W: np.ndarray | None = None  # the lean's filtered value (None: zero)
    height_integral: float = 0.0  # the stance's integral of the CoM height error, m s
    compliance: np.ndarray | None = None  # the admittance's [offset, rate] (None: at rest)

    @staticmethod
    def after(references: TaskReferences) -> "CarriedState":
        """What a tick's references leave to the next tick."""
        return CarriedState(
            momentum_integral=references.next_momentum_integral,
            posture=references.next_posture,
            lean_W=references.lean_W,
            height_integral=references.next_height_integral,
            compliance=references.next_compliance,
        )


class PhaseReferences:
    """StateReferences of states 1-7 from the phase table (phases.py), the arms reaching as
    the phases' postures have them or braced (arm_joints hold the first tick's posture,
    as the robot sat: standup.brace_arms)."""

    def __init__(
        self,
        table: PhaseTable,
        config: ControllerConfig,
        joint_names: list[str],
        q_min: np.ndarray,
        q_max: np.ndarray,
        arm_joints: list[str] = (),
        *,
        braced_drop_m: float = 0.0,
    ):
        """arm_joints: the joints a brace holds; braced_drop_m: how much lower the CoM
        stands with the arms braced (the CoM target's offset in the states that lean)."""
        margin = config.posture_limit_margin_rad
        self.q_target_min = q_min + margin
        self.q_target_max = q_max - margin
        arms = np.isin(joint_names, list(arm_joints))
        # The joints that lean the body forward (the torso, the hips: a sit-down phase's
        # trunk may lead its return, return_path.returning).
        self.trunk = np.array(
            [name.startswith("torso_") or name.endswith("hip_pitch") for name in joint_names]
        )
        self._by_state = {}
        for state, phase in enumerate(table.every(), start=1):
            target = joint_values(joint_names, phase.posture_rad, "posture_rad")
            returns = PHASES.index(phase.returns_to) + 1 if phase.returns_to else 0
            kp = np.array(phase.com_kp_per_s2)
            for braced in (False, True):
                held = np.where(arms, np.nan, target) if braced else target
                self._by_state[state, braced] = StateReferences(
                    kp,
                    2.0 * config.com_damping_ratio * np.sqrt(kp),
                    np.clip(held, self.q_target_min, self.q_target_max),
                    np.isnan(held),
                    phase.base_pitch_rad,
                    phase.seat_hold == "hinged",
                    phase.lean,
                    phase.stance,
                    -braced_drop_m if braced and phase.lean else 0.0,
                    returns,
                    phase.stance_throughout,
                    phase.trunk_leads_by,
                    phase.posture_leads,
                )

    def __getitem__(self, key: int | tuple[int, bool]) -> StateReferences:
        """The state's references (key: the state, or (the state, the arms braced))."""
        return self._by_state[key if isinstance(key, tuple) else (key, False)]


def _angular_rows(terms: RobotTerms, columns) -> np.ndarray:
    """A_G,ang's columns: the angular momentum about the CoM per unit of those velocities."""
    return terms.M[:3, columns] - skew(terms.p_BoCom) @ terms.M[3:6, columns]


class TaskReferenceGenerator:
    """The module docstring's references for each tick: the CoM target chain, then each
    task's law, from the phase's references and the state the tick keeps (momentum and
    height integrals, posture filter, lean, admittance)."""

    def __init__(
        self,
        config: ControllerConfig,
        phases: PhaseReferences,
        q_joints: slice | np.ndarray,
        period_s: float,
        gravity_mps2: float = 0.0,
        compliance: ComplianceConfig | None = None,
        *,
        standing_need: Callable | None = None,
        usage_limit: float = 1.0,
        v_joints: np.ndarray | None = None,
        trunk: np.ndarray | None = None,
        responses: tuple[Response, ...] = SHIPPED,
    ):
        """q_joints: the actuated joints' entries of q, in the phase references' order;
        gravity_mps2: g, the plant's. The robot's weight is that of the model the terms
        are computed with (terms.mass_kg g: the controller's estimate once it has
        weighed the robot), for the lean against the pull and the height integral's
        bound. compliance, standing_need, usage_limit: the CoM target's (com_path.py:
        CoMTarget). v_joints: the actuated joints' entries of v; trunk: the trunk's
        twist joints' places among the actuated ones (robot/limbs.py: TRUNK_TWIST_JOINTS),
        held standing by the contacts (ControllerConfig.standing_trunk_attitude; None:
        not). responses: what each response code does (config/responses.py)."""
        self._responses = responses
        self._config = config
        self.phases = phases
        self._q_joints = q_joints
        self._nu = len(phases.q_target_min)
        self._period_s = period_s
        self._latched = np.ones(1)  # the posture state's latched flag
        self.com_target = CoMTarget(
            config, period_s, gravity_mps2, compliance, standing_need, usage_limit
        )
        self.momentum = MomentumLaw(config, period_s, gravity_mps2)
        self.base_target = BaseTarget()
        self._trunk = None
        if config.standing_trunk_attitude and trunk is not None and len(trunk):
            self._trunk = (np.asarray(trunk), np.asarray(v_joints)[np.asarray(trunk)])
        self._leaning = None
        if config.lowering_attitude and v_joints is not None:
            places = np.flatnonzero(phases.trunk)
            self._leaning = (places, np.asarray(v_joints)[places])
        zeta, kp = config.base_orientation_damping_ratio, config.base_orientation_kp_per_s2
        self._base_kd = 2.0 * zeta * math.sqrt(kp)
        self._posture_kd = 2.0 * config.posture_damping_ratio * math.sqrt(config.posture_kp_per_s2)

    def _posture_Ldot(
        self, terms: RobotTerms, joints: tuple[np.ndarray, np.ndarray], q_reference: np.ndarray
    ) -> np.ndarray:
        """A_G,ang[joints] qddot*: the angular momentum rate that the joints' posture
        accelerations (posture_acceleration_reference toward q_reference) make; joints:
        (their places among the actuated joints, their entries of v)."""
        places, v = joints
        q = terms.q[self._q_joints][places]
        qddot = posture_acceleration_reference(
            q, terms.v[v], q_reference[places], self._config.posture_kp_per_s2, self._posture_kd
        )
        return _angular_rows(terms, v) @ qddot

    def _trunk_Ldot(
        self, terms: RobotTerms, q_reference: np.ndarray, stance: float
    ) -> np.ndarray | None:
        """stance A_G,ang[trunk] qddot*_trunk: the angular momentum rate that the trunk's
        posture acceleration makes, asked of the contacts in the stance (None: not in the
        stance, or no trunk)."""
        if self._trunk is None or stance <= 0.0:
            return None
        return stance * self._posture_Ldot(terms, self._trunk, q_reference)

    def _leaning_Ldot(
        self, terms: RobotTerms, q_reference: np.ndarray, R_WB_target: np.ndarray
    ) -> np.ndarray:
        """A_G,ang [wdot*_WB; qddot*]: the angular momentum rate that the pelvis, toward its
        target, and the joints that lean the body (phases.trunk: the torso's, the hips'
        pitch), toward their posture references, make."""
        config = self._config
        wdot = base_orientation_reference(
            terms.R_WB, terms.v[:3], R_WB_target, config.base_orientation_kp_per_s2, self._base_kd
        )
        base = _angular_rows(terms, slice(0, 3)) @ wdot
        return base + self._posture_Ldot(terms, self._leaning, q_reference)

    def _com_weight_scale(self, state: StateReferences, progress: float) -> float:
        """The momentum task's CoM rows' weight scale: 1, or where the posture leads the
        configured scale, reached over the first posture_led_fade_progress of the path
        (progress, 0-1) with a smoothstep in its exponent (a decade at a time)."""
        if not state.posture_leads:
            return 1.0
        config = self._config
        fade = config.posture_led_fade_progress
        share = 1.0 if fade <= 0.0 or not progress < fade else smoothstep(progress / fade)
        return config.posture_led_com_weight_scale**share

    def _stance(self, state: StateReferences, path_progress: float) -> tuple[float, float]:
        """(how far the legs have taken over the end of the rise, 0-1; the momentum
        task's vertical row weight scale): the legs' posture, not the CoM height, ends a
        phase with stance."""
        if not state.stance:
            return 0.0, 1.0
        config = self._config
        stance = smoothstep(
            (path_progress - config.stance_from_progress) / (1.0 - config.stance_from_progress)
        )
        if state.stance_throughout:
            stance = 1.0
        return stance, 1.0 - stance * (1.0 - config.stance_vertical_weight_scale)

    def _posture(
        self,
        terms: RobotTerms,
        state: StateReferences,
        posture: np.ndarray,
        psi_dot: float,
        now: TickInputs,
    ) -> tuple[np.ndarray, np.ndarray, float, float]:
        """(q_ref this tick, the posture state after it, the first tick's base yaw, the base's
        pitch target; a sit-down phase's posture and pitch return along the path,
        return_path.py): the
        first tick latches the posture it finds (and the base's yaw). The filter runs on
        psi, never slower than time: the postures advance with the CoM path, as the
        paper's trajectory does (psi = t: as on time); on time, a rise at psi_dot 2.5
        reached its height with the trunk still pitched, the knees taking the rise."""
        blend = psi_clock_blend(
            self._period_s, self._config.posture_filter_time_constant_s, psi_dot
        )
        nu = self._nu
        if posture[0] > 0.5:
            q_initial = posture[1 : 1 + nu]
            q_reference, q_stage = posture[1 + nu : 1 + 2 * nu], posture[1 + 2 * nu : 1 + 3 * nu]
            base_yaw = posture[1 + 3 * nu]
        else:
            q_initial = q_reference = q_stage = terms.q[self._q_joints]
            base_yaw = math.atan2(terms.R_WB[1, 0], terms.R_WB[0, 0])
        memory = next_memory(
            posture[2 + 3 * nu :] if posture[0] > 0.5 else None,
            now.standup_state,
            q_reference,
            terms.q[self._q_joints],
            base_pitch(terms.R_WB),
        )
        target, hold, pitch = state.posture_rad, state.posture_hold, state.base_pitch_rad
        if state.posture_returns_to:
            target, pitch = returning(
                memory,
                state.posture_returns_to,
                now.descent_progress,
                self.phases.trunk,
                state.trunk_leads_by,
            )
            hold = np.zeros_like(state.posture_hold)
        memory = with_pitch(memory, nu, pitch)
        two_stages = self._config.posture_filter_stages == 2
        # The stage that follows the state's posture: the first of two, or q_ref itself.
        q_stage_next = next_posture_reference(
            q_initial,
            q_stage if two_stages else q_reference,
            hold,
            target,
            self.phases.q_target_min,
            self.phases.q_target_max,
            blend=blend,
        )
        q_next = q_reference + blend * (q_stage - q_reference) if two_stages else q_stage_next
        next_posture = np.concatenate(
            (self._latched, q_initial, q_next, q_stage_next, (base_yaw,), memory)
        )
        return q_reference, next_posture, base_yaw, pitch

    def calc(self, terms: RobotTerms, now: TickInputs, carried: CarriedState) -> TaskReferences:
        """This tick's references from the robot's terms, what the tick reads now and what
        the last tick left."""
        standup_state, F_hand_W, response = now.standup_state, now.F_hand_W, now.response
        psi_dot, compliance = now.psi_dot, carried.compliance
        state = self.phases[standup_state, now.braced]
        tau_hand = None if F_hand_W is None else terms.J_W.reshape(len(F_hand_W), -1).T @ F_hand_W
        com_target, lean, next_compliance = self.com_target.target(
            terms,
            state,
            now.com_reference,
            tau_hand,
            F_hand_W,
            carried.lean_W,
            compliance=np.zeros(6) if compliance is None else compliance,
            compliant=self._responses[response].yields,
            psi_dot=psi_dot,
        )
        stance, vertical_weight_scale = self._stance(state, now.path_progress)
        helped = F_hand_W is not None and self._responses[response].lets_help_through
        q_reference, next_posture, base_yaw, pitch = self._posture(
            terms, state, carried.posture, psi_dot, now
        )
        R_WB_target = self.base_target(base_yaw, pitch)
        # Where the legs' posture or the whole posture leads a return (the lowering, the
        # landing, the settle), the contacts lean the body.
        leads = state.stance_throughout or state.posture_leads
        if self._leaning is not None and state.posture_returns_to and leads:
            # The lean's joints hold the standing trunk's (the torso's roll and yaw) too.
            trunk_Ldot = self._leaning_Ldot(terms, q_reference, R_WB_target)
        else:
            trunk_Ldot = self._trunk_Ldot(terms, q_reference, stance)
        momentum = self.momentum.target(
            terms,
            com_target,
            state.com_kp_per_s2,
            state.com_kd_per_s,
            carried.momentum_integral,
            stance,
            height_integral=carried.height_integral,
            pull_W=F_hand_W[3:6] + F_hand_W[9:12] if helped else None,
            heading_rad=base_yaw,
            trunk_Ldot=trunk_Ldot,
        )
        return TaskReferences(
            standup_state=standup_state,
            state=state,
            Ldot_star=momentum.Ldot_star,
            tau_hand=tau_hand,
            q_reference=q_reference,
            R_WB_target=R_WB_target,
            helpful_force_W=momentum.helpful_force_W,
            lean_W=lean,
            vertical_weight_scale=vertical_weight_scale,
            stance=stance,
            next_height_integral=momentum.next_height_integral,
            next_compliance=next_compliance,
            next_momentum_integral=momentum.next_momentum_integral,
            next_posture=next_posture,
            com_weight_scale=self._com_weight_scale(state, now.descent_progress),
        )
