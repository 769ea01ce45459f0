"""The QP's solver backends, chosen by name (controller.qp_solver).

Each solves  min 0.5 z^T H z + g^T z  s.t.  lo[:n] <= z <= hi[:n],
lo[n:] <= A z <= hi[n:], with equality[i] (1 or 0) marking the entries where
lo[i] == hi[i].
"""

import daqp
import numpy as np
from pydrake.solvers import ClarabelSolver, MathematicalProgram, OsqpSolver, SolverOptions

from drake_standup.config.controller import QP_SOLVERS as SOLVERS


def make_backend(solver: str, n: int, m: int):
    if solver == "daqp":
        return DaqpBackend(n + m)
    if solver in ("osqp", "clarabel"):
        return DrakeBackend(solver, n, m)
    raise ValueError(f"controller.qp_solver: '{solver}'; accepted: {', '.join(SOLVERS)}")


class DaqpBackend:
    """daqp (dense active-set), solved cold each tick. Its cost is the set-up (factorising
    H, A R^-1), not the 1-15 active-set iterations: neither its Model API (which redoes
    the set-up on any update of H or A) nor a hot start from the last active set (sense
    flags: 5 iterations down to 1) nor handing it an identity Hessian after a Cholesky and
    triangular solve in LAPACK paid in the closed loop (measured)."""

    EQUALITY = 5  # sense flags: ACTIVE (1) | IMMUTABLE (4)

    def __init__(self, size: int):
        self._sense = np.zeros(size, dtype=np.int32)
        # daqp's infeasible verdict is wrong on some programs that have a solution
        # (tests/control/test_controller.py counts them on random states): Clarabel tries each
        # program daqp fails, and only a solution meeting its rows is taken.
        self._fallback: dict[tuple[int, int], DrakeBackend] = {}
        self.fallbacks = 0  # programs daqp failed that Clarabel solved

    def solve(self, H, g, A, lo, hi, equality) -> tuple[np.ndarray, bool]:
        """Any size of program (the QP leaves rows out: control/qp.py)."""
        if len(equality) == len(self._sense):
            sense = self._sense
            np.multiply(equality, self.EQUALITY, out=sense)
        else:
            sense = (equality * self.EQUALITY).astype(np.int32)
        z, _, exitflag, _ = daqp.solve(H, g, A, hi, lo, sense)
        if exitflag >= 1:
            return np.asarray(z), True
        n, m = len(g), len(A)
        fallback = self._fallback.get((n, m))
        if fallback is None:
            fallback = self._fallback[n, m] = DrakeBackend("clarabel", n, m)
        z, ok = fallback.solve(H, g, A, lo, hi, equality)
        ok = ok and bool(np.isfinite(z).all()) and _meets(z, A, lo, hi)
        self.fallbacks += int(ok)
        return z, ok


def _meets(z, A, lo, hi, tolerance: float = 1e-6) -> bool:
    """Whether z meets the simple bounds and rows within tolerance, relative (an
    interior-point solver's equalities hold to ~1e-8)."""
    values = np.concatenate((z, A @ z))
    slack = tolerance * (1.0 + np.abs(values))
    return bool(np.all(values >= lo - slack) and np.all(values <= hi + slack))


class DrakeBackend:
    """Drake's OSQP or Clarabel on a MathematicalProgram built once (UpdateCoefficients)."""

    def __init__(self, solver: str, n: int, m: int):
        prog = MathematicalProgram()
        z = prog.NewContinuousVariables(n, "z")
        self._cost = prog.AddQuadraticCost(np.eye(n), np.zeros(n), z, is_convex=True)
        self._rows = prog.AddLinearConstraint(
            np.zeros((m, n)), -np.inf * np.ones(m), np.inf * np.ones(m), z
        )
        self._bounds = prog.AddBoundingBoxConstraint(-np.inf * np.ones(n), np.inf * np.ones(n), z)
        self._prog = prog
        self._n = n
        self._solver = OsqpSolver() if solver == "osqp" else ClarabelSolver()
        self._options = SolverOptions()
        if solver == "osqp":
            # Tight enough for the equality rows to hold to ~1e-6 (default 1e-3 relative).
            for key in ("eps_abs", "eps_rel"):
                self._options.SetOption(OsqpSolver.id(), key, 1e-7)
            self._options.SetOption(OsqpSolver.id(), "max_iter", 20000)
            self._options.SetOption(OsqpSolver.id(), "polishing", 1)

    def solve(self, H, g, A, lo, hi, equality) -> tuple[np.ndarray, bool]:
        n = self._n
        self._cost.evaluator().UpdateCoefficients(H, g, is_convex=True)
        self._rows.evaluator().UpdateCoefficients(A, lo[n:], hi[n:])
        self._bounds.evaluator().set_bounds(lo[:n], hi[:n])
        result = self._solver.Solve(self._prog, None, self._options)
        return result.GetSolution(), result.is_success()
