"""The iCub's joints by limb, and the shoulder's tendon-bound range.

JOINT_GROUPS sorts the actuated joints by the body they move (what a roboticist compares
when judging a whip: a light limb should not outrun the trunk that carries it).

The shoulder of iCub 2.x is driven by tendons whose lengths bound its three joints
(pitch, roll, yaw) together, A q + b > 0, not by the box of joint limits the URDF (and the
firmware) declare: icub-tech's documentation ([icub-tech]), "Range of Motion of the iCub
Shoulders" (iCub kinematics pages), gives one row per tendon, 14 rows with c = 1.71; they are held
here, in radians (b scaled by pi / 180).
"""

from __future__ import annotations

import math

import numpy as np

# Limb -> the joint-name parts that put a joint in it (every actuated joint has one).
JOINT_GROUPS: dict[str, tuple[str, ...]] = {
    "arms": ("shoulder", "elbow", "wrist"),
    "neck": ("neck",),
    "torso": ("torso",),
    "legs": ("hip", "knee", "ankle"),
}

_C = 1.71
# The documentation's A and b, one row per tendon, over (pitch, roll, yaw); b in degrees.
# (Its 5-row reduction is stricter inside the URDF's box: it excludes 12 % of the box that
# the 14 rows admit, sampled uniformly; the tendons' own rows are held here.)
_TENDON_A = np.array(
    [
        [_C, -_C, 0.0],
        [-1.0, 1.0, 0.0],
        [-_C, _C, 0.0],
        [1.0, -1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [_C, -_C, -_C],
        [-1.0, 1.0, 1.0],
        [-_C, _C, _C],
        [1.0, -1.0, -1.0],
        [0.0, 1.0, 1.0],
        [0.0, -1.0, -1.0],
    ]
)
_TENDON_B_DEG = np.array(
    [404.0, 54.3, 46.0, 305.7, 215.7, 150.0, 54.3, 210.0, 431.0, 101.7, 109.0, 258.3, 71.7, 228.3]
)
SHOULDER_JOINTS = ("shoulder_pitch", "shoulder_roll", "shoulder_yaw")
# The trunk's joints out of the sagittal plane: a symmetric stand-up holds them where the
# robot sat (outputs/metrics.py judges their twist; standup/task_references.py holds them
# standing).
TRUNK_TWIST_JOINTS = ("torso_roll", "torso_yaw")


def joint_limits_rad(plant, instance, names) -> dict[str, tuple[float, float]]:
    """(lower, upper) position limits of each named joint the model has, rad."""
    limits = {}
    for name in names:
        if plant.HasJointNamed(name, instance):
            joint = plant.GetJointByName(name, instance)
            limits[name] = (joint.position_lower_limits()[0], joint.position_upper_limits()[0])
    return limits


def joint_group(name: str) -> str:
    """The limb (a JOINT_GROUPS key) of an actuated joint, by its name."""
    for group, parts in JOINT_GROUPS.items():
        if any(part in name for part in parts):
            return group
    raise ValueError(f"joint '{name}': no limb of {', '.join(JOINT_GROUPS)} names it")


def shoulder_tendon_rows() -> tuple[np.ndarray, np.ndarray]:
    """(a, b): the tendon rows a q + b >= 0 over (pitch, roll, yaw), rad, each row scaled
    to unit norm, so that a q + b is the distance in joint space (rad) to its bound."""
    norms = np.linalg.norm(_TENDON_A, axis=1)
    return _TENDON_A / norms[:, None], np.radians(_TENDON_B_DEG) / norms


def shoulder_columns(joint_names: list[str]) -> list[list[int]]:
    """Per side that has all three shoulder joints, their indices in joint_names in the
    order (pitch, roll, yaw)."""
    columns = []
    for side in ("l", "r"):
        names = [f"{side}_{joint}" for joint in SHOULDER_JOINTS]
        if all(name in joint_names for name in names):
            columns.append([joint_names.index(name) for name in names])
    return columns


def shoulder_tendon_margin_rad(q: np.ndarray, joint_names: list[str]) -> np.ndarray:
    """The smallest distance (rad) of either shoulder to its tendon bound, per sample of
    q (samples x joints, in joint_names' order); negative: past it. nan if no shoulder."""
    q = np.atleast_2d(q)
    a, b = shoulder_tendon_rows()
    margins = [q[:, cols] @ a.T + b for cols in shoulder_columns(list(joint_names))]
    if not margins:
        return np.full(len(q), math.nan)
    return np.min(np.concatenate(margins, axis=1), axis=1)


def shoulder_tendon_limits(joint_names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """(a, b) with a q + b >= 0 the tendon rows of every shoulder, a over all joint_names
    (k x len(joint_names)), rows of unit norm; k = 0 without shoulders."""
    a_side, b_side = shoulder_tendon_rows()
    columns = shoulder_columns(list(joint_names))
    a = np.zeros((len(a_side) * len(columns), len(joint_names)))
    for k, cols in enumerate(columns):
        a[k * len(a_side) : (k + 1) * len(a_side), cols] = a_side
    return a, np.tile(b_side, len(columns))
