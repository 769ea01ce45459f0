"""RobotSensing: what the advancement and the state machine measure.

From the robot's state and the measured hand wrenches it computes the CoM
position and velocity, Omega f (the CoM acceleration the hand wrenches cause,
Omega = J M^-1 J_h^T of the paper) and the x of the soles' heel edge.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.robot import Robot

HANDS = ("l_hand", "r_hand")


def heel_points(robot: Robot) -> dict[str, np.ndarray]:
    """Sole frame -> the middle of its pad's rear bottom edge, in that frame."""
    points = {}
    for shape in robot.contact_shapes:
        if shape.group == "sole" and shape.shape == "box":
            x, y, z = shape.xyz_m
            points[shape.frame] = np.array([x - shape.size_m[0] / 2, y, z - shape.size_m[2] / 2])
    return points


class RobotSensing(LeafSystem):
    """Inputs robot_state [q; v], hand_wrenches_W (12: [tau_l, f_l, tau_r, f_r]).

    Outputs com_W (3, m), com_velocity_W (3, m/s), omega_f_W (3, m/s^2) and
    heel_x_W (1, m: the front-most of the two soles' heel edges, so "CoM ahead
    of the heels" holds for both feet).
    """

    def __init__(self, plant: MultibodyPlant, robot: Robot, heel_points: dict[str, np.ndarray]):
        super().__init__()
        self._plant = plant
        self._instance = robot.model_instance
        self._context = plant.CreateDefaultContext()
        self._hands = [robot.frame(plant, h) for h in HANDS]
        self._heels = [(robot.frame(plant, s), np.asarray(p)) for s, p in heel_points.items()]
        nx = plant.num_multibody_states(self._instance)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        self._wrenches = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        state_only = {self._state.ticket()}
        self.DeclareVectorOutputPort("com_W", 3, self._CalcCom, prerequisites_of_calc=state_only)
        self.DeclareVectorOutputPort(
            "com_velocity_W", 3, self._CalcComVelocity, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "omega_f_W",
            3,
            self._CalcOmegaF,
            prerequisites_of_calc={self._state.ticket(), self._wrenches.ticket()},
        )
        self.DeclareVectorOutputPort(
            "heel_x_W", 1, self._CalcHeelX, prerequisites_of_calc=state_only
        )

    def _sync(self, context: Context) -> Context:
        x = self._state.Eval(context)
        self._plant.SetPositionsAndVelocities(self._context, self._instance, x)
        return self._context

    def _CalcCom(self, context: Context, output: BasicVector) -> None:
        c = self._sync(context)
        output.SetFromVector(self._plant.CalcCenterOfMassPositionInWorld(c, [self._instance]))

    def _CalcComVelocity(self, context: Context, output: BasicVector) -> None:
        c = self._sync(context)
        output.SetFromVector(
            self._plant.CalcCenterOfMassTranslationalVelocityInWorld(c, [self._instance])
        )

    def _CalcOmegaF(self, context: Context, output: BasicVector) -> None:
        """Omega f = J_com M^-1 sum_h J_h^T F_h (paper, Sec. II)."""
        F = self._wrenches.Eval(context).reshape(2, 6)
        if not F.any():
            output.SetFromVector(np.zeros(3))
            return
        plant, c = self._plant, self._sync(context)
        world = plant.world_frame()
        tau = np.zeros(plant.num_velocities())
        for frame, F_h in zip(self._hands, F):
            J_h = plant.CalcJacobianSpatialVelocity(
                c, JacobianWrtVariable.kV, frame, np.zeros(3), world, world
            )
            tau += J_h.T @ F_h
        M = plant.CalcMassMatrix(c)
        J_com = plant.CalcJacobianCenterOfMassTranslationalVelocity(
            c, JacobianWrtVariable.kV, world, world
        )
        output.SetFromVector(J_com @ np.linalg.solve(M, tau))

    def _CalcHeelX(self, context: Context, output: BasicVector) -> None:
        c = self._sync(context)
        world = self._plant.world_frame()
        xs = [
            self._plant.CalcPointsPositions(c, frame, p.reshape(3, 1), world)[0, 0]
            for frame, p in self._heels
        ]
        output.SetFromVector([max(xs)])
