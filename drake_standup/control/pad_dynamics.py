"""A seat pad's normal dynamics in the QP: the force it plans on a thigh pad is the force
the pad will give for the motion it plans.

A thigh pad is a compliant box (models/icub_contact.yaml) on the seat. Drake's
hydroelastic pressure in a compliant box grows linearly from its surface to E at half its
smallest dimension, so on a rigid plane the pad is a Winkler foundation of modulus
kappa = E / (h / 2) (Pa/m; in series with a cushion's, when the seat has one). Pressed
flat by delta it gives F = kappa A delta, its normal stiffness k = kappa L W (1.9e6 N/m on
the shipped pads: 16 um of sinking per 30 N). Tilted by theta about an axis along one
side, it bears on a wedge along the other side (length W) until the wedge spans the pad:
F = kappa W delta^2 / (2 theta), so dF/d delta = sqrt(2 F kappa W / theta), and

    k(F, theta) = min(kappa L W, sqrt(2 F kappa W / theta))                        (1)

(tests/control/test_pad_dynamics.py checks it against Drake's contact surfaces). At 0.1 degrees of
tilt and a few newtons the pad is 50 times softer than flat: k is worked out each tick.

Over the coming control period T the pad's normal force, from the F measured now and the
pad's normal acceleration a_n (along C's z, away from the seat), is on average
F - k a_n T^2 / 6. The QP's row for each thigh whose normal it holds while its load is
released (state 3):

    f_z + (k T^2 / 6) (J_n vdot + Jdot_n v) = F                                    (2)

in place of a_n = -k_v v_n: the QP plans on what the pad carries, and to carry less it
plans the thigh's lift that sheds it. Measured (issue 46; controller.seat_pad_dynamics):
the plan then matches the pads to a newton (with f_z free up to F + 20 N it sat on that
bound, 20 N per thigh above what they carried), but the slaps stay: the pads ring (a
thigh on 1.9e6 N/m is a ~130 Hz mode, past the 250 Hz loop's Nyquist), and a plan that
follows them follows the ring. With the mean over T of the pad's velocity term too,
-(k T / 2) v_n on the right, the sampled ring was fed back: 893 N of chatter in the
default run. Without it: default 78 N (30 N with the bound), iCubDarmstadt01 298 N
(198 N). Off by default until the pads' ring is damped.

F is the simulator's contact result (sensing.py); on the iCub the thigh's load is
estimated from the F/T sensor in each upper leg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# A tilt below this is flat: (1)'s flat branch holds (rad).
_FLAT_RAD = 1e-9


@dataclass(frozen=True)
class PadCompliance:
    """A compliant box pad's normal compliance on a plane, (1) of the module docstring."""

    foundation_Pa_per_m: float  # kappa = E / (h / 2), in series with the seat's
    length_m: float  # along C's x (the thigh)
    width_m: float  # along C's y

    @classmethod
    def of_box(
        cls,
        size_m: tuple[float, float, float],
        modulus_Pa: float,
        seat_modulus_Pa: float | None = None,
        seat_thickness_m: float = 0.0,
    ) -> PadCompliance:
        """A pad of box size_m (x, y, z) and hydroelastic modulus; seat_modulus_Pa: the
        seat's cushion, seat_thickness_m thick (None: a rigid seat)."""
        length, width, _ = size_m  # the depth is min(size_m), Drake's pressure field's
        compliance = (min(size_m) / 2.0) / modulus_Pa
        if seat_modulus_Pa is not None:
            compliance += (seat_thickness_m / 2.0) / seat_modulus_Pa
        return cls(1.0 / compliance, float(length), float(width))

    def stiffness_N_per_m(self, force_N: float, tilt_rad: float, rolled: bool = False) -> float:
        """(1): dF/d delta at normal force force_N, the pad tilted by tilt_rad (rolled:
        about C's x, so that it bears along its length)."""
        flat = self.foundation_Pa_per_m * self.length_m * self.width_m
        if tilt_rad <= _FLAT_RAD:
            return flat
        edge = self.length_m if rolled else self.width_m
        wedge = np.sqrt(2.0 * max(force_N, 0.0) * self.foundation_Pa_per_m * edge / tilt_rad)
        return float(min(flat, wedge))


def pad_rows(
    J_n: np.ndarray,
    Jdotv_n: float,
    force_N: float,
    R_WC: np.ndarray,
    compliance: PadCompliance,
    period_s: float,
) -> tuple[float, np.ndarray, float]:
    """(2)'s coefficients for one pad: (the coefficient of f_z, of vdot (nv,), the right
    side). J_n: the pad's normal rows of its Jacobian (nv,), in C; R_WC: its rotation
    (the seat's normal is the world's z)."""
    up_C = R_WC[2]  # the seat's normal in C
    tilt = float(np.arccos(np.clip(up_C[2], -1.0, 1.0)))
    rolled = abs(up_C[1]) > abs(up_C[0])
    k = compliance.stiffness_N_per_m(force_N, tilt, rolled) if force_N > 0.0 else 0.0
    beta = k * period_s**2 / 6.0
    return 1.0, beta * J_n, max(force_N, 0.0) - beta * Jdotv_n


class PadRows:
    """(2) for each held contact of a QP with a compliance, written into its program."""

    def __init__(self, qp, period_s: float):
        """qp: the WholeBodyQp (its contacts, held contacts, A, lo, hi, unknowns); its held
        contacts' rows come first in A, 6 each. period_s: T (0: no rows)."""
        held, contacts = qp._held, qp.contacts
        pads = [c for c in held if contacts[c].compliance is not None and period_s > 0]
        self._A, self._lo, self._hi, self._vdot = qp._A, qp._lo, qp._hi, qp.layout.vdot
        # (contact, held index, its normal row of A, its f_z column, the row's entry in lo, hi)
        rows = [6 * held.index(c) + 5 for c in pads]
        self._pads = [
            (c, held.index(c), row, int(qp._normal[c]), qp.n + row)
            for c, row in zip(pads, rows, strict=True)
        ]
        self._compliances = [contacts[c].compliance for c in pads]
        self._period_s = period_s

    def fill(self, terms, partially_held: dict, measured_N: np.ndarray | None) -> None:
        """Writes (2) for the pads whose normal partially_held holds (a contact not in it
        holds all its rows) and measured_N measures (per contact, NaN where not; None:
        none); the others keep their held row, with no f_z. terms: the tick's RobotTerms,
        the held rows already written."""
        A, lo, hi = self._A, self._lo, self._hi
        rotations = None
        for (c, j, row, column, entry), compliance in zip(
            self._pads, self._compliances, strict=True
        ):
            A[row, column] = 0.0
            force = np.nan if measured_N is None else measured_N[c]
            held = c not in partially_held or partially_held[c][5]
            if not held or not np.isfinite(force):
                continue
            if rotations is None:
                rotations = terms.frame_rotations()
            A[row, column], A[row, self._vdot], lo[entry] = pad_rows(
                terms.J_P[j, 5],
                terms.Jdotv_P[j, 5],
                force,
                rotations[c],
                compliance,
                self._period_s,
            )
            hi[entry] = lo[entry]
