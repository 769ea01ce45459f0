"""The stand-up plan: the phase table resolved once for this robot in this scene.

make_plan runs once per diagram (sim/diagram.py) and everything downstream reads the
plan instead of asking the scene again: the state machine, the contact schedule, the task
references and the controller (its table, make_standup_controller), the metrics (the
erect height a stand-up is judged against) and the visuals (the number of states).
"""

from __future__ import annotations

from dataclasses import dataclass

from drake_standup.config import ControllerConfig, Scenario
from drake_standup.config.chair import SEATED_JOINTS
from drake_standup.config.phases import (
    EVERY_PHASE,
    PHASES,
    PhaseTable,
    resolve_com_heights,
    resolve_com_x,
    resolve_descent,
    resolve_postures,
)
from drake_standup.robot.limbs import joint_limits_rad
from drake_standup.world.scene import Scene
from drake_standup.world.seating import JOINT_MARGIN_RAD, LEG_JOINTS
from drake_standup.world.sensing import FeetReach
from drake_standup.world.station import Station


@dataclass(frozen=True)
class StandupPlan:
    """What the stand-up does with this robot on this chair."""

    # The scenario's table, its com_height_erect phases ended at this robot's height.
    table: PhaseTable
    # The rise's posture standing on this floor: the height a stand-up is judged at, m.
    erect_com_height_m: float

    @property
    def n_states(self) -> int:
        """The stand-up states, 1 to n_states (one per phase)."""
        return len(PHASES)

    @property
    def states(self) -> tuple[int, ...]:
        """The stand-up's and the sit-down's states (1-7): the modes the controller's
        tasks are active in."""
        return tuple(range(1, len(EVERY_PHASE) + 1))

    @property
    def stance_states(self) -> set[int]:
        """The states whose phase ends on the legs' posture (the stance tasks act)."""
        return {k for k, phase in enumerate(self.table.every(), start=1) if phase.stance}


def feet_reach(config: ControllerConfig) -> FeetReach:
    """How far the controller leans the standing CoM and its soles' CoP boxes, for the
    world's measure of what a pull asks of the standing feet."""
    return FeetReach(
        lean_m=(config.lean_max_forward_m, config.lean_max_back_m, config.lean_max_m),
        cop_x_m=tuple(config.foot_cop_x_m),
        cop_y_m=tuple(config.foot_cop_y_m),
    )


def seated_shift(scene: Scene) -> tuple[dict[str, float], dict[str, tuple[float, float]]]:
    """(how far the robot's seated leg joints (seating.LEG_JOINTS, both sides) are from
    the shipped seated pose's, and those joints' limits), rad, by joint name."""
    plant, instance = scene.plant, scene.robot.model_instance
    names = [f"{side}_{joint}" for side in "lr" for joint in LEG_JOINTS]
    limits = joint_limits_rad(plant, instance, [n for n in names if n in scene.seated.joints_rad])
    shift = {name: scene.seated.joints_rad[name] - SEATED_JOINTS[name] for name in limits}
    return shift, limits


def make_plan(scenario: Scenario, station: Station) -> StandupPlan:
    """The plan for scenario's robot in the station's scene: the forward ends from where the
    soles are seated (resolve_com_x); the lift-off's postures from the seated pose
    (resolve_postures); each standing posture's CoM height from forward kinematics
    (scene.standing, which works each posture out once per build and so gives the
    station's own standing support the same numbers)."""
    erect = station.scene.standing.erect_com_height_m
    seated = station.scene.seated
    soles_x = scenario.chair.seat_edge_x_m() + seated.feet_ahead_of_seat_edge_m
    shift, limits = seated_shift(station.scene)
    table = resolve_postures(scenario.phases, shift, limits, JOINT_MARGIN_RAD)
    table = resolve_descent(resolve_com_heights(resolve_com_x(table, soles_x), erect))
    return StandupPlan(table, erect(scenario.phases.rise.posture_rad))
