"""The contact schedule: from the stand-up mode, what the QP may ask of each contact.

The controller's contacts (CONTACTS): the seat (a 6-D contact on root_link under the
buttocks, held at the hip axis), both thighs (point forces, pinned by the others) and
both soles (6-D). The phase table (phases.py) says when each seat pad's load is released
(state_machine.seat_loads: what is left of it, NaN while seated). From that:

    chair contacts in the QP   while any seat pad is seated or still carries load
    seated pad                 f_z in [f_min, f_max_seat]
    releasing pad              f_z in [0, min(left * F_0, F_measured + margin)]
    sole                       f_z in [f_min, f_max_foot]
    seat hold                  the phase's seat_hold (seat_hold_sat_back after a sit-back)
                               until the buttocks' release is over; no rows then
    thighs held                once the buttocks are off, while seated: flat (pitch and
                               normal); while they unload: their normal; released: none.
                               The QP counts on their wrench, so it may not plan motions
                               that lift them while they still carry load

F_0 is what the controller commanded the pad when its release began (the schedule's
memory: a pad lifting off cannot push). The measured bound: the thighs are forces the QP
does not pin, and it planned on up to three times what the compliant pads carried. Why
the seat holds no rows once the buttocks release: docs/design.md, "Contacts".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.common.value import Value
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from drake_standup.caching import declare_cached
from drake_standup.config import ControllerConfig
from drake_standup.phases import PhaseTable
from drake_standup.state_machine import StandupMode, seat_loads, seat_releases

# The controller's contacts: the seat pads (state_machine.SEAT_LOADS' order) and soles.
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
        bound = np.minimum(
            bound, np.maximum(measured_N[releasing], 0.0) + config.seat_measured_margin_N
        )
    high[CHAIR][releasing] = bound
    return ContactCommands(
        active=(chair, chair, chair, True, True),
        min_normal_force_N=low,
        max_normal_force_N=high,
        seat_hold="free" if seat_off else seat_hold,
        thighs_hold=thighs_hold,
    )


def phase_seat_hold(mode: StandupMode, table: PhaseTable) -> str:
    """How the seat holds the pelvis in mode's phase while the buttocks are seated."""
    phase = table.phase(mode.state)
    return phase.seat_hold_sat_back if mode.sat_back else phase.seat_hold


class ContactScheduler(LeafSystem):
    """ContactCommands for the whole-body controller, every period_s.

    Inputs: mode (abstract StandupMode, the state machine's), seat_pad_normal_forces_N
    (3: buttocks, left and right thigh pad, measured),
    commanded_normal_forces_N (5: what the controller's last tick asked of CONTACTS, NaN
    where its QP failed). Output: contact_commands (abstract ContactCommands).
    Discrete state: [the loads the seat pads' release starts from (3), the controller's
    last successful commands to them (3)], N.
    """

    def __init__(self, config: ControllerConfig, table: PhaseTable, period_s: float):
        super().__init__()
        self._config = config
        self._table = table
        self._releases = seat_releases(table)
        # The commands while every seat pad is seated, by hold, and once every one is
        # released: constant, so computed once (most ticks are in one or the other).
        seated = np.full(3, np.nan)
        self._seated = {
            hold: contact_commands(config, seated, seated, None, hold) for hold in HOLDS
        }
        self._released = contact_commands(config, np.zeros(3), np.zeros(3), None, "free")
        self._first_release = min((release[0] for release in self._releases), default=math.inf)
        self._mode = self.DeclareAbstractInputPort("mode", Value[object](StandupMode()))
        self._measured = self.DeclareVectorInputPort("seat_pad_normal_forces_N", 3)
        self._commanded = self.DeclareVectorInputPort("commanded_normal_forces_N", len(CONTACTS))
        self._memory = self.DeclareDiscreteState(6)
        # This tick's commands and the memory after it, computed once for both.
        self._next = declare_cached(
            self,
            "commands and next memory",
            self._tick,
            {
                self._mode.ticket(),
                self._measured.ticket(),
                self._commanded.ticket(),
                self.discrete_state_ticket(self._memory),
                self.time_ticket(),
            },
        )
        self.DeclareAbstractOutputPort(
            "contact_commands",
            lambda: Value[object](None),
            self._CalcCommands,
            {self._next.ticket()},
        )
        self.DeclareInitializationDiscreteUpdateEvent(self._Update)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._Update)

    def _tick(self, context: Context) -> tuple[ContactCommands, np.ndarray]:
        memory = context.get_discrete_state(self._memory).value()
        mode = self._mode.Eval(context)
        commanded = self._commanded.Eval(context)[CHAIR]
        last = commanded if np.isfinite(commanded).all() else memory[3:]
        if mode.state < self._first_release:  # every pad seated: following its commands
            return self._seated[phase_seat_hold(mode, self._table)], np.concatenate((last, last))
        loads = seat_loads(mode, context.get_time(), self._releases)
        if not np.count_nonzero(loads):  # every pad released (NaN, seated, counts as nonzero)
            return self._released, np.concatenate((memory[:3], last))
        unload_from = next_unload_from(memory[:3], last, loads)
        measured = self._measured.Eval(context)
        commands = contact_commands(
            self._config, loads, unload_from, measured, phase_seat_hold(mode, self._table)
        )
        return commands, np.concatenate((unload_from, last))

    def _CalcCommands(self, context: Context, output: Value) -> None:
        output.set_value(self._next.Eval(context)[0])

    def _Update(self, context: Context, discrete_state: DiscreteValues) -> None:
        discrete_state.set_value(self._memory, self._next.Eval(context)[1])
