"""The mass estimate: the robot weighs itself while it sits, before it first stands up.

At rest on the chair the pads' and the hands' vertical forces carry the robot's weight,
m g = sum F_z. While seated in state 1, and until the first stand-up begins, the ratio of
that measured weight to the model's is low-pass filtered (first order, period T, time
constant tau) and bounded:

    s <- clip(s + min(T / tau, 1) (F_z / (m_model g) - s), s_min, s_max)

The controller's model scales every body's mass by s (control/model.py), following the
estimate only once it has moved by more than RESCALE_ABOVE: rescaling the model costs
83 us, against a ~600 us tick (docs/performance.md). Frozen from the first stand-up on: a
robot sat back by a hindering pull rocks on the seat, and weighing it then put the model
off (docs/design.md, "The robot weighs itself").
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, Context, DiscreteValues, LeafSystem

from drake_standup.caching import declare_cached
from drake_standup.payloads import HAND_WRENCHES

_F_Z_LEFT = HAND_WRENCHES["f_l"].start + 2
_F_Z_RIGHT = HAND_WRENCHES["f_r"].start + 2
RESCALE_ABOVE = 1e-4


def mass_estimate(
    scale: float,
    began: bool,
    standup_state: int,
    weight_N: float | None,
    model_weight_N: float,
    blend: float,
    bounds: tuple[float, float],
) -> tuple[float, bool]:
    """(the estimate, the stand-up has begun) after one tick: weight_N the measured
    weight (pads and hands, None: unmeasured), blend = min(T / tau, 1) (0: no estimate)."""
    began = began or standup_state > 1
    if not began and blend > 0.0 and weight_N is not None:
        scale += blend * (weight_N / model_weight_N - scale)
        scale = min(max(scale, bounds[0]), bounds[1])
    return scale, began


class MassEstimator(LeafSystem):
    """Inputs pads_vertical_force_N (1: the vertical force on all the robot's pads;
    unconnected: not measured, the nominal model throughout), hand_wrenches_W (12,
    payloads.HAND_WRENCHES), standup_state (1). Discrete state [the estimate, the
    stand-up has begun, the model's scale], updated every period_s. Outputs mass_scale
    (1: the model's scale this tick) and mass_estimate (1: the estimate after the last
    tick, for logging)."""

    def __init__(
        self, model_mass_kg: float, g_mps2: float, period_s: float, filter_s: float, bounds
    ):
        super().__init__()
        self._model_weight_N = model_mass_kg * g_mps2
        self._blend = min(period_s / filter_s, 1.0) if filter_s > 0.0 else 0.0
        self._bounds = tuple(bounds)
        self._support = self.DeclareVectorInputPort("pads_vertical_force_N", 1)
        self._hands = self.DeclareVectorInputPort("hand_wrenches_W", HAND_WRENCHES.size)
        self._state_input = self.DeclareVectorInputPort("standup_state", 1)
        self._state = self.DeclareDiscreteState(np.array([1.0, 0.0, 1.0]))
        self._next = declare_cached(self, "estimate", self._tick, {self.all_sources_ticket()})
        self.DeclareVectorOutputPort(
            "mass_scale", 1, self._CalcScale, prerequisites_of_calc={self._next.ticket()}
        )
        self.DeclareVectorOutputPort(
            "mass_estimate",
            1,
            self._CalcEstimate,
            prerequisites_of_calc={self.discrete_state_ticket(self._state)},
        )
        self.DeclareInitializationDiscreteUpdateEvent(self._Update)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._Update)

    def _tick(self, context: Context) -> np.ndarray:
        scale, began, model_scale = context.get_discrete_state(self._state).value()
        weight_N = None
        if self._support.HasValue(context):
            hands = self._hands.Eval(context)
            weight_N = float(self._support.Eval(context)[0]) + hands[_F_Z_LEFT] + hands[_F_Z_RIGHT]
        state = min(max(int(round(self._state_input.Eval(context)[0])), 1), 4)
        scale, began = mass_estimate(
            scale, bool(began), state, weight_N, self._model_weight_N, self._blend, self._bounds
        )
        if abs(scale - model_scale) > RESCALE_ABOVE:
            model_scale = scale
        return np.array([scale, float(began), model_scale])

    def _CalcScale(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._next.Eval(context)[2])

    def _CalcEstimate(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, context.get_discrete_state(self._state).GetAtIndex(0))

    def _Update(self, context: Context, discrete_state: DiscreteValues) -> None:
        discrete_state.set_value(self._state, self._next.Eval(context))
