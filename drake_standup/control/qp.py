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
           S_c (J_c vdot + Jdot_c v) = -k S_c J_c v    each held contact (S_c: held rows;
                                  k: a slip braked back to rest; a thigh pad's normal
                                  row: its dynamics instead, control/pad_dynamics.py)
           K_c F_c <= 0,  f_z,c in [lo_c, hi_c]       each contact
           -tau_max <= T z + t0 <= tau_max            torque limits
           vdot_min <= vdot <= vdot_max               joint limits, and the shoulders'
                                                      tendon rows (control/tasks/)

The program holds only the contacts that are active: the controller keeps one per set
of active contacts (its size, and so its solve time, shrinks once the seat is released).
The tasks (A_k, b_k, w_k) are Task objects (control/tasks/), consumed generically: the
ones active in the tick's standup state, each refreshed by its update(); the solver is a
backend chosen by name (daqp, or Drake's OSQP / Clarabel).

The torque limits rarely bind: each tick first solves without them (daqp 10-20 % faster),
again with them only if the torques come out beyond; a solution within the limits is the
optimum with them (the program is strictly convex). Likewise the soft joint-limit rows
(a row and a slack each) are left out for the joints whose limit is not in play: the
program without them is a relaxation of the full one, so its optimum is the full one's
whenever it keeps those joints' vdot within bounds unslacked; each tick checks that and
solves again with the joints that break it. Kept: those in play at the last tick.

daqp's infeasible verdict is wrong on some programs that have a solution (random states
near a torque limit): where it fails a program, Clarabel solves it before the relaxed
fallback is tried (counted: QpSolution.fallback, metrics' qp_fallback_ticks).
"""

import time

import numpy as np

from drake_standup.control.backends import make_backend
from drake_standup.control.contacts import WRENCH_SIZE, wrench_cone_matrix
from drake_standup.control.pad_dynamics import PadRows

# Other modules and the tests import the QP's types from here too (QpLayout only for them).
from drake_standup.control.qp_types import (
    AccelerationBounds,
    ActiveTasks,
    ContactMap,
    QpContactBounds,
    QpSolution,
    Task,
    as_slice,
)
from drake_standup.control.qp_types import QpLayout as QpLayout
from drake_standup.control.soft_rows import SoftRows
from drake_standup.control.targets import TaskReferences
from drake_standup.control.terms import RobotTerms

N_BASE = 6  # unactuated floating-base velocities


class WholeBodyQp:
    """Builds the program of the module docstring once for a set of active contacts;
    refills and solves it each tick.

    Everything that does not depend on the state is filled in once: the cone rows, the
    regularisation, and for each set of active tasks the constant tasks' cost and the
    Hessian blocks of those whose A is constant.
    """

    def __init__(
        self,
        contact_map: ContactMap,
        B: np.ndarray,
        *,
        torque_limit_Nm: float,
        torque_weight: float,
        wrench_weight: float,
        acceleration_weight: float,
        tasks: list[Task],
        modes: tuple[int, ...],
        acceleration_bounds: AccelerationBounds | None = None,
        soft_bounds: AccelerationBounds | None = None,
        soft_bound_weight: float = 0.0,
        solver: str = "daqp",
        contact_velocity_gain_per_s: float = 0.0,
        pad_period_s: float = 0.0,
    ):
        """contact_map: the active contacts and their map (the tasks may share it).
        tasks: the cost's tasks. modes: the values references.standup_state takes
        (each task is active in its active_states of them). acceleration_bounds: bounds on
        entries of vdot, computed each tick (None: none). soft_bounds: bounds that a slack
        s per row may move, vdot_min <= vdot - s <= vdot_max (and c^T vdot - s for each of
        its combined_rows c, where it has them), at the cost soft_bound_weight s^2 (at the
        optimum |s| is the violation; one two-sided row each, the slacks last in z, after
        the layout's unknowns): the program stays feasible whatever the state."""
        nv, nu = B.shape
        if not (np.all((B == 0) | (B == 1)) and np.all(B.sum(axis=0) == 1)):
            raise ValueError("the actuation matrix B must select one velocity per actuator")
        self.contact_map = contact_map
        self.layout = layout = contact_map.layout
        self.contacts = contacts = contact_map.contacts
        self.frames = [spec.frame for spec in contacts]
        self._solver = solver
        self._velocity_gain = contact_velocity_gain_per_s
        self._torque_limit_Nm = torque_limit_Nm
        self._torque_weight = torque_weight
        nw = layout.n_wrench
        self._soft_bounds = soft_bounds
        # Soft rows: one per entry of v_indices (vdot_i), then one per combined row (c^T vdot).
        self._combined = np.zeros((0, B.shape[0]))
        if soft_bounds is not None and getattr(soft_bounds, "combined_rows", None) is not None:
            self._combined = np.asarray(soft_bounds.combined_rows, dtype=float)
        n_soft = 0 if soft_bounds is None else len(soft_bounds.v_indices) + len(self._combined)
        self.n = n = layout.n + n_soft  # unknowns: the layout's, then the slacks
        self._slack = slice(layout.n, n)

        rows_acc, rows_dynamics = self._lay_out_rows(nu, n_soft)
        self._set_up_screening(n_soft)
        # The constrained contacts' rows are equalities (all rows held) until solve() gets
        # QpContactBounds.partially_held: the last one it got.
        self._equality[self._bounds(rows_acc)] = 1
        self._partially_held: dict[int, np.ndarray] = {}
        # Rows of A that the last partially_held leaves free (None: all held).
        self._free_rows: np.ndarray | None = None
        self._acceleration_bounds = acceleration_bounds
        self._make_views(B, rows_acc, rows_dynamics)
        self._pad_rows = PadRows(self, pad_period_s)  # the seat pads' rows
        self._H_regularisation = np.diag(
            np.concatenate(
                [
                    np.full(nw, wrench_weight),
                    np.full(nv, acceleration_weight),
                    np.full(n_soft, soft_bound_weight),
                ]
            )
        )
        self.tasks = list(tasks)
        # mode -> its ActiveTasks.
        self._active_tasks = self._tasks_by_mode(modes)
        # Without the torque rows (tried first), and with them (module docstring): A, lo,
        # hi, equality and a backend for each.
        A, lo, hi, m = self._A, self._lo, self._hi, self._rows_tau.stop
        self._programs = [
            (A[:rows], lo[: n + rows], hi[: n + rows], self._equality[: n + rows], None)
            for rows in (self._rows_tau.start, m)
        ]
        self.fallback_solves = 0  # ticks solved by daqp's fallback

    def _lay_out_rows(self, nu: int, n_soft: int) -> tuple[slice, slice]:
        """Allocates A, lo, hi, equality with the constant rows; returns the held and (1) rows."""
        layout, contacts, soft_bounds, n = self.layout, self.contacts, self._soft_bounds, self.n
        # Rows of A: accelerations of the constrained contacts (6 each), cones (10 per
        # contact), then the rows of (1): the six base rows and, last, the torques (nu),
        # tau = B^T (...) picking the actuated rows of a generalized force. The bound
        # vectors lo, hi hold first the simple bounds on all n unknowns, then one entry
        # per row of A (daqp's layout); _bounds(rows) maps rows of A to their entries.
        self._held = [c for c, spec in enumerate(contacts) if spec.constrained]
        rows_acc = slice(0, WRENCH_SIZE * len(self._held))
        cones = [wrench_cone_matrix(spec) for spec in contacts]
        row = rows_acc.stop
        rows_cones = slice(row, row + sum(len(K) for K in cones))
        # Soft bounds: vdot_min_i <= vdot_i - s_i <= vdot_max_i.
        rows_soft = slice(rows_cones.stop, rows_cones.stop + n_soft)
        rows_dynamics = slice(rows_soft.stop, rows_soft.stop + N_BASE + nu)
        self._rows_tau = slice(rows_dynamics.start + N_BASE, rows_dynamics.stop)
        m = self._rows_tau.stop
        self._A = A = np.zeros((m, n))
        self._lo = lo = np.full(n + m, -np.inf)
        self._hi = hi = np.full(n + m, np.inf)
        self._equality = np.zeros(n + m, dtype=np.int32)  # 1: lo == hi is an equality
        for c, K in enumerate(cones):
            cone = slice(row, row + len(K))
            row = cone.stop
            A[cone, layout.wrench(c)] = K
            hi[self._bounds(cone)] = 0.0
        self._equality[self._bounds(slice(rows_dynamics.start, self._rows_tau.start))] = 1
        if n_soft:
            entries = np.arange(n_soft)
            n_single = len(soft_bounds.v_indices)
            columns = layout.vdot.start + np.asarray(soft_bounds.v_indices, dtype=int)
            A[rows_soft.start + entries[:n_single], columns] = 1.0
            A[rows_soft.start + n_single : rows_soft.stop, layout.vdot] = self._combined
            A[rows_soft.start + entries, self._slack.start + entries] = -1.0
            self._soft_lo = lo[self._bounds(rows_soft)]
            self._soft_hi = hi[self._bounds(rows_soft)]
        self._rows_soft = rows_soft
        return rows_acc, rows_dynamics

    def _set_up_screening(self, n_soft: int) -> None:
        """Screening the soft rows (module docstring; soft_rows.py), and which rows the
        next tick keeps. daqp only: the Drake backends hold programs of one size."""
        soft_bounds = self._soft_bounds
        self._soft_rows = SoftRows(
            self.n,
            self.layout.vdot,
            np.zeros(0, dtype=int) if soft_bounds is None else soft_bounds.v_indices,
            self._combined,
            self._slack.start,
            self._rows_soft.start,
        )
        self._screen = bool(n_soft) and self._solver == "daqp"
        self._soft_kept = np.zeros(n_soft, dtype=bool)
        self.screening_resolves = 0  # ticks that had to solve again (a joint broke in)

    def _make_views(self, B: np.ndarray, rows_acc: slice, rows_dynamics: slice) -> None:
        """The views of A, lo, hi that solve() refills each tick, and the indices it fills."""
        A, lo, hi, layout = self._A, self._lo, self._hi, self.layout
        nw, nc, nu = layout.n_wrench, len(self.contacts), B.shape[1]
        self._A_acc = A[rows_acc, layout.vdot]
        self._lo_acc, self._hi_acc = lo[self._bounds(rows_acc)], hi[self._bounds(rows_acc)]
        self._A_dynamics_F = A[rows_dynamics, :nw]
        self._A_dynamics_vdot = A[rows_dynamics, layout.vdot]
        self._lo_dynamics = lo[self._bounds(rows_dynamics)]
        self._hi_dynamics = hi[self._bounds(rows_dynamics)]
        self._T = A[self._rows_tau]  # tau = T z + t0
        # Rows of a generalized force in the rows of (1); the actuated ones.
        self._generalized_rows = as_slice(np.r_[np.arange(N_BASE), B.argmax(axis=0)])
        self._actuated = as_slice(B.argmax(axis=0))
        # lo, hi of the rows of (1) are r + these, r = tau_hand - h (rows in order).
        self._dynamics_lo = np.r_[np.zeros(N_BASE), np.full(nu, -self._torque_limit_Nm)]
        self._dynamics_hi = -self._dynamics_lo
        # The normal forces' entries of z.
        self._normal = np.array([layout.wrench(c).stop - 1 for c in range(nc)])
        if self._acceleration_bounds is not None:
            self._bounded_vdot = nw + np.asarray(self._acceleration_bounds.v_indices, dtype=int)

    def _tasks_by_mode(self, modes: tuple[int, ...]) -> dict[int, ActiveTasks]:
        """Each mode's ActiveTasks (modes with the same active tasks share one)."""
        by_flags: dict[tuple[bool, ...], ActiveTasks] = {}
        active_tasks: dict[int, ActiveTasks] = {}
        for state in modes:
            flags = tuple(
                task.active_states is None or state in task.active_states for task in self.tasks
            )
            if flags not in by_flags:
                by_flags[flags] = ActiveTasks.of(
                    [task for task, on in zip(self.tasks, flags, strict=True) if on],
                    self._H_regularisation,
                )
            active_tasks[state] = by_flags[flags]
        return active_tasks

    def _solve_screened(self, backend, H, g, A, lo, hi, *, equality) -> tuple[np.ndarray, bool]:
        """The program (A: its rows) solved without the soft rows of the joints whose limit
        is not in play, and again with those that break their bounds (module docstring).
        z has every entry (the left-out slacks 0)."""
        if not self._screen:
            return backend.solve(H, g, A, lo, hi, equality)
        n, m = self.n, A.shape[0]
        soft_lo, soft_hi = self._soft_lo, self._soft_hi
        kept = self._soft_kept
        while True:
            if kept.all():
                z, ok = backend.solve(H, g, A, lo, hi, equality)
                break
            dropped, columns, rows, entries = self._soft_rows.screened_indices(kept, m)
            z_kept, ok = backend.solve(
                H.take(columns, 0).take(columns, 1),
                g.take(columns),
                A.take(rows, 0).take(columns, 1),
                lo.take(entries),
                hi.take(entries),
                equality.take(entries),
            )
            z = np.zeros(n)
            z[columns] = z_kept
            if not ok:
                break  # a relaxation infeasible: so is the full program
            vdot = self._soft_rows.values(z, dropped)
            tolerance = 1e-9 * (1.0 + np.abs(vdot))
            broken = (vdot < soft_lo[dropped] - tolerance) | (vdot > soft_hi[dropped] + tolerance)
            if not broken.any():
                break
            kept = kept.copy()
            kept[dropped[broken]] = True
            self.screening_resolves += 1
        if ok:
            # In play: at a bound (within 1e-6 of its width) or moved by its slack.
            s = z[self._slack]
            v = self._soft_rows.values(z) - s
            span = soft_hi - soft_lo  # a one-sided row's (a tendon's) is infinite
            width = 1e-6 * (1.0 + np.where(np.isfinite(span), span, 0.0))
            self._soft_kept = (np.abs(s) > 1e-9) | (v <= soft_lo + width) | (v >= soft_hi - width)
        return z, ok

    def _solve_relaxed(self, H: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, bool]:
        """The fallback when the program is infeasible (or the solver fails): the same
        cost and torque limits, but no minimum normal force and no held contact
        acceleration (contact forces stay in their cones). Feasible by construction: the
        contact forces 0 and any torques within the limits satisfy the dynamics through
        vdot = M^-1 (...). Solved on copies of the bounds, once per failure."""
        A, lo, hi, equality, backend = self._programs[-1]
        if backend is None:
            backend = make_backend(self._solver, *A.shape[::-1])
            self._programs[-1] = A, lo, hi, equality, backend
        lo, hi, equality = lo.copy(), hi.copy(), equality.copy()
        lo[self._normal] = 0.0
        held = self._bounds(slice(0, len(self._lo_acc)))
        lo[held], hi[held], equality[held] = -np.inf, np.inf, 0
        z, ok = backend.solve(H, g, A, lo, hi, equality)
        return z, ok and bool(np.isfinite(z).all())

    def _bounds(self, rows: slice) -> slice:
        """Entries of lo, hi (after the n simple bounds) that belong to rows of A."""
        n = self.n
        return slice(n + rows.start, n + rows.stop)

    def solve(
        self,
        terms: RobotTerms,
        references: TaskReferences,
        commands: QpContactBounds,
    ) -> QpSolution:
        """Solves the tick's QP.

        terms: for the program's contact frames (frames), in its order. references: what
        the tasks track (and tau_hand = J_h^T F_hand, the hands' generalized force, None:
        no pull); the tasks active in references.standup_state are updated from them.
        commands: the contact plan's bounds and held rows.
        """
        t_start = time.perf_counter()
        active = self._active_tasks[references.standup_state]
        for task in active.updated:
            task.update(terms, references)
        r = self._fill_dynamics(terms, references.tau_hand)
        self._fill_held_contacts(terms, commands.partially_held)
        self._pad_rows.fill(terms, commands.partially_held, commands.measured_normal_force_N)
        self._fill_bounds(terms, commands)
        r_actuated = r[self._actuated]
        H, g = self._cost(active, r_actuated)
        t_assembled = time.perf_counter()
        z, ok, tau, relaxed, fallback = self._solve_within_limits(H, g, r_actuated)
        self.fallback_solves += int(fallback)
        t_solved = time.perf_counter()
        nc, nw = len(self.contacts), self.layout.n_wrench
        F_C = np.zeros((nc, WRENCH_SIZE))
        F_C.reshape(-1)[self.contact_map.unknowns] = z[:nw]
        return QpSolution(
            frames=list(self.frames),
            ok=ok,
            vdot=z[self.layout.vdot],
            slack=z[self._slack],
            relaxed=relaxed,
            fallback=fallback,
            F_C=F_C,
            tau=tau,
            assembly_s=t_assembled - t_start,
            solve_s=t_solved - t_assembled,
            frame_rotations=terms.frame_rotations,
        )

    def _fill_dynamics(self, terms: RobotTerms, tau_hand: np.ndarray | None) -> np.ndarray:
        """Fills the rows of (1) and (2), [-G, M] z in [r + lo, r + hi]; r = tau_hand - h."""
        GT = self.contact_map(terms)
        rows = self._generalized_rows
        np.negative(GT.T[rows], out=self._A_dynamics_F)
        self._A_dynamics_vdot[:] = terms.M[rows]
        r = np.negative(terms.h) if tau_hand is None else tau_hand - terms.h
        np.add(r[rows], self._dynamics_lo, out=self._lo_dynamics)
        np.add(r[rows], self._dynamics_hi, out=self._hi_dynamics)
        return r

    def _fill_held_contacts(self, terms: RobotTerms, partially_held: dict[int, np.ndarray]) -> None:
        """Fills the held rows of J_CP vdot = -Jdot_CP v - k J_CP v, in C; frees the others."""
        self._A_acc[:] = terms.J_P.reshape(self._A_acc.shape)
        np.negative(terms.Jdotv_P.reshape(-1), out=self._lo_acc)
        if self._velocity_gain:
            self._lo_acc -= self._velocity_gain * (self._A_acc @ terms.v)
        self._hi_acc[:] = self._lo_acc
        if partially_held is not self._partially_held:
            self._partially_held = partially_held
            free = [
                WRENCH_SIZE * self._held.index(c) + np.flatnonzero(~held)
                for c, held in partially_held.items()
            ]
            self._free_rows = np.concatenate(free) if free else None
            self._equality[self._bounds(slice(0, len(self._lo_acc)))] = 1
            if self._free_rows is not None:
                self._equality[self.n + self._free_rows] = 0
        if self._free_rows is not None:
            self._lo_acc[self._free_rows] = -np.inf
            self._hi_acc[self._free_rows] = np.inf

    def _fill_bounds(self, terms: RobotTerms, commands: QpContactBounds) -> None:
        """Fills the bounds of the normal forces (f_z comes last in F_c) and accelerations."""
        lo, hi = self._lo, self._hi
        lo[self._normal] = commands.min_normal_force_N
        hi[self._normal] = commands.max_normal_force_N
        if self._acceleration_bounds is not None:
            vdot_min, vdot_max = self._acceleration_bounds.calc(terms)
            lo[self._bounded_vdot] = vdot_min
            hi[self._bounded_vdot] = vdot_max
        if self._soft_bounds is not None:
            self._soft_lo[:], self._soft_hi[:] = self._soft_bounds.calc(terms)

    def _cost(self, active: ActiveTasks, r_actuated: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """H, g: w_tau ||T z + t0||^2 with t0 = -r[actuated], the tasks, the fixed part."""
        T = self._T
        WT = self._torque_weight * T.T
        H = WT @ T
        H += active.H_fixed
        g = WT @ r_actuated
        np.negative(g, out=g)
        if active.g_fixed is not None:
            g += active.g_fixed
        for task in active.varying:
            WA = task.A.T * task.weight
            H[task.columns, task.columns] += WA @ task.A
            g[task.columns] -= WA @ task.b
        for task, minus_WA in active.tracking:
            g[task.columns] += minus_WA @ task.b
        return H, g

    def _solve_within_limits(
        self, H: np.ndarray, g: np.ndarray, r_actuated: np.ndarray
    ) -> tuple[np.ndarray, bool, np.ndarray, bool, bool]:
        """z, ok, tau, relaxed, fallback: without the torque rows, then with them, then
        relaxed if need be; fallback: the solution is the fallback solver's (backends.py)."""
        T = self._T
        fallbacks = self._fallbacks()
        for k, (A, lo_k, hi_k, equality, backend) in enumerate(self._programs):
            if backend is None:
                backend = make_backend(self._solver, *A.shape[::-1])
                self._programs[k] = A, lo_k, hi_k, equality, backend
            z, ok = self._solve_screened(backend, H, g, A, lo_k, hi_k, equality=equality)
            tau = T @ z
            tau -= r_actuated
            if not ok or np.abs(tau).max() <= self._torque_limit_Nm:
                break
        ok = ok and bool(np.isfinite(z).all())
        relaxed = False
        if not ok:
            z, ok = self._solve_relaxed(H, g)
            tau = T @ z
            tau -= r_actuated
            relaxed = ok
        return z, ok, tau, relaxed, ok and not relaxed and self._fallbacks() > fallbacks

    def _fallbacks(self) -> int:
        """Programs daqp failed that its fallback solved, so far (backends.py)."""
        return sum(getattr(program[-1], "fallbacks", 0) for program in self._programs)
