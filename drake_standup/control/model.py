"""The controller's model of the robot: its contacts, its joints, and ControllerModel.

ControllerModel's terms, RobotTerms (control/terms.py: M, h, the CoM and the centroidal
momentum, the contact frames' and the hands' Jacobians), is what the task references and
the whole-body QP both read, so the dynamics are computed once a tick and both see the
same numbers. Only the frames a tick needs are computed: the active contacts' (the
contact commands say which), and the hands' while they are pulled. Every body's mass
follows the robot's weighing while seated (control/mass.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from drake_standup.config import ControllerConfig
from drake_standup.control.contacts import CONTACTS, ContactCommands, ContactSpec
from drake_standup.control.mass import next_mass_state
from drake_standup.control.pad_dynamics import PadCompliance
from drake_standup.control.terms import RobotKinematics, RobotTerms
from drake_standup.ports.payloads import HAND_WRENCHES
from drake_standup.robot.icub import Robot, actuated_joints, arm_joint_names

HANDS = ("l_hand", "r_hand")
_F_Z_LEFT = HAND_WRENCHES["f_l"].start + 2
_F_Z_RIGHT = HAND_WRENCHES["f_r"].start + 2


def contact_specs(
    plant: MultibodyPlant, robot: Robot, config: ControllerConfig, chair=None
) -> list[ContactSpec]:
    """The controller's contacts (CONTACTS): the seat, held at the hip axis (the mid-point
    of controller.seat_hinge_joints' frames), both thighs (6-D, a CoP box on
    each pad), both soles; friction and CoP boxes from the config; with
    controller.seat_pad_dynamics, the thighs' pads' compliance on chair's seat
    (ChairConfig; None: a rigid seat)."""
    seat = robot.frame(plant, "seat")
    context = plant.CreateDefaultContext()
    p_SeatHinge = np.mean(
        [
            plant.GetJointByName(name, robot.model_instance)
            .frame_on_parent()
            .CalcPose(context, seat)
            .translation()
            for name in config.seat_hinge_joints
        ],
        axis=0,
    )
    friction = {
        "friction_coefficient": config.friction_coefficient,
        "torsional_friction_coefficient": config.torsional_friction_coefficient_m,
    }
    seat_box = {"cop_x_m": tuple(config.seat_cop_x_m), "cop_y_m": tuple(config.seat_cop_y_m)}
    thigh_box = {"cop_x_m": tuple(config.thigh_cop_x_m), "cop_y_m": tuple(config.thigh_cop_y_m)}
    foot_box = {"cop_x_m": tuple(config.foot_cop_x_m), "cop_y_m": tuple(config.foot_cop_y_m)}
    pads = thigh_compliances(robot, chair) if config.seat_pad_dynamics else {}
    return [
        ContactSpec("seat", **friction, **seat_box, hold_point_m=tuple(p_SeatHinge.tolist())),
        # Held once the buttocks are off the seat, while the thighs carry load (flat while
        # seated, by their normal while they unload: standup/contact_schedule.py).
        ContactSpec("l_thigh", **friction, **thigh_box, compliance=pads.get("l_thigh")),
        ContactSpec("r_thigh", **friction, **thigh_box, compliance=pads.get("r_thigh")),
        ContactSpec("l_sole", **friction, **foot_box, rectangle_yaw=True),
        ContactSpec("r_sole", **friction, **foot_box, rectangle_yaw=True),
    ]


def thigh_compliances(robot: Robot, chair=None) -> dict[str, PadCompliance]:
    """Each thigh contact's pad compliance (control/pad_dynamics.py) from its box and
    modulus in the robot's contact model and the seat's cushion (chair.cushion; a chair of
    one's own file is taken as rigid)."""
    modulus = robot.contact_modulus_Pa
    cushion = None if chair is None or chair.file else chair.cushion
    seat = (
        {}
        if cushion is None
        else {"seat_modulus_Pa": cushion.modulus_Pa, "seat_thickness_m": cushion.thickness_m}
    )
    frames = {robot.TASK_FRAMES[name]: name for name in ("l_thigh", "r_thigh")}
    return {
        frames[shape.frame]: PadCompliance.of_box(tuple(shape.size_m), modulus, **seat)
        for shape in robot.contact_shapes
        if shape.frame in frames and shape.shape == "box"
    }


@dataclass(frozen=True)
class ControllerJoints:
    """The actuated joints, in actuator order, as the controller indexes them: the chair
    and floor are welded, so the robot's q and v are the plant's."""

    names: list[str]
    q_indices: np.ndarray  # index of each joint's angle in q
    v_indices: np.ndarray  # index of each joint's rate in v
    q_min: np.ndarray  # position limits, rad
    q_max: np.ndarray
    instance: object = None  # the robot's ModelInstanceIndex
    # The arms' joints (robot/icub.py: arm_joint_names), a mask in actuator order (None: none).
    arms: np.ndarray | None = None

    @classmethod
    def of(cls, plant: MultibodyPlant, robot: Robot) -> ControllerJoints:
        actuated = actuated_joints(plant, robot.model_instance)
        joints = [plant.GetJointByName(name, robot.model_instance) for name in actuated.names]
        return cls(
            names=actuated.names,
            q_indices=actuated.q_index,
            v_indices=actuated.v_index,
            q_min=np.array([joint.position_lower_limits()[0] for joint in joints]),
            q_max=np.array([joint.position_upper_limits()[0] for joint in joints]),
            instance=robot.model_instance,
            arms=np.isin(actuated.names, arm_joint_names(plant, robot)),
        )


def active_frames(specs: list[ContactSpec], active: tuple[bool, ...]) -> list[str]:
    """The frames of the active contacts, in CONTACTS' order (the QP's)."""
    return [spec.frame for spec, on in zip(specs, active, strict=True) if on]


class ControllerModel:
    """The controller's model at the robot's state, once a tick, and its weighing: a
    plain object the stand-up controller's tick calls (standup/whole_body.py).

    The weighing is [estimate, began, model's scale] (control/mass.py: next_mass_state);
    its state lives in the calling system, from INITIAL_WEIGHING.
    """

    INITIAL_WEIGHING = (1.0, 0.0, 1.0)

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: Robot,
        specs: list[ContactSpec],
        config: ControllerConfig,
        period_s: float,
        *,
        last_com=None,
        unknown_damping: dict[str, float] | None = None,
    ):
        """last_com: where the model puts each state's CoM for the sensing
        (world/scene.py robot_last_com); unknown_damping: the plant's joint damping the
        model leaves out (RobotKinematics)."""
        if [spec.frame for spec in specs] != list(CONTACTS):
            raise ValueError(f"contact specs must be {CONTACTS}")
        self.specs = specs
        library = RobotKinematics
        if config.model_library == "pinocchio":  # an optional package: imported if asked
            from drake_standup.control.pinocchio_terms import PinocchioKinematics

            library = PinocchioKinematics
        self.kinematics = library(
            plant,
            robot,
            held_frames=[spec.frame for spec in specs if spec.constrained],
            other_frames=[spec.frame for spec in specs if not spec.constrained] + list(HANDS),
            hold_points_m={spec.frame: spec.hold_point_m for spec in specs},
            last_com=last_com,
            unknown_damping=unknown_damping,
        )
        g = -plant.gravity_field().gravity_vector()[2]
        filter_s = config.mass_estimation_filter_s
        self._mass = (
            self.kinematics.nominal_mass_kg * g,
            min(period_s / filter_s, 1.0) if filter_s > 0.0 else 0.0,
            tuple(config.mass_scale_bounds),
        )
        self._frames: dict[tuple[bool, ...], list[str]] = {}

    def next_weighing(
        self,
        weighing: np.ndarray,
        standup_state: int,
        hand_wrenches_W: np.ndarray,
        pads_vertical_force_N: float,
    ) -> np.ndarray:
        """The weighing after this tick: the pads' and the hands' vertical forces carry
        the weight while seated; frozen once the stand-up has begun."""
        if weighing[1]:
            return weighing.copy()
        weight_N = pads_vertical_force_N + hand_wrenches_W[_F_Z_LEFT] + hand_wrenches_W[_F_Z_RIGHT]
        return next_mass_state(weighing, standup_state, weight_N, *self._mass)

    def terms(
        self,
        robot_state: np.ndarray,
        commands: ContactCommands,
        hand_wrenches_W: np.ndarray,
        mass_scale: float,
    ) -> RobotTerms:
        """RobotTerms at robot_state ([q; v]) for the commands' active contacts, and the
        hands while they are pulled, with every mass scaled by mass_scale."""
        self.kinematics.set_mass_scale(mass_scale)
        frames = self._frames.get(commands.active)
        if frames is None:
            frames = self._frames[commands.active] = active_frames(self.specs, commands.active)
        pulled = np.count_nonzero(hand_wrenches_W) > 0
        return self.kinematics.calc(robot_state, frames, HANDS if pulled else ())
