"""smoothstep: the C1 blend the laws fade with (the advancement's, the controller's and
the seat's unloading)."""


def smoothstep(r: float) -> float:
    """3 r^2 - 2 r^3 on r clamped to [0, 1]: 0 -> 1 with zero slope at both ends (the
    fades and ramps of the advancement, the controller and the seat's unloading)."""
    r = min(max(r, 0.0), 1.0)
    return r * r * (3.0 - 2.0 * r)
