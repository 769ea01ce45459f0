"""The sole's yaw-moment bounds (control/contacts.py: rectangle_yaw_rows) against the
rectangle they stand for: four corner forces, each in the friction pyramid, whose
largest and smallest yaw moment a linear program finds (independent of the closed
form)."""

import numpy as np
import pytest
from pydrake.solvers import MathematicalProgram, Solve

from drake_standup.control.contacts import ContactSpec, rectangle_yaw_rows, wrench_cone_matrix

MU = 1.0 / 3.0
COP_X = (-0.05, 0.10)  # the soles' CoP box (config/controller.py), off centre in x
COP_Y = (-0.025, 0.025)


def _corner_yaw(wrench: np.ndarray, sense: float) -> float | None:
    """The largest (sense 1) or smallest (-1) tau_z about C's origin of four corner forces
    in their pyramids summing to wrench's f, tau_x, tau_y; None if none do."""
    corners = [(x, y) for x in COP_X for y in COP_Y]
    prog = MathematicalProgram()
    f = prog.NewContinuousVariables(4, 3)
    for i in range(4):
        prog.AddLinearConstraint(f[i, 2] >= 0)
        for k in (0, 1):
            prog.AddLinearConstraint(f[i, k] <= MU * f[i, 2])
            prog.AddLinearConstraint(-f[i, k] <= MU * f[i, 2])
    for k in range(3):
        prog.AddLinearConstraint(sum(f[i, k] for i in range(4)) == wrench[3 + k])
    prog.AddLinearConstraint(sum(y * f[i, 2] for i, (x, y) in enumerate(corners)) == wrench[0])
    prog.AddLinearConstraint(sum(-x * f[i, 2] for i, (x, y) in enumerate(corners)) == wrench[1])
    tau_z = sum(x * f[i, 1] - y * f[i, 0] for i, (x, y) in enumerate(corners))
    prog.AddLinearCost(-sense * tau_z)
    result = Solve(prog)
    return -sense * result.get_optimal_cost() if result.is_success() else None


def _row_bounds(wrench: np.ndarray) -> tuple[float, float]:
    """The [tau_min, tau_max] the 8 rows allow for wrench's other components."""
    K = np.array(rectangle_yaw_rows(MU, COP_X, COP_Y))
    rest = K[:, [0, 1, 3, 4, 5]] @ wrench[[0, 1, 3, 4, 5]]
    up, down = K[:, 2] > 0, K[:, 2] < 0
    return float(np.max(-rest[down] / K[down, 2])), float(np.min(-rest[up] / K[up, 2]))


@pytest.mark.parametrize("seed", range(4))
def test_yaw_bounds_equal_the_corner_forces(seed):
    rng = np.random.default_rng(seed)
    checked = 0
    for _ in range(25):
        fz = rng.uniform(20.0, 200.0)
        fx, fy = rng.uniform(-MU, MU, 2) * fz
        cop = [rng.uniform(*COP_X), rng.uniform(*COP_Y)]
        wrench = np.array([cop[1] * fz, -cop[0] * fz, 0.0, fx, fy, fz])
        high, low = _corner_yaw(wrench, 1.0), _corner_yaw(wrench, -1.0)
        tau_min, tau_max = _row_bounds(wrench)
        if high is None:
            assert tau_min > tau_max - 1e-9  # no yaw moment is admissible either
            continue
        checked += 1
        assert tau_max == pytest.approx(high, abs=1e-9)
        assert tau_min == pytest.approx(low, abs=1e-9)
    assert checked >= 10


def test_no_yaw_moment_at_a_corner():
    """The CoP at the box's toe-outer corner, no tangential force: only tau_z = 0."""
    fz = 100.0
    wrench = np.array([COP_Y[0] * fz, -COP_X[1] * fz, 0.0, 0.0, 0.0, fz])
    tau_min, tau_max = _row_bounds(wrench)
    assert tau_min == pytest.approx(0.0, abs=1e-12)
    assert tau_max == pytest.approx(0.0, abs=1e-12)


def test_the_cone_keeps_its_other_rows():
    """The full matrix: the pyramid, the torsion cap, the CoP box, then the 8 yaw rows
    (only where the spec asks for them: the soles)."""
    spec = ContactSpec("l_sole", MU, 1.0 / 75.0, COP_X, COP_Y, rectangle_yaw=True)
    assert wrench_cone_matrix(ContactSpec("seat", MU, 1.0 / 75.0, COP_X, COP_Y)).shape == (10, 6)
    K = wrench_cone_matrix(spec)
    assert K.shape == (18, 6)
    np.testing.assert_array_equal(K[10:], np.array(rectangle_yaw_rows(MU, COP_X, COP_Y)))
    centred = np.array([0.0, -0.025 * 100.0, 0.5, 0.0, 0.0, 100.0])  # CoP at the box centre
    assert np.all(K @ centred <= 1e-12)
