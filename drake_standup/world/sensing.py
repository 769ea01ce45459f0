"""RobotSensing: what the advancement and the state machine measure.

From the robot's state and the measured hand wrenches it computes the CoM
position and velocity, Omega f (the CoM acceleration the hand wrenches cause,
Omega = J M^-1 J_h^T of the paper) and the x of the soles' heel edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.helper.hands import TASK_FRAMES
from drake_standup.ports.caching import declare_cached
from drake_standup.robot.balance import static_lean
from drake_standup.robot.icub import Robot
from drake_standup.robot.last_com import LastCoM
from drake_standup.robot.spatial import cross

# The outputs of RobotSensing the controller reads (the station's of the true state, the
# senses' of the estimated one: senses/wiring.py).
SENSED = (
    "com_W",
    "com_velocity_W",
    "omega_f_W",
    "heel_x_W",
    "thigh_x_W",
    "thigh_z_W",
    "buttocks_z_W",
    "standing_pull_usage",
    "braced_pull_usage",
    "pull_cop_shift_m",
)


def heel_points(robot: Robot) -> dict[str, np.ndarray]:
    """Sole frame -> the middle of its pad's rear bottom edge, in that frame."""
    points = {}
    for shape in robot.contact_shapes:
        if shape.group == "sole" and shape.shape == "box":
            x, y, z = shape.xyz_m
            points[shape.frame] = np.array([x - shape.size_m[0] / 2, y, z - shape.size_m[2] / 2])
    return points


def thigh_points(robot: Robot) -> dict[str, np.ndarray]:
    """Thigh frame -> the centre of its pad's bottom face, in that frame."""
    return _pad_bottoms(robot, "thigh")


def buttocks_points(robot: Robot) -> dict[str, np.ndarray]:
    """The buttocks pad's frame -> the centre of the pad's bottom face, in that frame."""
    return _pad_bottoms(robot, "buttocks")


def _pad_bottoms(robot: Robot, group: str) -> dict[str, np.ndarray]:
    """Frame -> the centre of the bottom face of group's box pad on it, in that frame."""
    points = {}
    for shape in robot.contact_shapes:
        if shape.group == group and shape.shape == "box":
            x, y, z = shape.xyz_m
            points[shape.frame] = np.array([x, y, z - shape.size_m[2] / 2])
    return points


@dataclass(frozen=True)
class FeetReach:
    """How far the stand-up may lean the standing CoM (forward, back, sideways) and each
    sole's CoP box, m: the controller's limits, which the caller hands the world
    (standup/plan.py: feet_reach)."""

    lean_m: tuple[float, float, float]
    cop_x_m: tuple[float, float]
    cop_y_m: tuple[float, float]


@dataclass(frozen=True)
class StandingSupport:
    """What the standing robot can hold, for standing_pull_usage: its erect CoM height,
    its hands' and soles' origins from the CoM (2 x 3 each, left and right;
    scene.StandingPose), how far the stand-up leans its CoM (forward, back, sideways)
    and each sole's CoP box (FeetReach), m."""

    com_height_m: float
    hands_m: np.ndarray
    soles_m: np.ndarray
    lean_m: tuple[float, float, float]
    cop_x_m: tuple[float, float]
    cop_y_m: tuple[float, float]


def standing_lean(
    hand_wrenches_W: np.ndarray, weight_N: float, support: StandingSupport
) -> tuple[np.ndarray, np.ndarray] | None:
    """What a pull asks of the standing robot's feet, judged on the robot standing
    (whatever its posture now): the hands' wrenches (payloads.HAND_WRENCHES) at its
    standing hands give a resultant about the CoM that needs the static lean d (3,) of
    balance.static_lean at the erect height; and how far the feet can shift the CoM
    against it (3: forward, back, sideways), leaning up to lean_m and moving the CoP to
    the edge of the soles' boxes (half their length forward and back, half the span of
    both boxes sideways). None if the pull lifts the robot."""
    F = np.asarray(hand_wrenches_W).reshape(2, 6)
    # The rows summed as numpy sums them (row 0 + row 1); spatial.cross for np.cross.
    hands = support.hands_m
    moment = cross(hands[0], F[0, 3:]) + cross(hands[1], F[1, 3:])
    wrench = np.concatenate([F[0, :3] + F[1, :3] + moment, F[0, 3:] + F[1, 3:]])
    if weight_N - wrench[5] <= 0.0:
        return None
    d = static_lean(wrench, support.com_height_m, weight_N, math.inf)
    half_x = (support.cop_x_m[1] - support.cop_x_m[0]) / 2
    span = abs(support.soles_m[0, 1] - support.soles_m[1, 1])
    half_y = (span + support.cop_y_m[1] - support.cop_y_m[0]) / 2
    forward, back, side = support.lean_m
    return d, np.array([forward + half_x, back + half_x, side + half_y])


def pull_cop_shift_m(
    hand_wrenches_W: np.ndarray,
    hands_W: np.ndarray,
    com_W: np.ndarray,
    ground_z_m: float,
    weight_N: float,
) -> float:
    """How far (x, m; negative: back) the hands' pull tips the centre of pressure under
    the robot held still at its posture now: from the moments about the y axis of the
    weight at the CoM and of the hands' wrenches at hands_W (2 x 3, world), on the ground
    at ground_z_m, over the load the feet carry,
    (x_cop - x_com) (W - sum f_z) = sum (z_h - z_g) f_x - (x_h - x_com) min(f_z, 0) + tau_y.
    A backward pull at the hands tips the robot back toward the heels; a hand pressed
    down in front of the CoM holds it forward. A lift's own lever is left out (a hand
    lifted in front of the CoM moves the CoP back too): a lift is help the robot leans
    into, and what the feet can hold of it is standing_pull_usage's to judge. -inf if
    the pull lifts the robot."""
    F = np.asarray(hand_wrenches_W).reshape(2, 6)
    hands = np.asarray(hands_W).reshape(2, 3)
    load = weight_N - F[0, 5] - F[1, 5]
    if load <= 0.0:
        return -math.inf
    moment = sum(
        (hands[i, 2] - ground_z_m) * F[i, 3]
        - (hands[i, 0] - com_W[0]) * min(F[i, 5], 0.0)
        + F[i, 1]
        for i in range(2)
    )
    return float(moment / load)


def standing_pull_usage(
    hand_wrenches_W: np.ndarray, weight_N: float, support: StandingSupport
) -> float:
    """The share of what the standing robot's feet can hold that a pull needs
    (standing_lean): 1 at the edge; 10 if the pull lifts the robot."""
    need = standing_lean(hand_wrenches_W, weight_N, support)
    if need is None:
        return 10.0
    d, (forward, back, side) = need
    return float(max(d[0] / forward, -d[0] / back, abs(d[1]) / side))


class RobotSensing(LeafSystem):
    """Inputs robot_state [q; v], hand_wrenches_W (12: [tau_l, f_l, tau_r, f_r]).

    Outputs com_W (3, m), com_velocity_W (3, m/s), omega_f_W (3, m/s^2),
    heel_x_W (1, m: the front-most of the two soles' heel edges, so "CoM ahead
    of the heels" holds for both feet), thigh_x_W (1, m: the mean x of the
    thigh pads' centres, where the seat's support ends; NaN without pads) and thigh_z_W
    (1, m: the lower of the thigh pads' undersides' centres, how near the seat they are;
    NaN without pads), buttocks_z_W (1, m: the buttocks pad's underside's centre; NaN
    without it),
    hand_positions_W and hand_velocities_W (6 each, m and m/s: the left and the right
    hand frame's origin, where a pull is applied, helper.hands.hand_forces; what the helper's
    work is summed over, helper.work.HelperWork), pull_cop_shift_m (1, m: pull_cop_shift_m of
    the measured pull at the posture now, on the ground under the heels) and, with a
    StandingSupport, standing_pull_usage (1: standing_pull_usage of the measured pull).

    The CoM outputs share one cache entry that depends on robot_state only:
    the plant context is set once per new state (once per plant step), not
    once per output and integrator stage. heel_x_W has its own: only the state
    machine reads it, at its own (slower) rate.
    """

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: Robot,
        heel_points: dict[str, np.ndarray],
        thigh_points: dict[str, np.ndarray] | None = None,
        standing: StandingSupport | None = None,
        braced: StandingSupport | None = None,
        *,
        last_com: LastCoM | None = None,
        buttocks_points: dict[str, np.ndarray] | None = None,
    ):
        """last_com: the controller's model's CoM of the state, where it computed it
        (robot/last_com.py); else from Drake's plant."""
        super().__init__()
        self._last_com = last_com
        self._plant = plant
        self._instance = robot.model_instance
        self._context = plant.CreateDefaultContext()
        self._context_state: np.ndarray | None = None  # robot_state in self._context
        self._mass_kg = plant.CalcTotalMass(self._context, [self._instance])
        self._heels = [(robot.frame(plant, s), np.asarray(p)) for s, p in heel_points.items()]
        self._thighs = self._on_frames(thigh_points)
        self._buttocks = self._on_frames(buttocks_points)
        self._hands = [robot.frame(plant, name) for name in TASK_FRAMES]
        self._g = -plant.gravity_field().gravity_vector()[2]
        nx = plant.num_multibody_states(self._instance)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        self._wrenches = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        state_only = {self._state.ticket()}
        self._kinematics = declare_cached(self, "com", self._calc_kinematics, state_only)
        depends = {self._kinematics.ticket()}
        for name, index in (("com_W", 0), ("com_velocity_W", 1)):
            self.DeclareVectorOutputPort(
                name, 3, self._reader(index), prerequisites_of_calc=depends
            )
        self.DeclareVectorOutputPort(
            "heel_x_W", 1, self._CalcHeelX, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "thigh_x_W", 1, self._CalcThighX, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "thigh_z_W", 1, self._CalcThighZ, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "buttocks_z_W", 1, self._CalcButtocksZ, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "omega_f_W", 3, self._CalcOmegaF, prerequisites_of_calc={self._wrenches.ticket()}
        )
        self._hand_positions = self.DeclareVectorOutputPort(
            "hand_positions_W", 6, self._CalcHandPositions, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "hand_velocities_W", 6, self._CalcHandVelocities, prerequisites_of_calc=state_only
        )
        self.DeclareVectorOutputPort(
            "pull_cop_shift_m",
            1,
            self._CalcPullCopShift,
            prerequisites_of_calc={self._state.ticket(), self._wrenches.ticket()},
        )
        for name, support in (("standing_pull_usage", standing), ("braced_pull_usage", braced)):
            if support is not None:
                self.DeclareVectorOutputPort(
                    name,
                    1,
                    self._usage_of(support),
                    prerequisites_of_calc={self._wrenches.ticket()},
                )

    def _on_frames(self, points: dict[str, np.ndarray] | None) -> list:
        """(the robot's frame, the point in it) of each frame name -> point."""
        return [
            (self._plant.GetFrameByName(f, self._instance), np.asarray(p))
            for f, p in (points or {}).items()
        ]

    def _set_plant_state(self, context: Context, check: bool) -> None:
        """The private plant context at robot_state (check: unless it is there
        already, so that its kinematics are not computed twice)."""
        state = self._state.Eval(context)
        last = self._context_state
        # The same bytes are the same state (a cheap test first; array_equal decides
        # otherwise, e.g. -0.0 == 0.0, as before).
        if not (
            check
            and last is not None
            and (state.tobytes() == last.tobytes() or np.array_equal(state, last))
        ):
            self._plant.SetPositionsAndVelocities(self._context, self._instance, state)
            self._context_state = state

    def _calc_kinematics(self, context: Context) -> tuple[np.ndarray, np.ndarray]:
        if self._last_com is not None:
            com = self._last_com.get(self._state.Eval(context))
            if com is not None:
                return com
        self._set_plant_state(context, check=False)
        plant, c = self._plant, self._context
        com = plant.CalcCenterOfMassPositionInWorld(c, [self._instance])
        com_velocity = plant.CalcCenterOfMassTranslationalVelocityInWorld(c, [self._instance])
        return com, com_velocity

    def _reader(self, index: int):
        def calc(context: Context, output: BasicVector) -> None:
            output.SetFromVector(self._kinematics.Eval(context)[index])

        return calc

    def _points(self, context: Context, points: list) -> list[np.ndarray]:
        """The world position of each (frame, point in it) at robot_state."""
        self._set_plant_state(context, check=True)
        plant, c = self._plant, self._context
        world = plant.world_frame()
        return [plant.CalcPointsPositions(c, f, p.reshape(3, 1), world)[:, 0] for f, p in points]

    def _points_x(self, context: Context, points: list) -> list[float]:
        """The world x of each (frame, point in it) at robot_state."""
        return [float(p[0]) for p in self._points(context, points)]

    def _CalcHeelX(self, context: Context, output: BasicVector) -> None:
        xs = self._points_x(context, self._heels)
        output.SetAtIndex(0, max(xs) if xs else np.nan)

    def _CalcThighX(self, context: Context, output: BasicVector) -> None:
        xs = self._points_x(context, self._thighs)
        output.SetAtIndex(0, float(np.mean(xs)) if xs else np.nan)

    def _lowest_z(self, context: Context, points: list) -> float:
        """The lowest world z of the (frame, point in it) at robot_state; NaN: none."""
        zs = [float(p[2]) for p in self._points(context, points)]
        return min(zs) if zs else np.nan

    def _CalcThighZ(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._lowest_z(context, self._thighs))

    def _CalcButtocksZ(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._lowest_z(context, self._buttocks))

    def _CalcHandPositions(self, context: Context, output: BasicVector) -> None:
        self._set_plant_state(context, check=True)
        output.SetFromVector(
            np.concatenate([f.CalcPoseInWorld(self._context).translation() for f in self._hands])
        )

    def _CalcHandVelocities(self, context: Context, output: BasicVector) -> None:
        self._set_plant_state(context, check=True)
        output.SetFromVector(
            np.concatenate(
                [f.CalcSpatialVelocityInWorld(self._context).translational() for f in self._hands]
            )
        )

    def _usage_of(self, support: StandingSupport):
        def calc(context: Context, output: BasicVector) -> None:
            F = self._wrenches.Eval(context)
            usage = (
                standing_pull_usage(F, self._mass_kg * self._g, support)
                if np.count_nonzero(F)
                else 0.0
            )
            output.SetAtIndex(0, usage)

        return calc

    def _CalcPullCopShift(self, context: Context, output: BasicVector) -> None:
        F = self._wrenches.Eval(context)
        if not np.count_nonzero(F) or not self._heels:
            output.SetAtIndex(0, 0.0)
            return
        ground_z = float(np.mean([p[2] for p in self._points(context, self._heels)]))
        hands = self._hand_positions.Eval(context)  # the cached hand_positions_W
        com = self._kinematics.Eval(context)[0]
        weight = self._mass_kg * self._g
        output.SetAtIndex(0, pull_cop_shift_m(F, hands, com, ground_z, weight))

    def _CalcOmegaF(self, context: Context, output: BasicVector) -> None:
        """Omega f = J_com M^-1 sum_h J_h^T F_h (paper, Sec. II).

        For a floating base whose translational velocity is the world-frame
        velocity of its origin (Drake's quaternion floating joint), the CoM
        Jacobian is the mass matrix's translational base rows over the mass,
        J_com = M[3:6, :] / m, so J_com M^-1 = [0 I 0] / m and Omega f is the
        hands' net force over the mass: the linear momentum theorem. Exact, and
        free of a mass-matrix solve (tests check it against the formula).
        """
        F = self._wrenches.Eval(context)
        output.SetFromVector((F[3:6] + F[9:12]) / self._mass_kg)


def pad_sensing(
    plant: MultibodyPlant,
    robot: Robot,
    standing: StandingSupport | None,
    braced: StandingSupport | None,
    last_com: LastCoM | None,
) -> RobotSensing:
    """RobotSensing of the robot's heels, thighs and buttocks where its contact shapes put
    them: the station's (the true state) and the senses' (the estimated one) alike."""
    return RobotSensing(
        plant,
        robot,
        heel_points(robot),
        thigh_points(robot),
        standing,
        braced,
        last_com=last_com,
        buttocks_points=buttocks_points(robot),
    )
