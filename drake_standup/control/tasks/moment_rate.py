"""The soles' moment rate: each sole's moments near the last tick's, w ||(tau - tau_last) / l||^2.

The momentum task fixes the contacts' total wrench, and the plan may move a sole's CoP
across its box from one tick to the next. A compliant sole cannot follow: loaded past the
middle third of its pad it rides on its toe edge, and a CoP moved back 4 cm in 30 ms
landed its heel with 327 N (docs/design.md, "The sole's heel landing"). Mature whole-body
QPs weigh the rate of the contact wrench for this reason: IHMC's momentum-based
controller has copRateDefaultWeight on each foot's CoP and rhoRateDefaultWeight on its
contact-force basis (MomentumOptimizationSettings). Here the moments only: their rate
is the CoP's (times the load); weighing the forces' rate too slowed the balance against a
30 N pull per hand until the robot fell (docs/design.md).

Each moment is divided by l, the half of its sole's CoP box's longer side, so that its
change counts as the force that would move the CoP across the box (N). The weight is
weight_s / period_s: a per-tick cost w blends the plan with the last one like a
first-order lag of w / w_other ticks, so the time scale stays with the control period.
"""

from __future__ import annotations

import numpy as np

from drake_standup.control.contacts import CONTACTS, SOLES, WRENCH_SIZE, ContactSpec
from drake_standup.control.qp_types import QpLayout, Task

SOLE_FRAMES = CONTACTS[SOLES]  # ("l_sole", "r_sole")


class SoleMomentRateTask(Task):
    """w ||S (F_soles - F_last)||^2, S picking both soles' moments (in their frames) over
    l; F_last the last tick's soles' wrenches (set_last; none yet: no cost)."""

    name = "sole_moment_rate"
    constant_A = False  # its weight is 0 until there is a last tick

    def __init__(
        self, layout: QpLayout, contacts: list[ContactSpec], weight_s: float, period_s: float
    ):
        frames = [spec.frame for spec in contacts]
        soles = [frames.index(sole) for sole in SOLE_FRAMES]
        if soles != [soles[0], soles[0] + 1]:
            raise ValueError("the soles must be consecutive contacts")
        first, last = layout.wrench(soles[0]), layout.wrench(soles[1])
        self.columns = slice(first.start, last.stop)
        self.A = np.zeros((3 * len(SOLE_FRAMES), WRENCH_SIZE * len(SOLE_FRAMES)))
        for k, c in enumerate(soles):
            spec = contacts[c]
            half = max(np.ptp(spec.cop_x_m), np.ptp(spec.cop_y_m)) / 2.0
            self.A[3 * k : 3 * k + 3, WRENCH_SIZE * k : WRENCH_SIZE * k + 3] = np.eye(3) / half
        self._weight = weight_s / period_s
        self.weight = 0.0
        self.b = np.zeros(len(self.A))

    def set_last(self, F_last: np.ndarray) -> None:
        """The soles' wrenches of the last tick, (2, 6) in their frames, [tau; f] (NaN:
        none)."""
        F_last = np.asarray(F_last, dtype=float).reshape(WRENCH_SIZE * len(SOLE_FRAMES))
        if np.all(np.isfinite(F_last)):
            self.weight = self._weight
            self.b = self.A @ F_last
        else:
            self.weight = 0.0
