"""TrajectoryAdvancement: the free parameter psi as continuous state.

psi(0) = 0 and, while the human's interaction helps,
    psi_dot = min{ psi_dot_upper, max{ 1, ratio } }
with ([tirupachuri2019]; t = d_psi x_d the path tangent, Omega f the CoM acceleration the
measured hand wrenches cause, xdot the measured CoM velocity):
    tangent law (the paper's proposition):   ratio = xdot.t / (|t|^2 + eps)
    interaction law (the authors' code):     ratio = (xdot.Omega f)(t.Omega f)
                                                     / ((t.Omega f)^2 + eps)
The interaction helps when alpha = t.Omega f / |t| (the part of Omega f along
the desired velocity) exceeds alpha_min; otherwise, and with advancement
disabled, or with a response other than advancement (config.RESPONSES), psi_dot = 1
and psi = t. psi therefore never runs backwards nor
faster than psi_dot_upper.

Lead gate (ours, on by default): the law also waits until the CoM is not behind
its reference along the path, lead = (x - x_d).t/|t| >= -lag_tolerance. The
ratio sets the reference's speed to the CoM's; with a finite-gain tracker,
advancing while the CoM lags closes a positive loop (x_d ahead -> K_P pushes ->
the CoM speeds up -> psi runs further ahead), which in our closed loop threw the
robot forward at the start of state 4. Advancing only on a lead keeps the
reference where the help has already brought the robot.

Graded gates (ours): the paper's law is on or off (alpha > alpha_min). With a
tracker that follows its reference (feed-forward xd_ddot), xdot = psi_dot t, so
ratio = psi_dot: any psi_dot sustains itself, and the smallest helpful pull ran
psi_dot to its bound (5 N per hand: 2.47 of 2.5; the stand-up time jumped 0.87 s
between 0 and 5 N, measured). So the law's excess over 1 is weighted,

    psi_dot = 1 + w g s (clip(ratio, 1, upper) - 1),
    w = min(1, (alpha - alpha_min) / (alpha_full - alpha_min)),
    g = min(1, 1 + lead / lag_tolerance)   (0 at a lag of lag_tolerance),
    s = 1 - smoothstep((progress - taper_from) / (1 - taper_from))   (segment's end),

and with ratio = psi_dot + e (e: the CoM's speed-up the help causes, in psi
units) the rate settles at psi_dot - 1 = e w g / (1 - w g): growing with the
help, the paper's law (w = g = s = 1) from alpha_full on, psi = t without help.
The taper s returns psi_dot to 1 before each segment ends (a rise ending at
psi_dot 2.5 drove the knees onto their stop, measured).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
from pydrake.systems.framework import BasicVector, Context, ContinuousState, LeafSystem

from drake_standup.config import AdvancementConfig
from drake_standup.control.smooth import smoothstep
from drake_standup.ports.caching import declare_cached
from drake_standup.standup.com_path import leaned

# The tangent of a phase that holds psi = t (read only).
_NO_TANGENT = np.zeros(3)
_NO_TANGENT.flags.writeable = False


def for_robot(config: AdvancementConfig, mass_kg: float) -> AdvancementConfig:
    """config with alpha_full_mps2 derived where it is None: the CoM acceleration
    full_help_pull_N on each hand along the path gives a robot of mass_kg."""
    if config.alpha_full_mps2 is not None:
        return config
    return dataclasses.replace(config, alpha_full_mps2=2.0 * config.full_help_pull_N / mass_kg)


def helpfulness(tangent: np.ndarray, omega_f: np.ndarray, eps: float) -> float:
    """alpha: Omega f projected on the desired direction (0 where the path stops)."""
    t2 = float(tangent @ tangent)
    if t2 <= eps:
        return 0.0
    return float(tangent @ omega_f) / math.sqrt(t2)


def lead(
    com: np.ndarray, x_d: np.ndarray, tangent: np.ndarray, lean: np.ndarray | None = None
) -> float:
    """How far the CoM is ahead of its target along the path, m: of x_d leaned as the
    controller leans it (com_path.leaned; None: not leaned). Against the bare x_d, the lean
    the controller asks for read as a lag: braced, the CoM target stands 1.3 cm lower, and
    the gate held psi = t through a rise the pull helped (issue 60's lagging partner)."""
    norm = float(np.linalg.norm(tangent))
    if norm <= 0.0:
        return 0.0
    target = x_d if lean is None else leaned(x_d, lean)
    return float((com - target) @ tangent) / norm


def psi_dot_law(
    config: AdvancementConfig,
    com_velocity: np.ndarray | Callable[[], np.ndarray],
    omega_f: np.ndarray,
    tangent: np.ndarray,
    lead_m: float | Callable[[], float] = 0.0,
    progress: float | Callable[[], float] = 0.0,
) -> tuple[float, float]:
    """(psi_dot, alpha) by the configured update law; lead_m feeds the lead gate
    (or a function giving it, called only when the gate decides); progress: how far
    along its segment the reference is (0-1), for the taper at the segment's end. The
    CoM velocity and the progress may be functions too, called only where the law acts.

    psi_dot = 1 + w(alpha) g(lead) (clip(ratio, 1, upper) - 1): the paper's law where
    the help is full (w = g = 1), psi = t where there is none; the weights grade the
    paper's on/off gates (module docstring)."""
    alpha = helpfulness(tangent, omega_f, config.eps)
    if not config.enabled or alpha <= config.alpha_min_mps2:
        return 1.0, alpha
    if callable(progress):
        progress = progress()
    weight = 1.0
    if config.alpha_full_mps2 > config.alpha_min_mps2:
        weight = min(
            1.0,
            (alpha - config.alpha_min_mps2) / (config.alpha_full_mps2 - config.alpha_min_mps2),
        )
    if progress > config.taper_from_progress:
        r = (progress - config.taper_from_progress) / (1.0 - config.taper_from_progress)
        weight *= 1.0 - smoothstep(r)
        if weight <= 0.0:
            return 1.0, alpha
    if config.lead_gate:
        if callable(lead_m):
            lead_m = lead_m()
        if lead_m < 0.0:
            if lead_m <= -config.lag_tolerance_m:
                return 1.0, alpha
            weight *= 1.0 + lead_m / config.lag_tolerance_m
    if callable(com_velocity):
        com_velocity = com_velocity()
    if config.law == "tangent":
        ratio = float(com_velocity @ tangent) / (float(tangent @ tangent) + config.eps)
    else:
        along = float(tangent @ omega_f)
        ratio = float(com_velocity @ omega_f) * along / (along * along + config.eps)
    return 1.0 + weight * (min(config.psi_dot_upper, max(1.0, ratio)) - 1.0), alpha


class AdvancementLaw(LeafSystem):
    """The law alone, without state: inputs com_W, com_velocity_W, omega_f_W, x_d_W,
    lean_W (optional), path_tangent_W (3 each), path_progress (1), advances (1: the phase
    lets psi advance, phases.py) and response (1: the response code; any but
    advancement's holds psi = t); outputs psi_dot_law (the law's value) and alpha (1
    each). Under icub the law on the truth beside the robot's (sim/diagram.py) is one:
    logged, never integrated."""

    def __init__(self, config: AdvancementConfig, *, declare_outputs: bool = True):
        """declare_outputs False: a subclass declares them after its own (the ports'
        order: psi, psi_dot, psi_ddot, psi_dot_law, alpha)."""
        super().__init__()
        if config.alpha_full_mps2 is None:
            raise ValueError("advancement.alpha_full_mps2 is None: resolve it with for_robot")
        self._config = config
        self._com = self.DeclareVectorInputPort("com_W", 3)
        self._v = self.DeclareVectorInputPort("com_velocity_W", 3)
        self._omega_f = self.DeclareVectorInputPort("omega_f_W", 3)
        self._x_d = self.DeclareVectorInputPort("x_d_W", 3)
        # The controller's lean of x_d (3, com_path.leaned; unconnected: none), for the lead
        # where config.lead_from_leaned_target.
        self._lean = self.DeclareVectorInputPort("lean_W", 3)
        self._tangent = self.DeclareVectorInputPort("path_tangent_W", 3)
        # How far along its segment the reference is (0-1), for the taper.
        self._progress = self.DeclareVectorInputPort("path_progress", 1)
        # Whether the stand-up's phase lets psi advance (> 0.5; phases.py: advances):
        # not while balancing seated or returning to the seat after a hindering pull,
        # which a backward pull helps (docs/design.md).
        self._advances = self.DeclareVectorInputPort("advances", 1)
        self._response = self.DeclareVectorInputPort("response", 1)
        # The law reads the inputs only: evaluated once per change of them,
        # however many outputs and integrator stages ask.
        inputs = {
            port.ticket()
            for port in (
                self._com,
                self._v,
                self._omega_f,
                self._x_d,
                self._lean,
                self._tangent,
                self._progress,
                self._advances,
                self._response,
            )
        }
        self._law_cache = declare_cached(self, "psi_dot law", self._calc_law, inputs)
        self._law_ticket = {self._law_cache.ticket()}
        if declare_outputs:
            self._declare_law_outputs()

    def _declare_law_outputs(self) -> None:
        """psi_dot_law and alpha."""
        self.DeclareVectorOutputPort(
            "psi_dot_law", 1, self._CalcPsiDotLaw, prerequisites_of_calc=self._law_ticket
        )
        self.DeclareVectorOutputPort(
            "alpha", 1, self._CalcAlpha, prerequisites_of_calc=self._law_ticket
        )

    def _law(self, context: Context) -> tuple[float, float]:
        return self._law_cache.Eval(context)

    def _calc_law(self, context: Context) -> tuple[float, float]:
        tangent = self._tangent.Eval(context)
        if self._response.Eval(context)[0] > 0.5:  # stiff or compliant: psi = t
            return 1.0, helpfulness(tangent, self._omega_f.Eval(context), self._config.eps)
        if self._advances.Eval(context)[0] < 0.5:
            tangent = _NO_TANGENT  # a phase that holds psi = t: nothing to advance along
        # The velocity, the lead and the progress only while the interaction helps (a
        # few seconds of a stand-up).
        return psi_dot_law(
            self._config,
            lambda: self._v.Eval(context),
            self._omega_f.Eval(context),
            tangent,
            lambda: lead(
                self._com.Eval(context),
                self._x_d.Eval(context),
                tangent,
                self._lean.Eval(context) if self._leaned(context) else None,
            ),
            lambda: self._progress.Eval(context)[0],
        )

    def _leaned(self, context: Context) -> bool:
        """The lead is measured from the leaned target (lead_from_leaned_target, connected)."""
        return self._config.lead_from_leaned_target and self._lean.HasValue(context)

    def _CalcPsiDotLaw(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._law(context)[0])

    def _CalcAlpha(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._law(context)[1])


class TrajectoryAdvancement(AdvancementLaw):
    """AdvancementLaw's inputs, and psi integrated.

    Continuous state [psi, psi_dot]: the law sets the rate psi_dot tends to,
    with time constant psi_ddot_filter_s, and psi integrates psi_dot. The
    law jumps where it saturates or its gates switch (1 -> 2.5 and back);
    a reference that followed it would jump in velocity, and its end-of-path
    deceleration at psi_dot 2.5 -> 1 lifted the erect robot off its feet
    (measured). So xd_dot is continuous and psi_ddot, which the reference's
    feed-forward acceleration needs, is the exact derivative of the rate it
    uses. psi_dot stays within [1, psi_dot_upper] (a first-order lag of a
    signal in that range), and psi = t exactly while the law says 1.
    Outputs psi, psi_dot, psi_ddot, alpha (1 each), and psi_dot_law (the
    law's value, the target of psi_dot).
    """

    def __init__(self, config: AdvancementConfig):
        super().__init__(config, declare_outputs=False)
        self.DeclareContinuousState(BasicVector([0.0, 1.0]))
        state = {self.all_state_ticket()}
        self.DeclareVectorOutputPort("psi", 1, self._CalcPsi, prerequisites_of_calc=state)
        self.DeclareVectorOutputPort("psi_dot", 1, self._CalcPsiDot, prerequisites_of_calc=state)
        self.DeclareVectorOutputPort(
            "psi_ddot", 1, self._CalcPsiDdot, prerequisites_of_calc=self._law_ticket | state
        )
        self._declare_law_outputs()

    def _psi_ddot(self, context: Context) -> float:
        """psi_ddot = (law - psi_dot) / psi_ddot_filter_s; exactly 0 while both are 1."""
        psi_dot = context.get_continuous_state_vector().GetAtIndex(1)
        return (self._law(context)[0] - psi_dot) / self._config.psi_ddot_filter_s

    def DoCalcTimeDerivatives(self, context: Context, derivatives: ContinuousState) -> None:
        # _psi_ddot inlined (the integrator asks twice a step): the same arithmetic.
        psi_dot = context.get_continuous_state_vector().GetAtIndex(1)
        psi_ddot = (self._law_cache.Eval(context)[0] - psi_dot) / self._config.psi_ddot_filter_s
        derivatives.get_mutable_vector().SetFromVector([psi_dot, psi_ddot])

    def _CalcPsi(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, context.get_continuous_state_vector().GetAtIndex(0))

    def _CalcPsiDot(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, context.get_continuous_state_vector().GetAtIndex(1))

    def _CalcPsiDdot(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._psi_ddot(context))
