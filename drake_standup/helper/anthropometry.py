"""A person as a body (issue 32, first part): segments scaled from an anthropometric table
to a height and a mass, added to a MultibodyPlant.

The table is [de-leva1996], de Leva (1996), "Adjustments to Zatsiorsky-Seluyanov's segment inertia
parameters", J. Biomech. 29(9): 1223-1230, male columns. Table 4 gives each segment's mass
(fraction of body mass), its centre of mass (fraction of its length from the first
landmark) and its radii of gyration (fractions of its length: sagittal, transverse,
longitudinal); its Table 1 the lengths on the reference stature of 1741 mm. The same
numbers are carried by biobuddy's DeLevaTable and the HeiMan model (read 2026-12).

The body stands upright in its own frame P (x forward, y left, z up, the origin on the
floor under the mid-hip). Its chain up the midline is ankle - knee - hip (MIDH) - OMPH
(navel) - XYPH (xiphoid) - CERV (C7) - VERT (vertex); the table's longitudinal lengths
leave 2.2 % of the stature below the ankle, the ankle's height here, so the vertex stands
exactly at the height (the remainder is what the table's segments do not span, feet and
landmark offsets). The lower body (feet, shanks, thighs, the lower trunk) is welded to the
world where the person stands: their legs' load is a reaction, not a motion. Above it the
lumbar joint (at OMPH: flexion, lateral bending, axial rotation) carries the middle and
upper trunk and the head welded together, and each arm hangs from a shoulder (3
revolutes) through an elbow (1) and a wrist (1). The shoulders sit at the
suprasternale's height (170.7 mm above XYPH on 1741, de Leva), 0.1 of the stature to
each side, and the hips 0.0461 of it (Dumas, Cheze, Verriest 2007, "Adjustments to
McConville et al. and Young et al. body segment inertial parameters", J. Biomech.
40(3), as the HeiMan model uses them). human.mode: body puts this person into the
plant (helper/body.py), kneeling: the shanks flat behind the knees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Box, Capsule, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    Frame,
    ModelInstanceIndex,
    RevoluteJoint,
    RigidBody,
    RotationalInertia,
    SpatialInertia,
)

# de Leva's reference stature, the lengths' denominator. m.
REFERENCE_STATURE_M = 1.741


@dataclass(frozen=True)
class Segment:
    """One row of the table. mass: fraction of body mass; length: fraction of stature;
    com: the centre of mass's distance from the first landmark, fraction of the length;
    radii: radii of gyration about the CoM (sagittal, transverse, longitudinal axes),
    fractions of the length; landmarks: (first, second), de Leva's."""

    mass: float
    length: float
    com: float
    radii: tuple[float, float, float]
    landmarks: tuple[str, str]


def _seg(mass, length_mm, com, radii, landmarks) -> Segment:
    return Segment(mass, length_mm / (1000.0 * REFERENCE_STATURE_M), com, radii, landmarks)


# de Leva 1996, male: Table 4 (mass, CoM, radii; in %, here fractions) and the lengths.
DE_LEVA_MALE = {
    "head": _seg(0.0694, 242.9, 0.5002, (0.303, 0.315, 0.261), ("VERT", "CERV")),
    "upper_trunk": _seg(0.1596, 242.1, 0.5066, (0.505, 0.320, 0.465), ("CERV", "XYPH")),
    "middle_trunk": _seg(0.1633, 215.5, 0.4502, (0.482, 0.383, 0.468), ("XYPH", "OMPH")),
    "lower_trunk": _seg(0.1117, 145.7, 0.6115, (0.615, 0.551, 0.587), ("OMPH", "MIDH")),
    "upper_arm": _seg(0.0271, 281.7, 0.5772, (0.285, 0.269, 0.158), ("SJC", "EJC")),
    "forearm": _seg(0.0162, 268.9, 0.4574, (0.276, 0.265, 0.121), ("EJC", "WJC")),
    "hand": _seg(0.0061, 86.2, 0.7900, (0.628, 0.513, 0.401), ("WJC", "MET3")),
    "thigh": _seg(0.1416, 422.2, 0.4095, (0.329, 0.329, 0.149), ("HJC", "KJC")),
    "shank": _seg(0.0433, 434.0, 0.4459, (0.255, 0.249, 0.103), ("KJC", "LMAL")),
    "foot": _seg(0.0137, 258.1, 0.4415, (0.257, 0.245, 0.124), ("HEEL", "TTIP")),
}
# The shoulders' height above XYPH: de Leva's other upper trunk, XYPH to SUPR (the
# suprasternale, the shoulders' level), 170.7 mm on 1741; a fraction of stature.
SHOULDER_ABOVE_XYPH = 0.1707 / REFERENCE_STATURE_M
# Shoulder and hip half-widths, fractions of stature (Dumas et al. 2007, via HeiMan).
SHOULDER_HALF_WIDTH = 0.10
HIP_HALF_WIDTH = 0.0461
# The midline chain from the ankle up (each segment's length stacks): its sum and the
# ankle's height (the remainder) make the stature.
MIDLINE = ("shank", "thigh", "lower_trunk", "middle_trunk", "upper_trunk", "head")
ARM_JOINTS = (
    ("shoulder_flexion", (0.0, 1.0, 0.0)),
    ("shoulder_abduction", (1.0, 0.0, 0.0)),
    ("shoulder_rotation", (0.0, 0.0, 1.0)),
)
ELBOW = (("elbow", (0.0, 1.0, 0.0)),)
WRIST = (("wrist", (0.0, 1.0, 0.0)),)
LUMBAR_JOINTS = (
    ("lumbar_flexion", (0.0, 1.0, 0.0)),
    ("lumbar_bending", (1.0, 0.0, 0.0)),
    ("lumbar_rotation", (0.0, 0.0, 1.0)),
)


def ankle_height_fraction(table: dict[str, Segment] = DE_LEVA_MALE) -> float:
    """The ankle's height as a fraction of stature: what the midline's segments leave."""
    return 1.0 - sum(table[name].length for name in MIDLINE)


def landmark_heights(height_m: float, table: dict[str, Segment] = DE_LEVA_MALE) -> dict:
    """Height above the floor of each midline landmark of the upright body. m."""
    z = ankle_height_fraction(table) * height_m
    heights = {"LMAL": z}
    for name in MIDLINE:
        z += table[name].length * height_m
        top = table[name].landmarks[0]
        heights[top] = z
    return heights


@dataclass
class Person:
    """The person's model instance in the plant, its size and its joints (in order)."""

    model_instance: ModelInstanceIndex
    height_m: float
    mass_kg: float
    joint_names: list[str]


# Where each segment's body origin is, and which way it runs from there: (the origin is
# the first landmark, the direction along z). Trunk and head stack up from their lower
# landmark; limbs hang from their proximal joint.
ORIGIN = {
    "head": (False, 1.0),
    "upper_trunk": (False, 1.0),
    "middle_trunk": (False, 1.0),
    "lower_trunk": (True, -1.0),
    "upper_arm": (True, -1.0),
    "forearm": (True, -1.0),
    "hand": (True, -1.0),
    "thigh": (True, -1.0),
    "shank": (True, -1.0),
}


def segment_com(segment: Segment, name: str, height_m: float, ankle_m: float) -> np.ndarray:
    """The segment's CoM in its body frame (ORIGIN): along its axis, com of its length
    from the first landmark. The foot's body origin is the ankle (ankle_m above the
    floor), the foot flat under it from the heel (under the ankle) forward: its CoM com
    of its length ahead, on the floor. m."""
    length = segment.length * height_m
    if name == "foot":
        return np.array([segment.com * length, 0.0, -ankle_m])
    first, direction = ORIGIN[name]
    along = segment.com if first else 1.0 - segment.com
    return np.array([0.0, 0.0, direction * along * length])


def segment_inertia(
    segment: Segment, name: str, height_m: float, mass_kg: float, ankle_m: float
) -> SpatialInertia:
    """SpatialInertia about the body origin: the table's mass, the CoM of segment_com, and
    the radii of gyration about the CoM on the axes (sagittal x, transverse y,
    longitudinal z; the foot's longitudinal axis is x, its sagittal z)."""
    length, mass = segment.length * height_m, segment.mass * mass_kg
    r = np.asarray(segment.radii) * length
    moments = (r[2], r[1], r[0]) if name == "foot" else tuple(r)
    I_com = RotationalInertia(*(mass * k**2 for k in moments))
    p_com = segment_com(segment, name, height_m, ankle_m)
    return SpatialInertia.MakeFromCentralInertia(mass, p_com, I_com)


class _Builder:
    """Adds the bodies and joints of one person (add_person)."""

    def __init__(self, plant: MultibodyPlant, instance, table, height_m, mass_kg):
        self.plant, self.instance, self.table = plant, instance, table
        self.H, self.M = height_m, mass_kg
        self.ankle_m = ankle_height_fraction(table) * height_m
        self.joints: list[str] = []

    def segment(self, key: str, name: str) -> RigidBody:
        inertia = segment_inertia(self.table[name], name, self.H, self.M, self.ankle_m)
        return self.plant.AddRigidBody(key, self.instance, inertia)

    def frame(self, name: str, body: RigidBody, p: list[float]) -> Frame:
        return self.plant.AddFrame(FixedOffsetFrame(name, body.body_frame(), RigidTransform(p)))

    def weld(self, parent: RigidBody, child: RigidBody, p: list[float]) -> None:
        self.plant.WeldFrames(parent.body_frame(), child.body_frame(), RigidTransform(p))

    def chain(self, prefix, parent, p, axes, child: RigidBody) -> None:
        """Revolutes about axes in turn (massless links between) from p on parent to child."""
        frame = self.frame(f"{prefix}{axes[0][0]}_parent", parent, p)
        for k, (joint, axis) in enumerate(axes):
            name = f"{prefix}{joint}"
            last = k == len(axes) - 1
            link = (
                child
                if last
                else self.plant.AddRigidBody(f"{name}_link", self.instance, SpatialInertia.Zero())
            )
            self.plant.AddJoint(RevoluteJoint(name, frame, link.body_frame(), axis))
            self.joints.append(name)
            frame = link.body_frame()

    def length(self, name: str) -> float:
        return self.table[name].length * self.H


def omph_height(height_m: float, kneeling: bool, table: dict[str, Segment] = DE_LEVA_MALE):
    """The lumbar joint's (OMPH's) height above the floor, standing or kneeling (the
    shanks flat on the floor behind the knees, the knee as high as a standing ankle: the
    same tissue under the joint, an assumption). m."""
    z = landmark_heights(height_m, table)["OMPH"]
    return z - table["shank"].length * height_m if kneeling else z


def add_person(
    plant: MultibodyPlant,
    height_m: float = 1.75,
    mass_kg: float = 75.0,
    X_WP: RigidTransform | None = None,
    name: str = "person",
    table: dict[str, Segment] = DE_LEVA_MALE,
    *,
    kneeling: bool = False,
) -> Person:
    """The module docstring's body, scaled to height_m and mass_kg, standing (or kneeling,
    omph_height) at X_WP (its frame P on the floor under the mid-hip, x forward); with
    simple shapes to see where the plant has a scene graph."""
    instance = plant.AddModelInstance(name)
    b = _Builder(plant, instance, table, height_m, mass_kg)
    H = height_m
    lower = b.segment("lower_trunk", "lower_trunk")
    X_WO = (X_WP or RigidTransform()) @ RigidTransform([0.0, 0.0, omph_height(H, kneeling, table)])
    plant.WeldFrames(plant.world_frame(), lower.body_frame(), X_WO)
    # Kneeling, the shank points backward from the knee (-z of its frame to -x) and the
    # foot stays level under its end.
    back = RotationMatrix.MakeYRotation(np.pi / 2 if kneeling else 0.0)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        thigh = b.segment(f"{side}_thigh", "thigh")
        b.weld(lower, thigh, [0.0, sign * HIP_HALF_WIDTH * H, -b.length("lower_trunk")])
        shank = b.segment(f"{side}_shank", "shank")
        plant.WeldFrames(
            thigh.body_frame(),
            shank.body_frame(),
            RigidTransform(back, [0.0, 0.0, -b.length("thigh")]),
        )
        plant.WeldFrames(
            shank.body_frame(),
            b.segment(f"{side}_foot", "foot").body_frame(),
            RigidTransform(back.inverse(), [0.0, 0.0, -b.length("shank")]),
        )
    middle = b.segment("middle_trunk", "middle_trunk")
    b.chain("", lower, [0.0, 0.0, 0.0], LUMBAR_JOINTS, middle)
    upper = b.segment("upper_trunk", "upper_trunk")
    b.weld(middle, upper, [0.0, 0.0, b.length("middle_trunk")])
    head = b.segment("head", "head")
    b.weld(upper, head, [0.0, 0.0, b.length("upper_trunk")])
    b.frame("vertex", head, [0.0, 0.0, b.length("head")])
    for side, sign in (("left", 1.0), ("right", -1.0)):
        arm = b.segment(f"{side}_upper_arm", "upper_arm")
        shoulder = [0.0, sign * SHOULDER_HALF_WIDTH * H, SHOULDER_ABOVE_XYPH * H]
        b.chain(f"{side}_", upper, shoulder, ARM_JOINTS, arm)
        forearm = b.segment(f"{side}_forearm", "forearm")
        b.chain(f"{side}_", arm, [0.0, 0.0, -b.length("upper_arm")], ELBOW, forearm)
        hand = b.segment(f"{side}_hand", "hand")
        b.chain(f"{side}_", forearm, [0.0, 0.0, -b.length("forearm")], WRIST, hand)
        b.frame(f"{side}_grip", hand, [0.0, 0.0, -b.length("hand")])
    if plant.geometry_source_is_registered():
        _add_shapes(plant, instance, table, H)
    return Person(instance, height_m, mass_kg, b.joints)


# What the person looks like: (segment, its width across, its depth), fractions of stature
# (simple shapes sized by eye on the proportions; only seen, they touch nothing).
SHAPES = {
    "head": (0.055, 0.06),
    "upper_trunk": (0.17, 0.07),
    "middle_trunk": (0.15, 0.07),
    "lower_trunk": (0.16, 0.07),
    "upper_arm": (0.022, 0.022),
    "forearm": (0.018, 0.018),
    "hand": (0.015, 0.015),
    "thigh": (0.035, 0.035),
    "shank": (0.027, 0.027),
    "foot": (0.025, 0.02),
}
SKIN = np.array([0.85, 0.66, 0.52, 1.0])


def _add_shapes(plant: MultibodyPlant, instance, table, height_m: float) -> None:
    """A box per trunk segment, a sphere for the head, a capsule along each limb."""
    for body_index in plant.GetBodyIndices(instance):
        body = plant.get_body(body_index)
        name = next((k for k in SHAPES if body.name().endswith(k)), None)
        if name is None:
            continue
        length = table[name].length * height_m
        width, depth = (f * height_m for f in SHAPES[name])
        if name == "foot":
            shape, X = Box(length, 2 * width, depth), [0.5 * length, 0.0, -0.6 * depth]
        elif name == "head":
            shape, X = Sphere(0.5 * length * 0.85), [0.0, 0.0, 0.5 * length]
        else:
            first, direction = ORIGIN[name]
            centre = [0.0, 0.0, 0.5 * direction * length]
            if name.endswith("trunk"):
                shape, X = Box(depth * 2, width, length), centre
            else:
                shape, X = Capsule(width, max(length - 2 * width, 1e-3)), centre
        plant.RegisterVisualGeometry(body, RigidTransform(X), shape, f"{body.name()}_shape", SKIN)
