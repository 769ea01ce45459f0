"""CoMReferenceGenerator: the CoM path x_d(psi) and its time derivatives.

Each stand-up state k >= 2 moves the CoM along a min-jerk segment
    x_d(psi) = x_start + delta * s(tau),  tau = clamp((psi - psi_entry) / T, 0, 1),
    s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5,
and time derivatives follow by the chain rule (SPEC 2):
    xd_dot  = d_psi x_d * psi_dot
    xd_ddot = d2_psi x_d * psi_dot^2 + d_psi x_d * psi_ddot.
Segments start where the previous one ended (the state machine passes its end
as x_start) and s', s'' vanish at both ends, so value and slope are continuous.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.caching import declare_cached

SEGMENT_SIZE = 8  # [psi_entry, T, x_start (3), delta (3)]


def smoothstep(r: float) -> float:
    """3 r^2 - 2 r^3 on r clamped to [0, 1]: 0 -> 1 with zero slope at both ends (the
    fades and ramps of the advancement, the controller and the seat's unloading)."""
    r = min(max(r, 0.0), 1.0)
    return r * r * (3.0 - 2.0 * r)


def min_jerk(tau: float) -> tuple[float, float, float]:
    """s, ds/dtau, d2s/dtau2 of the min-jerk profile, clamped outside [0, 1]."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    t2, t3 = tau * tau, tau * tau * tau
    return (
        10 * t3 - 15 * t3 * tau + 6 * t3 * t2,
        30 * t2 - 60 * t3 + 30 * t2 * t2,
        60 * tau - 180 * t2 + 120 * t3,
    )


def path(segment: np.ndarray, psi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x_d, d_psi x_d and d2_psi x_d of one segment at psi."""
    psi_entry, T = segment[0], segment[1]
    x_start, delta = segment[2:5], segment[5:8]
    s, ds, dds = min_jerk((psi - psi_entry) / T)
    return x_start + delta * s, delta * ds / T, delta * dds / (T * T)


class CoMReferenceGenerator(LeafSystem):
    """Inputs psi, psi_dot, psi_ddot (1 each), segment (8, from the state machine).

    Outputs com_reference (9: [x_d, xd_dot, xd_ddot], world), and x_d_W (3)
    and path_tangent_W (3: d_psi x_d), which depend on psi and segment only,
    so the advancement can use them without an algebraic loop; path_progress
    (1: (psi - psi_entry) / T in [0, 1], how far along the current segment).
    """

    def __init__(self):
        super().__init__()
        self._psi = self.DeclareVectorInputPort("psi", 1)
        self._psi_dot = self.DeclareVectorInputPort("psi_dot", 1)
        self._psi_ddot = self.DeclareVectorInputPort("psi_ddot", 1)
        self._segment = self.DeclareVectorInputPort("segment", SEGMENT_SIZE)
        # Where psi is outside its segment the path is the segment's start or end:
        # (segment bytes, end) -> path(), computed once (most of a run; read only).
        self._clamped: dict[tuple[bytes, bool], tuple[np.ndarray, ...]] = {}
        # The path depends on psi and the segment only: evaluated once per
        # change of them for all four outputs.
        self._path = declare_cached(
            self, "path at psi", self._calc_path, {self._psi.ticket(), self._segment.ticket()}
        )
        path_only = {self._path.ticket()}
        self.DeclareVectorOutputPort(
            "com_reference",
            9,
            self._CalcReference,
            prerequisites_of_calc=path_only | {self._psi_dot.ticket(), self._psi_ddot.ticket()},
        )
        self.DeclareVectorOutputPort(
            "x_d_W", 3, self._CalcPosition, prerequisites_of_calc=path_only
        )
        self.DeclareVectorOutputPort(
            "path_tangent_W", 3, self._CalcTangent, prerequisites_of_calc=path_only
        )
        self.DeclareVectorOutputPort(
            "path_progress", 1, self._CalcProgress, prerequisites_of_calc=path_only
        )

    def _calc_path(self, context: Context) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """x_d, d_psi x_d, d2_psi x_d and the progress along the segment at psi."""
        segment = self._segment.Eval(context)
        psi = self._psi.Eval(context)[0]
        tau = (psi - segment[0]) / segment[1]
        progress = min(max(tau, 0.0), 1.0)
        if not (tau <= 0.0 or tau >= 1.0):  # min_jerk's own test (NaN: computed)
            return (*path(segment, psi), progress)
        # min_jerk is constant there: path() of the segment at its start or end.
        key = (segment.tobytes(), tau >= 1.0)
        clamped = self._clamped.get(key)
        if clamped is None:
            if len(self._clamped) > 64:
                self._clamped.clear()
            clamped = self._clamped[key] = path(segment, psi)
            for array in clamped:
                array.flags.writeable = False
        return (*clamped, progress)

    def _CalcReference(self, context: Context, output: BasicVector) -> None:
        x_d, d_x, dd_x, _ = self._path.Eval(context)
        psi_dot = self._psi_dot.Eval(context)[0]
        psi_ddot = self._psi_ddot.Eval(context)[0]
        output.SetFromVector(
            np.concatenate([x_d, d_x * psi_dot, dd_x * psi_dot**2 + d_x * psi_ddot])
        )

    def _CalcPosition(self, context: Context, output: BasicVector) -> None:
        x_d = self._path.Eval(context)[0]
        output.SetFromVector(x_d)

    def _CalcTangent(self, context: Context, output: BasicVector) -> None:
        d_x = self._path.Eval(context)[1]
        output.SetFromVector(d_x)

    def _CalcProgress(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._path.Eval(context)[3])
