"""The reactive partner: a person guiding each of the robot's hands, as forces from what
they see of the robot (HumanWrenchSource, helper/hands.py, evaluates them):
- velocity guide (reactive_force): along a direction at a pace, from wherever they saw
  the hand; they follow a hand that outruns them, still pulling it (lead_min ahead).
- path guide (path_force): along a path in the sagittal plane at a pace, between
  lead_min and lead_max ahead of the hand, only forwards along the path.
Both decide on what they saw reaction_time_s ago (the caller's `seen`), act on the hand
now through their arm's impedance, are capped, and let go once the robot is up (eased).
"""

from __future__ import annotations

import math

import numpy as np

from drake_standup.config import ReactiveHumanConfig


def trapezoid(t: float, start_s: float, duration_s: float, ramp_s: float) -> float:
    """0 -> 1 over ramp_s from start_s, 1, then 1 -> 0 over the last ramp_s."""
    local = t - start_s
    if local <= 0.0 or local >= duration_s:
        return 0.0
    if ramp_s <= 0.0:
        return 1.0
    return min(1.0, local / ramp_s, (duration_s - local) / ramp_s)


def eased(cfg: ReactiveHumanConfig, t: float, com_rise_m: float) -> float:
    """The pull's scale: its trapezoid in time, faded out while the robot's CoM (as the
    person sees it) rises through ease_com_rise_m: they let go once it is up."""
    scale = trapezoid(t, cfg.start_s, cfg.duration_s, cfg.ramp_s)
    low, high = cfg.ease_com_rise_m
    return scale * min(1.0, max(0.0, (high - com_rise_m) / (high - low)))


def reactive_force(
    cfg: ReactiveHumanConfig,
    t: float,
    p_hand: np.ndarray,
    v_hand: np.ndarray,
    p_start: np.ndarray,
    com_rise_m: float = 0.0,
    *,
    seen: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """A person guiding one hand along the direction u of target_velocity_mps, capped. N.

    Their own progress along u is the pace |v| (t - start), at most travel_m. They move
    the hand from where they saw it (seen: its position and velocity reaction_time_s
    ago; None: now) to that progress, and follow a hand that outruns it keeping lead_min_m
    ahead of it (their grip's pull; only while their reach, travel_m, lasts):
        s_target = max(s_pace, min(s_seen + lead_min, max(travel, s_seen))),
        target = p_seen + (s_target - s_seen) u,
    so a hand that outruns them, or swings across u, is followed and still helped, never
    pulled back to a line in space; their arm's impedance acts on the hand now, along u
    (across it their arm yields):
        F = [(K (target - p_hand) + D (v_target - v_hand)) . u] u,
    v_target the target's velocity: the hand's as seen, at least the pace along u (a
    person leading a hand that moves faster than their pace follows its speed: the
    pace follows the robot's rise). Faded by eased (they let go once the robot is up).
    """
    scale = eased(cfg, t, com_rise_m)
    if scale == 0.0:
        return np.zeros(3)
    p_seen, v_seen = (p_hand, v_hand) if seen is None else seen
    v_pace = np.asarray(cfg.target_velocity_mps, dtype=float)
    speed = float(np.linalg.norm(v_pace))
    u = v_pace / speed if speed > 0 else np.zeros(3)
    walked = speed * (t - cfg.start_s)
    s_pace = min(walked, cfg.travel_m)
    s_seen = float((p_seen - p_start) @ u)
    # Following a hand that outruns their pace they keep lead_min_m ahead of it (their
    # grip's pull, as the path guide does) until their reach, travel_m, is used up.
    s_follow = min(s_seen + cfg.lead_min_m, max(cfg.travel_m, s_seen))
    ahead = max(s_pace, s_follow) - s_seen
    target, v_target = p_seen, v_seen
    if ahead > 0.0:  # the person leads the hand along u, never slower than they see it go
        pacing = speed if walked < cfg.travel_m and s_pace >= s_follow else 0.0
        target = p_seen + ahead * u
        v_target = v_seen + max(pacing - float(v_seen @ u), 0.0) * u
    # Along u only: across it the person's arm yields (a spring there, to where they saw
    # the hand 0.2 s ago, rang the robot's light arms sideways at +-13 N; measured).
    along = cfg.stiffness_N_per_m * (target - p_hand) + cfg.damping_Ns_per_m * (v_target - v_hand)
    f = float(along @ u) * u
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
    *,
    com_rise_m: float,
    seen: tuple[np.ndarray, np.ndarray] | None = None,
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
    rises through ease_com_rise_m (eased). The person decides s_t from what they
    saw (seen: the hand's position and velocity reaction_time_s ago; None: now),
    so s_h and its rate in s_t are those; the pull acts on the hand now.
    """
    scale = eased(cfg, t, com_rise_m)
    if scale == 0.0:
        return np.zeros(3)
    s_hand, tangent = path.project(_xz(p_hand - p_start))
    s_dot_hand = float(_xz(v_hand) @ tangent)
    s_seen, s_dot_seen = s_hand, s_dot_hand
    if seen is not None:  # where the person saw the hand, reaction_time_s ago
        s_seen, tangent_seen = path.project(_xz(seen[0] - p_start))
        s_dot_seen = float(_xz(seen[1]) @ tangent_seen)
    s_pace = cfg.pace_mps * (t - cfg.start_s)
    if s_pace > s_seen + cfg.lead_max_m:  # the person waits for the hand
        s_target, s_dot_target = s_seen + cfg.lead_max_m, s_dot_seen
    elif s_pace < s_seen + cfg.lead_min_m:  # the person follows the hand
        s_target, s_dot_target = s_seen + cfg.lead_min_m, s_dot_seen
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
