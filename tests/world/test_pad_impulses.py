"""PadImpulses: the pads' impulse over the plant's steps, against the exact integral of a
force held piecewise constant between updates (issue 60)."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput

from drake_standup.outputs.signals import group_mean_normal_forces
from drake_standup.world.pad_forces import PadImpulses

STEP_S = 0.004  # a plant step 2.5 of which make the loggers' 10 ms: instants between steps


def _force(n: int) -> np.ndarray:
    """A force that changes at every step, with a one-step slap at n = 6 (N)."""
    slap = 500.0 if n == 6 else 0.0
    return np.array([np.sin(n), 2.0 * n, 100.0 + 3.0 * (n % 5) + slap])


class _HeldForce(LeafSystem):
    """A discrete plant's sampled contact force: the force of step n, computed at its
    update at t_n, held until the next update."""

    def __init__(self):
        super().__init__()
        self._state = self.DeclareDiscreteState(4)  # [force (3), steps taken]
        self.DeclareVectorOutputPort("force", 3, self._CalcForce)
        self.DeclarePeriodicDiscreteUpdateEvent(STEP_S, 0.0, self._Update)

    def _CalcForce(self, context, output: BasicVector):
        output.SetFromVector(context.get_discrete_state(self._state).value()[:3])

    def _Update(self, context, discrete_state):
        n = int(context.get_discrete_state(self._state).value()[3])
        discrete_state.get_mutable_vector(self._state).SetFromVector(np.r_[_force(n), n + 1])


def _exact_impulse(t: float) -> np.ndarray:
    """int f dt from 0 to t: step n's force held over [n h, (n + 1) h)."""
    whole = int(np.floor(t / STEP_S + 1e-9))
    total = sum((_force(n) * STEP_S for n in range(whole)), np.zeros(3))
    return total + _force(whole) * (t - whole * STEP_S)


def _simulate(log_period_s: float, end_s: float):
    builder = DiagramBuilder()
    held = builder.AddSystem(_HeldForce())
    impulses = builder.AddSystem(PadImpulses(1, STEP_S))
    builder.Connect(held.get_output_port(), impulses.get_input_port())
    log = LogVectorOutput(impulses.get_output_port(), builder, log_period_s)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(end_s)
    data = log.FindLog(simulator.get_context())
    return data.sample_times(), data.data().T


@pytest.mark.parametrize("log_period_s", [0.01, 0.004, 0.006])
def test_the_impulse_is_the_exact_integral_at_any_logging_instant(log_period_s):
    """Logged between the steps (10 ms: 2.5 steps) or on them, the impulse is the force's
    exact integral: no step counted twice or missed, the step in progress counted for
    the time it has run."""
    times, impulses = _simulate(log_period_s, 0.2)
    expected = np.array([_exact_impulse(t) for t in times])
    np.testing.assert_allclose(impulses, expected, rtol=1e-12, atol=1e-9)


def test_the_mean_force_keeps_a_one_step_slap_the_samples_miss():
    """A 500 N slap held one 4 ms step, logged every 10 ms: the interval's mean force
    carries its impulse (500 N x 4 ms / 10 ms = 200 N above the load, which changes by
    at most 12 N a step); a logged sample misses it where no logging instant falls inside
    that step."""
    times, impulses = _simulate(0.01, 0.1)
    samples = np.array([_force(int(np.floor(t / STEP_S + 1e-9)))[2] for t in times])
    signals = {
        "time_s": times,
        "pad_groups": np.array(["soles"]),
        "pad_normal_force_N": samples[:, None],
        "pad_impulses_Ns": impulses[:, None, :],
    }
    mean = group_mean_normal_forces(signals)["soles"]
    # The slap is step 6, [24, 28) ms: wholly inside the interval (20, 30] ms, and no
    # logging instant (multiples of 10 ms) falls inside it.
    assert samples.max() < 200.0
    k = int(np.argmin(np.abs(times - 0.03)))
    assert mean[k] - mean[k - 1] == pytest.approx(500.0 * 0.004 / 0.01, abs=15.0)
    assert mean[k + 1] - mean[k - 1] == pytest.approx(0.0, abs=15.0)
