"""The arms' speed bound (control/tasks/joint_limits.py: speed_bounds): checked against the
exact solution of a joint driven into it, and against the position bounds it must yield to."""

import numpy as np
import pytest

from drake_standup.control.tasks.joint_limits import speed_bounds

V_MAX = 2.7  # rad/s
TAU = 0.02  # s
FREE = (np.full(1, -np.inf), np.full(1, np.inf))


def test_the_bound_is_the_barrier_of_the_speed_margin():
    """(+-v_max - qdot) / T on both sides, at rest and moving either way."""
    qdot = np.array([0.0, 1.0, -2.5, 4.0])
    low, high = speed_bounds(qdot, np.full(4, V_MAX), TAU, np.full(4, -np.inf), np.full(4, np.inf))
    np.testing.assert_allclose(high, (V_MAX - qdot) / TAU, rtol=1e-12)
    np.testing.assert_allclose(low, (-V_MAX - qdot) / TAU, rtol=1e-12)
    assert high[3] < 0.0  # a joint already too fast is brought back, at the barrier's rate


def test_an_unbounded_joint_keeps_its_bounds():
    low, high = speed_bounds(np.array([9.0]), np.array([np.inf]), TAU, np.array([-3.0]), [4.0])
    assert low[0] == -3.0 and high[0] == 4.0


@pytest.mark.parametrize("dt", [0.002, 0.004, 0.01])
def test_a_joint_pushed_into_the_bound_approaches_it_and_never_passes(dt):
    """A joint asked for 500 rad/s^2 (a strong pull), its acceleration held at the bound
    for each tick dt <= T: its speed follows v_max (1 - (1 - dt/T)^k) exactly (the discrete
    barrier's solution), reaches v_max within 1 % in 5 T, and never passes it."""
    v, speeds = 0.0, []
    for _ in range(int(round(10 * TAU / dt))):
        _, high = speed_bounds(np.array([v]), np.array([V_MAX]), TAU, *FREE)
        v += dt * min(500.0, high[0])
        speeds.append(v)
    k = np.arange(1, len(speeds) + 1)
    exact = V_MAX * (1.0 - (1.0 - dt / TAU) ** k)
    np.testing.assert_allclose(speeds, exact, rtol=1e-9, atol=1e-12)
    assert max(speeds) <= V_MAX
    assert speeds[int(round(5 * TAU / dt)) - 1] > 0.99 * V_MAX * (1 - np.exp(-5)) - 1e-9


def test_the_position_bounds_win_where_they_conflict():
    """A joint at 3.5 rad/s into a limit that asks it to stop harder than the speed bound
    allows (low > the speed's high would leave no acceleration): the bounds stay ordered
    and keep the position bound's side; where they agree, the tighter of the two."""
    qdot = np.array([3.5, 1.0])
    low_pos, high_pos = np.array([-200.0, -50.0]), np.array([-100.0, 300.0])
    low, high = speed_bounds(qdot, np.full(2, V_MAX), TAU, low_pos, high_pos)
    assert np.all(low <= high)
    assert low[0] == -200.0 and high[0] == -100.0  # the speed bound (-40) is looser here
    np.testing.assert_allclose([low[1], high[1]], [-50.0, (V_MAX - 1.0) / TAU])
    low_c, high_c = speed_bounds(np.array([3.5]), np.array([V_MAX]), TAU, [0.0], [100.0])
    # speed wants qddot in [-310, -40], position in [0, 100]: inside the position's range,
    # at its end nearest the speed's.
    assert low_c[0] == 0.0 and high_c[0] == 0.0
