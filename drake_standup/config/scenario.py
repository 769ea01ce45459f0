"""The scenario's sections: every number a run uses, with its unit and where it comes from.

Defaults live here (and in config/controller.py) and nowhere else; the YAML files in
scenarios/ override what they name (config/loading.py).
"""

from dataclasses import dataclass, field

from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig

from drake_standup.config.body import BodyHelperConfig
from drake_standup.config.chair import ChairConfig, InitialPose
from drake_standup.config.controller import ControllerConfig
from drake_standup.config.cycle import SitDownConfig
from drake_standup.config.hardware import HardwareConfig
from drake_standup.config.phases import PhaseTable
from drake_standup.config.recording import RecordedHelperConfig
from drake_standup.config.resources import data_root

SCENARIO_DIR = data_root() / "scenarios"
DEFAULT_SCENARIO = SCENARIO_DIR / "assisted.yaml"
# Every actuator's effort limit: the paper's torque saturation ([authors-code]). N m.
EFFORT_LIMIT_NM = 60.0


# robot.reflected_inertia's settings (robot.reflects_motor_inertia).
REFLECTED_INERTIA = ("none", "all", "real_robots")
# response's settings, the robot's answer to a pull ([tirupachuri2019]; the paper's
# introduction names the three): its index is the response code the controller's systems read.
RESPONSES = ("advancement", "stiff", "compliant")


@dataclass
class RobotConfig:
    # Any name from icub_models.get_robot_names().
    model: str = "iCubGazeboV2_5"
    # Replace massless sensor/skin links by frames ([drake-docs]: 3-10x faster terms).
    reduced: bool = True
    # Every actuator's effort limit, which the controller reads from the plant. N m.
    effort_limit_Nm: float = EFFORT_LIMIT_NM
    # Triangles per visual mesh after decimation. Meshcat's HTML is 2.2 MB of
    # viewer, ~0.15 MB per simulated second of animation, plus the meshes: at
    # 1000 faces they take ~1.3 MB and a 15 s recording stays under 8 MB.
    visual_max_faces: int = 1000
    # The motors' reflected inertia (gear ratio^2 x rotor inertia on each actuated
    # joint, robot/icub.py MOTOR_INERTIAS), in the plant and the controller's model alike:
    # none | all | real_robots (every model but the Gazebo ones). As the authors had it
    # ([authors-code]: on for the real robots, off in Gazebo); the convergence study found it
    # cheaper per step and converged at a larger step (docs/performance.md).
    reflected_inertia: str = "real_robots"
    # What the robot knows and how its joints act (HARDWARE): ideal, the simulator's exact
    # state and contact forces at controller_period_s and exact torques; icub, the real
    # robot's senses and muscles at its own rate (HardwareConfig, drake_standup/senses).
    hardware: str = "ideal"


@dataclass
class Pull:
    """A scripted pull on one hand: a trapezoid in time, constant direction."""

    hand: str = "left"  # left | right
    start_s: float = 3.0
    duration_s: float = 6.0
    # Linear ramp up at the start and down at the end, inside duration_s. s.
    ramp_s: float = 0.5
    # World frame; the robot faces +x, z is up. N.
    force_N: list[float] = field(default_factory=lambda: [15.0, 0.0, 15.0])


@dataclass
class ReactiveHumanConfig:
    """A helper who guides each hand; the pull fades in and out over ramp_s
    ([authors-code]: the authors' human pulled 10-25 N per hand).

    Both guides are a person (issue 31, [reaction-time]): they decide on what they saw
    reaction_time_s ago, follow a hand that outruns them and let go once the robot
    is up (ease_com_rise_m).
    guide: velocity (the default): a person moving each hand along the direction
    of target_velocity_mps at its speed, for at most travel_m, from wherever they
    saw the hand, keeping lead_min_m ahead of a hand that outruns them (helper/hands.py,
    reactive_force): F = sat(K (p_target - p_hand) + D (v_target - v_hand), force_cap_N).
    guide: path (helper/hands.py, path_force): a person walking each hand along a path
    in the sagittal plane (path_xz_m from where the hand was) at pace_mps, never
    more than lead_max_m ahead of the hand, never less than lead_min_m while the
    path goes on; the pull acts along the path only (never backwards, never
    sideways), is capped, and eases off as the hand reaches the path's end or
    the robot's CoM has risen by ease_com_rise_m.
    """

    guide: str = "velocity"
    # What the person does is decided on what they saw this long ago; their arm's
    # impedance acts at once. A person's simple reaction time to a felt force is about
    # 0.15-0.25 s ([reaction-time]), but the default is 0 (decisions at once, as the first
    # models) until the stand-up tells a partner who lags from one who hinders: at 0.2 s
    # the shipped reactive partner stands the robot up 14 % sooner than alone, not 18 %
    # (issue 31, docs/design.md). s.
    reaction_time_s: float = 0.0
    start_s: float = 3.0
    duration_s: float = 8.0
    ramp_s: float = 0.5
    # Arm-like stiffness and damping of a person guiding a hand. N/m, N s/m.
    stiffness_N_per_m: float = 150.0
    damping_Ns_per_m: float = 20.0
    # Per hand; the authors' human pulled 10-25 N ([authors-code]). N.
    force_cap_N: float = 20.0
    # guide: velocity.
    target_velocity_mps: list[float] = field(default_factory=lambda: [0.10, 0.0, 0.10])
    travel_m: float = 0.35
    # guide: path. Waypoints [forward, up] from the hand's position at t = 0,
    # the start itself implied: forward and a little up (37 deg) past where the
    # robot's hands are while it leans forward (states 2-3: ~0.3 m forward,
    # 0.2-0.3 m up), then nearly straight up, beyond where they are standing
    # (~0.35 m forward, 0.4-0.5 m up). A first leg mostly up kept the robot in
    # state 2 at psi = t (the pull unloaded its feet). m.
    path_xz_m: list[list[float]] = field(default_factory=lambda: [[0.40, 0.30], [0.45, 0.70]])
    # The path's corners rounded to this radius: a person's hands turn no
    # sharp corner, and the hand's closest point on the path (so the pull)
    # then moves continuously as the hand passes the corner's inside. m.
    path_corner_radius_m: float = 0.2
    # A person's pace walking the hands: a stand-up of the order of 2 s. m/s.
    pace_mps: float = 0.3
    # The target's distance ahead of the hand along the path: at most
    # lead_max_m (no yank: the spring's pull stays under K lead_max), at least
    # lead_min_m (the person keeps pulling a hand that outruns the pace, with
    # K lead_min: 22.5 N at 150 N/m, within [authors-code]'s 10-25 N). The velocity
    # guide keeps lead_min_m too, ahead of a hand that outruns its pace. m.
    lead_min_m: float = 0.15
    lead_max_m: float = 0.20
    # The pull fades linearly from full to zero while the CoM rises from the
    # first to the second height above where it was at t = 0: from coming up
    # to nearly up (seated 0.38 m; standing 0.53-0.58 m). The CoM rises at up
    # to 0.5 m/s there: a band of 0.07 m lets go over ~0.15 s. m.
    ease_com_rise_m: list[float] = field(default_factory=lambda: [0.07, 0.14])


@dataclass
class HumanConfig:
    # scripted: the pulls below; reactive: the impedance helper (reactive:); body: a
    # person's body pulling with reactive:'s intent (body:, helper/body.py); recorded:
    # hand forces replayed from a CSV file (recorded:, helper/recorded.py).
    mode: str = "scripted"
    # Empty list: nobody helps.
    pulls: list[Pull] = field(default_factory=list)
    reactive: ReactiveHumanConfig = field(default_factory=ReactiveHumanConfig)
    body: BodyHelperConfig = field(default_factory=BodyHelperConfig)
    recorded: RecordedHelperConfig = field(default_factory=RecordedHelperConfig)


@dataclass
class AdvancementConfig:
    # false: psi = t (the plain time-parametrised controller).
    enabled: bool = True
    # tangent: the paper's proposition, psi_dot = clip(xdot . d_psi x_d /
    #   (|d_psi x_d|^2 + eps)), applied while the interaction helps (alpha >
    #   alpha_min). interaction: the authors' code, the same ratio measured along
    #   Omega f ([tirupachuri2019]).
    law: str = "tangent"
    # Upper bound of psi_dot; the authors' last setting (earlier 5). [authors-code].
    psi_dot_upper: float = 2.5
    # Regulariser of the denominators, m^2 (per unit psi^2): 0.4% of the
    # squared peak tangent of the state-2 segment (|d_psi x_d| <= 0.16 m), so it
    # only matters where the tangent vanishes, at the ends of each segment.
    eps: float = 1.0e-4
    # alpha (hand-induced CoM acceleration along the path) above which the
    # interaction counts as helpful: ~1.6 N of net pull along the path. m/s^2.
    alpha_min_mps2: float = 0.05
    # alpha from which the law acts in full (advancement.py: graded gates); in
    # between, psi_dot's excess over 1 is weighted by (alpha - alpha_min) /
    # (alpha_full - alpha_min). alpha_full <= alpha_min: the paper's on/off
    # gate. None: derived from the robot, the acceleration full_help_pull_N on
    # each hand along the path gives its mass (advancement.for_robot). m/s^2.
    alpha_full_mps2: float | None = None
    # Per hand: the law acts in full from a trained helper's pull on. The real
    # iCub's trained helper peaked at 13.3/9.9 N per hand ([icub-logs]), the authors'
    # human pulled 10-25 N ([authors-code]): 0.60 m/s^2 on iCubGazeboV2_5 (33 kg; it was
    # a fixed 0.9, the default 15 + 15 N pull's peak, which gave a 15 N partner 2/3
    # of the law; issue 31, docs/design.md). N.
    full_help_pull_N: float = 10.0
    # Over the last part of each segment (path progress from taper_from_progress
    # to 1) the law's excess over 1 is tapered to 0 (smoothstep), so psi_dot
    # returns to 1 before the path ends: the rise at psi_dot 2.5 ended on
    # straight knees and the standing robot rocked between its feet (measured;
    # from 0.7 it still did). From 0.4 the rise's reference still braked at
    # 2.6-3.0 m/s^2 at its end and the heels slapped (up to 364 N of sole chatter);
    # from 0.2 at 1.3-2.0 m/s^2, no slap in ten helped runs (issue 30, docs/design.md).
    taper_from_progress: float = 0.2
    # Advance only while the CoM is not behind its reference along the path
    # (see advancement.py: without it the law and the tracker run away). The
    # tolerance admits the tracker's own lag: at psi = t the CoM lags its
    # reference by up to 8 mm in state 2 and 17 mm in state 3, where the feet take
    # the load (measured; at 5 mm state 3 and a braced rise never advanced). m.
    lead_gate: bool = True
    lag_tolerance_m: float = 0.015
    # The lead measured from x_d as the controller leans it against the pull (the target
    # it tracks) instead of the bare x_d: braced, that target stands 1.3 cm lower and the
    # gate reads it as a lag. On, the lagging 26 N partner stands up in 3.60 s (4.04 s
    # off; alone 3.70), but the faster rises slap the soles harder on the person's body
    # (79 -> 130 N by the hands) and its run then depends on the plant's step
    # (docs/decisions/020-lead-from-the-leaned-target.md): off until those are quiet.
    lead_from_leaned_target: bool = False
    # psi_dot tends to the law's value with this time constant (psi integrates
    # it): the law jumps (1 -> 2.5 at a gate); a reference following it jumped
    # in velocity and lifted the erect robot off its feet (measured). s.
    psi_ddot_filter_s: float = 0.05


@dataclass
class ComplianceConfig:
    """The CoM reference's admittance for response: compliant (standup/task_references.py):

        M a + D v + K x = f_hands,   D = 2 zeta sqrt(K M),

    x the reference's offset (W), f_hands the measured pull of both hands. Bounded so the
    robot stays over its support: each axis within max_offset_m; horizontally only as far
    as the standing feet could still hold the pull (standup.standing_pull_usage_limit);
    on the feet alone not above the path (standup/task_references.py)."""

    # The robot's own mass (iCubGazeboV2_5: 33 kg): the reference yields to the pull as
    # the robot itself would, free, at first (Omega f = f / m, [tirupachuri2019]). kg.
    virtual_mass_kg: float = 33.0
    # The top of a realistic helper's envelope, 2 x 26 N ([icub-logs]: an untrained person's
    # peak per hand), reaches the forward bound: 52 N / 0.04 m. A trained helper's
    # 13 + 10 N ([icub-logs]) yields 1.8 cm. N/m.
    stiffness_N_per_m: float = 1300.0
    # Critically damped: the offset follows a steady pull without overshoot.
    damping_ratio: float = 1.0
    # x, y, z. Forward and back 4 cm: inside the 6.8 cm from the standing CoM to the toes
    # and the 8.2 cm to the heels (issue 21, docs/results.md); sideways and up or down
    # 3 cm. m.
    max_offset_m: list[float] = field(default_factory=lambda: [0.04, 0.03, 0.03])


@dataclass
class StandupConfig:
    """The state machine's settings across phases ([authors-code], [early-probe]); what each
    state does, and the guard that leaves it, is the phase table (phases.py). Reasons:
    docs/design.md."""

    # hands: state 1 -> 2 needs the pull (both hands, x force > threshold) or the live
    # page's button; time: the balancing time alone.
    trigger: str = "hands"
    # x component of the force on each hand that starts the stand-up. N.
    hand_force_threshold_N: float = 10.0
    # ... or a gentler pull held longer: both hands pulled the stand-up's way (forward
    # and up, guards.helping_pull_N) by more than the real iCub's hands register with
    # nobody helping ([icub-logs]: 5.4/6.5 N peak, states 2-3), for a person's reaction time
    # ([reaction-time]: 0.15-0.25 s). A firm pull starts it at once, a gentle grip once it is
    # plainly meant (issue 31: 12 of 48 partners, 8-26 N grips, never started at 10 N;
    # 2 more, 9 N along a 45-degree pace, on the forward force alone). N, s.
    gentle_pull_force_N: float = 6.5
    gentle_pull_time_s: float = 0.25
    # A pull is against the stand-up by its effect: when holding it would need more than
    # standing_pull_usage_limit of the CoM's reach back over the heels (guards.heel_usage);
    # the stand-up then waits (each phase's when_hindered says how). Older files set
    # this: both hands together pulled back by more than it counted too, whatever it did
    # (2.5 until issue 31; a partner's lag dipping through zero sat the robot back). N.
    hindering_force_threshold_N: float | None = None
    # A pull that would need more than this share of what the standing robot's feet can
    # hold (sensing.standing_pull_usage: its lean plus the soles' CoP boxes) is answered
    # as a hindering pull is: the stand-up waits, or sits back, until it eases. 20 N
    # forward and up per hand (0.52) stands up at every psi_dot bound; 25 N (0.68) stood
    # up and fell at two of four (docs/design.md, "Hindering pulls"). -.
    standing_pull_usage_limit: float = 0.6
    # Such a pull first braces the arms: they hold the posture they sat with instead of
    # reaching out, which brings the hands lower and nearer the feet and shortens the
    # pull's lever; the stand-up waits only if the pull is beyond the feet braced too,
    # and the arms reach out again once it eases (docs/decisions/010-reactive-partners.md,
    # "A strong pull").
    brace_arms: bool = True
    # After a hindering pull stops, the stand-up waits this long: the pull is over, and
    # the arms it swung back return to their posture first. s.
    resume_after_s: float = 0.5
    # A step back (when_hindered) sits the robot back into state 1 while the pads its
    # phase releases still carry more than this fraction of their load, and goes back
    # one phase while they unload (docs/design.md, "Hindering pulls").
    reseat_above_thigh_load: float = 0.9
    # The force guards read forces low-pass filtered with this time constant: the pads'
    # contact forces ring at 20-50 Hz. s.
    force_filter_time_constant_s: float = 0.05
    # ... through Schmitt triggers: on after the filtered force stays above the threshold
    # for guard_dwell_s, off after it stays below guard_off_ratio times the threshold as
    # long. s, -.
    guard_dwell_s: float = 0.05
    guard_off_ratio: float = 0.8
    # Period of the state machine's update; the authors' whole controller ran at 100 Hz
    # ([authors-code]), and the guards' thresholds are met for seconds. s.
    update_period_s: float = 0.01
    # After standing: the sit-down, and standing again.
    sit_down: SitDownConfig = field(default_factory=SitDownConfig)


@dataclass
class SeatHoldConfig:
    """Joint-space hold: Drake's implicit joint PD plus gravity feed-forward.

    Holds the seated pose until the whole-body controller exists; also the
    near-zero-cost controller of the plant-only benchmark.
    """

    kp_Nm_per_rad: float = 100.0
    kd_Nms_per_rad: float = 4.0


@dataclass
class FallConfig:
    """Bounds that end a run early as a fall (success false, reason recorded)."""

    # Seated the root is at 0.38 m, standing ~0.6 m. m.
    min_root_height_m: float = 0.25
    max_com_horizontal_m: float = 0.5
    # The controller holds its last torques through a failed QP; this long a
    # run of failures ends the run. s.
    max_qp_failure_streak_s: float = 0.1


@dataclass
class Push:
    """A push on one robot body: a constant world force over a time window."""

    # A body of the robot; the torso's upper body is 'chest'.
    body: str = "chest"
    start_s: float = 5.0
    duration_s: float = 0.2
    # World frame, at the body's origin; the robot faces +x, z is up. N.
    force_N: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class PerturbationConfig:
    """Disturbances and model errors for robustness studies; all off by default.

    The model errors act on the simulated robot only: the controller, the
    sensing and the human keep the nominal model, as on a real robot whose
    model is wrong.
    """

    pushes: list[Push] = field(default_factory=list)
    # Every body's mass and rotational inertia of the simulated robot times
    # this factor (CoM locations unchanged).
    mass_scale: float = 1.0
    # Every contact geometry's Coulomb friction (pads, chair, floor) times this
    # factor, so the combined coefficient of each pair scales by it too; the
    # controller's friction pyramid keeps its nominal mu.
    friction_scale: float = 1.0
    # Standard deviation of white noise on each force component of the
    # measured hand wrenches (what sensing, the state machine and the
    # controller see; the plant gets the true pull). N.
    hand_wrench_noise_N: float = 0.0
    # The noise is held for this long: the wrist sensor's sample period. s.
    hand_wrench_noise_period_s: float = 0.01
    # Seed of the noise: the same seed gives the same noise.
    noise_seed: int = 0


@dataclass
class VisualizationConfig:
    # Meshcat recording frame period: 25 fps keeps a 15 s HTML small. A publish
    # off the plant's step grid splits an integrator step, which changed the
    # simulation (psi to 1e-9, a stand-up sample) and cost ~5% at a 4 ms step
    # (measured), so both visualizer periods are rounded to whole plant steps
    # (diagram.py); 40 ms is a whole multiple of every step of the study. s.
    publish_period_s: float = 0.04
    # Camera position and target that frame the robot on its chair; with a person's body
    # helping and both at these defaults, the camera frames the person too
    # (sim/visuals.camera_pose). m.
    camera_xyz_m: list[float] = field(default_factory=lambda: [1.05, -1.0, 0.8])
    target_xyz_m: list[float] = field(default_factory=lambda: [0.15, 0.0, 0.42])
    show_contact_forces: bool = True
    # Contact force arrows at 10 Hz: enough to read, and they cost the HTML
    # ~0.13 MB per simulated second at 30 Hz. s.
    contact_publish_period_s: float = 0.1


@dataclass
class Scenario:
    robot: RobotConfig = field(default_factory=RobotConfig)
    # Simulated time. s.
    duration_s: float = 5.0
    # Drake's own plant settings: discrete 'similar' ([drake-docs]: 'lagged' and
    # 'similar' ran 1.4-2.2x faster than real time, SAP 0.6x), stepped at 2 ms under the
    # controller's 4 ms: at 4 ms the soles' contact is not resolved (a heel landing or
    # the thighs leaving the seat slap them, 175-281 N, where a 1 ms plant gives 40-61
    # N); at 2 ms every case of the convergence study is within 15 N of the 1 ms plant's,
    # for 1.4x the run time (docs/decisions/018-plant-step-resolves-the-soles.md).
    # 1 ms: plant.time_step 0.001.
    plant: MultibodyPlantConfig = field(
        default_factory=lambda: MultibodyPlantConfig(
            time_step=0.002,
            discrete_contact_approximation="similar",
            contact_model="hydroelastic_with_fallback",
        )
    )
    # Drake's simulator settings. The only continuous state is psi (and its
    # filter), whose derivative is constant between plant steps but for the
    # reference tangent: fixed RK2 steps. The integrator never steps over a
    # discrete event, so with max_step_size at least the plant's step psi takes
    # one RK2 step per plant step, whatever the step: the integrator follows
    # plant.time_step with no second key to keep in line. 10 ms is the largest
    # plant step of the convergence study.
    # (Explicit Euler, one derivative evaluation instead of two, saved under
    # 0.1 ms a step but moved the assisted stand-up from 2.68 to 3.04 s at a
    # 1 ms step: the gated law and the per-foot guard of state 4 amplify the
    # O(dt) change.) Run as fast as possible.
    simulator: SimulatorConfig = field(
        default_factory=lambda: SimulatorConfig(
            integration_scheme="runge_kutta2",
            max_step_size=0.01,
            use_error_control=False,
            target_realtime_rate=0.0,
        )
    )
    human: HumanConfig = field(default_factory=HumanConfig)
    # How the robot answers the pull (RESPONSES): advancement, the paper's (psi runs ahead
    # while the pull helps, by advancement.law); stiff, psi = t and the pull compensated in
    # full, the CoM tracking its time reference as if nobody pulled; compliant, psi = t and
    # the CoM reference yielding to the pull through an admittance (compliance).
    response: str = "advancement"
    compliance: ComplianceConfig = field(default_factory=ComplianceConfig)
    advancement: AdvancementConfig = field(default_factory=AdvancementConfig)
    standup: StandupConfig = field(default_factory=StandupConfig)
    # What each stand-up state does and the guard that leaves it (phases.py).
    phases: PhaseTable = field(default_factory=PhaseTable)
    # The momentum-based whole-body controller (drake_standup/control/controller.py).
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    # Its period: a whole multiple of the plant's step (a faster controller is wasted on
    # a discrete plant). 250 Hz, twice the plant's step: the plant at 1 ms under it
    # stands up as under a 1 ms controller (decision 018); the authors ran 100 Hz
    # ([authors-code]). s.
    controller_period_s: float = 0.004
    initial: InitialPose = field(default_factory=InitialPose)
    chair: ChairConfig = field(default_factory=ChairConfig)
    seat_hold: SeatHoldConfig = field(default_factory=SeatHoldConfig)
    fall: FallConfig = field(default_factory=FallConfig)
    # The real robot's senses and muscles, under robot.hardware: icub.
    hardware: HardwareConfig = field(default_factory=HardwareConfig)
    # Pushes, model errors and sensor noise (robustness sweeps).
    perturbation: PerturbationConfig = field(default_factory=PerturbationConfig)
    visualization: VisualizationConfig = field(default_factory=VisualizationConfig)
    # Period of the signal loggers used by metrics and figures. s.
    log_period_s: float = 0.01
