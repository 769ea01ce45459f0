"""What the standing robot's feet can hold (sensing.standing_pull_usage), and how far a
pull moves the centre of pressure under the robot now (sensing.pull_cop_shift_m), against
moment balances written out here."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.world.sensing import StandingSupport, pull_cop_shift_m, standing_pull_usage

WEIGHT_N = 324.0
SUPPORT = StandingSupport(
    com_height_m=0.575,
    hands_m=np.array([[0.34, 0.13, 0.29], [0.34, -0.13, 0.29]]),
    soles_m=np.array([[0.03, 0.12, -0.56], [0.03, -0.12, -0.56]]),
    lean_m=(0.05, 0.065, 0.11),
    cop_x_m=(-0.05, 0.10),
    cop_y_m=(-0.025, 0.025),
)
HALF_X = 0.075  # half the CoP box's length
HALF_Y = (0.24 + 0.05) / 2  # half the span of both boxes


def _cop_shift(left_N, right_N):
    """Where the ground reaction must act, from below the CoM, for the standing robot
    (CoM at height h over the point G) to be in static balance under the hands' forces:
    moments about G, sum_h (r_h + h z) x f_h + p x R = 0 with R = m g z - sum f (the
    ground's reaction on the robot) and p on the ground."""
    h = SUPPORT.com_height_m
    moment = np.zeros(3)
    total = np.zeros(3)
    for r, f in zip(SUPPORT.hands_m, (left_N, right_N), strict=True):
        arm = r + np.array([0.0, 0.0, h])
        moment += np.cross(arm, f)
        total += f
    R = np.array([0.0, 0.0, WEIGHT_N]) - total
    # p x R with p = (px, py, 0): (py Rz, -px Rz, px Ry - py Rx); the x, y rows balance.
    return np.array([moment[1] / R[2], -moment[0] / R[2]])


def _usage(left_N, right_N):
    F = np.zeros(12)
    F[3:6], F[9:12] = left_N, right_N
    return standing_pull_usage(F, WEIGHT_N, SUPPORT)


def test_no_pull_needs_nothing():
    assert _usage(np.zeros(3), np.zeros(3)) == 0.0


@pytest.mark.parametrize("seed", range(5))
def test_usage_is_the_cop_shift_over_lean_and_half_box(seed):
    """The feet hold a pull by leaning (up to lean_m) and moving the CoP to the edge of
    the soles' boxes: the usage is the CoP shift the balance needs over that reach, in
    the direction that binds (a backward pull moves the CoP back, which a forward lean
    undoes)."""
    rng = np.random.default_rng(seed)
    left, right = rng.uniform(-25, 25, 3), rng.uniform(-25, 25, 3)
    left[2], right[2] = abs(left[2]), abs(right[2])
    px, py = _cop_shift(left, right)
    forward, back, side = SUPPORT.lean_m
    expected = max(-px / (forward + HALF_X), px / (back + HALF_X), abs(py) / (side + HALF_Y))
    assert _usage(left, right) == pytest.approx(expected, rel=1e-9)


def test_the_opposing_person_and_a_sideways_pull():
    """18 N backwards per hand (the authors' opposing person): the CoP 9 cm back of the
    CoM's foot, 0.72 of the 12.5 cm the feet reach; 25 N sideways per hand: 0.51; the
    same pull on either side alike."""
    back = np.array([-18.0, 0.0, 0.0])
    px, _ = _cop_shift(back, back)
    assert px == pytest.approx(-2 * 18.0 * (0.575 + 0.29) / WEIGHT_N)
    assert _usage(back, back) == pytest.approx(-px / 0.125)
    left, right = np.array([0.0, 25.0, 0.0]), np.array([0.0, -25.0, 0.0])
    assert _usage(left, left) == pytest.approx(_usage(right, right))
    assert _usage(left, left) == pytest.approx(2 * 25 * 0.865 / WEIGHT_N / (0.11 + HALF_Y))


def test_a_pull_that_lifts_the_robot_is_beyond_the_feet():
    up = np.array([0.0, 0.0, WEIGHT_N / 2 + 1.0])
    assert _usage(up, up) == 10.0


def _moment_y_about(p_x, ground_z, com, hands, F, weight_N):
    """The y moment about the ground point (p_x, *, ground_z) of the weight at the CoM, the
    hands' moments, their horizontal forces and their downward forces at the hands, a
    lift acting below the CoM (its own lever left out, sensing.pull_cop_shift_m), by 3-D
    cross products."""
    p = np.array([p_x, 0.0, ground_z])
    total = np.cross(com - p, [0.0, 0.0, -weight_N])
    for h in range(2):
        horizontal = np.array([F[h, 3], F[h, 4], 0.0])
        vertical = np.array([0.0, 0.0, F[h, 5]])
        at = hands[h] if F[h, 5] < 0.0 else np.array([com[0], hands[h, 1], hands[h, 2]])
        total = total + np.cross(hands[h] - p, horizontal) + np.cross(at - p, vertical)
        total = total + F[h, :3]
    return total[1]


@pytest.mark.parametrize("seed", range(5))
def test_the_pull_moves_the_cop_to_where_the_moments_balance(seed):
    """The CoP is the ground point about which the weight, the pull and the ground's
    reaction (acting there) have no y moment: found by the linear root of the moment
    written with 3-D cross products; the shift is its x from the CoM's."""
    rng = np.random.default_rng(seed)
    com = np.array([0.15, 0.0, 0.35]) + rng.uniform(-0.05, 0.05, 3)
    hands = np.array([[0.3, 0.12, 0.4], [0.3, -0.12, 0.4]]) + rng.uniform(-0.1, 0.1, (2, 3))
    F = np.hstack([rng.uniform(-1, 1, (2, 3)), rng.uniform(-25, 25, (2, 3))])
    ground_z = 0.011
    m0, m1 = (_moment_y_about(x, ground_z, com, hands, F, WEIGHT_N) for x in (0.0, 1.0))
    cop_x = -m0 / (m1 - m0)
    shift = pull_cop_shift_m(F.ravel(), hands, com, ground_z, WEIGHT_N)
    assert shift == pytest.approx(cop_x - com[0], abs=1e-12)


def test_a_backward_pull_moves_the_cop_back_by_its_moment_over_the_weight():
    """Both hands pulled back 10 N at 0.35 m over the ground: the CoP 2 x 10 x 0.35 / W
    behind the CoM, a forward pull as far forward; pressed down 10 N each 0.15 m in front
    of the CoM: 2 x 10 x 0.15 / (W + 20) forward; an upward pull in front of the CoM is
    left to the standing feet (no shift here); one lifting the robot cannot be held
    (-inf)."""
    com = np.array([0.2, 0.0, 0.36])
    hands = np.array([[0.35, 0.1, 0.36], [0.35, -0.1, 0.36]])
    back = np.array([0, 0, 0, -10.0, 0, 0] * 2)
    expected = -2 * 10.0 * 0.35 / WEIGHT_N
    assert pull_cop_shift_m(back, hands, com, 0.01, WEIGHT_N) == pytest.approx(expected)
    assert pull_cop_shift_m(-back, hands, com, 0.01, WEIGHT_N) == pytest.approx(-expected)
    down = np.array([0, 0, 0, 0, 0, -10.0] * 2)
    assert pull_cop_shift_m(down, hands, com, 0.01, WEIGHT_N) == pytest.approx(
        2 * 10.0 * 0.15 / (WEIGHT_N + 20.0)
    )
    assert pull_cop_shift_m(-down, hands, com, 0.01, WEIGHT_N) == 0.0
    lift = np.array([0, 0, 0, 0, 0, WEIGHT_N / 2 + 1] * 2)
    assert pull_cop_shift_m(lift, hands, com, 0.01, WEIGHT_N) == -np.inf
