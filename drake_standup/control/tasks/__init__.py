"""The controller's least-squares tasks (control/qp_types.py: Task), each in
its module with its own law:

Each task is w ||A z[columns] - b||^2 over the QP's unknowns z = [F_1 .. F_nc, vdot],
refreshed by update(terms, references) from one tick's TaskReferences
(standup/task_references.py):

    momentum.py       sum_c X_Com,c F_c = Ldot* - [0; m g] - W_hand,Com   (MomentumLaw: Ldot*)
    posture.py        qddot = qddot* = -K_P (q - q_ref) - K_D qdot   (the q_ref filter)
    base.py           wdot_WB = wdot* = -K_P theta k - K_D w_WB      (BaseTarget: R_WB*)
    cop.py            (CoP_c - c) f_z,c = 0 for each 6-D contact (constant)
    moment_rate.py    (tau_sole - tau_sole,last) / l = 0: the soles' CoPs near the last tick's
    joint_limits.py   soft bounds on vdot that keep q in its limits

The hands' measured wrench F_hand acts on the robot in full (it is in the dynamics rows of
the QP, and in the momentum balance above); Ldot* lets its helpful part f_par through, so
the contacts cancel everything else of it.
"""

from drake_standup.control.tasks.base import BaseOrientationTask, BaseTarget
from drake_standup.control.tasks.cop import CopCenteringTask
from drake_standup.control.tasks.joint_limits import (
    JointLimitBounds,
    joint_limit_acceleration_bounds,
)
from drake_standup.control.tasks.moment_rate import SoleMomentRateTask
from drake_standup.control.tasks.momentum import (
    MomentumLaw,
    MomentumTarget,
    MomentumTask,
    com_acceleration_reference,
    helpful_force,
)
from drake_standup.control.tasks.posture import (
    PostureTask,
    StancePostureTask,
    next_posture_reference,
    posture_acceleration_reference,
)

__all__ = [
    "BaseOrientationTask",
    "BaseTarget",
    "CopCenteringTask",
    "JointLimitBounds",
    "MomentumLaw",
    "MomentumTarget",
    "MomentumTask",
    "PostureTask",
    "SoleMomentRateTask",
    "StancePostureTask",
    "com_acceleration_reference",
    "helpful_force",
    "joint_limit_acceleration_bounds",
    "next_posture_reference",
    "posture_acceleration_reference",
]
