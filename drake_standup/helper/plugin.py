"""A helper as a plug-in (human.mode names it: drake_standup/plugins).

A helper is a factory helper(plant, robot, config) -> System: plant the MultibodyPlant, robot
its iCub (robot/icub.py Robot: robot.frame(plant, 'l_hand')), config the scenario's human:
section. The system has HumanWrenchSource's ports (helper/hands.py):

    input  robot_state       [q; v] of the robot's model instance
    output hand_wrenches_W   (12) [torque_l, force_l, torque_r, force_r] on the robot's hands,
                             at the hand frames' origins, world frame, N m and N
    output spatial_forces    the same as ExternallyAppliedSpatialForce for the plant

HandWrenchHelper writes the ports: subclass it and give hand_wrenches(time_s, robot_state).
A factory marked adds_body = True also gets the person's body the scene adds to the plant
and the live page's intent (the shipped `body`, helper/body_control.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context, LeafSystem, System

from drake_standup.config import HumanConfig
from drake_standup.config.plugins import PluginError, call_problem
from drake_standup.helper.hands import applied_wrenches, declare_hand_outputs, hand_forces
from drake_standup.robot.icub import Robot

PORTS = {"input": ("robot_state",), "output": ("hand_wrenches_W", "spatial_forces")}


class HandWrenchHelper(LeafSystem):
    """The ports of the module docstring around hand_wrenches(time_s, robot_state), which a
    subclass gives: (12,) finite, or (2, 6) rows [torque, force] per hand."""

    def __init__(self, plant: MultibodyPlant, robot: Robot, config: HumanConfig):
        super().__init__()
        self.plant, self.robot, self.config = plant, robot, config
        self._applied = hand_forces(plant, robot)
        nx = plant.num_multibody_states(robot.model_instance)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        prereq = {self.time_ticket(), self._state.ticket()}
        declare_hand_outputs(self, self._evaluate, prereq, self._applied, applied_wrenches)

    def hand_wrenches(self, time_s: float, robot_state: np.ndarray) -> np.ndarray:
        """The wrenches on the hands now (module docstring); a subclass gives them."""
        raise NotImplementedError("a HandWrenchHelper gives hand_wrenches(time_s, robot_state)")

    def _evaluate(self, context: Context) -> np.ndarray:
        t = context.get_time()
        value = self.hand_wrenches(t, self._state.Eval(context))
        wrenches = np.asarray(value, dtype=float)
        if wrenches.size != 12 or wrenches.shape not in ((12,), (2, 6)):
            raise PluginError(
                f"human.mode: {type(self).__name__}.hand_wrenches gave shape {wrenches.shape} "
                f"at t = {t:.3f} s; accepted: (12,) or (2, 6)"
            )
        if not np.all(np.isfinite(wrenches)):
            raise PluginError(
                f"human.mode: {type(self).__name__}.hand_wrenches gave a non-finite value at "
                f"t = {t:.3f} s; accepted: finite N m and N"
            )
        return wrenches.reshape(12)


def check_helper(obj: Any) -> str | None:
    """What is wrong with obj as a helper factory (None: nothing)."""
    if getattr(obj, "adds_body", False):
        return call_problem(obj, 5, "helper(plant, robot, config, person, intent) -> System")
    return call_problem(obj, 3, "helper(plant, robot, config) -> System")


def check_helper_ports(system: System, spec: str) -> None:
    """A PluginError if the helper spec built lacks a port the diagram wires."""
    if not isinstance(system, System):
        raise PluginError(
            f"human.mode: '{spec}' built a {type(system).__name__}; accepted: a Drake System "
            "with the ports robot_state (in), hand_wrenches_W and spatial_forces (out)"
        )
    missing = [f"{name} (in)" for name in PORTS["input"] if not system.HasInputPort(name)]
    missing += [f"{name} (out)" for name in PORTS["output"] if not system.HasOutputPort(name)]
    if missing:
        raise PluginError(
            f"human.mode: '{spec}' built a system without the port(s) {', '.join(missing)}; "
            "accepted: the ports of drake_standup.helper.plugin.HandWrenchHelper"
        )
