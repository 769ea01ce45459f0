"""The whole-body QP's soft rows (control/qp.py): one per bounded joint (vdot_i) and one
per combined row (c^T vdot, the shoulders' tendons), each with its slack; their values at
a solution, and the index sets of a program that leaves some of them out (screening)."""

import numpy as np


class SoftRows:
    """The soft rows of a program of n unknowns whose slacks start at slack_start and
    whose soft rows of A start at first_row."""

    def __init__(
        self,
        n: int,
        vdot: slice,
        v_indices: np.ndarray,
        combined: np.ndarray,
        slack_start: int,
        first_row: int,
    ):
        """vdot: the accelerations' entries of z; v_indices: each joint row's vdot entry;
        combined: the combined rows' coefficients over vdot (k x nv)."""
        self._n, self._vdot, self._combined = n, vdot, combined
        self._single = vdot.start + np.asarray(v_indices, dtype=int)
        self._slack_start, self._first_row = slack_start, first_row
        self._cache: dict[tuple[bytes, int], tuple[np.ndarray, ...]] = {}

    def values(self, z: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """The rows' values at z (rows: those of them, all if None), slacks aside: vdot_i
        for a joint's row, c^T vdot for a combined one."""
        n_single = len(self._single)
        if rows is None:
            rows = np.arange(n_single + len(self._combined))
        if not len(self._combined):
            return z[self._single[rows]]
        values = np.empty(len(rows))
        single = rows < n_single
        values[single] = z[self._single[rows[single]]]
        values[~single] = self._combined[rows[~single] - n_single] @ z[self._vdot]
        return values

    def screened_indices(self, kept: np.ndarray, m: int) -> tuple[np.ndarray, ...]:
        """For the rows kept (bool, per row) of a program of m rows: the rows left out,
        and the kept entries of z, rows of A and entries of lo, hi (integer arrays: take()
        copies them several times faster than a boolean mask)."""
        key = (kept.tobytes(), m)
        indices = self._cache.get(key)
        if indices is None:
            dropped = np.flatnonzero(~kept)
            columns = np.setdiff1d(np.arange(self._n), self._slack_start + dropped)
            rows = np.setdiff1d(np.arange(m), self._first_row + dropped)
            entries = np.concatenate((columns, self._n + rows))
            if len(self._cache) > 256:  # joints in play come and go
                self._cache.clear()
            indices = self._cache[key] = (dropped, columns, rows, entries)
        return indices
