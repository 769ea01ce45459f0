"""The helper as a body in the plant (human.mode: body): a person (anthropometry.py)
kneeling in front of the robot, their joints driven by Drake's PD actuators within their strength,
their hands holding the robot's through a compliant grip.

- Kneeling: the seated iCub's hands lie ~0.3 m above the floor, out of a standing
  adult's reach (arms ~0.64 m, shoulders ~1.4 m up); a helper kneels to a child's size.
- Placement (place): in front of the seated robot's hands, facing them, bent forward
  at the lumbar joint just enough that the hands lie within 0.65 of an arm's length
  (elbows bent: room to follow the hands both ways; bend_for).
- Strength (STRENGTH_NM_PER_KG): each joint's effort limit, maximal voluntary isometric
  torque of young men per kg of body mass (torque scales with mass^1, Jaric 2002, Sports
  Med 32:615); Drake clamps each actuator's total torque (PD and feed-forward) to it, so
  no torque the person could not produce acts. One limit for both directions: the weaker.
- Impedance (JOINT_IMPEDANCE): joint stiffness and damping, scaled with mass (stiffness
  grows with the torque a joint holds, Gomi & Osu 1998).
- Grip (helper.body_control.Grips): a spring-damper between each of the person's grip frames
  and the robot's hand frame, force only (config/body.py); the person's right hand holds
  the robot's left hand (they face each other). Drake's LinearBushingRollPitchYaw is
  the same element but throws near a 90 deg pitch between its frames (its roll-pitch-yaw),
  and a held hand twists freely against the other; so the grip is evaluated in Python.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, PdControllerGains

from drake_standup.config.body import BodyHelperConfig
from drake_standup.helper.anthropometry import (
    DE_LEVA_MALE,
    SHOULDER_ABOVE_XYPH,
    Person,
    add_person,
    omph_height,
)

# Maximal isometric torque per kg, young men (reference mass 75 kg where a study gave
# N m): shoulder flexion 68.6 N m at 45 deg (its weaker angle; 89.9 at 0 deg; "Dynamic
# shoulder flexion strength ...", 26 men); shoulder abduction and rotation 48 N m, the
# strongest shoulder movement's isokinetic peak (Clin Biomech 1989, 4(1), 20 men: a
# floor for the isometric); elbow extension (the weaker) 0.67 N m/kg (Lategan & Kruger
# 2003, 199 men, isokinetic); wrist extension (the weaker) 7.1 N m (Delp, Grierson &
# Buchanan 1996, J Biomech 29:1371); trunk extension 504 N standing (Kocjan & Sarabon
# 2014, J Sports Sci Med 13:365, 72.7 kg) at a 0.4 m lever (the pad about T9 over the
# lumbar joint: an assumption, the pad's height was not retrieved);
# lateral bending and axial rotation half of it (no measurement found: an assumption).
STRENGTH_NM_PER_KG = {
    "shoulder_flexion": 68.6 / 75.0,
    "shoulder_abduction": 48.0 / 75.0,
    "shoulder_rotation": 48.0 / 75.0,
    "elbow": 0.67,
    "wrist": 7.1 / 75.0,
    "lumbar_flexion": 504.0 * 0.4 / 72.7,
    "lumbar_bending": 0.5 * 504.0 * 0.4 / 72.7,
    "lumbar_rotation": 0.5 * 504.0 * 0.4 / 72.7,
}
# Joint stiffness N m/rad and damping N m s/rad of a 75 kg person, soft and stiff.
# Shoulder and elbow, relaxed: the diagonal of Shadmehr & Mussa-Ivaldi 1994 (J Neurosci
# 14:3208), K 15 and 16, B 2.3 and 2.4; co-contracted 3 times stiffer, the damping
# ratio kept (Perreault et al. 2004), so B x sqrt(3). Wrist: no measurement found, a
# third of the elbow's (an assumption). Trunk: 14.5 and 19.8 N/mm at the chest at 20 and
# 40 % effort (Gardner-Morse & Stokes 2001, J Biomech 34:457) at a 0.3 m lever: 1300
# and 1780 N m/rad; damping at a damping ratio of 0.5 on their 14.1 kg effective trunk.
_ARM = {"shoulder": (15.0, 2.3), "elbow": (16.0, 2.4), "wrist": (16.0 / 3.0, 0.8)}
_TRUNK_MOMENT_KG_M2 = 14.1 * 0.3**2
JOINT_IMPEDANCE = {
    tone: {
        **{joint: (k * scale, b * math.sqrt(scale)) for joint, (k, b) in _ARM.items()},
        "lumbar": (k_trunk, 2 * 0.5 * math.sqrt(k_trunk * _TRUNK_MOMENT_KG_M2)),
    }
    for tone, scale, k_trunk in (("relaxed", 1.0, 14500.0 * 0.09), ("firm", 3.0, 19800.0 * 0.09))
}
REFERENCE_MASS_KG = 75.0
# How soon the arms' rest posture gives way to where the robot moves them (helper_control:
# the set-point's time constant). Soft: a relaxed person yields at the pace of the
# long-latency stretch reflex (~50-100 ms); stiff: they hold until they react, a simple
# reaction time (0.15-0.25 s, [reaction-time]). A modelling assumption, no measurement. s.
YIELD_TIME_S = {"relaxed": 0.1, "firm": 0.2}
# The robot's hand each of the person's grips holds (facing each other).
GRIPS = {"l_hand": "right_grip", "r_hand": "left_grip"}
# At t = 0 the robot's hands lie within this fraction of the person's arm (elbows bent).
REACH_FRACTION = 0.65


@dataclass
class HelperBody:
    """The person in the plant and what their controller and logs need."""

    person: Person
    X_WP: RigidTransform  # where they kneel (their frame P), facing the robot
    effort_limits_Nm: np.ndarray  # per joint, in joint_names' order
    kp: np.ndarray
    kd: np.ndarray
    q0: dict[str, float]  # their joints at t = 0 (rad), holding the robot's hands as it sits
    config: BodyHelperConfig


def joint_kind(name: str) -> str:
    """A person's joint name (helper/anthropometry.py) without its side: the tables' keys."""
    return name.removeprefix("left_").removeprefix("right_")


def strength_and_impedance(
    names: list[str], cfg: BodyHelperConfig
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(effort limits N m, stiffness N m/rad, damping N m s/rad) of each joint in names,
    for cfg's mass and tone."""
    scale = cfg.mass_kg / REFERENCE_MASS_KG
    impedance = JOINT_IMPEDANCE[cfg.tone]
    limits, kp, kd = [], [], []
    for name in names:
        kind = joint_kind(name)
        limits.append(STRENGTH_NM_PER_KG[kind] * cfg.mass_kg)
        k, b = impedance[kind.split("_")[0]]
        kp.append(k * scale)
        kd.append(b * scale)
    return np.array(limits), np.array(kp), np.array(kd)


def arm_length_m(height_m: float) -> float:
    t = DE_LEVA_MALE
    return (t["upper_arm"].length + t["forearm"].length + t["hand"].length) * height_m


# The trunk's bend stays within these: upright-ish, and at most 80 deg forward. rad.
BEND_RANGE_RAD = (0.2, 1.4)


def bend_for(height_m: float, hands_z_m: float) -> float:
    """The least lumbar flexion (within BEND_RANGE_RAD) that brings a kneeling person's
    shoulders within 0.9 of a reach (REACH_FRACTION of an arm) above hands at hands_z_m:
    how far they bend to hold hands that low, and straighten as the hands rise."""
    t = DE_LEVA_MALE
    radius = (t["middle_trunk"].length + SHOULDER_ABOVE_XYPH) * height_m
    above = hands_z_m + 0.9 * REACH_FRACTION * arm_length_m(height_m)
    cosine = (above - omph_height(height_m, kneeling=True)) / radius
    return min(max(math.acos(min(max(cosine, -1.0), 1.0)), BEND_RANGE_RAD[0]), BEND_RANGE_RAD[1])


def place(height_m: float, hands_W: np.ndarray) -> tuple[RigidTransform, float]:
    """Where the person kneels facing -x (the robot) and their lumbar flexion at t = 0
    (bend_for the hands' midpoint), in front of the hands by the rest of a reach
    (REACH_FRACTION of an arm). hands_W: (2, 3) the robot's hands at t = 0."""
    mid = hands_W.mean(axis=0)
    reach = REACH_FRACTION * arm_length_m(height_m)
    t = DE_LEVA_MALE
    radius = (t["middle_trunk"].length + SHOULDER_ABOVE_XYPH) * height_m
    bend = bend_for(height_m, mid[2])
    drop = omph_height(height_m, kneeling=True) + radius * math.cos(bend) - mid[2]
    ahead = math.sqrt(max(reach**2 - drop**2, 0.0))
    x = mid[0] + ahead + radius * math.sin(bend)
    return RigidTransform(RotationMatrix.MakeZRotation(math.pi), [x, mid[1], 0.0]), bend


def add_helper_body(
    plant: MultibodyPlant, cfg: BodyHelperConfig, hands_W: np.ndarray
) -> HelperBody:
    """Adds the person kneeling before the robot's hands (hands_W, (2, 3): the robot's
    l_hand and r_hand at t = 0) and their actuators (effort limits, PD gains) to plant
    (not yet finalized); their posture at t = 0 holds those hands (reach)."""
    X_WP, bend = place(cfg.height_m, hands_W)
    model = person_model(cfg, X_WP)
    q0 = dict(zip(joint_names(model), reach(model, bend, hands_W)))
    person = add_person(plant, cfg.height_m, cfg.mass_kg, X_WP, kneeling=True)
    limits, kp, kd = strength_and_impedance(person.joint_names, cfg)
    for name, limit, k, b in zip(person.joint_names, limits, kp, kd):
        joint = plant.GetJointByName(name, person.model_instance)
        actuator = plant.AddJointActuator(f"{name}_muscles", joint, limit)
        actuator.set_controller_gains(PdControllerGains(p=k, d=b))
    return HelperBody(person, X_WP, limits, kp, kd, q0, cfg)


def person_model(cfg: BodyHelperConfig, X_WP: RigidTransform) -> MultibodyPlant:
    """The person alone, where they kneel: their controller's model (gravity, the grips'
    Jacobians) and the inverse-dynamics check's; finalized, continuous."""
    plant = MultibodyPlant(0.0)
    add_person(plant, cfg.height_m, cfg.mass_kg, X_WP, kneeling=True)
    plant.Finalize()
    return plant


def joint_names(model: MultibodyPlant) -> list[str]:
    """The person model's (person_model's) joints in the order of its positions."""
    return instance_joint_names(model, model.GetModelInstanceByName("person"))


def grip_frames(model: MultibodyPlant):
    """The person's grip frames in GRIPS' order."""
    return [model.GetFrameByName(grip) for grip in GRIPS.values()]


def grips_jacobian(
    model: MultibodyPlant, context, wrt: JacobianWrtVariable = JacobianWrtVariable.kV
) -> np.ndarray:
    """(6, n) the translational Jacobians of the person's grips' origins (GRIPS' order),
    world, in context."""
    world = model.world_frame()
    return np.vstack(
        [
            model.CalcJacobianTranslationalVelocity(context, wrt, f, np.zeros(3), world, world)
            for f in grip_frames(model)
        ]
    )


def reach(model: MultibodyPlant, bend_rad: float, targets_W: np.ndarray) -> np.ndarray:
    """The person's joints that put their grips (GRIPS' order) on targets_W (2, 3):
    damped Gauss-Newton from arms reaching forward with the elbows bent and the trunk
    bent by bend_rad, the least-squares posture change (elbows kept flexed)."""
    context = model.CreateDefaultContext()
    names = joint_names(model)
    nominal = np.zeros(model.num_positions())
    for i, name in enumerate(names):
        kind = joint_kind(name)
        nominal[i] = {"lumbar_flexion": bend_rad, "shoulder_flexion": -0.8, "elbow": -1.4}.get(
            kind, 0.0
        )
    elbows = [i for i, name in enumerate(names) if joint_kind(name) == "elbow"]
    frames = grip_frames(model)
    q = nominal.copy()
    for iteration in range(200):
        model.SetPositions(context, q)
        error = np.concatenate(
            [f.CalcPoseInWorld(context).translation() - p for f, p in zip(frames, targets_W)]
        )
        J = grips_jacobian(model, context, JacobianWrtVariable.kQDot)
        mu = 1e-3 if iteration < 150 else 1e-9
        step = np.linalg.solve(J.T @ J + mu * np.eye(len(q)), -J.T @ error - mu * (q - nominal))
        q = q + step
        q[elbows] = np.minimum(q[elbows], -0.05)
    return q


def instance_joint_names(plant: MultibodyPlant, instance) -> list[str]:
    """The instance's one-dof joints in the order of its positions in the plant."""
    joints = [plant.get_joint(i) for i in plant.GetJointIndices(instance)]
    joints = [j for j in joints if j.num_positions() == 1]
    return [j.name() for j in sorted(joints, key=lambda j: j.position_start())]


def state_order(plant: MultibodyPlant, helper: HelperBody) -> np.ndarray:
    """Indices into the person's positions in plant (their state's first half) in the
    order of their joint_names (the actuators')."""
    names = instance_joint_names(plant, helper.person.model_instance)
    return np.array([names.index(name) for name in helper.person.joint_names])
