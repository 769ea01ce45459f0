"""The braking-distance joint-limit bound (control/tasks/joint_limits.py: braking_bounds):
checked against the kinematics of a joint braking at constant deceleration."""

import numpy as np
import pytest

from drake_standup.control.tasks.joint_limits import (
    JointLimitBounds,
    braking_bounds,
    joint_limit_acceleration_bounds,
)

A = 20.0  # reserved braking, rad/s^2
T = 0.1  # the barrier's time constant, s


def test_on_the_braking_curve_the_bound_is_the_reserved_braking():
    """Where qdot^2 = 2 a d (the last instant a braking of a can stop the joint at its
    limit) and qdot >= a T, the bound is exactly -a toward q_max and +a toward q_min."""
    d = np.array([0.1, 0.2, 0.6])
    v = np.sqrt(2.0 * A * d)
    q_max, q_min = np.full(3, 1.0), np.full(3, -1.0)
    _, high = braking_bounds(q_max - d, v, q_min, q_max, A, T)
    np.testing.assert_allclose(high, -A, rtol=1e-12)
    low, _ = braking_bounds(q_min + d, -v, q_min, q_max, A, T)
    np.testing.assert_allclose(low, A, rtol=1e-12)


def test_never_more_than_a_stop_within_the_time_constant():
    """Past its limit or too fast for the reserve (h < 0), the bound asks min(a, qdot/T):
    it goes to 0 with qdot, no step at qdot = 0 for a joint resting at its limit."""
    q_min, q_max = np.full(4, -1.0), np.full(4, 1.0)
    v = np.array([1e-6, 0.5, 1.5, 6.0])
    _, high = braking_bounds(np.full(4, 1.01), v, q_min, q_max, A, T)  # 0.01 past q_max
    np.testing.assert_allclose(high, -np.minimum(A, v / T), rtol=1e-12)
    assert abs(high[0]) < 1e-4


def test_no_bound_at_rest_or_moving_away():
    q = np.array([0.0, 0.9, -0.9])
    q_min, q_max = np.full(3, -1.0), np.full(3, 1.0)
    low, high = braking_bounds(q, np.zeros(3), q_min, q_max, A, T)
    assert np.all(np.isinf(low) & (low < 0)) and np.all(np.isinf(high) & (high > 0))
    low, high = braking_bounds(q, np.array([-3.0, -3.0, -3.0]), q_min, q_max, A, T)
    assert np.all(np.isinf(high))  # moving away from q_max: only q_min may bound it


def test_mirror_symmetry():
    """Toward q_min is toward q_max seen in the mirror q -> -q."""
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.9, 0.9, 50)
    v = rng.uniform(-6.0, 6.0, 50)
    q_min, q_max = np.full(50, -1.2), np.full(50, 0.8)
    low, high = braking_bounds(q, v, q_min, q_max, A, T)
    low_m, high_m = braking_bounds(-q, -v, -q_max, -q_min, A, T)
    np.testing.assert_allclose(low, -high_m)
    np.testing.assert_allclose(high, -low_m)


@pytest.mark.parametrize("v0", [1.0, 3.0, 5.0, 8.0])
def test_a_joint_driven_at_its_limit_stops_before_it(v0):
    """A joint pushed toward q_max by a drive far stronger than the bound (100 rad/s^2),
    its acceleration clipped to the bounds each 1 ms step: it stops inside the limit
    wherever the reserved braking could still stop it from its start, and never brakes
    harder than the reserve."""
    q_min, q_max = np.array([-2.0]), np.array([1.0])
    q, v = np.array([-1.5]), np.array([v0])
    dt, hardest = 1e-3, 0.0
    viable = v0**2 / (2 * A) <= q_max[0] - q[0]
    for _ in range(3000):
        low, high = braking_bounds(q, v, q_min, q_max, A, T)
        h_low, h_high = joint_limit_acceleration_bounds(q, v, q_min, q_max, T)
        a = np.clip(100.0, max(low[0], h_low[0]), min(high[0], h_high[0]))
        hardest = min(hardest, float(a))
        q = q + dt * v + 0.5 * dt * dt * a
        v = v + dt * a
    assert viable
    assert q[0] <= q_max[0] + 1e-3
    assert abs(v[0]) < 0.05  # settled at the limit
    assert hardest >= -A - 1e-6


def test_the_bounds_are_the_tighter_of_both_and_none_keeps_the_horizon_bound():
    """With a braking reserve each joint's bounds are the tighter of the horizon's and the
    braking bound's; with none (braking_rad_per_s2 None) the horizon's alone."""
    rng = np.random.default_rng(5)
    n = 6
    q_min, q_max = np.full(n, -1.0), np.full(n, 1.0)
    q, v = rng.uniform(-0.8, 0.8, n), rng.uniform(-5, 5, n)
    terms = type("Terms", (), {"q": q, "v": v})()
    h_low, h_high = joint_limit_acceleration_bounds(q, v, q_min, q_max, T)
    b_low, b_high = braking_bounds(q, v, q_min, q_max, A, T)
    low, high = JointLimitBounds(np.arange(n), np.arange(n), q_min, q_max, T, A).calc(terms)
    np.testing.assert_allclose(low, np.maximum(h_low, b_low))
    np.testing.assert_allclose(high, np.minimum(h_high, b_high))
    assert np.any(high < h_high)  # the braking bound binds somewhere in this draw
    low, high = JointLimitBounds(np.arange(n), np.arange(n), q_min, q_max, T).calc(terms)
    np.testing.assert_array_equal(low, h_low)
    np.testing.assert_array_equal(high, h_high)
