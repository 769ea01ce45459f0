"""The stand-up plan: the phase table resolved once for this robot in this scene.

make_plan runs once per diagram (sim/diagram.py) and everything downstream reads the
plan instead of asking the scene again: the state machine, the contact schedule, the task
references and the controller (its table, make_standup_controller), the metrics (the
erect height a stand-up is judged against) and the visuals (the number of states).
"""

from __future__ import annotations

from dataclasses import dataclass

from drake_standup.config import Scenario
from drake_standup.config.phases import PHASES, SEAT_PADS, PhaseTable, resolve_com_heights
from drake_standup.world.scene import Scene, erect_com_height_m


@dataclass(frozen=True)
class StandupPlan:
    """What the stand-up does with this robot on this chair."""

    # The scenario's table, its com_height_erect phases ended at this robot's height.
    table: PhaseTable
    # The rise's posture standing on this floor: the height a stand-up is judged at, m.
    erect_com_height_m: float
    # The seat's pad groups, in the order every consumer keeps them (SEAT_PADS).
    seat_pads: tuple[str, ...] = SEAT_PADS

    @property
    def n_states(self) -> int:
        """The stand-up states, 1 to n_states (one per phase)."""
        return len(PHASES)

    @property
    def final_state(self) -> int:
        return self.n_states


def make_plan(scenario: Scenario, scene: Scene) -> StandupPlan:
    """The plan for scenario's robot in scene: each standing posture's CoM height from
    forward kinematics (scene.erect_com_height_m), once per distinct posture."""
    heights: dict[tuple, float] = {}

    def erect(posture_rad: dict[str, float]) -> float:
        key = tuple(sorted(posture_rad.items()))
        if key not in heights:
            heights[key] = erect_com_height_m(scene, scenario, posture_rad)
        return heights[key]

    table = resolve_com_heights(scenario.phases, erect)
    return StandupPlan(table, erect(scenario.phases.rise.posture_rad))
