"""Contact wrenches: the constraints one 6-D contact puts on its wrench, and its maps.

A contact wrench F_C = [tau_C; f_C] acts at the origin of the contact frame C and is
expressed in C (z along the surface normal, into the robot), so the constraints below
are constant; only the maps to the world change with the robot's state.
"""

from dataclasses import dataclass

import numpy as np

from drake_standup.control.pad_dynamics import PadCompliance

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
    # True: a force at Co only (unknowns f_C; friction pyramid, no CoP box), for a contact
    # whose CoP does not matter to the task (none of CONTACTS since the thighs became
    # 6-D in issue 21).
    point: bool = False
    # True: the QP may hold the contact's body still at hold_point_m (the rows of C that
    # the contact command picks). False: a wrench only, for a contact that the held ones
    # already pin (the thighs on the chair while seat and soles hold the pelvis and the
    # feet: a second constraint on them would make the QP rank-deficient).
    constrained: bool = True
    # The held point in C, m: the origin, or for the seat the hip axis, so that the pelvis
    # may pitch about the hips while the thighs stay on the chair.
    hold_point_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    # True: the yaw moment is bounded by the CoP box as a rectangle of friction
    # (wrench_cone_matrix): the soles, which give it through their own pad alone. The
    # seated pelvis also turns on the thighs' lever arm, which its box does not see.
    rectangle_yaw: bool = False
    # A seat pad's normal compliance (control/pad_dynamics.py: PadCompliance): while its
    # normal is held, the QP plans on the force the pad gives for the motion it plans.
    compliance: PadCompliance | None = None

    @property
    def components(self) -> slice:
        """The components of the 6-D wrench [tau; f] that are unknowns."""
        return slice(3, 6) if self.point else slice(0, 6)

    @property
    def size(self) -> int:
        return 3 if self.point else WRENCH_SIZE


def wrench_cone_matrix(spec: ContactSpec) -> np.ndarray:
    """K (10 x 6, 18 x 6 with rectangle_yaw) with K F_C <= 0: the contact's admissible
    wrenches for f_z >= 0.

    |f_x| <= mu f_z,  |f_y| <= mu f_z     linearised friction pyramid
    |tau_z| <= mu_t f_z                  torsional friction
    x_min f_z <= -tau_y <= x_max f_z     centre of pressure, x = -tau_y / f_z
    y_min f_z <=  tau_x <= y_max f_z     centre of pressure, y =  tau_x / f_z
    tau_min <= tau_z <= tau_max          rectangle_yaw: the CoP box as a rectangle of
                                         friction (8 rows)

    The last: a rectangle whose corners each push with a force in the friction pyramid
    can give a yaw moment only as far as its CoP and its tangential force leave it room
    ([caron2015]: Caron, Pham, Nakamura, ICRA 2015, the contact wrench cone's closed
    form), about the rectangle's centre c and
    with X, Y its half-sizes:
        tau_max =  mu (X + Y) f_z - |Y f_x + mu tau_x| - |X f_y + mu tau_y|
        tau_min = -mu (X + Y) f_z + |Y f_x - mu tau_x| + |X f_y - mu tau_y|
    so that at a corner of the box there is none. Without it the QP held the CoP at the
    box's toe-outer corner with the full mu_t f_z of yaw moment at the rise's end: the
    compliant sole, bearing on its corner, could not give it, and the feet twisted
    (docs/design.md, "Chatter at the seat's release").

    A point contact keeps the pyramid only: K (4 x 3) on f_C.
    """
    if spec.point:
        mu = spec.friction_coefficient
        return np.array([[1.0, 0.0, -mu], [-1.0, 0.0, -mu], [0.0, 1.0, -mu], [0.0, -1.0, -mu]])
    mu, mu_t = spec.friction_coefficient, spec.torsional_friction_coefficient
    (x_min, x_max), (y_min, y_max) = spec.cop_x_m, spec.cop_y_m
    #                tau_x tau_y tau_z  f_x   f_y   f_z
    rows = [
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
    if spec.rectangle_yaw:
        rows += rectangle_yaw_rows(mu, (x_min, x_max), (y_min, y_max))
    return np.array(rows)


def rectangle_yaw_rows(
    mu: float, cop_x_m: tuple[float, float], cop_y_m: tuple[float, float]
) -> list[list[float]]:
    """wrench_cone_matrix's 8 rows tau_min <= tau_z <= tau_max, on F_C (moments about C's
    origin): with the rectangle's centre c, tau_c = tau - c x f."""
    (x_min, x_max), (y_min, y_max) = cop_x_m, cop_y_m
    cx, cy = (x_min + x_max) / 2.0, (y_min + y_max) / 2.0
    X, Y = (x_max - x_min) / 2.0, (y_max - y_min) / 2.0
    rows = []
    for s1 in (1.0, -1.0):
        for s2 in (1.0, -1.0):
            # tau_c,z + s1 (Y f_x + mu tau_c,x) + s2 (X f_y + mu tau_c,y) <= mu (X + Y) f_z
            rows.append(
                [
                    s1 * mu,
                    s2 * mu,
                    1.0,
                    cy + s1 * Y,
                    -cx + s2 * X,
                    -s1 * mu * cy + s2 * mu * cx - mu * (X + Y),
                ]
            )
            # -tau_c,z + s1 (Y f_x - mu tau_c,x) + s2 (X f_y - mu tau_c,y) <= mu (X + Y) f_z
            rows.append(
                [
                    -s1 * mu,
                    -s2 * mu,
                    -1.0,
                    -cy + s1 * Y,
                    cx + s2 * X,
                    s1 * mu * cy - s2 * mu * cx - mu * (X + Y),
                ]
            )
    return rows


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
    # The seat pads' measured normal forces (5,: NaN where not measured), N.
    measured_normal_force_N: np.ndarray | None = None
