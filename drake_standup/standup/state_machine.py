"""StandupStateMachine: the four states of the stand-up as a Drake system.

The mode and its transitions are transitions.py's pure functions (the guards, their
filtered forces and Schmitt triggers, the answer to a pull against the stand-up, the
seat pads' release); this system holds the mode as abstract state, measures what the
guards read from its input ports, updates the mode on the period
standup.update_period_s and publishes it.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.common.value import Value
from pydrake.systems.framework import BasicVector, Context, LeafSystem, State

from drake_standup.config import StandupConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.ports.payloads import SEGMENT
from drake_standup.standup.sit_down import next_cycle_mode
from drake_standup.standup.transitions import (
    N_STATES,
    Measurements,
    StandupMode,
    initial_mode,
)


class StandupStateMachine(LeafSystem):
    """Periodic (standup.update_period_s) state machine with the mode as abstract state.

    Inputs: psi (1), com_W (3), heel_x_W (1), thigh_x_W (1; unconnected: never passed),
    thigh_z_W and buttocks_z_W (1 each; unconnected: the pads' height above the seat
    unknown),
    standing_pull_usage and braced_pull_usage (1 each; unconnected: 0, and never braced),
    pull_cop_shift_m (1; unconnected: 0), pad_forces_W (3 per pad, rows of the soles
    given as sole_rows = (left, right)), hand_wrenches_W (12, payloads.HAND_WRENCHES),
    stand_up and sit_down (1 each: how often the live page's buttons asked for them;
    unconnected: never), which only the live helper has, and seat_pad_normal_forces_N (3;
    unconnected: the sit-down's pads never touch).
    Outputs: mode (abstract StandupMode), standup_state (1; 5-7: the sit-down), advances
    (1: the phase lets psi advance), segment (payloads.SEGMENT), entry_times_s (4: the
    stand-up's states' last entries, NaN for states not reached), held_back (4: [a
    backward pull holds it (1/0), the time it has waited so far, s, a pull beyond the
    standing feet holds it (1/0), the part of that time it did, s]).
    """

    def __init__(
        self,
        config: StandupConfig,
        table: PhaseTable,
        n_pads: int,
        sole_rows: tuple[int, int],
        *,
        seat_top_z_m: float = math.nan,
    ):
        """seat_top_z_m: the seat's top (the chair's geometry), which the thighs' height
        above it is measured from (NaN: not known, the sit-down's approach never ends
        early)."""
        super().__init__()
        if table.unresolved_heights():
            raise ValueError(
                f"phases {table.unresolved_heights()}: com_height_erect unresolved "
                "(phases.resolve_com_heights)"
            )
        self._cfg = config
        self._table = table
        self._advances = [float(phase.advances) for phase in table.every()]
        self._sole_rows = sole_rows
        self._mode_index = self.DeclareAbstractState(Value[object](StandupMode()))
        self._psi = self.DeclareVectorInputPort("psi", 1)
        self._com = self.DeclareVectorInputPort("com_W", 3)
        self._heel = self.DeclareVectorInputPort("heel_x_W", 1)
        self._thigh = self.DeclareVectorInputPort("thigh_x_W", 1)
        self._thigh_z = self.DeclareVectorInputPort("thigh_z_W", 1)
        self._buttocks_z = self.DeclareVectorInputPort("buttocks_z_W", 1)
        self._seat_top_z = seat_top_z_m
        self._usage = self.DeclareVectorInputPort("standing_pull_usage", 1)
        self._braced_usage = self.DeclareVectorInputPort("braced_pull_usage", 1)
        self._cop_shift = self.DeclareVectorInputPort("pull_cop_shift_m", 1)
        self._pads = self.DeclareVectorInputPort("pad_forces_W", 3 * n_pads)
        self._hands = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        self._stand_up = self.DeclareVectorInputPort("stand_up", 1)
        self._sit_down = self.DeclareVectorInputPort("sit_down", 1)
        self._seat = self.DeclareVectorInputPort("seat_pad_normal_forces_N", 3)
        self.DeclareInitializationUnrestrictedUpdateEvent(self._Initialize)
        self.DeclarePeriodicUnrestrictedUpdateEvent(config.update_period_s, 0.0, self._Update)
        mode_only = {self.abstract_state_ticket(self._mode_index)}
        self.DeclareAbstractOutputPort(
            "mode", lambda: Value[object](StandupMode()), self._CalcMode, mode_only
        )
        vectors = {
            "standup_state": (1, self._CalcState),
            "advances": (1, self._CalcAdvances),
            "segment": (SEGMENT.size, self._CalcSegment),
            "entry_times_s": (N_STATES, self._CalcEntryTimes),
            "held_back": (4, self._CalcHeldBack),
            "arms_braced": (1, self._CalcBraced),
        }
        for name, (size, calc) in vectors.items():
            self.DeclareVectorOutputPort(name, size, calc, prerequisites_of_calc=mode_only)

    def mode(self, context: Context) -> StandupMode:
        return context.get_abstract_state(self._mode_index).get_value()

    def _Initialize(self, context: Context, state: State) -> None:
        mode = initial_mode(self._com.Eval(context), context.get_time())
        state.get_mutable_abstract_state(self._mode_index).set_value(mode)

    def _gap(self, port, context: Context) -> float:
        """How high a pad's underside (port: its z) is above the seat's top; NaN: unknown."""
        if not port.HasValue(context):
            return math.nan
        return float(port.Eval(context)[0]) - self._seat_top_z

    def _measure(self, context: Context) -> Measurements:
        pads = self._pads.Eval(context).reshape(-1, 3)
        hands = self._hands.Eval(context).reshape(2, 6)
        left, right = self._sole_rows
        return Measurements(
            t=context.get_time(),
            psi=float(self._psi.Eval(context)[0]),
            com_W=self._com.Eval(context),
            heel_x=float(self._heel.Eval(context)[0]),
            thigh_x=float(self._thigh.Eval(context)[0])
            if self._thigh.HasValue(context)
            else math.nan,
            foot_fz_N=(float(pads[left, 2]), float(pads[right, 2])),
            hand_fx_N=(float(hands[0, 3]), float(hands[1, 3])),
            hand_fz_N=(float(hands[0, 5]), float(hands[1, 5])),
            stand_up=float(self._stand_up.Eval(context)[0])
            if self._stand_up.HasValue(context)
            else 0.0,
            sit_down=float(self._sit_down.Eval(context)[0])
            if self._sit_down.HasValue(context)
            else 0.0,
            thigh_gap_m=self._gap(self._thigh_z, context),
            buttocks_gap_m=self._gap(self._buttocks_z, context),
            seat_fz_N=tuple(float(f) for f in self._seat.Eval(context))
            if self._seat.HasValue(context)
            else (math.nan,) * 3,
            pull_usage=float(self._usage.Eval(context)[0])
            if self._usage.HasValue(context)
            else 0.0,
            braced_usage=float(self._braced_usage.Eval(context)[0])
            if self._braced_usage.HasValue(context)
            else math.nan,
            cop_shift_m=float(self._cop_shift.Eval(context)[0])
            if self._cop_shift.HasValue(context)
            else 0.0,
        )

    def _Update(self, context: Context, state: State) -> None:
        new = next_cycle_mode(self.mode(context), self._measure(context), self._cfg, self._table)
        state.get_mutable_abstract_state(self._mode_index).set_value(new)

    def _CalcMode(self, context: Context, output: Value) -> None:
        output.set_value(self.mode(context))

    def _CalcState(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self.mode(context).state)

    def _CalcAdvances(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, self._advances[self.mode(context).state - 1])

    def _CalcSegment(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(self.mode(context).segment())

    def _CalcHeldBack(self, context: Context, output: BasicVector) -> None:
        mode = self.mode(context)
        g = mode.guards
        output.SetFromVector(
            [
                float(g.hindering()),
                mode.held_back_s,
                float(g.beyond_feet.on),
                mode.held_beyond_feet_s,
            ]
        )

    def _CalcBraced(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, float(self.mode(context).guards.brace.on))

    def _CalcEntryTimes(self, context: Context, output: BasicVector) -> None:
        output.SetFromVector(np.array(self.mode(context).entry_times_s[:N_STATES]))
