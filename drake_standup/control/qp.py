"""The whole-body QP: one program over z = [F_1 .. F_nc, vdot], tau eliminated.

With F_c the wrench of contact c in its own frame (control/contacts.py) and
G_c = J_c^T X_WC the map to generalized forces, the floating-base dynamics

    M vdot + h = B tau + sum_c G_c F_c + J_h^T F_hand                          (1)

split into the six unactuated rows S_f (1), kept as equality constraints, and the
actuated rows, which give the torques as an affine function of z:

    tau = B^T (M vdot + h - sum_c G_c F_c - J_h^T F_hand) = T z + t0.          (2)

The program, built once and refilled every tick:

    min_z  sum_k w_k ||A_k z - b_k||^2 + w_tau ||T z + t0||^2 + w_F ||F||^2 + w_a ||vdot||^2
    s.t.   S_f (M vdot - sum_c G_c F_c) = S_f (J_h^T F_hand - h)     dynamics, base rows
           S_c (J_c vdot + Jdot_c v) = 0              each held contact (S_c: held rows)
           K_c F_c <= 0,  f_z,c in [lo_c, hi_c]       each contact
           -tau_max <= T z + t0 <= tau_max            torque limits
           vdot_min <= vdot <= vdot_max               joint limits (control/tasks.py)

The program holds only the contacts that are active: the controller keeps one per set
of active contacts (its size, and so its solve time, shrinks once the seat is released).
The tasks (A_k, b_k, w_k) come from control/tasks.py; the solver is a backend chosen by
name (daqp, or Drake's OSQP / Clarabel).
"""

import time
from dataclasses import dataclass, field

import daqp
import numpy as np
from pydrake.solvers import (
    ClarabelSolver,
    MathematicalProgram,
    OsqpSolver,
    SolverOptions,
)

from drake_standup.control.contacts import (
    WRENCH_SIZE,
    ContactSpec,
    held_point_terms,
    wrench_cone_matrix,
)
from drake_standup.control.terms import RobotTerms

N_BASE = 6  # unactuated floating-base velocities
DAQP_EQUALITY = 5  # daqp's constraint "sense" flag for an equality row
SOLVERS = ("daqp", "osqp", "clarabel")


class QpLayout:
    """Where each unknown sits in z = [F_1 .. F_nc, vdot]; F_c has wrench_sizes[c] entries
    (6, or 3 for a point contact)."""

    def __init__(self, wrench_sizes: tuple[int, ...], nv: int):
        self.wrench_sizes = tuple(wrench_sizes)
        self.nv = nv
        self.n_wrench = sum(self.wrench_sizes)
        self.n = self.n_wrench + nv
        starts = np.cumsum((0,) + self.wrench_sizes)
        self._wrench = [slice(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]
        self.wrenches = slice(0, self.n_wrench)
        self.vdot = slice(self.n_wrench, self.n)

    @classmethod
    def of(cls, contacts: list[ContactSpec], nv: int) -> "QpLayout":
        return cls(tuple(spec.size for spec in contacts), nv)

    def wrench(self, c: int) -> slice:
        return self._wrench[c]


@dataclass
class Task:
    """One least-squares objective, weight * ||A z[columns] - b||^2."""

    name: str
    weight: float
    A: np.ndarray  # (rows, width of columns)
    b: np.ndarray  # (rows,)
    columns: slice


@dataclass
class ContactCommand:
    """What the contact plan asks of an active contact this tick."""

    min_normal_force_N: float
    max_normal_force_N: float
    # Rows of the spatial acceleration at the hold point, in C ([alpha; a]), that are
    # held at zero; a constrained contact only.
    held_rows: np.ndarray = field(default_factory=lambda: np.ones(6, dtype=bool))


@dataclass
class QpSolution:
    """A tick's solution; on failure (ok False) its numbers are not to be used."""

    frames: list[str]  # the contacts' task frames, in the order of F_C and F_W
    ok: bool
    vdot: np.ndarray  # (nv,)
    F_C: np.ndarray  # (nc, 6) each contact's wrench in its frame, [tau; f], N m / N
    F_W: np.ndarray  # (nc, 6) the same wrenches at each contact frame's origin, in W
    tau: np.ndarray  # (nu,) joint torques, actuator order, N m
    assembly_s: float
    solve_s: float


class WholeBodyQp:
    """Builds the program of the module docstring once for a set of active contacts;
    refills and solves it each tick."""

    def __init__(
        self,
        contacts: list[ContactSpec],
        B: np.ndarray,
        *,
        torque_limit_Nm: float,
        torque_weight: float,
        wrench_weight: float,
        acceleration_weight: float,
        fixed_tasks: list[Task],
        solver: str = "daqp",
    ):
        """fixed_tasks: tasks whose A and b never change, added to the cost once."""
        nv, nu = B.shape
        if not (np.all((B == 0) | (B == 1)) and np.all(B.sum(axis=0) == 1)):
            raise ValueError("the actuation matrix B must select one velocity per actuator")
        # tau = B^T (...) picks the actuated rows of a generalized force.
        self._actuated = B.argmax(axis=0)
        self.layout = layout = QpLayout.of(contacts, nv)
        self.contacts = list(contacts)
        self._torque_limit_Nm = torque_limit_Nm
        self._torque_weight = torque_weight
        n, nw = layout.n, layout.n_wrench

        # Rows of A: dynamics (6), accelerations of the constrained contacts (6 each),
        # cones (10 per contact), torques (nu). The bound vectors lo, hi hold first the
        # simple bounds on all n unknowns, then one entry per row of A (daqp's layout);
        # _bounds(rows) maps rows of A to their entries.
        self._rows_dyn = slice(0, N_BASE)
        self._rows_acc: dict[int, slice] = {}
        row = N_BASE
        for c, spec in enumerate(contacts):
            if spec.constrained:
                self._rows_acc[c] = slice(row, row + WRENCH_SIZE)
                row += WRENCH_SIZE
        cones = [wrench_cone_matrix(spec) for spec in contacts]
        rows_cones = slice(row, row + sum(len(K) for K in cones))
        self._rows_tau = slice(rows_cones.stop, rows_cones.stop + nu)
        m = self._rows_tau.stop
        self._A = np.zeros((m, n))
        self._lo = np.full(n + m, -np.inf)
        self._hi = np.full(n + m, np.inf)
        self._equality = np.zeros(n + m, dtype=bool)
        for c, K in enumerate(cones):
            cone = slice(row, row + len(K))
            row = cone.stop
            self._A[cone, layout.wrench(c)] = K
            self._hi[self._bounds(cone)] = 0.0
        self._equality[self._bounds(self._rows_dyn)] = True
        self._hold_points = [np.array(spec.hold_point_m) for spec in contacts]
        self._T = np.zeros((nu, n))  # tau = T z + t0

        self._H_fixed = np.diag(
            np.concatenate([np.full(nw, wrench_weight), np.full(nv, acceleration_weight)])
        )
        self._g_fixed = np.zeros(n)
        self._add_tasks(self._H_fixed, self._g_fixed, fixed_tasks)
        self._backend = make_backend(solver, n, m)

    def _bounds(self, rows: slice) -> slice:
        """Entries of lo, hi (after the n simple bounds) that belong to rows of A."""
        n = self.layout.n
        return slice(n + rows.start, n + rows.stop)

    @staticmethod
    def _add_tasks(H: np.ndarray, g: np.ndarray, tasks: list[Task]) -> None:
        """H += sum w A^T A, g -= sum w A^T b, each on its task's block of columns."""
        for task in tasks:
            WA = task.weight * task.A.T
            H[task.columns, task.columns] += WA @ task.A
            g[task.columns] -= WA @ task.b

    def solve(
        self,
        terms: RobotTerms,
        tasks: list[Task],
        commands: list[ContactCommand],
        tau_hand: np.ndarray,
        vdot_min: np.ndarray,
        vdot_max: np.ndarray,
    ) -> QpSolution:
        """Solves the tick's QP.

        tau_hand = J_h^T F_hand is the hands' generalized force; vdot_min <= vdot <= vdot_max
        are simple bounds (+-inf where none), e.g. from joint limits.
        """
        t_start = time.perf_counter()
        layout, nw, vdot = self.layout, self.layout.n_wrench, self.layout.vdot
        A, lo, hi, equality, T = self._A, self._lo, self._hi, self._equality, self._T
        frames = [terms.frames[spec.frame] for spec in self.contacts]
        # X_c: the contact's unknowns -> its 6-D wrench at Co, in W.
        X = [frame.X_WF[:, spec.components] for spec, frame in zip(self.contacts, frames)]

        # G = [G_1 .. G_nc], G_c = J_c^T X_c: contact wrenches -> generalized forces.
        G = np.hstack([frame.J_WF.T @ X_c for frame, X_c in zip(frames, X)])

        # (1), base rows: [-G_f, M_f] z = S_f (tau_hand - h).
        A[self._rows_dyn, :nw] = -G[:N_BASE]
        A[self._rows_dyn, vdot] = terms.M[:N_BASE]
        dyn = self._bounds(self._rows_dyn)
        lo[dyn] = hi[dyn] = tau_hand[:N_BASE] - terms.h[:N_BASE]

        # Contacts: held rows of J_CP vdot = -Jdot_CP v; normal-force bounds (f_z comes
        # last in F_c).
        for c, (frame, command) in enumerate(zip(frames, commands, strict=True)):
            if c in self._rows_acc:
                rows = self._rows_acc[c]
                acc = self._bounds(rows)
                held = command.held_rows
                equality[acc] = held
                J_WP, bias_WP = held_point_terms(frame, terms.v, self._hold_points[c])
                if held.all():  # all six rows: the frame they are expressed in is moot
                    A[rows, vdot] = J_WP
                    lo[acc] = hi[acc] = -bias_WP
                else:  # some rows of C only
                    X_CW = frame.X_WF.T
                    A[rows, vdot] = X_CW @ J_WP
                    rhs = -(X_CW @ bias_WP)
                    lo[acc] = np.where(held, rhs, -np.inf)
                    hi[acc] = np.where(held, rhs, np.inf)
            normal = layout.wrench(c).stop - 1
            lo[normal] = command.min_normal_force_N
            hi[normal] = command.max_normal_force_N
        lo[vdot], hi[vdot] = vdot_min, vdot_max

        # (2): tau = T z + t0 within the limits.
        T[:, :nw] = -G[self._actuated]
        T[:, vdot] = terms.M[self._actuated]
        t0 = terms.h[self._actuated] - tau_hand[self._actuated]
        A[self._rows_tau] = T
        tau_bounds = self._bounds(self._rows_tau)
        lo[tau_bounds] = -self._torque_limit_Nm - t0
        hi[tau_bounds] = self._torque_limit_Nm - t0

        WT = self._torque_weight * T.T
        H = self._H_fixed + WT @ T
        g = self._g_fixed + WT @ t0
        self._add_tasks(H, g, tasks)
        t_assembled = time.perf_counter()

        z, ok = self._backend.solve(H, g, A, lo, hi, equality)
        t_solved = time.perf_counter()
        ok = ok and bool(np.all(np.isfinite(z)))
        F_C = np.zeros((len(self.contacts), WRENCH_SIZE))
        for c, spec in enumerate(self.contacts):
            F_C[c, spec.components] = z[layout.wrench(c)]
        return QpSolution(
            frames=[spec.frame for spec in self.contacts],
            ok=ok,
            vdot=z[vdot],
            F_C=F_C,
            F_W=np.array([frame.X_WF @ F for frame, F in zip(frames, F_C, strict=True)]),
            tau=T @ z + t0,
            assembly_s=t_assembled - t_start,
            solve_s=t_solved - t_assembled,
        )


# --- Solver backends ------------------------------------------------------------------
# Each solves  min 0.5 z^T H z + g^T z  s.t.  lo[:n] <= z <= hi[:n],
# lo[n:] <= A z <= hi[n:], with equality[i] marking the entries where lo[i] == hi[i].


def make_backend(solver: str, n: int, m: int):
    if solver == "daqp":
        return DaqpBackend()
    if solver in ("osqp", "clarabel"):
        return DrakeBackend(solver, n, m)
    raise ValueError(f"controller.qp_solver: '{solver}'; accepted: {', '.join(SOLVERS)}")


class DaqpBackend:
    """daqp (dense active-set). Solved cold each tick: its Model.update + warm-started
    solve measured slower here (178 us) than a cold solve (154 us), whose cost is the
    set-up (factorising H) rather than the 1-5 active-set iterations."""

    def solve(self, H, g, A, lo, hi, equality) -> tuple[np.ndarray, bool]:
        sense = np.where(equality, DAQP_EQUALITY, 0).astype(np.int32)
        z, _, exitflag, _ = daqp.solve(H, g, A, hi, lo, sense)
        return np.asarray(z), exitflag >= 1


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
