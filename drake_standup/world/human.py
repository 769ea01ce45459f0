"""HumanWrenchSource: the helper's hands on the robot's hands.

Two humans: 'scripted' applies the scenario's pulls (trapezoids in time, each
on one hand, constant world direction); 'reactive' guides each hand, like a
person helping the robot up, in one of two ways (reactive.guide):
- velocity: an impedance pulling toward a target that leaves from where the
  hand was and moves up and forward at a constant velocity, force capped.
- path: a person walking the hand along a path at a human pace, following the
  robot: the target stays between lead_min and lead_max ahead of the hand
  along the path, the pull acts along the path only and only forwards along
  it, capped, and eases off once the robot is up (path_force).
The wrench acts at the origin of the hand task frame (the hand's DH frame).
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.common.value import Value
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.config import HumanConfig, Pull, ReactiveHumanConfig
from drake_standup.ports.caching import declare_cached
from drake_standup.robot.icub import Robot

HANDS = {"left": 0, "right": 1}
TASK_FRAMES = ("l_hand", "r_hand")
# HelperWork's output, entry by entry (signals.npz and metrics.json name them so).
HELPER_SPENT = (
    "helper_work_J",
    "helper_positive_work_J",
    "helper_impulse_Ns",
    "helper_peak_force_N",
)


def hand_forces(plant: MultibodyPlant, robot: Robot) -> list[ExternallyAppliedSpatialForce]:
    """One applied force per hand (TASK_FRAMES), at the hand frame's origin; a human
    source sets their forces each time it outputs them (spatial_forces)."""
    applied = []
    for name in TASK_FRAMES:
        frame = robot.frame(plant, name)
        force = ExternallyAppliedSpatialForce()
        force.body_index = frame.body().index()
        force.p_BoBq_B = frame.GetFixedPoseInBodyFrame().translation()
        applied.append(force)
    return applied


def spatial_forces(
    applied: list[ExternallyAppliedSpatialForce], hand_wrenches_W: np.ndarray
) -> list[ExternallyAppliedSpatialForce]:
    """applied (hand_forces) set to the forces of hand_wrenches_W = [0, f_l, 0, f_r], the
    pulled hands only (none while nobody pulls: the plant then has nothing to apply)."""
    pulled = []
    for force, f in zip(applied, (hand_wrenches_W[3:6], hand_wrenches_W[9:12])):
        if np.count_nonzero(f):
            force.F_Bq_W = SpatialForce(np.zeros(3), f)
            pulled.append(force)
    return pulled


def trapezoid(t: float, start_s: float, duration_s: float, ramp_s: float) -> float:
    """0 -> 1 over ramp_s from start_s, 1, then 1 -> 0 over the last ramp_s."""
    local = t - start_s
    if local <= 0.0 or local >= duration_s:
        return 0.0
    if ramp_s <= 0.0:
        return 1.0
    return min(1.0, local / ramp_s, (duration_s - local) / ramp_s)


def scripted_forces(pulls: list[Pull], t: float) -> np.ndarray:
    """(2, 3) world forces on the left and right hand at time t. N."""
    forces = np.zeros((2, 3))
    for pull in pulls:
        scale = trapezoid(t, pull.start_s, pull.duration_s, pull.ramp_s)
        forces[HANDS[pull.hand]] += scale * np.asarray(pull.force_N)
    return forces


def reactive_force(
    cfg: ReactiveHumanConfig, t: float, p_hand: np.ndarray, v_hand: np.ndarray, p_start: np.ndarray
) -> np.ndarray:
    """Impedance pull of one hand toward its moving target, capped. N."""
    scale = trapezoid(t, cfg.start_s, cfg.duration_s, cfg.ramp_s)
    if scale == 0.0:
        return np.zeros(3)
    v_target = np.asarray(cfg.target_velocity_mps)
    speed = np.linalg.norm(v_target)
    travel = min(speed * (t - cfg.start_s), cfg.travel_m)
    direction = v_target / speed if speed > 0 else np.zeros(3)
    target = p_start + travel * direction
    f = cfg.stiffness_N_per_m * (target - p_hand) - cfg.damping_Ns_per_m * v_hand
    norm = np.linalg.norm(f)
    if norm > cfg.force_cap_N:
        f *= cfg.force_cap_N / norm
    return scale * f


# Largest turn of one segment of a rounded corner: a hand 0.1 m inside the
# arc sees its closest point jump 2 (0.1 m) tan(0.5 deg) = 1.7 mm per vertex. rad.
ARC_STEP_RAD = math.radians(1.0)


def _round_corners(points: np.ndarray, radius: float) -> np.ndarray:
    """points with each interior corner replaced by a circular arc of radius
    (less where a leg is too short: the arc takes at most half of each leg),
    as segments turning ARC_STEP_RAD at most."""
    if radius <= 0.0 or len(points) < 3:
        return points
    out = [points[0]]
    for before, corner, after in zip(points[:-2], points[1:-1], points[2:]):
        a, b = corner - before, after - corner
        la, lb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        a, b = a / la, b / lb
        turn = math.acos(min(1.0, max(-1.0, float(a @ b))))
        if turn < 1e-6 or turn > math.pi - 1e-6:
            out.append(corner)
            continue
        cut = min(radius * math.tan(turn / 2), 0.5 * la, 0.5 * lb)
        r = cut / math.tan(turn / 2)
        centre = corner + (r / math.cos(turn / 2)) * (b - a) / float(np.linalg.norm(b - a))
        u0, u1 = corner - cut * a - centre, corner + cut * b - centre
        phi0 = math.atan2(u0[1], u0[0])
        sweep = (math.atan2(u1[1], u1[0]) - phi0 + math.pi) % (2 * math.pi) - math.pi
        n = max(1, math.ceil(abs(sweep) / ARC_STEP_RAD))
        for k in range(n + 1):
            phi = phi0 + sweep * k / n
            out.append(centre + r * np.array([math.cos(phi), math.sin(phi)]))
    out.append(points[-1])
    return np.array(out)


class Path:
    """A polyline in the sagittal (x, z) plane from [0, 0] through waypoints,
    its corners rounded to corner_radius_m, parametrised by arc length s.

    Rounded, the hand's closest point moves continuously as the hand passes
    inside a corner (at a sharp corner it jumps from one leg to the next, and
    the pull's direction with it) as long as the hand stays closer to the path
    than the radius."""

    def __init__(self, waypoints_xz: list[list[float]], corner_radius_m: float = 0.0):
        sharp = np.vstack([np.zeros(2), np.asarray(waypoints_xz, dtype=float)])
        self.points = _round_corners(sharp, corner_radius_m)
        self.lengths = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        self.s_start = np.concatenate([[0.0], np.cumsum(self.lengths)])
        self.length = float(self.s_start[-1])
        self.tangents = np.diff(self.points, axis=0) / self.lengths[:, None]

    def point(self, s: float) -> np.ndarray:
        """The path's point at arc length s (clamped to the path). (x, z)."""
        s = min(max(s, 0.0), self.length)
        i = min(int(np.searchsorted(self.s_start, s, side="right")) - 1, len(self.lengths) - 1)
        return self.points[i] + (s - self.s_start[i]) * self.tangents[i]

    def project(self, p: np.ndarray) -> tuple[float, np.ndarray]:
        """(s, unit tangent) of the path's point closest to p (x, z); of two
        equally close, the first along the path."""
        a = self.points[:-1]
        u = np.clip(np.einsum("ij,ij->i", p - a, self.tangents), 0.0, self.lengths)
        d = np.linalg.norm(p - (a + u[:, None] * self.tangents), axis=1)
        i = int(np.argmin(d))
        return float(self.s_start[i] + u[i]), self.tangents[i]


def _xz(v: np.ndarray) -> np.ndarray:
    return np.array([v[0], v[2]])


def path_force(
    cfg: ReactiveHumanConfig,
    path: Path,
    t: float,
    p_hand: np.ndarray,
    v_hand: np.ndarray,
    p_start: np.ndarray,
    com_rise_m: float,
) -> np.ndarray:
    """A person walking one hand along path (from p_start), capped. World, N.

    The hand's progress s_h is its closest point on the path (its sideways
    position is ignored). The person's own progress would be pace (t - start),
    but they never get more than lead_max ahead of the hand (no yank) and
    keep at least lead_min ahead (they follow a hand that outruns them with a
    light pull), never past the path's end:
        s_t = min(L, clip(pace (t - start), s_h + lead_min, s_h + lead_max)).
    The pull K (s_t - s_h) + D (ds_t/dt - ds_h/dt), clipped to [0, cap], acts
    along the path from the hand's closest point toward the target's point
    (the path's tangent, turning with it through a corner): only forwards
    along the path, no force across it or sideways. It fades in and out with
    the trapezoid (start_s, duration_s, ramp_s) and fades out while the CoM
    rises through ease_com_rise_m.
    """
    scale = trapezoid(t, cfg.start_s, cfg.duration_s, cfg.ramp_s)
    low, high = cfg.ease_com_rise_m
    scale *= min(1.0, max(0.0, (high - com_rise_m) / (high - low)))
    if scale == 0.0:
        return np.zeros(3)
    s_hand, tangent = path.project(_xz(p_hand - p_start))
    s_dot_hand = float(_xz(v_hand) @ tangent)
    s_pace = cfg.pace_mps * (t - cfg.start_s)
    if s_pace > s_hand + cfg.lead_max_m:  # the person waits for the hand
        s_target, s_dot_target = s_hand + cfg.lead_max_m, s_dot_hand
    elif s_pace < s_hand + cfg.lead_min_m:  # the person follows the hand
        s_target, s_dot_target = s_hand + cfg.lead_min_m, s_dot_hand
    else:
        s_target, s_dot_target = s_pace, cfg.pace_mps
    if s_target >= path.length:  # the person stops at the path's end
        s_target, s_dot_target = path.length, 0.0
    pull = cfg.stiffness_N_per_m * (s_target - s_hand) + cfg.damping_Ns_per_m * (
        s_dot_target - s_dot_hand
    )
    pull = min(max(pull, 0.0), cfg.force_cap_N)
    chord = path.point(s_target) - path.point(s_hand)
    norm = float(np.linalg.norm(chord))
    direction = chord / norm if norm > 1e-9 else tangent
    return scale * pull * np.array([direction[0], 0.0, direction[1]])


class HumanWrenchSource(LeafSystem):
    """Outputs spatial_forces (for the plant's applied_spatial_force input)
    and hand_wrenches_W (12: [torque_l, force_l, torque_r, force_r]), the same
    wrenches as the robot's wrist sensors would measure them.

    Input robot_state [q; v] (used by the reactive human only).
    """

    def __init__(self, plant: MultibodyPlant, robot: Robot, config: HumanConfig):
        super().__init__()
        self._cfg = config
        self._plant = plant
        self._instance = robot.model_instance
        self._context = plant.CreateDefaultContext()
        self._frames = [robot.frame(plant, name) for name in TASK_FRAMES]
        self._applied = hand_forces(plant, robot)
        nx = plant.num_multibody_states(self._instance)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        prereq = {self.time_ticket()}
        self._path = None
        if config.mode == "reactive":
            # Where the hands are at t = 0: the targets leave from there (the
            # robot sits still until the pull starts); and the CoM height then,
            # from which the path guide sees the robot rise.
            if config.reactive.guide == "path":
                r = config.reactive
                self._path = Path(r.path_xz_m, r.path_corner_radius_m)
            self._start_index = self.DeclareDiscreteState(7)
            self.DeclareInitializationDiscreteUpdateEvent(self._CaptureStart)
            prereq |= {self._state.ticket(), self.all_state_ticket()}
        # The scripted pulls are a function of time alone: the last time and
        # its wrenches, because the integrator sets each step's end time twice
        # (its last stage, then the step's end), which Drake counts as a change.
        self._last_scripted: tuple[float, np.ndarray] | None = None
        # The pulls as _wrenches sums them: (start, duration, ramp, their rows of
        # hand_wrenches_W, force).
        self._pulls = [
            (
                pull.start_s,
                pull.duration_s,
                pull.ramp_s,
                slice(6 * HANDS[pull.hand] + 3, 6 * HANDS[pull.hand] + 6),
                np.asarray(pull.force_N, dtype=float),
            )
            for pull in (config.pulls if config.mode == "scripted" else [])
        ]
        # Both outputs read one evaluation of the human per time (and state):
        # hand_wrenches_W itself, (12,).
        self._wrenches_cache = declare_cached(self, "hand wrenches", self._wrenches, prereq)
        prereq = {self._wrenches_cache.ticket()}
        self.DeclareVectorOutputPort(
            "hand_wrenches_W", 12, self._CalcWrenches, prerequisites_of_calc=prereq
        )
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
            self._CalcSpatialForces,
            prerequisites_of_calc=prereq,
        )

    def _hands(self, context: Context) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """World positions and velocities of the hand frames' origins."""
        plant, c = self._plant, self._context
        plant.SetPositionsAndVelocities(c, self._instance, self._state.Eval(context))
        world = plant.world_frame()
        p = [f.CalcPoseInWorld(c).translation() for f in self._frames]
        v = [f.CalcSpatialVelocity(c, world, world).translational() for f in self._frames]
        return p, v

    def _com_height(self) -> float:
        """The robot's CoM height in the context _hands last set. m."""
        com = self._plant.CalcCenterOfMassPositionInWorld(self._context, [self._instance])
        return float(com[2])

    def _CaptureStart(self, context: Context, discrete_state) -> None:
        p, _ = self._hands(context)
        discrete_state.set_value(self._start_index, np.concatenate([*p, [self._com_height()]]))

    def _forces(self, context: Context) -> np.ndarray:
        """(2, 3) world forces on the left and right hand. N."""
        t = context.get_time()
        if self._cfg.mode == "scripted":
            return scripted_forces(self._cfg.pulls, t)
        captured = context.get_discrete_state(self._start_index).value()
        start = captured[:6].reshape(2, 3)
        r = self._cfg.reactive
        if not r.start_s < t < r.start_s + r.duration_s:
            return np.zeros((2, 3))  # no kinematics needed outside the pull
        p, v = self._hands(context)
        if self._path is not None:
            rise = self._com_height() - captured[6]
            return np.array(
                [path_force(r, self._path, t, p[i], v[i], start[i], rise) for i in range(2)]
            )
        return np.array(
            [reactive_force(self._cfg.reactive, t, p[i], v[i], start[i]) for i in range(2)]
        )

    def _wrenches(self, context: Context) -> np.ndarray:
        """hand_wrenches_W (12,): [0, f_l, 0, f_r]."""
        if self._cfg.mode != "scripted":
            wrenches = np.zeros(12)
            wrenches.reshape(2, 6)[:, 3:] = self._forces(context)
            return wrenches
        t = context.get_time()
        if self._last_scripted is not None and self._last_scripted[0] == t:
            return self._last_scripted[1]
        # scripted_forces' sums, straight into the wrenches (a pull at scale 0 adds
        # nothing: no entry is ever -0.0).
        wrenches = np.zeros(12)
        for start_s, duration_s, ramp_s, rows, force in self._pulls:
            scale = trapezoid(t, start_s, duration_s, ramp_s)
            if scale != 0.0:
                wrenches[rows] += scale * force
        self._last_scripted = t, wrenches
        return wrenches

    def _CalcWrenches(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self._wrenches_cache.Eval(context))

    def _CalcSpatialForces(self, context: Context, output) -> None:
        output.set_value(spatial_forces(self._applied, self._wrenches_cache.Eval(context)))


class HelperWork(LeafSystem):
    """What the helper spends on the robot, as the discrete plant integrates it.

    Inputs hand_positions_W (6: the left and right hand frame's origin, where the pull
    acts, hand_forces; sensing.py) and hand_wrenches_W (12: the pull applied, [0, f_l,
    0, f_r]). Updated at every plant step t_n (period step_s): the plant holds the pull
    of t_n over its step, so the step's work is f_n . (p_{n+1} - p_n) per hand. Output
    helper_spent (4): [work J, its positive part J (per step, max(work, 0)), impulse
    N s (sum of |f_l| + |f_r| times the step), peak |f| of either hand N], over the
    steps taken so far. The hands' positions are read (and kept) only at the steps
    that begin or end under a pull."""

    def __init__(self, step_s: float):
        super().__init__()
        self._step_s = step_s
        self._positions = self.DeclareVectorInputPort("hand_positions_W", 6)
        self._wrenches = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        # [totals (4), p_l, p_r at the last step (6), f_l, f_r held since (6), started].
        self._memory = self.DeclareDiscreteState(17)
        self.DeclareVectorOutputPort(
            "helper_spent",
            4,
            self._CalcSpent,
            prerequisites_of_calc={self.discrete_state_ticket(self._memory)},
        )
        self.DeclarePeriodicDiscreteUpdateEvent(step_s, 0.0, self._Update)

    def _CalcSpent(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(context.get_discrete_state(self._memory).value()[:4])

    def _Update(self, context: Context, discrete_state) -> None:
        # In place (discrete_state holds the current values): a plant step's Python is
        # the closed loop's cost, so no numpy temporaries where floats do (the norms'
        # sums in numpy's order, (a + b) + c: bitwise the same totals).
        memory = discrete_state.get_mutable_value(self._memory)
        F = self._wrenches.Eval(context)
        pulled = np.count_nonzero(F) > 0
        held = memory[16] and np.count_nonzero(memory[10:16]) > 0
        # The hands' positions only where a pull was held over the step just taken or is
        # held over the next: without one a step spends nothing, whatever they did.
        p = self._positions.Eval(context) if held or pulled else None
        if held:  # the step just taken, under the pull held since the last one
            work = float(memory[10:16] @ (p - memory[4:10]))
            memory[0] += work
            memory[1] += max(work, 0.0)
            fx, fy, fz, gx, gy, gz = memory[10:16].tolist()
            held_l = math.sqrt((fx * fx + fy * fy) + fz * fz)
            held_r = math.sqrt((gx * gx + gy * gy) + gz * gz)
            memory[2] += (held_l + held_r) * self._step_s
            memory[3] = max(memory[3], max(held_l, held_r))
        if p is not None:
            memory[4:10] = p
        memory[10:13], memory[13:16], memory[16] = F[3:6], F[9:12], 1.0
