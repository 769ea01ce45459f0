"""TrajectoryAdvancement: the free parameter psi as continuous state, advanced by the law
advancement.law names (standup/laws.py: the paper's law, its gates, and a law's interface).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np
from pydrake.systems.framework import BasicVector, Context, ContinuousState, LeafSystem

from drake_standup.config import AdvancementConfig
from drake_standup.config.responses import SHIPPED_ADVANCES
from drake_standup.ports.caching import declare_cached
from drake_standup.standup.laws import (
    LawInputs,
    checked_rate,
    for_robot,
    helpfulness,
    lead,
    psi_dot_law,
)

# LawInputs' names read straight from the input port of the same name.
_PORTS = frozenset(("x_d_W", "com_W", "com_velocity_W", "hand_wrenches_W", "omega_f_W"))


def _resolve_law(spec: str) -> Callable:
    """The law advancement.law names (drake_standup/plugins: registered, module:attribute
    or an entry point)."""
    from drake_standup.config.plugins import resolve

    return resolve("laws", spec).obj


class AdvancementLaw(LeafSystem):
    """The law alone, without state: inputs com_W, com_velocity_W, omega_f_W, x_d_W,
    lean_W (optional), path_tangent_W (3 each), path_progress (1), advances (1: the phase
    lets psi advance, phases.py) and response (1: the response code; any but
    advancement's holds psi = t); outputs psi_dot_law (the law's value) and alpha (1
    each). Under icub the law on the truth beside the robot's (sim/diagram.py) is one:
    logged, never integrated."""

    def __init__(
        self,
        config: AdvancementConfig,
        *,
        declare_outputs: bool = True,
        advances: tuple[bool, ...] = SHIPPED_ADVANCES,
    ):
        """declare_outputs False: a subclass declares them after its own (the ports'
        order: psi, psi_dot, psi_ddot, psi_dot_law, alpha). advances: whether each
        response code lets psi advance (config/responses.py; default: the shipped three)."""
        super().__init__()
        self._advances_by_code = advances
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
        # What a law may read besides (standup/laws.py LawInputs): the measured hand
        # wrenches (12), the stand-up state (1) and, for the law alone, psi and psi_dot.
        self._wrenches = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        self._state = self.DeclareVectorInputPort("standup_state", 1)
        if declare_outputs:
            self._psi_in = self.DeclareVectorInputPort("psi", 1)
            self._psi_dot_in = self.DeclareVectorInputPort("psi_dot", 1)
        self._law_spec = config.law
        self._law_fn = _resolve_law(config.law)
        # The law reads the inputs (and psi): evaluated once per change of them,
        # however many outputs and integrator stages ask.
        inputs = {self.input_port_ticket(p.get_index()) for p in self._input_ports()}
        inputs |= {self.time_ticket(), self.all_state_ticket()}
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

    def _input_ports(self) -> list:
        return [self.get_input_port(i) for i in range(self.num_input_ports())]

    def _calc_law(self, context: Context) -> tuple[float, float]:
        """(psi_dot, alpha): psi_dot = 1 where the response, the phase or the config hold
        psi = t, else the law's rate (standup/laws.py), checked and bounded."""
        config = self._config
        tangent = self._tangent.Eval(context)
        if not self._advances_by_code[int(round(self._response.Eval(context)[0]))]:  # psi = t
            return 1.0, helpfulness(tangent, self._omega_f.Eval(context), config.eps)
        if self._advances.Eval(context)[0] < 0.5:  # a phase that holds psi = t
            return 1.0, 0.0
        alpha = helpfulness(tangent, self._omega_f.Eval(context), config.eps)
        if not config.enabled:
            return 1.0, alpha
        inputs = LawInputs(
            config, context.get_time(), functools.partial(self._read, context, tangent, alpha)
        )
        rate = checked_rate(self._law_fn(inputs), self._law_spec, inputs.time_s)
        return min(rate, config.psi_dot_upper), alpha

    def _read(self, context: Context, tangent: np.ndarray, alpha: float, name: str):
        """The law's input name now (standup/laws.py LawInputs)."""
        if name == "tangent_W":
            return tangent
        if name == "alpha":
            return alpha
        if name == "lead_m":
            lean = self._lean.Eval(context) if self._leaned(context) else None
            return lead(self._com.Eval(context), self._x_d.Eval(context), tangent, lean)
        if name in ("progress", "state"):
            port = self._progress if name == "progress" else self._state
            value = port.Eval(context)[0]
            return int(round(value)) if name == "state" else value
        if name in ("psi", "psi_dot"):
            return self._psi_now(context)[0 if name == "psi" else 1]
        if name not in _PORTS:
            raise KeyError(f"LawInputs: no input '{name}'")
        return self.GetInputPort(name).Eval(context)

    def _psi_now(self, context: Context) -> tuple[float, float]:
        """psi and psi_dot, from the inputs psi and psi_dot (NaN where not connected)."""
        ports = (self._psi_in, self._psi_dot_in)
        return tuple(p.Eval(context)[0] if p.HasValue(context) else math.nan for p in ports)

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

    def __init__(self, config: AdvancementConfig, advances: tuple[bool, ...] = SHIPPED_ADVANCES):
        super().__init__(config, declare_outputs=False, advances=advances)
        self.DeclareContinuousState(BasicVector([0.0, 1.0]))
        state = {self.all_state_ticket()}
        self.DeclareVectorOutputPort("psi", 1, self._CalcPsi, prerequisites_of_calc=state)
        self.DeclareVectorOutputPort("psi_dot", 1, self._CalcPsiDot, prerequisites_of_calc=state)
        self.DeclareVectorOutputPort(
            "psi_ddot", 1, self._CalcPsiDdot, prerequisites_of_calc=self._law_ticket | state
        )
        self._declare_law_outputs()

    def _psi_now(self, context: Context) -> tuple[float, float]:
        psi, psi_dot = context.get_continuous_state_vector().CopyToVector()
        return float(psi), float(psi_dot)

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


__all__ = ["AdvancementLaw", "TrajectoryAdvancement", "for_robot", "psi_dot_law"]
