"""The seated pose solved from the chair's geometry, and the seats a robot can sit on.

The pelvis is upright at the scenario's yaw with the buttocks pad's bottom on the seat
top, the hip axes hips_behind_seat_edge_m behind the seat's front edge (or as deep as the
thigh pads lie wholly on the seat, SEAT_DEPTH_MARGIN_M inside its edge, shallower where
the legs need it). The sagittal leg joints (hip pitch, knee, ankle pitch, left = right)
are then the closest to SEATED_JOINTS that put the soles flat on the floor (the pads'
bottoms at z = 0), keep every thigh pad's bottom out of the seat wherever it lies over it,
and stay JOINT_MARGIN_RAD inside their limits. A small nonlinear program (Drake's
MathematicalProgram on the plant's AutoDiff twin); every other joint keeps SEATED_JOINTS.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import MultibodyPlant
from pydrake.solvers import MathematicalProgram, Solve

from drake_standup.config import Scenario, ScenarioError
from drake_standup.config.chair import SEATED_BASE_XYZ_M, SEATED_JOINTS, ChairConfig, InitialPose
from drake_standup.config.chair_mesh import is_mesh
from drake_standup.robot.icub import add_icub
from drake_standup.world.chair import SEAT_DEPTH_M

# The solved joints: both sides alike (the seated pose is symmetric).
LEG_JOINTS = ("hip_pitch", "knee", "ankle_pitch")
# The joints stay this far inside their limits (a posture task's room to act). rad.
JOINT_MARGIN_RAD = 0.05
# Sitting deep, the thigh pads' front ends this far inside the seat's edge (5 mm:
# the shipped pose's); sitting shallow, at least the pads' back half on the seat. m.
SEAT_DEPTH_MARGIN_M = 0.005
# How far a thigh pad's edge may sink into the seat: the pads sink about 1 mm under the
# robot's weight (models/icub_contact.yaml), the shipped pose's thighs 1.1 mm at their back. m.
PAD_SINK_M = 0.0015
# A thigh rests on the seat: its pad's lowest point over the seat at most this high. m.
THIGH_REST_GAP_M = 0.003
# How far the pads may be off their surface in a solved pose (solver tolerance). m.
CONTACT_TOL_M = 1e-4


@dataclass(frozen=True)
class SeatedPose:
    """The robot on its chair at t = 0."""

    base: RigidTransform  # root_link in the world
    joints_rad: dict[str, float]
    # The hip axes behind the seat's edge, and the soles' frames ahead of it. m.
    hips_behind_seat_edge_m: float
    feet_ahead_of_seat_edge_m: float


@dataclass(frozen=True)
class _Geometry:
    """What the program needs of a robot on a seat."""

    top: float  # the seat's top (or its cushion's) in the world, m
    edge: float  # the seat's front edge's x, m
    depth: tuple[float, float]  # the hips' distance behind the edge: (shallowest, deepest)
    feet: float | None  # the soles' frames' x, if asked for


def _pad_bottom_m(robot, group: str) -> float:
    """How far below its frame a pad group's box reaches (models/icub_contact.yaml)."""
    shape = next(s for s in robot.contact_shapes if s.group == group)
    return -(shape.xyz_m[2] - shape.size_m[2] / 2)


class _Seating:
    """The program's pieces on one plant: indices, frames and the pose's fixed part."""

    def __init__(self, plant: MultibodyPlant, robot, init: InitialPose):
        self.plant, self.instance = plant, robot.model_instance
        self.context = plant.CreateDefaultContext()
        names = {plant.get_joint(j).name() for j in plant.GetJointIndices(self.instance)}
        self.joints = {k: v for k, v in SEATED_JOINTS.items() if k in names}
        root = plant.GetBodyByName("root_link", self.instance)
        self.root = root
        self.rotation = RollPitchYaw(init.base_rpy_rad).ToRotationMatrix()
        plant.SetFreeBodyPose(self.context, root, RigidTransform(self.rotation, [0, 0, 0]))
        for name, value in self.joints.items():
            plant.GetJointByName(name, self.instance).set_angle(self.context, value)
        self.q0 = plant.GetPositions(self.context).copy()
        self.base_xyz = root.floating_positions_start() + 4
        self.free = [
            [plant.GetJointByName(f"{s}_{j}", self.instance).position_start() for s in "lr"]
            for j in LEG_JOINTS
        ]
        self.limits = [
            (
                plant.GetJointByName(f"l_{j}", self.instance).position_lower_limits()[0],
                plant.GetJointByName(f"l_{j}", self.instance).position_upper_limits()[0],
            )
            for j in LEG_JOINTS
        ]
        self.nominal = np.array([SEATED_JOINTS[f"l_{j}"] for j in LEG_JOINTS])
        frame = robot.frame
        self.soles = [frame(plant, n) for n in ("l_sole", "r_sole")]
        self.thighs = [frame(plant, n) for n in ("l_thigh", "r_thigh")]
        self.sole_z = _pad_bottom_m(robot, "sole")
        thigh = next(s for s in robot.contact_shapes if s.group == "thigh")
        self.thigh_half = thigh.size_m[0] / 2
        buttocks = frame(plant, "buttocks")
        self.buttocks_below_base = -buttocks.CalcPoseInWorld(self.context).translation()[2]
        hip = plant.GetJointByName("l_hip_pitch", self.instance).frame_on_parent()
        self.hip_x = hip.CalcPoseInWorld(self.context).translation()[0]
        self.thigh_front = self._thigh_front_ahead_of_hip()
        # The buttocks pad's front and back ends behind the hip axes. m.
        pad = next(c for c in robot.contact_shapes if c.group == "buttocks")
        ends = buttocks.CalcPoseInWorld(self.context)
        xs = [ends.multiply([x * pad.size_m[0] / 2, 0, 0])[0] for x in (-1, 1)]
        self.buttocks_span = (self.hip_x - max(xs), self.hip_x - min(xs))

    @functools.cached_property
    def autodiff(self):
        """The plant's AutoDiff twin, its context and its sole and thigh frames (built only
        when a pose is solved: a given pose needs none)."""
        ad = self.plant.ToAutoDiffXd()
        frames = [ad.GetFrameByName(f.name(), self.instance) for f in (*self.soles, *self.thighs)]
        return ad, ad.CreateDefaultContext(), frames[:2], frames[2:]

    def _thigh_front_ahead_of_hip(self) -> float:
        """The thigh pads' front end ahead of the hip axes in SEATED_JOINTS. m."""
        pad = self.thighs[0].CalcPoseInWorld(self.context)
        return float(pad.multiply([self.thigh_half, 0, 0])[0] - self.hip_x)

    def q(self, x, base_x: float, base_z: float) -> np.ndarray:
        """The full position vector for leg angles x (hip pitch, knee, ankle)."""
        q = self.q0.astype(x.dtype)
        for k, (left, right) in enumerate(self.free):
            q[left] = q[right] = x[k]
        q[self.base_xyz] = base_x
        q[self.base_xyz + 2] = base_z
        return q


def _residuals(s: _Seating, geo: _Geometry, z) -> np.ndarray:
    """[soles' pad bottoms' height, soles' pitch, (soles' x - feet)] and each thigh pad's
    lowest point over the seat above its top, for z = [hip pitch, knee, ankle, depth]."""
    base_x = geo.edge - z[3] - s.hip_x
    base_z = geo.top + s.buttocks_below_base
    if z.dtype == object:
        plant, context, soles, thighs = s.autodiff
    else:
        plant, context, soles, thighs = s.plant, s.context, s.soles, s.thighs
    plant.SetPositions(context, s.q(z[:3], base_x, base_z))
    sole_rows = []
    for frame in soles:
        pose = frame.CalcPoseInWorld(context)
        p, R = pose.translation(), pose.rotation().matrix()
        sole_rows.append([p[2] - s.sole_z, R[0, 2], p[0]])
    # Both soles, on average: the model's two legs differ by 0.1 mm.
    z_sole, pitch, x_sole = [(a + b) / 2 for a, b in zip(*sole_rows, strict=True)]
    out = [z_sole, pitch] + ([] if geo.feet is None else [x_sole - geo.feet])
    for frame in thighs:
        pose = frame.CalcPoseInWorld(context)
        back = pose.multiply(np.array([-s.thigh_half, 0.0, 0.0]))
        front = pose.multiply(np.array([s.thigh_half, 0.0, 0.0]))
        # The pad's bottom where it leaves the seat (its front, or the seat's edge).
        share = (geo.edge - back[0]) / (front[0] - back[0])
        if share <= 0.0:  # the pad wholly beyond the edge (perched): nothing to rest on
            out += [share * 0 + 1.0] * 3
            continue
        share = share if share < 1.0 else share * 0 + 1.0
        ends = [back[2] - geo.top, back[2] + share * (front[2] - back[2]) - geo.top]
        # Out of the seat, and resting on it (its lower end on the top).
        out += [ends[0] + PAD_SINK_M, ends[1] + PAD_SINK_M]
        out.append(THIGH_REST_GAP_M - (ends[0] if ends[0] < ends[1] else ends[1]))
    return np.array(out)


def _solve(s: _Seating, geo: _Geometry) -> np.ndarray | None:
    """[hip pitch, knee, ankle, depth] of the seated pose, or None if there is none: on
    the thighs as deep as it can, else (a high seat) perched, the thighs beyond the edge."""
    sol = _solve_at(s, geo)
    if sol is None and geo.depth[0] < geo.depth[1]:
        perched = (0.0, s.thigh_front - 2 * s.thigh_half - SEAT_DEPTH_MARGIN_M)
        sol = _solve_at(s, dataclasses.replace(geo, depth=perched), perched=True)
    return sol


def _solve_at(s: _Seating, geo: _Geometry, perched: bool = False) -> np.ndarray | None:
    prog = MathematicalProgram()
    z = prog.NewContinuousVariables(4, "z")
    if perched:  # on a high seat: the thighs slope down from the hips, not up
        prog.AddBoundingBoxConstraint(-np.inf, s.nominal[0], z[0])
    for k, (low, high) in enumerate(s.limits):
        prog.AddBoundingBoxConstraint(low + JOINT_MARGIN_RAD, high - JOINT_MARGIN_RAD, z[k])
    prog.AddBoundingBoxConstraint(geo.depth[0], geo.depth[1], z[3])
    n_eq = 2 + (1 if geo.feet is not None else 0)
    lower = np.r_[np.zeros(n_eq), np.zeros(6)]
    upper = np.r_[np.zeros(n_eq), np.full(6, np.inf)]
    prog.AddConstraint(lambda v: _residuals(s, geo, v), lower, upper, z)
    prog.AddQuadraticErrorCost(np.eye(3), s.nominal, z[:3])
    prog.AddQuadraticErrorCost(np.eye(1) * 100.0, [geo.depth[1]], z[3:])
    prog.SetInitialGuess(z, np.r_[s.nominal, geo.depth[1]])
    result = Solve(prog)
    if not result.is_success():
        return None
    sol = result.GetSolution(z)
    res = _residuals(s, geo, sol)
    if np.max(np.abs(res[:n_eq])) > CONTACT_TOL_M or np.min(res[n_eq:]) < -CONTACT_TOL_M:
        return None
    return sol


def _geometry(s: _Seating, chair: ChairConfig, init: InitialPose) -> _Geometry:
    edge = chair.seat_edge_x_m()
    deep = s.thigh_front + SEAT_DEPTH_MARGIN_M
    if init.hips_behind_seat_edge_m is not None:
        depth = (init.hips_behind_seat_edge_m,) * 2
    else:
        depth = (s.thigh_front - s.thigh_half, deep)
    feet = init.feet_ahead_of_seat_edge_m
    return _Geometry(chair.seat_top_z_m(), edge, depth, None if feet is None else edge + feet)


def _check_depth(s: _Seating, chair: ChairConfig, depth: float | None) -> None:
    """A given depth keeps the buttocks pad wholly on the seat (on a chair of one's own
    file, whose depth the program does not know, in front of its back only loosely)."""
    if depth is None:
        return
    low = -s.buttocks_span[0]
    high = SEAT_DEPTH_M - s.buttocks_span[1] if not chair.file else math.inf
    if not low <= depth <= high:
        raise ScenarioError(
            f"initial.hips_behind_seat_edge_m: {depth:g}; accepted: a number in "
            f"[{low:.3f}, {high:.3f}] m, the buttocks pad wholly on the "
            f"{SEAT_DEPTH_M:g} m deep seat, or null (as deep as the seat allows)"
        )


def seated_pose(plant: MultibodyPlant, robot, scenario: Scenario) -> SeatedPose:
    """The scenario's seated pose on plant (finalized, with its chair): as given
    (initial.joints_rad), else solved. Raises ScenarioError (one line) if the robot cannot
    sit on the chair, naming the seat heights it can sit on."""
    init, chair = scenario.initial, scenario.chair
    s = _Seating(plant, robot, init)
    if init.joints_rad is not None:
        joints = {**s.joints, **init.joints_rad}
        base = init.base_xyz_m or SEATED_BASE_XYZ_M
        return _placed_pose(s, base, joints, chair.seat_edge_x_m())
    _check_depth(s, chair, init.hips_behind_seat_edge_m)
    geo = _geometry(s, chair, init)
    sol = _solve(s, geo)
    if sol is None:
        raise ScenarioError(_cannot_sit(scenario))
    joints = dict(s.joints)
    for k, joint in enumerate(LEG_JOINTS):
        joints[f"l_{joint}"] = joints[f"r_{joint}"] = float(sol[k])
    base_xyz = [geo.edge - sol[3] - s.hip_x, 0.0, geo.top + s.buttocks_below_base]
    return _placed_pose(s, init.base_xyz_m or base_xyz, joints, geo.edge)


def _placed_pose(s: _Seating, base_xyz, joints: dict[str, float], edge: float) -> SeatedPose:
    """The pose of base_xyz and joints, its hips' and feet's places measured about the
    seat's edge."""
    base = RigidTransform(s.rotation, list(base_xyz))
    plant, context = s.plant, s.plant.CreateDefaultContext()
    plant.SetFreeBodyPose(context, s.root, base)
    for name, value in joints.items():
        plant.GetJointByName(name, s.instance).set_angle(context, value)
    hip = plant.GetJointByName("l_hip_pitch", s.instance).frame_on_parent()
    hip_x = hip.CalcPoseInWorld(context).translation()[0]
    feet_x = np.mean([f.CalcPoseInWorld(context).translation()[0] for f in s.soles])
    return SeatedPose(base, joints, float(edge - hip_x), float(feet_x - edge))


def _cannot_sit(scenario: Scenario) -> str:
    depth = scenario.initial.hips_behind_seat_edge_m
    low, high = seat_height_range(scenario.robot.model, depth)
    chair = scenario.chair
    if np.isnan(low):
        return (
            f"initial.hips_behind_seat_edge_m: {depth:g}; the {scenario.robot.model} cannot "
            "sit that far behind the seat's edge with its soles flat on the floor; accepted: "
            "null (as deep as the seat allows) or a depth it sits at on the shipped seat"
        )
    # A mesh's seat height is the mesh's (config/chair_kind.py with_chair_seat): name the file.
    key = f"chair.seat_height_m: {chair.seat_height_m:g}"
    if is_mesh(chair.file):
        key = f"chair.file: '{chair.file}' (its seat {chair.seat_height_m:g} m high)"
    return (
        f"{key}; the {scenario.robot.model} cannot sit "
        f"on this chair with its soles flat on the floor"
        + (" where initial.* place it" if _placed(scenario.initial) else "")
        + f"; accepted: a seat {low:.3f}-{high:.3f} m high (its top above the floor)"
    )


def _placed(init: InitialPose) -> bool:
    return init.hips_behind_seat_edge_m is not None or init.feet_ahead_of_seat_edge_m is not None


@functools.lru_cache(maxsize=16)
def seat_height_range(model: str, hips_behind_seat_edge_m: float | None = None) -> tuple:
    """(lowest, highest) seat top above the floor the model can sit on with its soles flat
    (the solved pose exists), to 1 mm, at that sitting depth (None: as deep as it can)."""
    init = InitialPose(hips_behind_seat_edge_m=hips_behind_seat_edge_m)
    s = _Seating(*_robot_plant(model), init)

    def sits(height: float) -> bool:
        chair = ChairConfig(seat_height_m=height)
        return _solve(s, _geometry(s, chair, init)) is not None

    nominal = SEATED_BASE_XYZ_M[2] - s.buttocks_below_base
    if not sits(nominal):
        return (float("nan"), float("nan"))

    def edge(inside: float, outside: float) -> float:
        while abs(outside - inside) > 5e-4:
            middle = (inside + outside) / 2
            inside, outside = (middle, outside) if sits(middle) else (inside, middle)
        return inside

    return (float(edge(nominal, 0.05)), float(edge(nominal, 0.6)))


def _robot_plant(model: str):
    """A plant with the model alone (the program needs no chair: its geometry is numbers)."""
    plant = MultibodyPlant(0.0)
    robot = add_icub(plant, model, reduce=True, visuals=False)
    plant.Finalize()
    return plant, robot
