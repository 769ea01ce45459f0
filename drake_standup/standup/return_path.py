"""The sit-down's way back (standup/sit_down.py): the posture and the pelvis' pitch with
which the robot began each stand-up state, remembered, and returned to along the CoM's
path. The task references keep the memory in their posture state (task_references.py);
these are its pure functions.

    memory = [the last tick's state, q_ref when the state began (nu), the measured joint
              positions when each stand-up state 1-4 began from the one before it (4 nu),
              the base pitch target of the last tick, the one when the state began, the
              measured base pitch when each stand-up state began so (4)]

A sit-down phase returning to stand-up state k aims its posture at q_from + s (q_k -
q_from) and its pelvis' pitch likewise, s the share of its path the CoM reference has
gone (sit_down.descent_progress): the body's shape stays that of the way up at each point
of the path. Led by the phase's own posture and base pitch instead, the trunk stayed
upright while the hips and knees folded under the CoM target, and the thighs met the seat
5 cm of CoM height early (234-350 N).
"""

from __future__ import annotations

import math

import numpy as np

STAND_UP_STATES = 4


def memory_size(nu: int) -> int:
    return 1 + nu * (1 + STAND_UP_STATES) + 2 + STAND_UP_STATES


def base_pitch(R_WB: np.ndarray) -> float:
    """The forward pitch of root_link's orientation, as control/tasks/base.py's BaseTarget
    builds it (R = Rz(yaw) Ry(-pitch): root_link's x axis points backwards)."""
    return math.atan2(R_WB[2, 0], R_WB[2, 2])


def next_memory(
    memory: np.ndarray | None,
    state: int,
    q_reference: np.ndarray,
    q_now: np.ndarray,
    pitch_now: float,
) -> np.ndarray:
    """The memory after this tick's state is known (None: the first tick, where every
    entry is the seated posture q_now). Its last-pitch entry is set by with_pitch."""
    nu = len(q_now)
    pitches = 1 + nu * (1 + STAND_UP_STATES)
    if memory is None:
        memory = np.empty(memory_size(nu))
        memory[0] = state
        memory[1 : 1 + nu] = q_reference
        memory[1 + nu : pitches] = np.tile(q_now, STAND_UP_STATES)
        memory[pitches : pitches + 2] = pitch_now
        memory[pitches + 2 :] = pitch_now
        return memory
    if memory[0] == state:
        return memory
    memory = memory.copy()  # the caller's is the system's state
    on_the_way_up = memory[0] == state - 1
    memory[0] = state
    memory[1 : 1 + nu] = q_reference
    memory[pitches + 1] = memory[pitches]  # the pitch aimed at when the state began
    # Only on the way up: standing again from a lowering, state 4 began half-way down.
    if state <= STAND_UP_STATES and on_the_way_up:
        memory[1 + nu * state : 1 + nu * (state + 1)] = q_now
        memory[pitches + 1 + state] = pitch_now
    return memory


def returning(
    memory: np.ndarray,
    returns_to: int,
    share: float,
    trunk: np.ndarray,
    trunk_leads_by: float = 1.0,
) -> tuple[np.ndarray, float]:
    """(the posture target, the base pitch target) share of the way from where the phase
    began to those stand-up state returns_to began with; the trunk (the joints where
    trunk is True: the torso's joints and the hips' pitch, and the pelvis' pitch) trunk_leads_by
    times as far along, up to all the way: the body leans forward before it lowers."""
    nu = len(trunk)
    pitches = 1 + nu * (1 + STAND_UP_STATES)
    q_from = memory[1 : 1 + nu]
    q_to = memory[1 + nu * returns_to : 1 + nu * (returns_to + 1)]
    pitch_from, pitch_to = memory[pitches + 1], memory[pitches + 1 + returns_to]
    lead = min(1.0, share * trunk_leads_by)
    shares = np.where(trunk, lead, share)
    return q_from + shares * (q_to - q_from), pitch_from + lead * (pitch_to - pitch_from)


def with_pitch(memory: np.ndarray, nu: int, pitch: float) -> np.ndarray:
    """A copy of memory with this tick's base pitch target as the last one."""
    memory = memory.copy()
    memory[1 + nu * (1 + STAND_UP_STATES)] = pitch
    return memory
