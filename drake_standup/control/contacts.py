"""Contact wrenches: the constraints one 6-D contact puts on its wrench, and its maps.

A contact wrench F_C = [tau_C; f_C] acts at the origin of the contact frame C and is
expressed in C (z along the surface normal, into the robot), so the constraints below
are constant; only the maps to the world change with the robot's state.
"""

from dataclasses import dataclass

import numpy as np

WRENCH_SIZE = 6
# Index of the normal force f_z in F_C = [tau_x, tau_y, tau_z, f_x, f_y, f_z].
NORMAL = 5


@dataclass(frozen=True)
class ContactSpec:
    """A contact on a robot task frame (robot.Robot.TASK_FRAMES): a 6-D wrench with a CoP
    box, or a point force."""

    frame: str
    friction_coefficient: float  # mu of the linearised pyramid
    torsional_friction_coefficient: float  # mu_t: |tau_z| <= mu_t f_z, m
    cop_x_m: tuple[float, float] = (0.0, 0.0)  # CoP box along C's x: (min, max)
    cop_y_m: tuple[float, float] = (0.0, 0.0)  # CoP box along C's y: (min, max)
    # True: a force at Co only (unknowns f_C; friction pyramid, no CoP box): the thighs,
    # whose CoP does not matter to the task and whose moments would cost QP size.
    point: bool = False
    # True: the QP may hold the contact's body still at hold_point_m (the rows of C that
    # the contact command picks). False: a wrench only, for a contact that the held ones
    # already pin (the thighs on the chair while seat and soles hold the pelvis and the
    # feet: a second constraint on them would make the QP rank-deficient).
    constrained: bool = True
    # The held point in C, m: the origin, or for the seat the hip axis, so that the pelvis
    # may pitch about the hips while the thighs stay on the chair.
    hold_point_m: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def components(self) -> slice:
        """The components of the 6-D wrench [tau; f] that are unknowns."""
        return slice(3, 6) if self.point else slice(0, 6)

    @property
    def size(self) -> int:
        return 3 if self.point else WRENCH_SIZE


def wrench_cone_matrix(spec: ContactSpec) -> np.ndarray:
    """K (10 x 6) with K F_C <= 0: the contact's admissible wrenches for f_z >= 0.

    |f_x| <= mu f_z,  |f_y| <= mu f_z     linearised friction pyramid
    |tau_z| <= mu_t f_z                  torsional friction
    x_min f_z <= -tau_y <= x_max f_z     centre of pressure, x = -tau_y / f_z
    y_min f_z <=  tau_x <= y_max f_z     centre of pressure, y =  tau_x / f_z

    A point contact keeps the pyramid only: K (4 x 3) on f_C.
    """
    if spec.point:
        mu = spec.friction_coefficient
        return np.array([[1.0, 0.0, -mu], [-1.0, 0.0, -mu], [0.0, 1.0, -mu], [0.0, -1.0, -mu]])
    mu, mu_t = spec.friction_coefficient, spec.torsional_friction_coefficient
    (x_min, x_max), (y_min, y_max) = spec.cop_x_m, spec.cop_y_m
    #                tau_x tau_y tau_z  f_x   f_y   f_z
    return np.array(
        [
            [0.0, 0.0, 0.0, 1.0, 0.0, -mu],
            [0.0, 0.0, 0.0, -1.0, 0.0, -mu],
            [0.0, 0.0, 0.0, 0.0, 1.0, -mu],
            [0.0, 0.0, 0.0, 0.0, -1.0, -mu],
            [0.0, 0.0, 1.0, 0.0, 0.0, -mu_t],
            [0.0, 0.0, -1.0, 0.0, 0.0, -mu_t],
            [0.0, -1.0, 0.0, 0.0, 0.0, -x_max],
            [0.0, 1.0, 0.0, 0.0, 0.0, x_min],
            [1.0, 0.0, 0.0, 0.0, 0.0, -y_max],
            [-1.0, 0.0, 0.0, 0.0, 0.0, y_min],
        ]
    )


# The controller's contacts: the seat pads (transitions.SEAT_LOADS' order) and soles.
CONTACTS = ("seat", "l_thigh", "r_thigh", "l_sole", "r_sole")
CHAIR = slice(0, 3)
SOLES = slice(3, 5)
HOLDS = ("held", "hinged", "free")
THIGH_HOLDS = ("free", "normal", "flat")


@dataclass(frozen=True)
class ContactCommands:
    """What the QP may ask of each contact this tick, in CONTACTS' order."""

    active: tuple[bool, ...]  # the contact is in the QP
    min_normal_force_N: np.ndarray  # (5,) f_z bounds, N
    max_normal_force_N: np.ndarray  # (5,)
    seat_hold: str  # HOLDS: the seat's rows held (all, all but the hip pitch, none)
    # The thighs' rows held: none (free), their normal (normal) or their pitch too (flat).
    thighs_hold: str = "free"
