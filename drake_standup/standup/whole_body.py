"""StandupWholeBodyController: the whole-body controller as one system, one tick a period.

The pieces of a tick are plain objects called in order inside one discrete update (each
system's event is a crossing into the interpreter: docs/design.md, "The systems"):

    contact schedule   the stand-up mode -> ContactCommands (standup/contact_schedule.py)
    controller model   the robot's state -> RobotTerms, and the weighing (control/model.py)
    task references    terms, x_d(psi), the pull -> TaskReferences (standup/task_references.py)
    whole-body QP      terms, references, commands -> torques (control/controller.py)

Every piece reads what the others held before the tick (the schedule the torques'
commanded normal forces of the last tick), as the separate systems it replaces did.

Inputs: robot_state ([q; v]), mode (abstract StandupMode, the state machine's),
seat_pad_normal_forces_N (3), pads_vertical_force_N (1), hand_wrenches_W (12, measured),
com_reference (9, payloads.COM_REFERENCE), path_progress (1), psi_dot (1: the
posture filter runs on psi; unconnected, on time), response (1: the response
code, config.RESPONSES' index).
Outputs: actuation (nu, N m, zero-order held), diagnostics (control/controller.py:
DIAGNOSTICS), lean_W (3, m), compliance_W (6: the admittance's offset and rate, m, m/s),
mass_estimate (1: the weighing's estimate after the last tick).
Discrete state: the schedule's memory, the weighing, the references' integrals, posture
filter, lean and admittance, the torques, the soles' planned wrenches and the diagnostics.
"""

from __future__ import annotations

import time

import numpy as np
from pydrake.common.value import Value
from pydrake.systems.framework import BasicVector, Context, DiscreteValues, LeafSystem

from drake_standup.control.controller import (
    DIAGNOSTICS,
    ControllerTick,
    WholeBodyController,
    next_diagnostics,
)
from drake_standup.control.model import ControllerModel
from drake_standup.ports.payloads import COM_REFERENCE, HAND_WRENCHES
from drake_standup.standup.contact_schedule import ContactSchedule
from drake_standup.standup.return_path import memory_size
from drake_standup.standup.sit_down import descent_progress
from drake_standup.standup.task_references import CarriedState, TaskReferenceGenerator, TickInputs
from drake_standup.standup.transitions import StandupMode

_COMMANDED = DIAGNOSTICS["commanded_normal_force_N"]


class StandupWholeBodyController(LeafSystem):
    """The module docstring's system, every period_s (and at initialization, so that the
    plant's first step sees computed torques)."""

    def __init__(
        self,
        schedule: ContactSchedule,
        model: ControllerModel,
        generator: TaskReferenceGenerator,
        controller: WholeBodyController,
        num_states: int,
        period_s: float,
    ):
        super().__init__()
        self._schedule, self.model = schedule, model
        self._generator, self.controller = generator, controller
        nu = controller.num_actuators
        self._inputs = {
            name: self.DeclareVectorInputPort(name, size)
            for name, size in (
                ("robot_state", num_states),
                ("seat_pad_normal_forces_N", 3),
                ("pads_vertical_force_N", 1),
                ("hand_wrenches_W", HAND_WRENCHES.size),
                ("com_reference", COM_REFERENCE.size),
                ("path_progress", 1),
                ("psi_dot", 1),
                ("response", 1),
            )
        }
        self._mode = self.DeclareAbstractInputPort("mode", Value[object](StandupMode()))
        self._memory = self.DeclareDiscreteState(ContactSchedule.MEMORY_SIZE)
        self._weighing = self.DeclareDiscreteState(np.array(ControllerModel.INITIAL_WEIGHING))
        self._integral = self.DeclareDiscreteState(3)
        # [latched flag, state-1 posture (nu), filtered posture reference (nu), the
        # filter's first stage (nu), base yaw, the sit-down's memory (return_path.py)].
        self._posture = self.DeclareDiscreteState(2 + 3 * nu + memory_size(nu))
        self._lean = self.DeclareDiscreteState(3)
        self._height_integral = self.DeclareDiscreteState(1)
        self._compliance = self.DeclareDiscreteState(6)
        self._actuation = self.DeclareDiscreteState(nu)
        # The soles' planned wrenches of the last solved tick (2 x 6; NaN: none yet).
        self._sole_wrenches = self.DeclareDiscreteState(np.full(12, np.nan))
        self._diagnostics = self.DeclareDiscreteState(DIAGNOSTICS.size)
        self.DeclareStateOutputPort("actuation", self._actuation)
        self.DeclareStateOutputPort("diagnostics", self._diagnostics)
        self.DeclareStateOutputPort("lean_W", self._lean)
        self.DeclareStateOutputPort("compliance_W", self._compliance)
        self.DeclareVectorOutputPort(
            "mass_estimate",
            1,
            self._CalcEstimate,
            prerequisites_of_calc={self.discrete_state_ticket(self._weighing)},
        )
        self.DeclareInitializationDiscreteUpdateEvent(self._Update)
        self.DeclarePeriodicDiscreteUpdateEvent(period_s, 0.0, self._Update)

    def _input(self, name: str, context: Context) -> np.ndarray:
        return self._inputs[name].Eval(context)

    def _psi_dot(self, context: Context) -> float:
        """The advancement's rate, the posture filter's clock (unconnected: 1, time)."""
        port = self._inputs["psi_dot"]
        return float(port.Eval(context)[0]) if port.HasValue(context) else 1.0

    def _CalcEstimate(self, context: Context, output: BasicVector) -> None:
        output.SetAtIndex(0, context.get_discrete_state(self._weighing).GetAtIndex(0))

    @property
    def actuation_state(self):
        """The index of the torques' discrete state (held where a QP fails)."""
        return self._actuation

    def calc_tick(self, context: Context) -> tuple[ControllerTick, list[tuple[object, object]]]:
        """One tick from the inputs and the state in context: the QP's tick, and the
        (discrete state index, value) pairs of the pieces' states after it."""
        t_start = time.perf_counter()
        state = context.get_discrete_state()
        mode: StandupMode = self._mode.Eval(context)
        hands = self._input("hand_wrenches_W", context)
        weighing = self.model.next_weighing(
            state.get_value(self._weighing),
            mode.state,
            hands,
            float(self._input("pads_vertical_force_N", context)[0]),
        )
        commands, memory = self._schedule.tick(
            mode,
            context.get_time(),
            state.get_value(self._memory),
            state.get_value(self._diagnostics)[_COMMANDED],
            lambda: self._input("seat_pad_normal_forces_N", context),
        )
        terms = self.model.terms(
            self._input("robot_state", context), commands, hands, float(weighing[2])
        )
        t_terms = time.perf_counter()
        references = self._generator.calc(
            terms,
            TickInputs(
                standup_state=mode.state,
                com_reference=self._input("com_reference", context),
                F_hand_W=hands if np.count_nonzero(hands) else None,
                path_progress=float(self._input("path_progress", context)[0]),
                response=int(round(self._input("response", context)[0])),
                psi_dot=self._psi_dot(context),
                braced=mode.guards.brace.on,
                descent_progress=descent_progress(
                    mode, self._input("com_reference", context)[:3], self._schedule.table
                ),
            ),
            CarriedState(
                momentum_integral=state.get_value(self._integral),
                posture=state.get_value(self._posture),
                lean_W=state.get_value(self._lean),
                height_integral=float(state.get_value(self._height_integral)[0]),
                compliance=state.get_value(self._compliance),
            ),
        )
        tick = self.controller.solve(
            terms,
            references,
            commands,
            inputs_s=time.perf_counter() - t_terms,
            kinematics_s=t_terms - t_start,
            last_sole_wrenches=state.get_value(self._sole_wrenches),
        )
        return tick, [
            (self._memory, memory),
            (self._weighing, weighing),
            (self._integral, references.next_momentum_integral),
            (self._posture, references.next_posture),
            (self._lean, references.lean_W),
            (self._height_integral, [references.next_height_integral]),
            (self._compliance, references.next_compliance),
        ]

    def _Update(self, context: Context, discrete_state: DiscreteValues) -> None:
        t_start = time.perf_counter()
        tick, states = self.calc_tick(context)
        for index, value in states:
            discrete_state.set_value(index, value)
        if tick.solution.ok:  # on failure the last torques stay
            discrete_state.set_value(self._actuation, tick.solution.tau)
            discrete_state.set_value(self._sole_wrenches, tick.sole_wrenches.ravel())
        total_s = time.perf_counter() - t_start
        before = context.get_discrete_state(self._diagnostics).value()
        discrete_state.set_value(self._diagnostics, next_diagnostics(before, tick, total_s))
        self.controller.record_timing(tick, total_s)
