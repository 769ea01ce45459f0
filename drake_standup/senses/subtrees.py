"""The robot cut at its six F/T sensors, and each piece's external wrench.

Cut at the F/T sensors, the iCub is seven pieces: the base (pelvis, torso, head,
shoulders, hips), each arm below its sensor, each leg between its two sensors and each
foot. A piece's Newton-Euler balance gives what acts on it from outside its sensors,

    F_ext = sum_i [ c_i x m_i (a_ci - g) + I_i alpha_i + w_i x I_i w_i ; m_i (a_ci - g) ]
            - sum_sensors (+-) F_sensor           (all about the world origin, in W)

from the model, the estimated state and accelerations and the sensors' wrenches:
the external-wrench estimation of robotology's wholeBodyDynamics with one unknown contact
a piece (Nori et al. 2015, Sec. 3). A piece's contact is what touches it: the hand of an
arm, the thigh pad of a leg, the sole of a foot, the buttocks of the base.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drake_standup.robot.spatial import cross


@dataclass(frozen=True)
class Piece:
    """A piece of the robot: its bodies (indices into the pieces' body list) and its
    sensors, each (sensor index, +1 if the piece is on the sensor's child side)."""

    name: str
    bodies: tuple[int, ...]
    sensors: tuple[tuple[int, float], ...]


class RobotPieces:
    """The robot's pieces (module docstring) for plant's instance cut at ft_joints (weld
    joints), with each body's mass, CoM and central inertia from the model."""

    def __init__(self, plant: MultibodyPlant, instance, ft_joints: list[str]):
        self._plant = plant
        self._bodies = [plant.get_body(b) for b in plant.GetBodyIndices(instance)]
        index = {body.index(): i for i, body in enumerate(self._bodies)}
        joints = [plant.GetJointByName(name, instance) for name in ft_joints]
        cut = {j.child_body().index(): k for k, j in enumerate(joints)}
        # Each body's piece: the nearest sensor above it (its child side), or the base.
        parent = {
            plant.get_joint(j).child_body().index(): plant.get_joint(j).parent_body().index()
            for j in plant.GetJointIndices(instance)
        }
        owner = []
        for body in self._bodies:
            b = body.index()
            while b not in cut and b in parent:
                b = parent[b]
            owner.append(cut.get(b, -1))
        pieces = []
        for k in [-1, *range(len(joints))]:
            bodies = tuple(i for i, o in enumerate(owner) if o == k)
            sensors = [(k, 1.0)] if k >= 0 else []
            # The sensors below this piece: their parent body is in it.
            for m, joint in enumerate(joints):
                if index[joint.parent_body().index()] in bodies:
                    sensors.append((m, -1.0))
            name = "base" if k < 0 else ft_joints[k]
            pieces.append(Piece(name, bodies, tuple(sensors)))
        self.pieces = pieces
        self._owner_piece = [[-1, *range(len(joints))].index(o) for o in owner]
        self._body_index = [int(b.index()) for b in self._bodies]
        self._mass = np.array([b.default_mass() for b in self._bodies])
        self._com_B = np.array([b.default_com() for b in self._bodies])
        self._inertia_B = np.array(
            [
                b.default_spatial_inertia()
                .Shift(b.default_com())
                .CalcRotationalInertia()
                .CopyToFullMatrix3()
                for b in self._bodies
            ]
        )
        # Which bodies each piece sums, and with which sign each sensor's wrench enters it.
        self._membership = np.zeros((len(pieces), len(self._bodies)))
        self._sensor_signs = np.zeros((len(pieces), len(joints)))
        for k, piece in enumerate(pieces):
            self._membership[k, list(piece.bodies)] = 1.0
            for m, sign in piece.sensors:
                self._sensor_signs[k, m] = sign
        self._joints = joints
        self._g = plant.gravity_field().gravity_vector()

    def piece_of(self, body_name: str) -> int:
        """The index of the piece holding the body body_name."""
        names = [b.name() for b in self._bodies]
        return self._owner_piece[names.index(body_name)]

    def external_wrenches(
        self, context: Context, vdot: np.ndarray, sensors: np.ndarray
    ) -> np.ndarray:
        """(n_pieces, 6) each piece's external wrench [torque; force] about the world origin,
        in W, at the state in context (the estimate), the accelerations vdot and the sensors'
        wrenches (36: [torque; force] on the child side at each joint's child frame, in it).
        All bodies at once in numpy (a loop over the 39 bodies cost 1.1 ms a tick)."""
        plant = self._plant
        poses = plant.get_body_poses_output_port().Eval(context)
        velocities = plant.get_body_spatial_velocities_output_port().Eval(context)
        accelerations = plant.CalcSpatialAccelerationsFromVdot(context, vdot)
        X = np.array([poses[i].GetAsMatrix34() for i in self._body_index])
        w = np.array([velocities[i].rotational() for i in self._body_index])
        A = np.array([accelerations[i].get_coeffs() for i in self._body_index])
        R, alpha = X[:, :, :3], A[:, :3]
        r = np.einsum("nij,nj->ni", R, self._com_B)
        c = X[:, :, 3] + r
        a_c = A[:, 3:] + np.cross(alpha, r) + np.cross(w, np.cross(w, r))
        inertia = np.einsum("nij,njk,nlk->nil", R, self._inertia_B, R)
        f = self._mass[:, None] * (a_c - self._g)
        tau = (
            np.cross(c, f)
            + np.einsum("nij,nj->ni", inertia, alpha)
            + np.cross(w, np.einsum("nij,nj->ni", inertia, w))
        )
        D = np.hstack([tau, f])
        return self._membership @ D - self._sensor_signs @ self._sensors_in_world(context, sensors)

    def _sensors_in_world(self, context: Context, sensors: np.ndarray) -> np.ndarray:
        """The sensors' wrenches (on their child sides) about the world origin, in W."""
        out = np.zeros((len(self._joints), 6))
        for m, joint in enumerate(self._joints):
            X = joint.frame_on_child().CalcPoseInWorld(context)
            R = X.rotation().matrix()
            tau, f = R @ sensors[6 * m : 6 * m + 3], R @ sensors[6 * m + 3 : 6 * m + 6]
            out[m, :3] = tau + cross(X.translation(), f)
            out[m, 3:] = f
        return out


def wrench_at(wrench_O: np.ndarray, point_W: np.ndarray) -> np.ndarray:
    """A wrench [torque; force] about the world origin, shifted to point_W."""
    return np.r_[wrench_O[:3] - cross(point_W, wrench_O[3:]), wrench_O[3:]]
