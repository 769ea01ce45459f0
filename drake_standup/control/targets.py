"""What the tasks track: one mode's settings (StateReferences) and one tick's references
(TaskReferences), made upstream of the QP (standup/task_references.py) and read by each
task's update (control/tasks/)."""

import math
from dataclasses import dataclass, field

import numpy as np


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
    # The CoM target's height offset where it leans (the arms braced stand lower), m.
    com_height_offset_m: float = 0.0
    # A sit-down phase's posture returns to the one the robot had entering this stand-up
    # state (1: as it sat), along the CoM's path (0: the posture target as it is).
    posture_returns_to: int = 0
    # The stance acts over the whole segment, not only its end.
    stance_throughout: bool = False
    # A sit-down phase's trunk returns this many times as fast along the path.
    trunk_leads_by: float = 1.0
    # The posture leads, the CoM follows it (Phase.posture_leads).
    posture_leads: bool = False


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
    # The momentum task's CoM rows' weight, a fraction of it (Phase.posture_leads).
    com_weight_scale: float = 1.0
