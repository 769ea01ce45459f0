"""Static balance of the robot under a wrench on its hands: the CoM shift that keeps the
feet's centre of pressure where it was (the lean the stand-up's CoM target takes, and the
measure of what the standing feet can still hold)."""

import numpy as np


def static_lean(
    hand_wrench_Com: np.ndarray, com_height_m: float, weight_N: float, max_lean_m: float
) -> np.ndarray:
    """(3,) CoM shift (x, y; z = 0) that keeps the feet's centre of pressure where it is
    without the pull, in static balance.

    hand_wrench_Com = [tau; f], the hands' resultant about the CoM (W, N m / N). With the
    CoM at height h above the soles and the ground reaction R = -(f + m g) acting at the
    CoP p, the moments about the CoM balance when

        p_x - c_x = (tau_y + h f_x) / (m g - f_z),   p_y - c_y = -(tau_x - h f_y) / (m g - f_z):

    so the CoM moves by -(tau_y + h f_x) / (m g - f_z) in x and (tau_x - h f_y) / (m g - f_z)
    in y for the CoP to stay put. Clipped to max_lean_m (each axis); zero if the pull
    would lift the robot."""
    tau, f = hand_wrench_Com[:3], hand_wrench_Com[3:]
    support = weight_N - f[2]
    if support <= 0.0:
        return np.zeros(3)
    lean = np.array(
        [-(tau[1] + com_height_m * f[0]) / support, (tau[0] - com_height_m * f[1]) / support, 0.0]
    )
    return np.clip(lean, -max_lean_m, max_lean_m)
