"""What helping costs: the work, impulse and peak force the helper's hands spend on the
robot's (HelperWork), as the discrete plant integrates them."""

import math

import numpy as np
from pydrake.systems.framework import BasicVector, Context, LeafSystem

# HelperWork's output, entry by entry (signals.npz and metrics.json name them so).
HELPER_SPENT = (
    "helper_work_J",
    "helper_positive_work_J",
    "helper_impulse_Ns",
    "helper_peak_force_N",
)


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
