"""The robot's kinematic and dynamic terms at one state, from Drake's MultibodyPlant.

Everything is in the world frame W. The floating base (root_link, body B) comes first
in v as [w_WB; v_WBo], both expressed in W (Drake's QuaternionFloatingJoint), which
gives exact shortcuts (SPEC 5, checked in tests/test_controller.py):
  - the first six rows of M v are the robot's spatial momentum about Bo,
    [h_WBo; l_W] = M[0:6] v, so the centroidal momentum needs no extra Drake call:
        L_Com = [h_WBo - p_BoCom x l_W; l_W];
  - the CoM Jacobian is J_com = M[3:6] / m and its bias Jdot_com v = C(q,v)v[3:6] / m;
  - hence the generalized gravity force is tau_g = J_com^T m g = M[3:6]^T g.
"""

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable

from drake_standup.control.spatial import block_rotation, skew
from drake_standup.robot import Robot

BASE_BODY = "root_link"


@dataclass
class FrameTerms:
    """One task frame F: pose, Jacobian and bias acceleration of its origin."""

    R_WF: np.ndarray  # (3, 3)
    p_WF: np.ndarray  # (3,) m
    J_WF: np.ndarray  # (6, nv): [w_WF; v_WFo] = J_WF v, expressed in W
    Jdotv_WF: np.ndarray | None  # (6,) bias spatial acceleration; None if not asked for
    X_WF: np.ndarray  # (6, 6) diag(R_WF, R_WF): a wrench or spatial vector at Fo, F -> W


@dataclass
class RobotTerms:
    """The equations of motion M vdot + h = B tau + sum J^T F at one state."""

    q: np.ndarray  # (nq,) [quaternion wxyz, p_WBo, joints] rad, m
    v: np.ndarray  # (nv,) [w_WB, v_WBo, joint rates] rad/s, m/s
    M: np.ndarray  # (nv, nv) mass matrix, kg m^2 / kg
    h: np.ndarray  # (nv,) C(q, v) v - tau_g(q) + D v
    mass_kg: float
    p_WCom: np.ndarray  # (3,) m
    v_WCom: np.ndarray  # (3,) m/s
    L_WCom: np.ndarray  # (6,) centroidal momentum [angular about Com, N m s; linear, kg m/s]
    R_WB: np.ndarray  # (3, 3) base orientation
    frames: dict[str, FrameTerms]


class RobotKinematics:
    """Computes RobotTerms from the robot's state with a private plant context.

    The plant may hold other models (chair, floor) as long as they are welded: the
    robot's state must be the plant's whole state. Joint damping D (the URDF's
    <dynamics damping>, 1 N m s/rad on every iCub joint) is part of the plant's dynamics
    but not of CalcBiasTerm; left out, arm accelerations were 30 rad/s^2 off the QP's
    prediction at 2.7 rad/s (measured), so h includes it.
    """

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: Robot,
        held_frames: list[str],
        other_frames: list[str],
    ):
        """held_frames get their bias acceleration Jdot v too (the QP holds them)."""
        instance = robot.model_instance
        if plant.num_velocities() != plant.num_velocities(instance):
            raise ValueError("the controller needs every non-robot model welded to the world")
        base = plant.GetBodyByName(BASE_BODY, instance)
        if not base.is_floating_base_body() or base.floating_velocities_start_in_v() != 0:
            raise ValueError(f"{BASE_BODY} must be the floating base, first in v")
        self._plant = plant
        self._instance = instance
        self._context = plant.CreateDefaultContext()
        self._base = base
        self._world = plant.world_frame()
        self._frames = {name: robot.frame(plant, name) for name in held_frames + other_frames}
        self._with_bias = set(held_frames)
        self._gravity_W = plant.gravity_field().gravity_vector()
        self.mass_kg = plant.CalcTotalMass(self._context, [instance])
        self.nq = plant.num_positions()
        self._damping = np.zeros(plant.num_velocities())
        for index in plant.GetJointIndices(instance):
            joint = plant.get_joint(index)
            start, count = joint.velocity_start(), joint.num_velocities()
            self._damping[start : start + count] = joint.default_damping_vector()

    def calc(self, x: np.ndarray, frame_names: list[str]) -> RobotTerms:
        """Terms at the robot state x = [q; v], for the named frames only (each frame's
        Jacobian costs ~20 us: the hands are left out while nobody pulls them)."""
        plant, context, world = self._plant, self._context, self._world
        plant.SetPositionsAndVelocities(context, self._instance, x)
        q, v = x[: self.nq], x[self.nq :]
        M = plant.CalcMassMatrix(context)
        h = plant.CalcBiasTerm(context) - M[3:6].T @ self._gravity_W + self._damping * v
        X_WB = plant.EvalBodyPoseInWorld(context, self._base)
        p_WCom = plant.CalcCenterOfMassPositionInWorld(context, [self._instance])
        L_WCom = M[:6] @ v  # [h_WBo; l_W], shifted to the CoM below
        L_WCom[:3] -= skew(p_WCom - X_WB.translation()) @ L_WCom[3:]
        frames = {}
        for name in frame_names:
            frame = self._frames[name]
            X_WF = frame.CalcPoseInWorld(context).GetAsMatrix34()
            J = plant.CalcJacobianSpatialVelocity(
                context, JacobianWrtVariable.kV, frame, np.zeros(3), world, world
            )
            Jdotv = None
            if name in self._with_bias:
                Jdotv = plant.CalcBiasSpatialAcceleration(
                    context, JacobianWrtVariable.kV, frame, np.zeros(3), world, world
                ).get_coeffs()
            R_WF = X_WF[:, :3]
            frames[name] = FrameTerms(R_WF, X_WF[:, 3], J, Jdotv, block_rotation(R_WF))
        return RobotTerms(
            q=q,
            v=v,
            M=M,
            h=h,
            mass_kg=self.mass_kg,
            p_WCom=p_WCom,
            v_WCom=L_WCom[3:] / self.mass_kg,
            L_WCom=L_WCom,
            R_WB=X_WB.rotation().matrix(),
            frames=frames,
        )
