"""The robot's kinematic and dynamic terms at one state, from Drake's MultibodyPlant.

Everything is in the world frame W unless a name says otherwise. The floating base
(root_link, body B) comes first in v as [w_WB; v_WBo], both expressed in W (Drake's
QuaternionFloatingJoint), which gives exact shortcuts ([drake-docs], checked in
tests/control/test_controller.py):
  - the first six rows of M v are the robot's spatial momentum about Bo,
    [h_WBo; l_W] = M[0:6] v, so the centroidal momentum needs no extra Drake call:
        L_Com = [h_WBo - p_BoCom x l_W; l_W];
  - M[0:3, 3:6] = m [p_BoCom]x (the moment about Bo of the momentum m v_WBo), so the CoM
    position needs no Drake call either;
  - the CoM Jacobian is J_com = M[3:6] / m and its bias Jdot_com v = C(q,v)v[3:6] / m;
  - hence the generalized gravity force is tau_g = J_com^T m g = M[3:6]^T g;
  - vdot[0:6] = [alpha_WB; a_WBo]: a point P on the base has the bias acceleration
    [0; w_WB x (w_WB x p_BoP)], no Drake call needed;
  - the first six rows of J^T map a wrench (at the Jacobian's point, expressed in its
    frame) to the resultant about Bo in W.

A contact frame's Jacobian is asked for expressed in the frame itself: its transpose maps
the contact wrench [tau_C; f_C], expressed in C, to generalized forces, and its rows are
those the QP holds at zero, so no frame pose is needed.
"""

from dataclasses import dataclass
from functools import partial

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable

from drake_standup.robot.icub import Robot
from drake_standup.robot.last_com import LastCoM
from drake_standup.robot.spatial import cross, rotation_from_quaternion

BASE_BODY = "root_link"


@dataclass(slots=True)
class RobotTerms:
    """The equations of motion M vdot + h = B tau + sum J^T F at one state, and the task
    frames asked for: frame_names (index k below), their Jacobians expressed in each
    frame F, and world_frame_names (index i), Jacobians expressed in W."""

    q: np.ndarray  # (nq,) [quaternion wxyz, p_WBo, joints] rad, m
    v: np.ndarray  # (nv,) [w_WB, v_WBo, joint rates] rad/s, m/s
    M: np.ndarray  # (nv, nv) mass matrix, kg m^2 / kg
    h: np.ndarray  # (nv,) C(q, v) v - tau_g(q) + D v
    mass_kg: float
    p_WCom: np.ndarray  # (3,) m
    p_BoCom: np.ndarray  # (3,) CoM from the base origin, in W, m
    v_WCom: np.ndarray  # (3,) m/s
    L_WCom: np.ndarray  # (6,) centroidal momentum [angular about Com, N m s; linear, kg m/s]
    R_WB: np.ndarray  # (3, 3) base orientation
    frame_names: list[str]
    J_F: np.ndarray  # (k, 6, nv): [w_WF; v_WFo], expressed in F, = J_F[k] v
    # The held frames among frame_names, in their order (index j): Jacobian and bias
    # spatial acceleration of each one's hold point P (fixed on F's body), expressed in F.
    J_P: np.ndarray  # (j, 6, nv): [w_WF; v_WP] = J_P[j] v
    Jdotv_P: np.ndarray  # (j, 6)
    world_frame_names: list[str]
    J_W: np.ndarray  # (i, 6, nv): [w_WF; v_WFo] = J_W[i] v, expressed in W
    # () -> (k, 3, 3): R_WF of frame_names, computed when called (a Drake call each).
    frame_rotations: partial

    def __deepcopy__(self, memo: dict) -> "RobotTerms":
        """Itself: the terms of one state, never changed once computed (Drake clones a
        context's cached values, e.g. the live mode's Reset point)."""
        return self


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
        hold_points_m: dict[str, tuple[float, float, float]] | None = None,
        *,
        last_com: LastCoM | None = None,
        unknown_damping: dict[str, float] | None = None,
    ):
        """held_frames get the Jacobian and bias acceleration Jdot v of their hold point
        too (hold_points_m: its position in the frame; default the origin); last_com
        gets each state's CoM for the sensing (robot/last_com.py); unknown_damping: the
        damping of the plant's joints (by name) that is not the model's (Scene.
        added_damping: the joints' true friction under icub, which the boards
        compensate as they identified it)."""
        self.last_com = last_com
        instance = robot.model_instance
        if plant.num_velocities() != plant.num_velocities(instance) or plant.num_positions() != (
            plant.num_positions(instance)
        ):
            raise ValueError("the controller needs every non-robot model welded to the world")
        base = plant.GetBodyByName(BASE_BODY, instance)
        if not base.is_floating_base_body() or base.floating_velocities_start_in_v() != 0:
            raise ValueError(f"{BASE_BODY} must be the floating base, first in v")
        hold_points_m = hold_points_m or {}
        self._plant = plant
        self._context = plant.CreateDefaultContext()
        self._pose_context = plant.CreateDefaultContext()  # for frame_rotations
        self._world = plant.world_frame()
        self._origin = np.zeros(3)
        self._held_frames = set(held_frames)
        self._frames = {}  # name -> (frame, hold point in F, or None: not held / at Fo)
        # Held frames on the base: (hold point P in B, R_FB).
        self._on_base: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        for name in held_frames + other_frames:
            frame = robot.frame(plant, name)
            p_FP = np.array(hold_points_m.get(name, (0.0, 0.0, 0.0)), dtype=float)
            self._frames[name] = frame, (p_FP if name in held_frames and p_FP.any() else None)
            if name in held_frames and frame.body().index() == base.index():
                X_BF = frame.GetFixedPoseInBodyFrame()
                self._on_base[name] = X_BF @ p_FP, X_BF.rotation().matrix().T
        self._requests: dict[tuple[str, ...], tuple[list, int]] = {}
        self._gravity_W = plant.gravity_field().gravity_vector()
        self.mass_kg = self.nominal_mass_kg = plant.CalcTotalMass(self._context, [instance])
        self._bodies = [plant.get_body(i) for i in plant.GetBodyIndices(instance)]
        self.mass_scale = 1.0
        self.nq, self.nv = plant.num_positions(), plant.num_velocities()
        # M[0:3, 3:6] = m [p_BoCom]x: its entries (2, 1), (0, 2), (1, 0) in M, flat.
        self._com_entries = np.array([2 * self.nv + 4, 5, self.nv + 3])
        # q = [quaternion wxyz, p_WBo, ...] from the base joint's first position.
        start = base.floating_positions_start()
        self._quaternion = slice(start, start + 4)
        self._p_WBo = slice(start + 4, start + 7)
        self._damping = np.zeros(self.nv)
        for index in plant.GetJointIndices(instance):
            joint = plant.get_joint(index)
            start, count = joint.velocity_start(), joint.num_velocities()
            self._damping[start : start + count] = joint.default_damping_vector()
            self._damping[start : start + count] -= (unknown_damping or {}).get(joint.name(), 0.0)

    def set_mass_scale(self, scale: float) -> None:
        """Every body's mass scaled by scale from its default (CoM and unit inertia kept,
        so the rotational inertia scales too): the model the terms are computed with."""
        if scale == self.mass_scale:
            return
        for body in self._bodies:
            body.SetMass(self._context, scale * body.default_mass())
        self.mass_scale = scale
        self.mass_kg = scale * self.nominal_mass_kg

    def _request(self, frame_names: list[str]) -> tuple[list, int]:
        """Per frame asked for: (frame, hold point or None, held, (P in B, R_FB) if on
        the base or None); the number of held frames."""
        key = tuple(frame_names)
        request = self._requests.get(key)
        if request is None:
            frames = [
                (*self._frames[name], name in self._held_frames, self._on_base.get(name))
                for name in frame_names
            ]
            request = self._requests[key] = frames, sum(held for _, _, held, _ in frames)
        return request

    def calc(
        self, x: np.ndarray, frame_names: list[str], world_frame_names: list[str] = ()
    ) -> RobotTerms:
        """Terms at the robot state x = [q; v], for the named frames only (each frame's
        Jacobian is a Drake call: the hands are left out while nobody pulls them)."""
        M, h, J_F, J_P, Jdotv_P, J_W = self._pass(x, frame_names, world_frame_names)
        q, v = x[: self.nq], x[self.nq :]
        h += self._damping * v
        mass = self.mass_kg
        p_BoCom = M.take(self._com_entries) / mass  # module docstring
        L_WCom = M[:6] @ v  # [h_WBo; l_W], shifted to the CoM below
        L_WCom[:3] -= cross(p_BoCom, L_WCom[3:])
        p_WCom, v_WCom = q[self._p_WBo] + p_BoCom, L_WCom[3:] / mass
        if self.last_com is not None:
            self.last_com.put(x, p_WCom, v_WCom)
        return RobotTerms(
            q=q,
            v=v,
            M=M,
            h=h,
            mass_kg=mass,
            p_WCom=p_WCom,
            p_BoCom=p_BoCom,
            v_WCom=v_WCom,
            L_WCom=L_WCom,
            R_WB=rotation_from_quaternion(q[self._quaternion]),
            frame_names=frame_names,
            J_F=J_F,
            J_P=J_P,
            Jdotv_P=Jdotv_P,
            world_frame_names=world_frame_names,
            J_W=J_W,
            frame_rotations=partial(self.frame_rotations, q, frame_names),
        )

    def _pass(self, x: np.ndarray, frame_names: list[str], world_frame_names) -> tuple:
        """(M, C v - tau_g, J_F, J_P, Jdotv_P, J_W) at x (RobotTerms' fields), by Drake."""
        plant, context, world, origin = self._plant, self._context, self._world, self._origin
        request, n_held = self._request(frame_names)
        plant.SetPositionsAndVelocities(context, x)
        M = plant.CalcMassMatrix(context)
        h = plant.CalcBiasTerm(context)
        h -= self._gravity_W @ M[3:6]
        nv, kV = self.nv, JacobianWrtVariable.kV
        J_F = np.empty((len(frame_names), 6, nv))
        J_P = np.empty((n_held, 6, nv))
        Jdotv_P = np.zeros((n_held, 6))
        R_WB = None
        j = 0
        for k, (frame, p_FP, held, on_base) in enumerate(request):
            J_F[k] = plant.CalcJacobianSpatialVelocity(context, kV, frame, origin, world, frame)
            if not held:
                continue
            if p_FP is None:
                J_P[j] = J_F[k]
            else:
                J_P[j] = plant.CalcJacobianSpatialVelocity(context, kV, frame, p_FP, world, frame)
            if on_base is None:
                Jdotv_P[j] = plant.CalcBiasSpatialAcceleration(
                    context, kV, frame, origin if p_FP is None else p_FP, world, frame
                ).get_coeffs()
            else:  # w x (w x p_BoP) (module docstring), in B, then in F
                if R_WB is None:
                    R_WB = rotation_from_quaternion(x[self._quaternion])
                p_BP, R_FB = on_base
                w_B = x[self.nq : self.nq + 3] @ R_WB
                Jdotv_P[j, 3:] = R_FB @ cross(w_B, cross(w_B, p_BP))
            j += 1
        J_W = np.empty((len(world_frame_names), 6, nv))
        for i, name in enumerate(world_frame_names):
            J_W[i] = plant.CalcJacobianSpatialVelocity(
                context, kV, self._frames[name][0], origin, world, world
            )
        return M, h, J_F, J_P, Jdotv_P, J_W

    def frame_rotations(self, q: np.ndarray, frame_names: list[str]) -> np.ndarray:
        """R_WF (k, 3, 3) of the named frames at the positions q."""
        self._plant.SetPositions(self._pose_context, q)
        return np.array(
            [
                self._frames[name][0].CalcPoseInWorld(self._pose_context).rotation().matrix()
                for name in frame_names
            ]
        )
