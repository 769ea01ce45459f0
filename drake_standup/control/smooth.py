"""smoothstep: the C1 blend the laws fade with (the advancement's, the controller's and
the seat's unloading); psi_clock_blend: one step of a first-order filter run on psi."""


def smoothstep(r: float) -> float:
    """3 r^2 - 2 r^3 on r clamped to [0, 1]: 0 -> 1 with zero slope at both ends (the
    fades and ramps of the advancement, the controller and the seat's unloading)."""
    r = min(max(r, 0.0), 1.0)
    return r * r * (3.0 - 2.0 * r)


def psi_clock_blend(period_s: float, time_constant_s: float, psi_dot: float) -> float:
    """The share of the gap a first-order filter of time_constant_s closes in one period_s
    step run on psi's clock, never slower than time (psi = t: the filter on time): the
    posture and the lean advance with the CoM path, as the paper's trajectory does."""
    return min(period_s / time_constant_s * max(psi_dot, 1.0), 1.0)
