"""The CoP centering task: each 6-D contact's centre of pressure at the middle of its
box, which settles how the load is shared among contacts (constant: no law to run)."""

import numpy as np

from drake_standup.control.contacts import ContactSpec
from drake_standup.control.qp_types import QpLayout, Task


class CopCenteringTask(Task):
    """Each 6-D contact's CoP at the centre c of its CoP box: [tau_x - c_y f_z;
    tau_y + c_x f_z] = 0, i.e. (CoP - c) f_z = 0. It settles how the load is shared, which
    the momentum task leaves free: away from the box edges, where a compliant pad starts
    to roll. Constant: the QP adds it once."""

    name = "cop_centering"
    constant_A = constant_b = True

    def __init__(self, layout: QpLayout, contacts: list[ContactSpec], weight: float):
        wrenches = [c for c, spec in enumerate(contacts) if not spec.point]
        self.weight = weight
        self.columns = layout.wrenches
        self.A = np.zeros((2 * len(wrenches), layout.n_wrench))
        for row, c in enumerate(wrenches):
            wrench = layout.wrench(c)
            c_x, c_y = np.mean(contacts[c].cop_x_m), np.mean(contacts[c].cop_y_m)
            self.A[2 * row, wrench] = [1.0, 0.0, 0.0, 0.0, 0.0, -c_y]
            self.A[2 * row + 1, wrench] = [0.0, 1.0, 0.0, 0.0, 0.0, c_x]
        self.b = np.zeros(len(self.A))
