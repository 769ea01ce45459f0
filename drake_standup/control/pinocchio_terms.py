"""The controller's model by Pinocchio (robot/dynamics.py): RobotTerms from one pass."""

from __future__ import annotations

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from drake_standup.control.terms import BASE_BODY, RobotKinematics
from drake_standup.robot.dynamics import RobotDynamics
from drake_standup.robot.icub import Robot

_HOLD = "@hold"  # an operational frame at a held frame's hold point


class PinocchioKinematics(RobotKinematics):
    """RobotKinematics whose pass is Pinocchio's (robot/dynamics.py): the same terms to
    round-off."""

    def __init__(self, plant: MultibodyPlant, robot: Robot, *args, **kwargs):
        super().__init__(plant, robot, *args, **kwargs)
        base = plant.GetBodyByName(BASE_BODY, robot.model_instance)
        dynamics = RobotDynamics.of(plant, robot.model_instance, base)
        for name, (frame, p_FP) in self._frames.items():
            dynamics.tree.add_frame(name, frame)
            if p_FP is not None:
                dynamics.tree.add_frame(name + _HOLD, frame, p_FP)
        self.dynamics = dynamics
        armature = dynamics.tree.armature
        self._armature = np.flatnonzero(armature)
        self._armature_values = armature[self._armature]
        self._armature_diagonal = self._armature * (self.nv + 1)
        self._pin_requests: dict[tuple[str, ...], tuple] = {}

    def set_mass_scale(self, scale: float) -> None:
        """Every body's mass scaled by scale (the pass's M and h are scaled by it)."""
        self.mass_scale = scale
        self.mass_kg = scale * self.nominal_mass_kg

    def _pin_request(self, frame_names: list[str]) -> tuple:
        """(the frames whose Jacobians are computed: frame_names, then the held hold
        points'; J_P's rows among them; the frames of Jdotv_P)."""
        key = tuple(frame_names)
        request = self._pin_requests.get(key)
        if request is None:
            extra, rows, biased = [], [], []
            for k, name in enumerate(frame_names):
                if name not in self._held_frames:
                    continue
                if self._frames[name][1] is None:
                    rows.append(k)
                    biased.append(name)
                else:
                    rows.append(len(frame_names) + len(extra))
                    extra.append(name + _HOLD)
                    biased.append(name + _HOLD)
            request = (list(frame_names) + extra, np.array(rows, dtype=int), biased)
            self._pin_requests[key] = request
        return request

    def _pass(self, x: np.ndarray, frame_names: list[str], world_frame_names) -> tuple:
        """(M, C v - tau_g, J_F, J_P, Jdotv_P, J_W) at x, from one pass."""
        names, held_rows, biased = self._pin_request(frame_names)
        dynamics = self.dynamics
        R2, M, h, _ = dynamics.run(x)
        if self.mass_scale != 1.0:
            M *= self.mass_scale
            h *= self.mass_scale
        if len(self._armature):  # the reflected motor inertias are no body's mass
            M.ravel()[self._armature_diagonal] += self._armature_values
        J = dynamics.jacobians(R2, names)
        J_W = dynamics.jacobians(R2, world_frame_names, world=True)
        Jdotv_P = dynamics.bias_accelerations(biased)
        return M, h, J[: len(frame_names)], J.take(held_rows, axis=0), Jdotv_P, J_W

    def frame_rotations(self, q: np.ndarray, frame_names: list[str]) -> np.ndarray:
        """R_WF (k, 3, 3) of the named frames at the positions q."""
        return self.dynamics.rotations(self.dynamics.positions(q), frame_names)
