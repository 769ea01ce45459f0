"""The sit-down's memory of the way up and the return along it (standup/return_path.py),
against values worked out here by hand."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RotationMatrix

from drake_standup.standup.return_path import (
    STAND_UP_STATES,
    base_pitch,
    memory_size,
    next_memory,
    returning,
    with_pitch,
)

NU = 3
PITCHES = 1 + NU * (1 + STAND_UP_STATES)


def _entry(memory, state):
    """The joint positions and the base pitch memory holds for stand-up state `state`."""
    return memory[1 + NU * state : 1 + NU * (state + 1)], memory[PITCHES + 1 + state]


def _walk(states, q_of=lambda k: np.full(NU, float(k)), pitch_of=lambda k: -0.1 * k):
    """The memory after one tick in each state of `states`, the measured posture and
    pitch at tick k being q_of(k) and pitch_of(k)."""
    memory = None
    for k, state in enumerate(states):
        memory = next_memory(memory, state, np.full(NU, 100.0 + k), q_of(k), pitch_of(k))
        memory = with_pitch(memory, NU, 10.0 * k)
    return memory


def test_the_first_tick_holds_the_seated_posture_for_every_stand_up_state():
    memory = _walk([1])
    assert len(memory) == memory_size(NU)
    for state in range(1, STAND_UP_STATES + 1):
        q, pitch = _entry(memory, state)
        np.testing.assert_array_equal(q, np.zeros(NU))
        assert pitch == 0.0


def test_each_stand_up_state_is_remembered_as_it_began_on_the_way_up():
    """Ticks 0-1 seated, 2 forward, 3-4 the lift-off, 5 rise: each entry holds the tick
    it began at; ticks within a state change nothing."""
    memory = _walk([1, 1, 2, 3, 3, 4])
    for state, tick in [(2, 2), (3, 3), (4, 5)]:
        q, pitch = _entry(memory, state)
        np.testing.assert_array_equal(q, np.full(NU, float(tick)))
        assert pitch == pytest.approx(-0.1 * tick)
    # q_ref and the pitch target when the last state began: tick 5's, and tick 4's target.
    np.testing.assert_array_equal(memory[1 : 1 + NU], np.full(NU, 105.0))
    assert memory[PITCHES + 1] == 40.0


def test_standing_again_from_a_lowering_keeps_the_way_ups_entries():
    """Up (1-4), a lowering (5) stood back up (4), lowered again (5, 6, 7), seated (1):
    the entries are the way up's; a second way up (2-4) records itself."""
    way_up = [1, 2, 3, 4]
    memory = _walk(way_up + [5, 4, 5, 6, 7, 1])
    for state in range(1, STAND_UP_STATES + 1):
        q, _ = _entry(memory, state)
        np.testing.assert_array_equal(q, np.full(NU, float(way_up.index(state))))
    memory = _walk(way_up + [5, 6, 7, 1, 2, 3, 4])
    for state, tick in [(1, 0), (2, 8), (3, 9), (4, 10)]:
        np.testing.assert_array_equal(_entry(memory, state)[0], np.full(NU, float(tick)))


@pytest.mark.parametrize("share", [0.0, 0.2, 0.5, 1.0])
def test_the_return_goes_its_share_of_the_way_the_trunk_ahead(share):
    """q = q_from + s (q_to - q_from), the trunk's joints and the pelvis' pitch at
    min(1, 3 s): worked out by hand for the memory of the walk 1, 2, 3, 4, 5."""
    memory = _walk([1, 2, 3, 4, 5])
    trunk = np.array([True, False, False])
    q, pitch = returning(memory, 3, share, trunk, trunk_leads_by=3.0)
    q_from, q_to = np.full(NU, 104.0), np.full(NU, 2.0)  # q_ref entering 5; state 3 began
    lead = min(1.0, 3.0 * share)
    expected = q_from + np.array([lead, share, share]) * (q_to - q_from)
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-12)
    pitch_from, pitch_to = 30.0, -0.2  # the target as 5 began (tick 3's); state 3's pitch
    assert pitch == pytest.approx(pitch_from + lead * (pitch_to - pitch_from), abs=1e-12)


@pytest.mark.parametrize("yaw", [0.0, 0.7, -2.5])
@pytest.mark.parametrize("pitch", [-0.8, 0.0, 0.3])
def test_base_pitch_reads_the_forward_pitch_back(yaw, pitch):
    """R = Rz(yaw) Ry(-pitch) (root_link's x axis points backwards: a forward pitch is
    about its -y) reads back as pitch, whatever the yaw."""
    R = RotationMatrix.MakeZRotation(yaw) @ RotationMatrix.MakeYRotation(-pitch)
    assert base_pitch(R.matrix()) == pytest.approx(pitch, abs=1e-12)
