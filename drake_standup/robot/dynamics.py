"""The robot's dynamics by Pinocchio, one pass a state, in Drake's conventions.

The simulated plant stays Drake's; this is the same tree, built from the plant itself
(each body's spatial inertia, each joint's frames and axis, each actuator's reflected
inertia), so it is the same URDF, reduced the same way, with the same inertias; the
controller's model (control/pinocchio_terms.py) computes its terms from one pass a state
(RobotDynamics). tests/control/test_pinocchio_terms.py checks every term against
Drake's on random states of every supported icub-models robot. Why Pinocchio (an
option): docs/decisions/015-controller-model-library.md.

Conventions. Drake's floating base (QuaternionFloatingJoint) has q = [quaternion wxyz;
p_WBo] and v = [w_WB; v_WBo], both in W. Pinocchio's free-flyer has q = [p_WBo;
quaternion xyzw] and v = [v_B; w_B], the base's twist in its own frame B. With R = R_WB,
and the joints in another order (the permutation P):

    v_pin = T v,   T = [[0, R^T, 0], [R^T, 0, 0], [0, 0, P]]

so M = T^T M_pin T, and a Jacobian J = J_pin T. T depends on q, so Drake's bias terms
(those at vdot = 0) are Pinocchio's at vdot_pin = Tdot v, whose only nonzero entries
are the base's linear ones, d/dt (R^T v_WBo) at a_WBo = 0: -w_B x v_B.

Every mass scaled by s (the weighing, control/mass.py) scales M, C(q, v) v and the
gravity force by s, so the pass is of the nominal model and its results are scaled; the
reflected motor inertias (on M's diagonal) and the joints' damping are not masses.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import QuaternionFloatingJoint, RevoluteJoint, WeldJoint

from drake_standup.robot.spatial import cross

_LOCAL = pin.ReferenceFrame.LOCAL
_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_SWAP = np.array([3, 4, 5, 0, 1, 2])  # Pinocchio's [linear; angular] -> Drake's [angular; linear]


def _se3(X) -> pin.SE3:
    """A Drake RigidTransform as Pinocchio's SE3."""
    return pin.SE3(X.rotation().matrix(), X.translation())


def _inertia(body) -> pin.Inertia:
    """The body's default spatial inertia, about its CoM, in its frame (Pinocchio's)."""
    M_BBo_B = body.default_spatial_inertia()
    mass, p = M_BBo_B.get_mass(), M_BBo_B.get_com()
    I_BBo = M_BBo_B.CalcRotationalInertia().CopyToFullMatrix3()
    I_Bcm = I_BBo - mass * (p @ p * np.eye(3) - np.outer(p, p))
    return pin.Inertia(mass, p, I_Bcm)


def _revolute_model(axis: np.ndarray):
    """Pinocchio's joint model for a revolute joint about axis (in its frame)."""
    for k, model in enumerate((pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ)):
        if axis[k] == 1.0 and np.count_nonzero(axis) == 1:
            return model()
    return pin.JointModelRevoluteUnaligned(axis)


class PinocchioTree:
    """Pinocchio's model of the robot instance of plant, and the index maps between the
    two: Pinocchio's q is Drake's q.take(q_take) (the quaternion's parts reordered), its
    v is (T v) with T v's entries v.take(v_drake) once rotated; armature holds the
    reflected inertias in Drake's v order. Frames are added by name (add_frame) before
    the first pass."""

    def __init__(self, plant: MultibodyPlant, instance, base_body):
        model = pin.Model()
        model.name = plant.GetModelInstanceName(instance)
        # Drake body index -> (Pinocchio joint id, X_JB: the body's pose in the joint frame)
        on_joint: dict = {}
        inboard = {}
        for index in plant.GetJointIndices(instance):
            joint = plant.get_joint(index)
            inboard[joint.child_body().index()] = joint
        if not isinstance(inboard.get(base_body.index()), QuaternionFloatingJoint):
            raise ValueError(f"{base_body.name()} must hang on a quaternion floating joint")
        joint_id = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
        on_joint[base_body.index()] = (joint_id, pin.SE3.Identity())
        model.appendBodyToJoint(joint_id, _inertia(base_body), pin.SE3.Identity())
        drake_index: dict[int, tuple[int, int]] = {}  # joint id -> Drake's q, v index
        children: dict = {}
        for joint in inboard.values():
            children.setdefault(joint.parent_body().index(), []).append(joint)
        added = [base_body]

        # Depth first: Pinocchio's algorithms take each subtree's velocities as contiguous.
        def add_subtree(body) -> None:
            for joint in sorted(children.get(body.index(), []), key=lambda j: j.index()):
                child = joint.child_body()
                parent_id, X_JP = on_joint[body.index()]
                X_PF = _se3(joint.frame_on_parent().GetFixedPoseInBodyFrame())
                X_CM = _se3(joint.frame_on_child().GetFixedPoseInBodyFrame())
                if isinstance(joint, RevoluteJoint):
                    axis = np.asarray(joint.revolute_axis(), dtype=float)
                    child_id = model.addJoint(
                        parent_id, _revolute_model(axis), X_JP * X_PF, joint.name()
                    )
                    drake_index[child_id] = (joint.position_start(), joint.velocity_start())
                    X_JC = X_CM.inverse()
                elif isinstance(joint, WeldJoint):
                    child_id = parent_id
                    X_JC = X_JP * X_PF * _se3(joint.X_FM()) * X_CM.inverse()
                else:
                    raise ValueError(f"unsupported joint type for {joint.name()}")
                model.appendBodyToJoint(child_id, _inertia(child), X_JC)
                on_joint[child.index()] = (child_id, X_JC)
                added.append(child)
                add_subtree(child)

        add_subtree(base_body)
        if len(added) != len(plant.GetBodyIndices(instance)):
            raise ValueError("the robot's bodies must form one tree under its floating base")
        model.gravity = pin.Motion.Zero()  # the pass adds Drake's gravity (PinocchioPass)
        self.model = model
        self._on_joint = on_joint
        self.frame_ids: dict[str, int] = {}
        nq, nv = model.nq, model.nv
        self.q_take = np.empty(nq, dtype=int)
        self.q_take[:7] = [4, 5, 6, 1, 2, 3, 0]
        self.v_drake = np.empty(nv, dtype=int)
        self.v_drake[:6] = [3, 4, 5, 0, 1, 2]
        for joint_id, (q_start, v_start) in drake_index.items():
            self.q_take[model.joints[joint_id].idx_q] = q_start
            self.v_drake[model.joints[joint_id].idx_v] = v_start
        # Drake's v order from Pinocchio's: v_pin_in_drake_order = v_pin.take(v_pin_of_drake).
        self.v_pin_of_drake = np.argsort(self.v_drake)
        self.armature = np.zeros(nv)  # in Drake's order
        for index in plant.GetJointActuatorIndices(instance):
            actuator = plant.get_joint_actuator(index)
            self.armature[actuator.joint().velocity_start()] = actuator.default_reflected_inertia()
        self.mass_kg = sum(inertia.mass for inertia in model.inertias)

    def add_frame(self, name: str, frame, p_FP=None) -> None:
        """An operational frame name at the point p_FP (default: the origin) of the Drake
        frame, with its orientation; a name added twice must be the same frame."""
        joint_id, X_JB = self._on_joint[frame.body().index()]
        X_BF = _se3(frame.GetFixedPoseInBodyFrame())
        X_FP = pin.SE3(np.eye(3), np.zeros(3) if p_FP is None else np.asarray(p_FP, float))
        placement = X_JB * X_BF * X_FP
        if name in self.frame_ids:
            if not self.model.frames[self.frame_ids[name]].placement.isApprox(placement):
                raise ValueError(f"frame {name} added twice at two places")
            return
        self.frame_ids[name] = self.model.addFrame(
            pin.Frame(name, joint_id, placement, pin.FrameType.OP_FRAME)
        )


class RobotDynamics:
    """One pass of Pinocchio at a Drake state x = [q; v], its results in Drake's
    conventions (the module docstring): nominal masses, no damping."""

    def __init__(self, tree: PinocchioTree, nq: int, gravity_W: np.ndarray):
        self.tree, self.nq = tree, nq
        perm = tree.v_pin_of_drake
        nv = len(perm)
        self._perm = perm
        # M in Drake's order from the upper triangle Pinocchio fills, in one take.
        i, j = perm[:, None], perm[None, :]
        self._M_take = np.where(i <= j, i * nv + j, j * nv + i)
        # A Jacobian's rows swapped and its columns in Drake's order, in one take.
        self._J_take = (_SWAP[:, None] * nv + perm[None, :]).ravel()
        self._v_take = tree.v_drake + nq  # Pinocchio's v from Drake's x = [q; v]
        self._R2 = np.zeros((6, 6))  # diag(R_WB, R_WB)
        self._a_pin = np.zeros(nv)
        self._gravity_W = np.asarray(gravity_W, dtype=float)
        self._frames_count = -1  # the data are made anew once frames were added
        self.data = self._pose_data = None

    @classmethod
    def of(cls, plant: MultibodyPlant, instance, base_body) -> RobotDynamics:
        """The robot instance of plant, its floating base base_body."""
        return cls(
            PinocchioTree(plant, instance, base_body),
            plant.num_positions(instance),
            plant.gravity_field().gravity_vector(),
        )

    def _data(self):
        if self._frames_count != len(self.tree.frame_ids):
            self.data = self.tree.model.createData()
            self._pose_data = self.tree.model.createData()
            self._frames_count = len(self.tree.frame_ids)
        return self.data

    def positions(self, q: np.ndarray) -> np.ndarray:
        """Pinocchio's q of Drake's q (or x = [q; v]), its quaternion made unit."""
        q_pin = q.take(self.tree.q_take)
        q_pin[3:7] *= 1.0 / math.sqrt(q_pin[3:7] @ q_pin[3:7])
        return q_pin

    def run(self, x: np.ndarray) -> tuple:
        """(diag(R_WB, R_WB), M, C v - tau_g, q_pin) at x; the data then hold x's
        placements, velocities, bias accelerations and joint Jacobians."""
        tree = self.tree
        data, model = self._data(), tree.model
        q_pin = self.positions(x)
        pin.crba(model, data, q_pin, pin.Convention.WORLD)  # M, and every joint's Jacobian
        R = data.oMi[1].rotation  # R_WB
        v_pin = x.take(self._v_take)
        v_pin[:6] = (v_pin[:6].reshape(2, 3) @ R).ravel()  # [R^T v_WBo; R^T w_WB]
        M = data.M.take(self._M_take)
        # Drake's bias is Pinocchio's at vdot_pin = Tdot v = [-w_B x v_B; 0]; the model
        # has no gravity, so forward kinematics at it give each frame's bias acceleration.
        a_pin = self._a_pin
        a_pin[:3] = -cross(v_pin[3:6], v_pin[:3])
        h = pin.rnea(model, data, q_pin, v_pin, a_pin).take(self._perm)
        pin.forwardKinematics(model, data, q_pin, v_pin, a_pin)  # rnea leaves data.a
        R2 = self._R2
        R2[:3, :3] = R2[3:, 3:] = R
        # T's base blocks: rows and columns 0:3 and 3:6 each by R.
        M[:6] = R2 @ M[:6]
        M[:, :6] = M[:, :6] @ R2.T
        h[:6] = R2 @ h[:6]
        h -= self._gravity_W @ M[3:6]  # -tau_g: J_com = M[3:6] / m (control/terms.py)
        return R2, M, h, q_pin

    def jacobians(self, R2: np.ndarray, names, world: bool = False) -> np.ndarray:
        """(k, 6, nv) [w; v] of the named frames, expressed in each frame (world: in W,
        at the frame's origin) = J v, after run() returned R2."""
        tree = self.tree
        model, data, ids = tree.model, self.data, tree.frame_ids
        k = len(names)
        if not k:
            return np.empty((0, 6, model.nv))
        ref = _ALIGNED if world else _LOCAL
        J = np.array([pin.getFrameJacobian(model, data, ids[n], ref) for n in names])
        J = J.reshape(k, -1).take(self._J_take, axis=1).reshape(k, 6, -1)
        J[:, :, :6] = J[:, :, :6] @ R2.T
        return J

    def bias_accelerations(self, names) -> np.ndarray:
        """(k, 6) [alpha; a] of the named frames' origins at vdot = 0, in each frame,
        after run()."""
        tree = self.tree
        model, data, ids = tree.model, self.data, tree.frame_ids
        out = np.empty((len(names), 6))
        for k, name in enumerate(names):
            a = pin.getFrameClassicalAcceleration(model, data, ids[name], _LOCAL).vector
            out[k, :3] = a[3:]
            out[k, 3:] = a[:3]
        return out

    def rotations(self, q_pin: np.ndarray, names) -> np.ndarray:
        """(k, 3, 3) R_WF of the named frames at Pinocchio's q_pin (data of their own:
        the terms ask for them after their tick)."""
        self._data()
        model, data, ids = self.tree.model, self._pose_data, self.tree.frame_ids
        pin.forwardKinematics(model, data, q_pin)
        return np.array([pin.updateFramePlacement(model, data, ids[n]).rotation for n in names])
