"""The iCub's limbs (robot/limbs.py): joint groups and the shoulder's tendon range,
against values worked out by hand from icub-tech's "Range of Motion of the iCub
Shoulders" (A q + b > 0, c = 1.71, b in degrees)."""

import math

import numpy as np
import pytest

from drake_standup.robot.limbs import (
    JOINT_GROUPS,
    joint_group,
    shoulder_tendon_limits,
    shoulder_tendon_margin_rad,
    shoulder_tendon_rows,
)

NAMES = [
    "torso_pitch",
    "neck_yaw",
    "l_shoulder_pitch",
    "l_shoulder_roll",
    "l_shoulder_yaw",
    "l_elbow",
    "l_wrist_pitch",
    "r_hip_pitch",
    "r_shoulder_pitch",
    "r_shoulder_roll",
    "r_shoulder_yaw",
    "r_ankle_roll",
]


def test_every_joint_has_one_limb():
    assert [joint_group(n) for n in NAMES] == [
        "torso", "neck", "arms", "arms", "arms", "arms", "arms", "legs",
        "arms", "arms", "arms", "legs",
    ]  # fmt: skip
    assert set(JOINT_GROUPS) == {"arms", "neck", "torso", "legs"}
    with pytest.raises(ValueError, match="l_thumb_oc"):
        joint_group("l_thumb_oc")


def test_margin_at_zero_is_the_tightest_row_by_hand():
    """At q = 0 each row's distance is b_k / |a_k|: the tightest is row 3's
    (-c, c, 0) with 46 deg, 46 deg / (c sqrt(2)) (row 2's (-1, 1, 0), 54.3 deg, gives
    38.4 deg; row 7's (0, 1, 0) 54.3 deg)."""
    q = np.zeros((1, len(NAMES)))
    expected = math.radians(46.0) / (1.71 * math.sqrt(2.0))
    np.testing.assert_allclose(shoulder_tendon_margin_rad(q, NAMES), [expected], rtol=1e-12)


def test_a_point_past_a_tendon_is_negative_and_the_rows_are_unit_distances():
    """pitch - roll = 60 deg lies past row 3 (c (pitch - roll) < 46 deg) by
    1.71 x 60 - 46 = 56.6 deg across its normal's length c sqrt(2), and past row 2
    (pitch - roll < 54.3 deg) by less. Moving the shoulder by t along a
    row's unit normal moves that row's value by t."""
    q = np.zeros((1, len(NAMES)))
    q[0, NAMES.index("r_shoulder_pitch")] = math.radians(60.0)
    margin = shoulder_tendon_margin_rad(q, NAMES)[0]
    np.testing.assert_allclose(
        margin, -math.radians(1.71 * 60.0 - 46.0) / (1.71 * math.sqrt(2.0)), rtol=1e-9
    )
    a, b = shoulder_tendon_rows()
    np.testing.assert_allclose(np.linalg.norm(a, axis=1), 1.0, rtol=1e-12)
    q0 = np.radians([-40.0, 20.0, 30.0])
    for k in range(len(a)):
        np.testing.assert_allclose((q0 + 0.01 * a[k]) @ a[k] - q0 @ a[k], 0.01, rtol=1e-9)


def test_the_seated_and_phase_postures_lie_inside():
    """The shipped seated pose (pitch -0.6981, roll 0.2094, yaw 1.3963) and the phases'
    arm postures (pitch -1.6455 / -1.4615, roll 0.4363, yaw 0.5862 / 0.1545) are inside."""
    a, b = shoulder_tendon_rows()
    for q in ([-0.6981, 0.2094, 1.3963], [-1.6455, 0.4363, 0.5862], [-1.4615, 0.4363, 0.1545]):
        assert np.all(a @ np.array(q) + b > 0.1)


def test_limits_over_all_joints_place_each_sides_rows():
    """shoulder_tendon_limits: one block of rows per side, on that side's three columns."""
    a, b = shoulder_tendon_limits(NAMES)
    a_side, b_side = shoulder_tendon_rows()
    k = len(a_side)
    assert a.shape == (2 * k, len(NAMES)) and b.shape == (2 * k,)
    left = [NAMES.index(f"l_shoulder_{j}") for j in ("pitch", "roll", "yaw")]
    right = [NAMES.index(f"r_shoulder_{j}") for j in ("pitch", "roll", "yaw")]
    np.testing.assert_array_equal(a[:k][:, left], a_side)
    np.testing.assert_array_equal(a[k:][:, right], a_side)
    others = np.setdiff1d(np.arange(len(NAMES)), left + right)
    assert not a[:, others].any()
    np.testing.assert_array_equal(b, np.tile(b_side, 2))
    assert shoulder_tendon_limits(["torso_pitch"])[0].shape == (0, 1)
