"""ControllerConfig: gains, weights and contact limits of the whole-body controller."""

from dataclasses import dataclass, field

# The QP solvers the controller can use (control/qp.py: make_backend).
QP_SOLVERS = ("daqp", "osqp", "clarabel")


@dataclass
class ControllerConfig:
    """Gains, weights and contact limits of the whole-body controller."""

    # K_D = 2 zeta sqrt(K_P), critically damped (SPEC 7).
    com_damping_ratio: float = 1.0
    # Angular momentum: Ldot_ang* = -K_D L_ang - K_P int L_ang; K_P,ang = 1 (SPEC 3). 1/s^2.
    angular_momentum_kp_per_s2: float = 1.0
    # Angular momentum damping K_D,ang (SPEC 7 probe: 5). 1/s.
    angular_momentum_kd_per_s: float = 5.0
    # Joint posture: qddot* = -K_P (q - q_ref) - K_D qdot (SPEC 7 probe: 30). 1/s^2.
    posture_kp_per_s2: float = 30.0
    # K_D = 2 zeta sqrt(K_P) for the posture, critically damped.
    posture_damping_ratio: float = 1.0
    # Time constant of the first-order filter that moves q_ref to a new state's table:
    # a step would ask for large joint accelerations at each switch. s.
    posture_filter_time_constant_s: float = 0.3
    # Posture targets are clamped this far inside the joint limits: SPEC 3's elbow target
    # 0.2473 rad lies below the URDF's 0.262 limit. rad.
    posture_limit_margin_rad: float = 0.05
    # Every actuated joint gets acceleration bounds that stop it at its limits within
    # this horizon (control/tasks.py). Without them the arms, swung to move the CoM in
    # state 2, hit the shoulder-pitch limit and the jolt threw the pelvis off the seat;
    # the knees, straightened by a pulled rise, hit their stop at 8 rad/s and the robot
    # hopped (measured). s.
    joint_limit_horizon_s: float = 0.1
    # The bounds are soft: a slack s per joint may exceed them at the cost w s^2
    # (rad/s^2). Hard bounds made the QP infeasible where the held soles pin the legs'
    # accelerations (random states; the knees of a rising robot) or the pull holds the
    # shoulders at their limit (measured); the slack's use is reported.
    joint_limit_weight: float = 1.0e3
    # Base (root_link) orientation: upright at the yaw of the first tick, pitched forward
    # by the phase's base_pitch_rad. The probe ended stooped 25 deg (SPEC 7). 1/s^2.
    base_orientation_kp_per_s2: float = 30.0
    # K_D = 2 zeta sqrt(K_P) for the base orientation.
    base_orientation_damping_ratio: float = 1.0
    # A hinged seat (phases.py: seat_hold) lets the pelvis pitch about the hip axis, the
    # mid-point of these joints' frames on root_link; the base orientation task steers it.
    seat_hinge_joints: list[str] = field(default_factory=lambda: ["l_hip_pitch", "r_hip_pitch"])
    # Task weights (QP cost, per squared residual): momentum (N, N m) dominates; posture
    # and base orientation (rad/s^2) act in what is left. The momentum rate is made by
    # accelerating the body, which the posture task charges for: at a weight of 1 the
    # momentum task gave up 1.7 N of a 51 N demand, at 100 0.05 N (measured).
    momentum_weight: float = 100.0
    # Posture weight per joint (measured: at 0.01 the QP swung the arms onto their limits
    # to make momentum, 57 N m peaks in the pulled stand-up; at 0.1, 25 N m).
    posture_weight: float = 0.1
    # Per-joint posture weights that replace posture_weight: the torso holds its own
    # against the twelve leg joints, whose targets the CoM task overrides anyway (with
    # equal weights the robot stood with the trunk 0.5 rad forward, measured).
    posture_weight_by_joint: dict[str, float] = field(
        default_factory=lambda: {"torso_pitch": 1.0, "torso_roll": 1.0, "torso_yaw": 1.0}
    )
    # Base orientation weight: at 1 the stand-up ended with the pelvis 1.4 deg back, at 10
    # 0.3 deg (measured).
    base_orientation_weight: float = 10.0
    # Each 6-D contact's CoP to the centre of its box (N m): it decides how the load is
    # shared, which the momentum task leaves free, away from the box edges (measured).
    cop_centering_weight: float = 1.0e-2
    # Regularisation: joint torques (N m), contact wrenches (N, N m), accelerations; they
    # make the Hessian positive definite (measured).
    torque_weight: float = 1.0e-4
    wrench_weight: float = 1.0e-5
    acceleration_weight: float = 1.0e-6
    # Linearised friction pyramid |f_t| <= mu f_z of the QP (SPEC 3; the pads have 1.0).
    friction_coefficient: float = 1.0 / 3.0
    # Torsional friction |tau_z| <= mu_t f_z (SPEC 3). m.
    torsional_friction_coefficient_m: float = 1.0 / 75.0
    # Minimum normal force of an active contact, scaled by the plan (SPEC 3). N.
    min_normal_force_N: float = 10.0
    # Seat (and each thigh) normal-force bound at seat_scale = 1: above the robot's weight
    # (324 N), so it binds only while the plan ramps it down (SPEC 7 release). N.
    seat_max_normal_force_N: float = 400.0
    # While the seat pads unload, each is bounded by its measured normal force plus
    # this (controller._contact_commands). N.
    seat_measured_margin_N: float = 20.0
    # Sole normal-force bound: three times the robot's weight, never binding. N.
    foot_max_normal_force_N: float = 1000.0
    # CoP box of each sole in its l_sole/r_sole frame (SPEC 3; inside the 0.19 x 0.09 m
    # pads at x in [-0.064, 0.126], models/icub_contact.yaml). m.
    foot_cop_x_m: list[float] = field(default_factory=lambda: [-0.05, 0.10])
    foot_cop_y_m: list[float] = field(default_factory=lambda: [-0.025, 0.025])
    # CoP box of the seat contact in its frame: the seat acts on root_link, whose only pad
    # is the buttocks pad (x in [-0.12, -0.05], y in [-0.06, 0.06] of the seat frame,
    # models/icub_contact.yaml: behind the hip axis at x = -0.0365), 1 cm inside; the
    # thighs are contacts of their own. A box over the thigh pads (SPEC 7's +-0.11) let
    # the QP ask for a CoP the buttocks cannot give and the pelvis rolled forward onto the
    # thighs (measured). m.
    seat_cop_x_m: list[float] = field(default_factory=lambda: [-0.11, -0.06])
    seat_cop_y_m: list[float] = field(default_factory=lambda: [-0.05, 0.05])
    # Joint torque saturation, N m. None: the actuators' effort limit in the plant
    # (robot.effort_limit_Nm, SPEC 3); a number: a tighter limit of the controller's own.
    torque_limit_Nm: float | None = None
    # ||xd_dot|| below which the helpful part of the pull fades out (smoothstep): the
    # standing robot compensates the whole pull (SPEC 7). m/s.
    help_fade_speed_mps: float = 0.02
    # CoM lead over its reference along the path at which the help is fully compensated:
    # with psi = t a 30 N pull otherwise carried the CoM 6 cm past the standing height onto
    # straight, locked knees (measured). m.
    help_max_lead_m: float = 0.02
    # State 4 ends with the legs, not the CoM height: over the last part of the rise
    # (path progress from stance_from_progress to 1, smoothstep) the momentum task's
    # vertical row fades to stance_vertical_weight_scale of its weight and the state-4
    # posture (stance_posture_weight_by_joint) sets the knees, hence the height. Near
    # straight legs 1 cm of CoM height is 0.3 rad of knee (measured): a CoM target there
    # drove the knees onto their stop, and the soles slid (measured).
    stance_from_progress: float = 0.7
    stance_vertical_weight_scale: float = 0.1
    # Integral gain on the CoM height error in the stance (control/references.py). 1/s^3.
    stance_height_ki_per_s3: float = 100.0
    # Time constant of the lean's first-order filter: the pull's moment, not its jitter,
    # and a slow return when a helper lets go (at 0.3 s a robot leaning 6 cm into a
    # 15 N per hand backward pull staggered at the release and fell, measured). s.
    lean_filter_time_constant_s: float = 0.8
    # Bounds of the lean: the CoM target stays over the soles' CoP box with ~1.7 cm to
    # spare (from the standing CoM: 0.068 m to the toes, 0.082 m to the heels, 0.132 m
    # sideways; foot_cop_x_m/_y_m), so that the robot still stands when the pull stops.
    # Leaning past the toes, 8 cm into a backward pull, it fell when the helper let go
    # (measured). A pull that needs more than this is beyond what the feet allow. m.
    lean_max_forward_m: float = 0.05
    lean_max_back_m: float = 0.065
    lean_max_m: float = 0.11  # sideways
    # Extra posture weights per joint in state 4 (a second posture task, active there
    # only): near straight legs 1 cm of CoM height is 0.3 rad of knee, so the CoM target
    # alone cannot place the knees (measured); the legs' posture sets them.
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
    # the arms, which carry the pull, held once standing (at 3 a 25 N per hand upward
    # pull swung the shoulders through their range in 0.2 s; held from the start of
    # state 4 they could not help balance the rise: 1.6 kN sole spikes, measured).
    stance_arm_weight_by_joint: dict[str, float] = field(
        default_factory=lambda: {
            f"{side}_{joint}": 7.0
            for side in "lr"
            for joint in ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")
        }
    )
    # The robot weighs itself while seated (state 1): the pads' measured vertical force
    # plus the hands' (m g = sum F_z, the robot at rest) low-pass filtered with this time
    # constant, and the controller's model scaled to the estimate (every body's mass
    # alike, control/terms.py). With the nominal model a robot 15 % lighter rose 2 cm ahead
    # of its reference onto locked knees, and one 15 % heavier stalled in state 2 with the
    # hips on their stop (measured). 0: the nominal model throughout. s.
    mass_estimation_filter_s: float = 0.3
    # Bounds of the estimated mass scale (estimate / model).
    mass_scale_bounds: list[float] = field(default_factory=lambda: [0.7, 1.3])
    # QP solver: daqp (measured fastest, exact equalities), or Drake's osqp / clarabel.
    qp_solver: str = "daqp"
