"""The contact schedule: from the stand-up mode, what the QP may ask of each contact.

The controller's contacts (CONTACTS): the seat (a 6-D contact on root_link under the
buttocks, held at the hip axis), both thighs (6-D, their CoP on their pads) and both
soles (6-D). The phase table (phases.py) says when each seat pad's load is released
(transitions.seat_loads: what is left of it, NaN while seated). From that:

    chair contacts in the QP   while any seat pad is seated or still carries load
    seated pad                 f_z in [min(f_min, F_measured), min(f_max_seat,
                               F_measured + margin)]
    releasing pad              f_z in [0, min(left * F_0, F_measured + margin)]
    landing pad (sit-down)     f_z in [0, min(landed * max(F_0, F_measured + margin),
                               F_measured + margin)]: seated at its end, no step
    sole                       f_z in [f_min, f_max_foot]
    seat hold                  the phase's seat_hold (seat_hold_sat_back after a sit-back)
                               until the buttocks' release is over; no rows then
    thighs held                once the buttocks are off, while seated: flat (pitch and
                               normal); while they unload: their normal; released: none.
                               The QP counts on their wrench, so it may not plan motions
                               that lift them while they still carry load

F_0 is what the controller commanded the pad when its release began (the schedule's
memory: a pad lifting off cannot push). The measured bound: the thighs are forces the QP
does not pin, and it planned on up to three times what the compliant pads carried; a
seated pad too (on a 0.18 m seat the thighs slope up off it: the plan leaned 50-58 N on
each while they carried none, and the robot dropped onto its feet, 209 N of chatter). Why
the seat holds no rows once the buttocks release: docs/design.md, "Leaving the seat".
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from drake_standup.config import ControllerConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.control.contacts import CHAIR, CONTACTS, SOLES, ContactCommands
from drake_standup.standup.transitions import (
    N_STATES,
    StandupMode,
    seat_landings,
    seat_loads,
    seat_releases,
)


def next_unload_from(
    unload_from_N: np.ndarray, last_commanded_N: np.ndarray, loads: np.ndarray
) -> np.ndarray:
    """The loads the seat pads' release starts from (3,): a pad still seated, or at the
    first ticks of its release (what is left >= 1), follows its last commanded load; a
    releasing pad keeps the load its release began from."""
    following = ~np.isfinite(loads) | (loads >= 1.0)
    return np.where(following, last_commanded_N, unload_from_N)


def contact_commands(
    config: ControllerConfig,
    loads: np.ndarray,
    unload_from_N: np.ndarray,
    measured_N: np.ndarray | None,
    seat_hold: str,
) -> ContactCommands:
    """The module docstring's bounds from the seat pads' loads (seat_loads), the loads
    their release started from, the pads' measured normal forces (None: not measured)
    and the phase's seat hold."""
    releasing = np.isfinite(loads)
    chair = bool(np.any(~releasing | (loads > 0.0)))
    seat_off = bool(releasing[0] and loads[0] <= 0.0)  # the buttocks' release is over
    thighs_hold = "free"
    if seat_off and not releasing[1]:
        thighs_hold = "flat"
    elif seat_off and loads[1] > 0.0:
        thighs_hold = "normal"
    low = np.full(len(CONTACTS), config.min_normal_force_N)
    high = np.empty(len(CONTACTS))
    high[CHAIR] = config.seat_max_normal_force_N
    high[SOLES] = config.foot_max_normal_force_N
    low[CHAIR][releasing] = 0.0
    bound = loads[releasing] * unload_from_N[releasing]
    if measured_N is not None:
        carried = np.maximum(measured_N, 0.0)
        bound = np.minimum(bound, carried[releasing] + config.seat_measured_margin_N)
        # A seated pad too is counted on only as far as it carries load: on a low seat the
        # thighs slope up off it, and the plan leaned on 50-58 N a thigh that had none.
        seated = ~releasing
        high[CHAIR][seated] = np.minimum(
            high[CHAIR][seated], carried[seated] + config.seat_measured_margin_N
        )
        low[CHAIR][seated] = np.minimum(low[CHAIR][seated], carried[seated])
    high[CHAIR][releasing] = bound
    measured = None
    if measured_N is not None and config.seat_pad_dynamics:
        measured = np.full(len(CONTACTS), np.nan)
        # Releasing pads only: the QP's row for their dynamics (control/pad_dynamics.py).
        measured[CHAIR] = np.where(releasing, measured_N, np.nan)
    return ContactCommands(
        active=(chair, chair, chair, True, True),
        min_normal_force_N=low,
        max_normal_force_N=high,
        seat_hold="free" if seat_off else seat_hold,
        thighs_hold=thighs_hold,
        measured_normal_force_N=measured,
    )


def phase_seat_hold(mode: StandupMode, table: PhaseTable) -> str:
    """How the seat holds the pelvis in mode's phase while the buttocks are seated."""
    phase = table.phase(mode.state)
    return phase.seat_hold_sat_back if mode.sat_back else phase.seat_hold


# Every seat pad seated: no release has begun (read only).
_SEATED = np.full(3, math.nan)
_SEATED.flags.writeable = False


class ContactSchedule:
    """ContactCommands for the whole-body controller, once a tick: a plain object the
    stand-up controller's tick calls (standup/whole_body.py).

    Its memory, kept by the caller (MEMORY_SIZE, zero at the start): [the loads the seat
    pads' release starts from (3), the controller's last successful commands to them
    (3)], N.
    """

    MEMORY_SIZE = 6

    def __init__(self, config: ControllerConfig, table: PhaseTable):
        self._config = config
        self._table = table
        self._releases = seat_releases(table)
        self._landings = seat_landings(table)
        # The commands once every pad is released: constant, so computed once.
        self._released = contact_commands(config, np.zeros(3), np.zeros(3), None, "free")
        self._first_release = min((release[0] for release in self._releases), default=math.inf)

    @property
    def table(self) -> PhaseTable:
        return self._table

    def tick(
        self,
        mode: StandupMode,
        t: float,
        memory: np.ndarray,
        commanded_N: np.ndarray,
        measured_N: Callable[[], np.ndarray],
    ) -> tuple[ContactCommands, np.ndarray]:
        """(this tick's commands, the memory after it). mode: the state machine's;
        commanded_N: what the controller's last tick asked of CONTACTS (NaN where its QP
        failed); measured_N(): the seat pads' normal forces (3: buttocks, left and right
        thigh pad), read while any pad is on the chair."""
        commanded = commanded_N[CHAIR]
        last = commanded if np.isfinite(commanded).all() else memory[3:]
        if mode.state < self._first_release:  # every pad seated: following its commands
            commands = contact_commands(
                self._config, _SEATED, _SEATED, measured_N(), phase_seat_hold(mode, self._table)
            )
            return commands, np.concatenate((last, last))
        loads = seat_loads(mode, t, self._releases, self._landings)
        if not np.count_nonzero(loads):  # every pad released (NaN, seated, counts as nonzero)
            return self._released, np.concatenate((memory[:3], last))
        unload_from = next_unload_from(memory[:3], last, loads)
        measured = measured_N()
        target = unload_from
        if mode.state > N_STATES:
            # A landing rises to no less than the seated bound (what the pad carries plus
            # the margin), so its end is no step: a buttocks' release remembered after
            # they lifted off (20 N) stepped to their seated 97 N at state 1 (Genova01).
            target = np.maximum(
                unload_from, np.maximum(measured, 0.0) + self._config.seat_measured_margin_N
            )
        commands = contact_commands(
            self._config, loads, target, measured, phase_seat_hold(mode, self._table)
        )
        return commands, np.concatenate((unload_from, last))
