"""The whole-body QP's types (the solver, WholeBodyQp, is control/qp.py): where each
unknown sits in z = [F_1 .. F_nc, vdot] (QpLayout), the contact unknowns' map to
generalized forces (ContactMap), the protocols of the cost's tasks and of the acceleration
bounds (Task, AccelerationBounds; control/tasks/ makes them), a set of active tasks with
their constant cost precomputed (ActiveTasks), what a tick's contact plan asks of the
program (QpContactBounds) and what it returns (QpSolution); as_slice, index arrays as
slices where they can be."""

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Protocol

import numpy as np

from drake_standup.control.contacts import WRENCH_SIZE, ContactSpec
from drake_standup.control.targets import TaskReferences
from drake_standup.control.terms import RobotTerms


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


class Task:
    """One least-squares objective, w ||A z[columns] - b||^2 (w: weight, a scalar or one
    weight per row of A), in the modes active_states (None: every mode; control/tasks/).

    A task sets weight, columns, A and b when it is made and refreshes what changes in
    update(), each tick it is active. constant_A: A never changes, so the QP adds w A^T A
    to its Hessian once per set of active tasks; constant_b: neither does b."""

    name: str
    weight: float | np.ndarray
    columns: slice
    A: np.ndarray  # (rows, width of columns)
    b: np.ndarray  # (rows,)
    active_states: frozenset[int] | None = None
    constant_A: bool = False
    constant_b: bool = False

    def update(self, terms: RobotTerms, references: TaskReferences) -> None:
        """Refreshes A and/or b for the tick (a constant task has nothing to do)."""


class AccelerationBounds(Protocol):
    """Bounds vdot_min <= vdot[v_indices] <= vdot_max that change with the state
    (control/tasks/: JointLimitBounds); a soft bound may add combined rows (k x nv), each
    bounding c^T vdot, after those of v_indices in calc()'s arrays."""

    v_indices: np.ndarray
    combined_rows: np.ndarray | None

    def calc(self, terms: RobotTerms) -> tuple[np.ndarray, np.ndarray]:
        """(vdot_min, vdot_max) at terms' state."""


@dataclass
class QpContactBounds:
    """What the contact plan asks of the program's contacts this tick (in its order)."""

    min_normal_force_N: np.ndarray  # (nc,)
    max_normal_force_N: np.ndarray  # (nc,)
    # Constrained contacts that hold only some rows of their hold point's spatial
    # acceleration, in C ([alpha; a]): contact index -> held rows; the others hold all.
    partially_held: dict[int, np.ndarray]
    # The contacts' measured normal forces (nc,: NaN where not measured; None: none), N.
    measured_normal_force_N: np.ndarray | None = None


@dataclass
class QpSolution:
    """A tick's solution; on failure (ok False) its numbers are not to be used."""

    frames: list[str]  # the contacts' task frames, in the order of F_C and F_W
    ok: bool
    vdot: np.ndarray  # (nv,)
    F_C: np.ndarray  # (nc, 6) each contact's wrench in its frame, [tau; f], N m / N
    tau: np.ndarray  # (nu,) joint torques, actuator order, N m
    assembly_s: float
    solve_s: float
    frame_rotations: Callable[[], np.ndarray]  # () -> the contact frames' R_WC (nc, 3, 3)
    slack: np.ndarray = field(default_factory=lambda: np.zeros(0))  # soft bounds' s
    # Solved only with the contacts relaxed (WholeBodyQp._solve_relaxed): the torques are
    # the best the program could do, not a command that keeps the contacts.
    relaxed: bool = False
    # Solved by the fallback solver where daqp called the program infeasible (qp.py).
    fallback: bool = False

    @cached_property
    def F_W(self) -> np.ndarray:
        """(nc, 6) F_C at each contact frame's origin, in W (computed when asked for: the
        controller does not need the frames' poses)."""
        nc = len(self.frames)
        # [tau; f] in C -> W, all contacts at once: (nc, 3, 3) @ (nc, 3, 2).
        R_WC = self.frame_rotations()
        F_W = (R_WC @ self.F_C.reshape(nc, 2, 3).transpose(0, 2, 1)).transpose(0, 2, 1)
        return F_W.reshape(nc, WRENCH_SIZE)


def as_slice(indices: np.ndarray) -> slice | np.ndarray:
    """indices as a slice when they are consecutive (a view instead of a copy)."""
    indices = np.asarray(indices)
    if len(indices) and np.array_equal(indices, np.arange(indices[0], indices[0] + len(indices))):
        return slice(int(indices[0]), int(indices[0]) + len(indices))
    return indices


class ContactMap:
    """G^T (n_wrench, nv), G_c = J_c^T X_c: the contact unknowns to generalized forces
    (X_c: the unknowns of contact c to its 6-D wrench at Co, in W): the rows of the
    contacts' Jacobians expressed in their own frames (control/terms.py) that act on the
    unknowns. Its first six columns map them to their resultant about the base origin, in
    W. Shared by the QP and the tasks that need it, computed once per terms."""

    def __init__(self, contacts: list[ContactSpec], nv: int):
        self.contacts = list(contacts)
        self.layout = QpLayout.of(contacts, nv)
        # The unknowns' rows among each contact's 6-D wrench [tau; f] (f_z last): rows of
        # the contacts' stacked Jacobians (nc * 6, nv).
        self.unknowns = np.concatenate(
            [
                WRENCH_SIZE * c + np.arange(WRENCH_SIZE)[spec.components]
                for c, spec in enumerate(contacts)
            ]
        )
        self._GT: np.ndarray | None = None
        self._terms: RobotTerms | None = None

    def __call__(self, terms: RobotTerms) -> np.ndarray:
        """G^T for terms, which holds the contact frames in this map's order."""
        if self._terms is not terms:
            self._GT = terms.J_F.reshape(-1, self.layout.nv)[self.unknowns]
            self._terms = terms
        return self._GT


@dataclass
class ActiveTasks:
    """The tasks active in a set of standup states and what the QP precomputes of them."""

    updated: list[Task]  # the ones with an update() to call
    varying: list[Task]  # A changes: w A^T A and w A^T b each tick
    # A constant, b not: (task, -w A^T); their Hessian blocks are in H_fixed.
    tracking: list[tuple[Task, np.ndarray]]
    H_fixed: np.ndarray  # regularisation + w A^T A of the constant-A tasks
    g_fixed: np.ndarray | None  # -w A^T b of the constant tasks (None: zero)

    @classmethod
    def of(cls, tasks: list[Task], H_regularisation: np.ndarray) -> "ActiveTasks":
        """For a set of active tasks: H_fixed = H_regularisation + w A^T A of those with a
        constant A, g_fixed = -w A^T b of the constant ones, in the tasks' order."""
        H = H_regularisation.copy()
        g = np.zeros(len(H))
        tracking = []
        for task in tasks:
            if not task.constant_A:
                continue
            WA = task.A.T * task.weight
            H[task.columns, task.columns] += WA @ task.A
            if task.constant_b:
                g[task.columns] -= WA @ task.b
            else:
                tracking.append((task, -WA))
        return cls(
            updated=[task for task in tasks if not (task.constant_A and task.constant_b)],
            varying=[task for task in tasks if not task.constant_A],
            tracking=tracking,
            H_fixed=H,
            g_fixed=g if g.any() else None,
        )
