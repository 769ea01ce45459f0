"""The CoM target as one chain: the segment, its min jerk, the lean, the compliance.

CoMReferenceGenerator (a system: psi is the advancement's continuous state) gives the CoM
path x_d(psi) and its time derivatives; CoMTarget (a plain object of the controller's
tick) leans it against the pull and, in the compliant response, yields it to the pull.

Each stand-up state k >= 2 moves the CoM along a min-jerk segment
    x_d(psi) = x_start + delta * s(tau),  tau = clamp((psi - psi_entry) / T, 0, 1),
    s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5,
and time derivatives follow by the chain rule ([tirupachuri2019]):
    xd_dot  = d_psi x_d * psi_dot
    xd_ddot = d2_psi x_d * psi_dot^2 + d_psi x_d * psi_ddot.
Segments start where the previous one ended (the state machine passes its end
as x_start) and s', s'' vanish at both ends, so value and slope are continuous.

A segment whose height follows the CoM (its height_follows entry; the phase's
com_height_follows, config/phases.py) gives x_d[2] = the measured CoM height, its rate
and acceleration 0: the height is not tracked there (the momentum task's z row only
damps the vertical motion), and the next segment starts at that height, where the
reference already is (transitions._enter).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.config import ComplianceConfig, ControllerConfig
from drake_standup.control.smooth import psi_clock_blend
from drake_standup.control.targets import StateReferences
from drake_standup.control.terms import RobotTerms
from drake_standup.ports.caching import declare_cached
from drake_standup.ports.payloads import SEGMENT
from drake_standup.robot.balance import static_lean
from drake_standup.robot.spatial import cross

SEGMENT_SIZE = SEGMENT.size  # [psi_entry, T, x_start (3), delta (3), height_follows]
_FOLLOWS = SEGMENT.index("height_follows")


def min_jerk(tau: float) -> tuple[float, float, float]:
    """s, ds/dtau, d2s/dtau2 of the min-jerk profile, clamped outside [0, 1]."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    t2, t3 = tau * tau, tau * tau * tau
    return (
        10 * t3 - 15 * t3 * tau + 6 * t3 * t2,
        30 * t2 - 60 * t3 + 30 * t2 * t2,
        60 * tau - 180 * t2 + 120 * t3,
    )


def path(segment: np.ndarray, psi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x_d, d_psi x_d and d2_psi x_d of one segment's min jerk at psi (its height as the
    segment gives it, whether or not the height follows the CoM: see reference_at)."""
    psi_entry, T = segment[0], segment[1]
    x_start, delta = segment[2:5], segment[5:8]
    s, ds, dds = min_jerk((psi - psi_entry) / T)
    return x_start + delta * s, delta * ds / T, delta * dds / (T * T)


def leaned(x_d: np.ndarray, lean: np.ndarray) -> np.ndarray:
    """The CoM target's position x_d leaned by lean (3: forward, sideways, down).

    Leaning is tilting about the feet: the target keeps its distance from the floor point
    below the unleaned one, so it drops as it leans (2 cm at a 15 cm lean; an unchanged
    height asked for legs longer than straight); lean[2] lowers it further (the arms
    braced stand lower)."""
    if not np.count_nonzero(lean):
        return x_d
    height = x_d[2]
    return np.array(
        [
            x_d[0] + lean[0],
            x_d[1] + lean[1],
            math.sqrt(max(height * height - lean[0] ** 2 - lean[1] ** 2, 0.0)) + lean[2],
        ]
    )


def height_follows(segment: np.ndarray) -> bool:
    """The segment's reference height is the measured CoM's (SEGMENT's height_follows)."""
    return bool(segment[_FOLLOWS] > 0.5)


def reference_at(segment: np.ndarray, psi: float, com_W: np.ndarray) -> np.ndarray:
    """The reference position x_d actually used at psi with the CoM measured at com_W: the
    segment's path, its height the CoM's where the segment's height follows it."""
    x_d = path(segment, psi)[0]
    if height_follows(segment):
        x_d[2] = com_W[2]
    return x_d


class CoMReferenceGenerator(LeafSystem):
    """Inputs psi, psi_dot, psi_ddot (1 each), segment (payloads.SEGMENT, from the state
    machine), com_W (3: the measured CoM, read where the segment's height follows it).

    Outputs com_reference (9: [x_d, xd_dot, xd_ddot], world), and x_d_W (3)
    and path_tangent_W (3: d_psi x_d), which depend on psi, segment and com_W only,
    so the advancement can use them without an algebraic loop; path_progress
    (1: (psi - psi_entry) / T in [0, 1], how far along the current segment). Where the
    segment's height follows the CoM: x_d[2] = com_W[2], its rate, acceleration and
    tangent 0.
    """

    def __init__(self):
        super().__init__()
        self._psi = self.DeclareVectorInputPort("psi", 1)
        self._psi_dot = self.DeclareVectorInputPort("psi_dot", 1)
        self._psi_ddot = self.DeclareVectorInputPort("psi_ddot", 1)
        self._segment = self.DeclareVectorInputPort("segment", SEGMENT_SIZE)
        self._com = self.DeclareVectorInputPort("com_W", 3)
        # Where psi is outside its segment the path is the segment's start or end:
        # (segment bytes, end) -> path(), computed once (most of a run; read only).
        self._clamped: dict[tuple[bytes, bool], tuple[np.ndarray, ...]] = {}
        # The path depends on psi and the segment only: evaluated once per
        # change of them for all four outputs.
        self._path = declare_cached(
            self, "path at psi", self._calc_path, {self._psi.ticket(), self._segment.ticket()}
        )
        path_only = {self._path.ticket()}
        # The measured height: read only while the segment's height follows it.
        with_com = path_only | {self._segment.ticket(), self._com.ticket()}
        self.DeclareVectorOutputPort(
            "com_reference",
            9,
            self._CalcReference,
            prerequisites_of_calc=with_com | {self._psi_dot.ticket(), self._psi_ddot.ticket()},
        )
        self.DeclareVectorOutputPort("x_d_W", 3, self._CalcPosition, prerequisites_of_calc=with_com)
        self.DeclareVectorOutputPort(
            "path_tangent_W", 3, self._CalcTangent, prerequisites_of_calc=path_only
        )
        self.DeclareVectorOutputPort(
            "path_progress", 1, self._CalcProgress, prerequisites_of_calc=path_only
        )

    def _calc_path(self, context: Context) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """x_d, d_psi x_d, d2_psi x_d and the progress along the segment at psi."""
        segment = self._segment.Eval(context)
        psi = self._psi.Eval(context)[0]
        tau = (psi - segment[0]) / segment[1]
        progress = min(max(tau, 0.0), 1.0)
        if not (tau <= 0.0 or tau >= 1.0):  # min_jerk's own test (NaN: computed)
            x_d, d_x, dd_x = path(segment, psi)
            if height_follows(segment):  # the height is not the path's: no slope in z
                d_x[2] = dd_x[2] = 0.0
            return x_d, d_x, dd_x, progress
        # min_jerk is constant there: path() of the segment at its start or end.
        key = (segment.tobytes(), tau >= 1.0)
        clamped = self._clamped.get(key)
        if clamped is None:
            if len(self._clamped) > 64:
                self._clamped.clear()
            clamped = self._clamped[key] = path(segment, psi)  # d_x, dd_x: 0
            for array in clamped:
                array.flags.writeable = False
        return (*clamped, progress)

    def _position(self, context: Context) -> np.ndarray:
        """x_d: the path's, its height the measured CoM's where the segment follows it."""
        x_d = self._path.Eval(context)[0]
        if height_follows(self._segment.Eval(context)):
            x_d = x_d.copy()
            x_d[2] = self._com.Eval(context)[2]
        return x_d

    def _CalcReference(self, context: Context, output: BasicVector) -> None:
        _, d_x, dd_x, _ = self._path.Eval(context)
        psi_dot = self._psi_dot.Eval(context)[0]
        psi_ddot = self._psi_ddot.Eval(context)[0]
        output.SetFromVector(
            np.concatenate(
                [self._position(context), d_x * psi_dot, dd_x * psi_dot**2 + d_x * psi_ddot]
            )
        )

    def _CalcPosition(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self._position(context))

    def _CalcTangent(self, context: Context, output: BasicVector) -> None:
        d_x = self._path.Eval(context)[1]
        output.SetFromVector(d_x)

    def _CalcProgress(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._path.Eval(context)[3])


class CoMTarget:
    """The CoM reference the momentum task tracks this tick: x_d(psi), leaned against the
    measured pull where the feet alone carry the robot, and moved by the compliant
    response's admittance (standup/task_references.py's docstring)."""

    def __init__(
        self,
        config: ControllerConfig,
        period_s: float,
        gravity_mps2: float,
        compliance: ComplianceConfig | None = None,
        standing_need: Callable | None = None,
        usage_limit: float = 1.0,
    ):
        """compliance: the admittance of the compliant response (default: its defaults);
        standing_need(F_hand_W, weight_N): what the pull asks of the standing feet, (d,
        reach) or None (sensing.standing_lean), and usage_limit the share of their reach
        the compliant offset may use (None: the box alone)."""
        self._config = config
        self._period_s = period_s
        self._gravity_mps2 = gravity_mps2
        self._standing_need = standing_need
        self._usage_limit = usage_limit
        compliance = compliance or ComplianceConfig()
        mass, stiffness = compliance.virtual_mass_kg, compliance.stiffness_N_per_m
        self._admittance = (
            mass,
            2.0 * compliance.damping_ratio * math.sqrt(stiffness * mass),
            stiffness,
            np.array(compliance.max_offset_m),
        )

    def target(
        self,
        terms: RobotTerms,
        state: StateReferences,
        com_reference: np.ndarray,
        tau_hand: np.ndarray | None,
        F_hand_W: np.ndarray | None,
        lean_W: np.ndarray | None,
        *,
        compliance: np.ndarray,
        compliant: bool,
        psi_dot: float = 1.0,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(the CoM target [x, xdot, xddot] (9,), the lean after this tick (3), the
        admittance's [offset, rate] after it (6)). com_reference: x_d(psi) and its
        derivatives; tau_hand = J_h^T F_hand (None: no pull); lean_W, compliance: their
        values before the tick; compliant: the response yields to the pull; psi_dot: the
        lean filter's clock, as the posture's (never slower than time)."""
        lean = self._lean(terms, state, tau_hand, lean_W, psi_dot)
        if np.count_nonzero(lean):
            com_reference = com_reference.copy()
            com_reference[:3] = leaned(com_reference[:3], lean)
        pulled = F_hand_W is not None and compliant
        next_compliance = compliance
        if pulled or np.count_nonzero(compliance):
            anchor = np.zeros(3)
            if pulled:
                bounds = self.offset_bounds(state, F_hand_W, terms.mass_kg * self._gravity_mps2)
                anchor = np.clip((F_hand_W[3:6] + F_hand_W[9:12]) / self._admittance[2], *bounds)
            next_compliance = self._yield(anchor, compliance)
            com_reference = com_reference + np.concatenate(
                (
                    next_compliance,
                    (next_compliance[3:] - compliance[3:]) / self._period_s,
                )
            )
        return com_reference, lean, next_compliance

    def _lean(
        self,
        terms: RobotTerms,
        state: StateReferences,
        tau_hand: np.ndarray | None,
        lean_W: np.ndarray | None,
        psi_dot: float = 1.0,
    ) -> np.ndarray:
        """tau_hand: the hands' generalized force J_h^T F_hand (None: no pull), whose first
        six entries are their resultant about the base origin (control/terms.py).

        The lean's next value: static_lean of the measured pull, bounded forward and
        back by the feet (lean_max_forward_m, lean_max_back_m; lean_max_m sideways),
        first-order filtered (lean_filter_time_constant_s), in the states that stand on
        the feet alone; it decays back to zero in the others and when the pull stops."""
        lean = np.zeros(3) if lean_W is None else lean_W
        target = np.zeros(3)
        if state.lean and tau_hand is not None:
            wrench = tau_hand[:6].copy()
            wrench[:3] -= cross(terms.p_BoCom, wrench[3:])
            target = static_lean(
                wrench,
                float(terms.p_WCom[2]),
                terms.mass_kg * self._gravity_mps2,
                self._config.lean_max_m,
            )
            target[0] = min(
                max(target[0], -self._config.lean_max_back_m), self._config.lean_max_forward_m
            )
        if state.lean:
            target[2] = state.com_height_offset_m
        # count_nonzero: .any() of a 3-vector costs ~5x more (NaN counts in both).
        if not (np.count_nonzero(target) or np.count_nonzero(lean)):
            return lean
        blend = psi_clock_blend(self._period_s, self._config.lean_filter_time_constant_s, psi_dot)
        return lean + blend * (target - lean)

    def offset_bounds(
        self, state: StateReferences, F_hand_W: np.ndarray, weight_N: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) of where the compliant offset may settle this tick (the anchor of
        _yield): within compliance.max_offset_m; horizontally, only as far as the
        standing feet could hold the pull with the CoM moved by x: the lean the pull then
        needs, d - x (standing_need: d and the feet's reach, judged on the robot standing
        whatever its posture now, as the stand-up's wait is), within standup.
        standing_pull_usage_limit of their reach, or x settles at 0 on that side; and, on
        the feet alone (the states that lean), not above the path: the legs carry the rise
        on the path's own timing (an upward yield ran the CoM 1.2 cm past the erect height
        at the rise's end, at a 1 ms step; measured)."""
        box = self._admittance[3]
        low, high = -box.copy(), box.copy()
        need = None if self._standing_need is None else self._standing_need(F_hand_W, weight_N)
        if need is not None:
            d, (forward, back, side) = need
            limit = self._usage_limit
            high[:2] = np.minimum(high[:2], np.maximum(0.0, d[:2] + limit * np.array([back, side])))
            low[:2] = np.maximum(
                low[:2], np.minimum(0.0, d[:2] - limit * np.array([forward, side]))
            )
        if state.lean:
            high[2] = 0.0
        return low, high

    def _yield(self, anchor: np.ndarray, compliance: np.ndarray) -> np.ndarray:
        """The admittance's next [offset, rate] (6,) from this tick's [offset, rate], by
        semi-implicit Euler, pulled toward anchor (3: where the pull alone would hold the
        offset, f / K within offset_bounds; 0 with no pull): so the offset follows a
        bound that moves as smoothly as it follows a pull, critically damped, instead of
        jumping to it. compliance.max_offset_m holds it in any case, with no rate outward
        there."""
        mass, damping, stiffness, box = self._admittance
        x, v = compliance[:3], compliance[3:]
        force = -damping * v - stiffness * (x - anchor)
        v_next = v + (self._period_s / mass) * force
        x_next = x + self._period_s * v_next
        held = np.clip(x_next, -box, box)
        outward = (held != x_next) & (v_next * x_next > 0.0)
        v_next[outward] = 0.0
        return np.concatenate((held, v_next))
