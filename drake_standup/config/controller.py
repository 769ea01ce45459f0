"""ControllerConfig: gains, weights and contact limits of the whole-body controller.

Each value has its source or its reason in a line; what was measured on the way to it is
in docs/design.md, "The controller's settings".
"""

from dataclasses import dataclass, field

# The QP solvers the controller can use (control/backends.py: make_backend).
QP_SOLVERS = ("daqp", "osqp", "clarabel")
# The axes the angular momentum's integral acts on (control/tasks/momentum.py).
MOMENTUM_INTEGRAL_AXES = ("pitch", "all")
# The libraries that can compute the controller's model (control/model.py).
MODEL_LIBRARIES = ("drake", "pinocchio")


@dataclass
class ControllerConfig:
    """Gains, weights and contact limits of the whole-body controller; what changes with
    the stand-up state (CoM gains, postures, base pitch, lean) is the phase table's."""

    # K_D = 2 zeta sqrt(K_P), critically damped ([early-probe]).
    com_damping_ratio: float = 1.0
    # Angular momentum: Ldot_ang* = -K_D L_ang - K_P int L_ang; K_P,ang = 1 ([authors-code]). 1/s^2.
    angular_momentum_kp_per_s2: float = 1.0
    # ... about all three axes ("all": the authors'), or the heading's pitch axis only
    # ("pitch"): the base orientation task already holds the pelvis' roll and yaw, and a
    # second reference on them wound up in a strong pull's twist and then drove the trunk
    # onto its stops with nobody pulling; "pitch" mends that on ideal senses but not under
    # icub (docs/decisions/021-momentum-integral-axes.md).
    angular_momentum_integral_axes: str = "all"
    # Angular momentum damping K_D,ang ([early-probe]: 5). 1/s.
    angular_momentum_kd_per_s: float = 5.0
    # Joint posture: qddot* = -K_P (q - q_ref) - K_D qdot ([early-probe]: 30). 1/s^2.
    posture_kp_per_s2: float = 30.0
    # K_D = 2 zeta sqrt(K_P) for the posture, critically damped.
    posture_damping_ratio: float = 1.0
    # q_ref moves to a new phase's posture with this first-order lag: a step would ask
    # for large joint accelerations at each switch. On psi's clock, never slower than
    # time (standup/task_references.py). s.
    posture_filter_time_constant_s: float = 0.3
    # ... in this many first-order stages in series, each of that time constant: one
    # starts q_ref at its fastest rate (the gap over tau) at every switch; two start it at
    # rest (docs/design.md, "The limbs the trunk carries"). 1 or 2.
    posture_filter_stages: int = 2
    # Posture targets are clamped this far inside the joint limits: [authors-code]'s elbow target
    # 0.2473 rad lies below the URDF's 0.262 limit. rad.
    posture_limit_margin_rad: float = 0.05
    # Acceleration bounds stop every actuated joint at its limits within this horizon
    # (control/tasks/): without them the shoulders and the knees hit their stops. s.
    joint_limit_horizon_s: float = 0.1
    # ... and keep each able to stop before its limit braking at this much, the
    # braking-distance bound (control/tasks/joint_limits.py; None: none). Without it the
    # shoulders and the knees reached their stops at 3-5 rad/s and rang the feet
    # (docs/design.md, "Chatter at the seat's release"). rad/s^2.
    joint_braking_rad_per_s2: float | None = 20.0
    # ... softly: a slack s per joint at the cost w s^2 (rad/s^2); hard bounds made the
    # QP infeasible where the soles pin the legs or the pull holds the shoulders.
    joint_limit_weight: float = 1.0e3
    # The arms' joints are held below this speed, softly (the same slack and weight): a
    # pull stronger than the feet hold moves them at a person's pace, and they never whip
    # back (control/tasks/joint_limits.py: speed_bounds; None: no bound). 0.4 below the
    # 3 rad/s it is for: where the plant's arms do not follow the plan (the trunk jolted at
    # a contact change) it is met only over its time constant: the margin is the overshoot
    # measured under strong pulls (docs/decisions/019-arms-at-a-persons-pace.md). rad/s.
    arm_speed_limit_rad_per_s: float | None = 2.6
    # ... approached with this time constant (the barrier's; two of the 10 ms ticks of
    # robot.hardware icub). s.
    arm_speed_time_constant_s: float = 0.02
    # The shoulders' tendon-bound range, A q + b > 0 over pitch, roll and yaw (iCub 2.x:
    # icub-tech, "Range of Motion of the iCub Shoulders"; robot/limbs.py), held as the joint
    # limits are: soft rows with the same horizon, braking and weight.
    shoulder_tendons: bool = True
    # Base (root_link) orientation: upright at the yaw of the first tick, pitched forward
    # by the phase's base_pitch_rad. The probe ended stooped 25 deg ([early-probe]). 1/s^2.
    base_orientation_kp_per_s2: float = 30.0
    # K_D = 2 zeta sqrt(K_P) for the base orientation.
    base_orientation_damping_ratio: float = 1.0
    # A hinged seat (phases.py: seat_hold) lets the pelvis pitch about the hip axis, the
    # mid-point of these joints' frames on root_link; the base orientation task steers it.
    seat_hinge_joints: list[str] = field(default_factory=lambda: ["l_hip_pitch", "r_hip_pitch"])
    # Task weights (QP cost, per squared residual). The momentum task (N, N m) dominates:
    # the momentum rate is made by accelerating the body, which the posture task charges.
    momentum_weight: float = 100.0
    # Posture weight per joint, rad/s^2: lower, the QP swung the arms onto their limits.
    posture_weight: float = 0.1
    # ... replaced per joint: the torso holds its own against the twelve leg joints.
    posture_weight_by_joint: dict[str, float] = field(
        default_factory=lambda: {"torso_pitch": 1.0, "torso_roll": 1.0, "torso_yaw": 1.0}
    )
    # True: the joints of the limbs the trunk carries (arms, neck) not named there weigh
    # the torso pitch's weight times (the mass the torso carries over the mass the joint
    # carries) to carried_limb_weight_exponent (the ratio is 6 at a shoulder, 13 at an
    # elbow, 17-64 at a wrist, 9-10 at the neck on iCubGazeboV2_5): light limbs ride with
    # the trunk instead of whipping in the lean (docs/design.md, issue 46).
    carried_limb_weight_by_mass: bool = True
    # Measured with the two-stage posture filter: 1 left the arms at 3.1 rad/s, 1.5 at 2.5.
    carried_limb_weight_exponent: float = 1.5
    # Base orientation weight: the pelvis ends upright to 0.3 deg (1.4 deg at 1).
    base_orientation_weight: float = 10.0
    # Each 6-D contact's CoP to the centre of its box (N m): it shares the load, which the
    # momentum task leaves free, away from the box edges where a compliant pad rolls.
    cop_centering_weight: float = 1.0e-2
    # The soles' moments near the last tick's: w ||(tau - tau_last) / l||^2 at w = this /
    # the control period (control/tasks/moment_rate.py; 0: none). A compliant sole cannot
    # follow a CoP moved across its box within a few ticks: its heel slapped down. s.
    sole_moment_rate_weight_s: float = 0.0
    # Regularisation: joint torques (N m), contact wrenches (N, N m), accelerations; they
    # make the Hessian positive definite.
    torque_weight: float = 1.0e-4
    wrench_weight: float = 1.0e-5
    acceleration_weight: float = 1.0e-6
    # Linearised friction pyramid |f_t| <= mu f_z of the QP ([authors-code]; the pads have 1.0).
    friction_coefficient: float = 1.0 / 3.0
    # Torsional friction |tau_z| <= mu_t f_z ([authors-code]). m.
    torsional_friction_coefficient_m: float = 1.0 / 75.0
    # A held contact's rows ask J vdot + Jdot v = -k J v: a foot that has begun to slip
    # (a pull the pads' friction barely holds) is braked back to rest instead of being
    # left to drift (docs/design.md, "Leaving the seat"). 1/s.
    contact_velocity_gain_per_s: float = 20.0
    # Minimum normal force of a seated pad and of each sole ([authors-code]). N.
    min_normal_force_N: float = 10.0
    # A seated pad's normal-force bound: above the robot's weight (324 N), never binding. N.
    seat_max_normal_force_N: float = 400.0
    # Every seat pad, seated or releasing, is also bounded by its measured normal force plus
    # this (standup/contact_schedule.py): the QP planned on more than the compliant pads
    # carried, and on a low seat leaned on thighs that carried nothing. N.
    seat_measured_margin_N: float = 20.0
    # While a thigh's load is released, the QP plans on the force its compliant pad gives
    # for the thigh's planned motion (control/pad_dynamics.py), not on any force up to the
    # bound above (it sat on that bound). Off: measured, the slaps stay (the pads ring).
    seat_pad_dynamics: bool = False
    # Sole normal-force bound: three times the robot's weight, never binding. N.
    foot_max_normal_force_N: float = 1000.0
    # CoP box of each sole in its l_sole/r_sole frame ([authors-code]; inside the 0.19 x 0.09 m
    # pads at x in [-0.064, 0.126], models/icub_contact.yaml). m.
    foot_cop_x_m: list[float] = field(default_factory=lambda: [-0.05, 0.10])
    foot_cop_y_m: list[float] = field(default_factory=lambda: [-0.025, 0.025])
    # CoP box of the seat contact in its frame: the buttocks pad (x in [-0.12, -0.05], y
    # in [-0.06, 0.06], behind the hip axis at x = -0.0365), 1 cm inside; the thighs are
    # contacts of their own. m.
    seat_cop_x_m: list[float] = field(default_factory=lambda: [-0.11, -0.06])
    seat_cop_y_m: list[float] = field(default_factory=lambda: [-0.05, 0.05])
    # CoP box of each thigh contact in its frame: the 0.14 x 0.09 m pad, 2 cm inside
    # (models/icub_contact.yaml); a flat thigh on the chair resists pitching and rolling,
    # which a point force does not model. m.
    thigh_cop_x_m: list[float] = field(default_factory=lambda: [-0.05, 0.05])
    thigh_cop_y_m: list[float] = field(default_factory=lambda: [-0.025, 0.025])
    # Joint torque saturation, N m. None: the actuators' effort limit in the plant
    # (robot.effort_limit_Nm, [authors-code]); a number: a tighter limit of the controller's own.
    torque_limit_Nm: float | None = None
    # ||xd_dot|| below which the helpful part of the pull fades out (smoothstep): the
    # standing robot compensates the whole pull ([early-probe]). m/s.
    help_fade_speed_mps: float = 0.02
    # CoM lead over its reference along the path at which the help is fully compensated:
    # a pull cannot carry the CoM past its reference (and past the standing height). m.
    help_max_lead_m: float = 0.02
    # In a phase with stance (phases.py), over the end of its segment (path progress from
    # stance_from_progress to 1, smoothstep) the momentum task's vertical row fades to
    # stance_vertical_weight_scale of its weight and the legs' posture sets the height:
    # near straight legs 1 cm of CoM height is 0.3 rad of knee.
    stance_from_progress: float = 0.7
    stance_vertical_weight_scale: float = 0.1
    # In the stance (the stance factor, 0 -> 1 over the rise's end) the angular momentum's
    # target asks the contacts for the moment that the trunk's roll and yaw posture needs
    # (their posture acceleration through the centroidal momentum matrix): the momentum
    # task, at 100 times the posture's weight, left the trunk's posture about 50 times
    # weaker than its gain, and a standing trunk drifted (icub) or stayed twisted onto its
    # stops after a strong pull. Through the rise the trunk stays free: held throughout,
    # iCubDarmstadt01's thighs slapped at their release (docs/decisions/022-standing-trunk.md).
    standing_trunk_attitude: bool = True
    # In a sit-down's lowering and landing the angular momentum's target asks the contacts
    # for the moment the pelvis' pitch and the trunk's joints (the torso's, the hips' pitch)
    # need to lean forward (their accelerations through the centroidal momentum matrix).
    lowering_attitude: bool = True
    # In a phase whose posture leads (phases.settle), the momentum task's CoM rows weigh
    # this fraction of the task's weight: at 0.1 the CoM path still won and the torso
    # folded onto its stop; at 1e-4 the pitch the contacts were asked for was met to
    # 0.01 N m (docs/results.md, "The settle led by its posture").
    posture_led_com_weight_scale: float = 1.0e-4
    # ... reached over this share of the phase's path (the scale's exponent a smoothstep
    # of it): released at once, the plan stepped (21 N on the soles on a 0.25 m seat).
    posture_led_fade_progress: float = 0.3
    # Integral gain on the CoM height error in the stance (standup/task_references.py). 1/s^3.
    stance_height_ki_per_s3: float = 100.0
    # The lean's first-order lag: the pull's moment, not its jitter, and about the CoM
    # loop's own time, so that a robot leaning into a pull is upright soon after the
    # helper lets go (docs/design.md, "The controller's settings"); on psi's clock, as the
    # posture filter's: a rise at psi_dot 2.5 outran it (issue 30). s.
    lean_filter_time_constant_s: float = 0.2
    # Bounds of the lean: the CoM target stays over the soles' CoP box with ~1.7 cm to
    # spare, so that the robot still stands when the pull stops; a pull that needs more
    # is beyond what the feet allow. m.
    lean_max_forward_m: float = 0.05
    lean_max_back_m: float = 0.065
    lean_max_m: float = 0.11  # sideways
    # Extra posture weights per joint in the stance phases (a second posture task): the
    # legs' posture places the knees, which the CoM target cannot.
    stance_posture_weight_by_joint: dict[str, float] = field(
        default_factory=lambda: {
            f"{side}_{joint}": weight
            for side in "lr"
            for joint, weight in (
                ("hip_pitch", 10.0),
                ("knee", 10.0),
                ("ankle_pitch", 10.0),
                ("shoulder_pitch", 3.0),
                ("shoulder_roll", 3.0),
                ("shoulder_yaw", 3.0),
                ("elbow", 3.0),
            )
        }
    )
    # Posture weights that grow with the stance factor (0 -> 1 over the end of the rise):
    # the arms, which carry the pull, held once standing, free to balance the rise.
    stance_arm_weight_by_joint: dict[str, float] = field(
        default_factory=lambda: {
            f"{side}_{joint}": 7.0
            for side in "lr"
            for joint in ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")
        }
    )
    # The robot weighs itself while seated (control/mass.py): the pads' and the hands'
    # vertical forces filtered with this time constant, the model scaled to them. 0: the
    # nominal model throughout. s.
    mass_estimation_filter_s: float = 0.3
    # Bounds of the estimated mass scale (estimate / model).
    mass_scale_bounds: list[float] = field(default_factory=lambda: [0.7, 1.3])
    # QP solver: daqp (the fastest here, exact equalities), or Drake's osqp / clarabel.
    qp_solver: str = "daqp"
    # What computes the controller's model: Drake's plant itself, or pinocchio (one pass
    # of the same tree; `pip install .[pinocchio]`). Drake:
    # Pinocchio's pass measured no faster in the loop (docs/decisions/015-...).
    model_library: str = "drake"
