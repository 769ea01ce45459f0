"""A gated advancement law: psi runs ahead in proportion to the help along the path."""

from drake_standup.plugins import LawInputs

GAIN_S2_PER_M = 2.0  # psi_dot's excess over 1 per m/s^2 of help along the path


def gated_law(inputs: LawInputs) -> float:
    """psi_dot = 1 + GAIN (alpha - alpha_min), while the CoM keeps up with its reference,
    tapered to 1 over the last part of each segment."""
    config = inputs.config
    if inputs.alpha <= config.alpha_min_mps2:
        return 1.0  # no help along the path: psi = t
    if inputs.lead_m < -config.lag_tolerance_m:
        return 1.0  # the CoM lags its reference: wait for it
    excess = GAIN_S2_PER_M * (inputs.alpha - config.alpha_min_mps2)
    start = config.taper_from_progress
    if inputs.progress > start:
        excess *= max(0.0, 1.0 - (inputs.progress - start) / (1.0 - start))
    return min(config.psi_dot_upper, 1.0 + excess)
