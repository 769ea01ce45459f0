"""The mass estimate: the robot weighs itself while it sits, before it first stands up.

At rest on the chair the pads' and the hands' vertical forces carry the robot's weight,
m g = sum F_z. While seated in state 1, and until the first stand-up begins, the ratio of
that measured weight to the model's is low-pass filtered (first order, period T, time
constant tau) and bounded:

    s <- clip(s + min(T / tau, 1) (F_z / (m_model g) - s), s_min, s_max)

The controller's model (control/model.py) scales every body's mass by its own scale,
which follows the estimate only once they differ by more than RESCALE_ABOVE: rescaling
the model costs 83 us, against a ~600 us tick (docs/performance.md). Frozen from the
first stand-up on: a robot sat back by a hindering pull rocks on the seat, and weighing
it then put the model off (docs/design.md, "Weighing itself while seated").
"""

from __future__ import annotations

import numpy as np

RESCALE_ABOVE = 1e-4


def mass_estimate(
    scale: float,
    began: bool,
    standup_state: int,
    weight_N: float,
    model_weight_N: float,
    blend: float,
    *,
    bounds: tuple[float, float],
) -> tuple[float, bool]:
    """(the estimate, the stand-up has begun) after one tick: weight_N the measured
    weight (pads and hands), blend = min(T / tau, 1) (0: no estimate)."""
    began = began or standup_state > 1
    if not began and blend > 0.0:
        scale += blend * (weight_N / model_weight_N - scale)
        scale = min(max(scale, bounds[0]), bounds[1])
    return scale, began


def next_mass_state(
    state: np.ndarray,
    standup_state: int,
    weight_N: float,
    model_weight_N: float,
    blend: float,
    bounds: tuple[float, float],
) -> np.ndarray:
    """[the estimate, began (1/0), the model's scale] after one tick from state (the same
    three); the model's scale follows the estimate where they differ by RESCALE_ABOVE."""
    scale, began, model_scale = state
    scale, began = mass_estimate(
        scale, bool(began), standup_state, weight_N, model_weight_N, blend, bounds=bounds
    )
    if abs(scale - model_scale) > RESCALE_ABOVE:
        model_scale = scale
    return np.array([scale, float(began), model_scale])
