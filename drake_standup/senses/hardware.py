"""The real iCub's senses and muscles as numbers (robot.hardware: icub), each with its source.

The nominal numbers are the robot's; HardwareConfig (config/scenario.py) scales the ones
the sensitivity study varies (F/T noise, IMU bias, friction) and sets the rate, the delay
and the seed. References in docs/references.md.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from drake_standup.config import HardwareConfig

# The six F/T sensors of the icub-models URDFs: the fixed joints they sit on (the
# <sensor type="force_torque"> elements of iCubGazeboV2_5, [icub-models]; [icub-tech]),
# upper arms, upper legs, feet.
FT_JOINTS = (
    "l_arm_ft_sensor",
    "r_arm_ft_sensor",
    "l_leg_ft_sensor",
    "r_leg_ft_sensor",
    "l_foot_ft_sensor",
    "r_foot_ft_sensor",
)
# The IMU robotology's estimators read: the head's (head_imu_0, a Bosch BNO055 on
# iCubGenova04: robots-configuration, iCubGenova04/hardware/inertials/head-inertial.xml).
IMU_FRAME = "head_imu_0"


@dataclass(frozen=True)
class JointFriction:
    """Coulomb and viscous friction of one joint group, N m and N m s / rad."""

    coulomb_Nm: float
    viscous_Nms: float


@dataclass(frozen=True)
class ICubHardware:
    """The numbers of the module docstring (nominal, before HardwareConfig's scales)."""

    period_s: float
    delay_ticks: int
    seed: int
    # The joints' absolute encoders: counts a revolution.
    encoder_counts: int
    # The motors' incremental encoders, counts a motor revolution; the gearbox; the
    # boards' loop period, s (the joint velocity the boards give).
    motor_encoder_counts: int
    gear_ratio: float
    board_period_s: float
    # The waist IMU: white noise (std at the robot's rate) and a constant bias.
    gyro_noise_rad_s: float
    gyro_bias_rad_s: float
    accel_noise_mps2: float
    accel_bias_mps2: float
    # The attitude filter's crossover: gyro above, accelerometer's gravity below. s.
    attitude_time_constant_s: float
    # The six-axis F/T sensors: white noise std and the residual offset's bound.
    ft_force_noise_N: float
    ft_torque_noise_Nm: float
    ft_force_offset_N: float
    ft_torque_offset_Nm: float
    # The joint torque loop: its first-order time constant, s.
    torque_time_constant_s: float
    # Friction by joint group (the first group whose key is in a joint's name).
    friction: dict[str, JointFriction]
    friction_scale: float  # the true friction over the identified one
    # Each hand's contact detector (a Schmitt trigger on its estimated force): make and
    # break thresholds, N, and how long the force stays past one, s.
    hand_contact_make_N: float = 5.0
    hand_contact_break_N: float = 2.5
    hand_contact_time_s: float = 0.1
    # The joints held by their boards' position loops, not torque-controlled (name keys).
    position_mode: tuple[str, ...] = ()
    # When the estimator calibrates the IMU's biases, s: the robot seated still once it has
    # settled on the chair, its pose known from the legs (as wholeBodyDynamics calibrates
    # the F/T sensors' offsets at start-up).
    imu_calibration_s: tuple[float, float] = (0.5, 1.0)

    @property
    def latency_s(self) -> float:
        """From a tick's measurements to the middle of the tick its torques act over:
        delay_ticks + 1/2 ticks (what the estimator predicts its state over)."""
        return (self.delay_ticks + 0.5) * self.period_s

    def friction_of(self, joint: str) -> JointFriction:
        for key, value in self.friction.items():
            if key in joint:
                return value
        raise KeyError(f"{joint}: no friction group")


# Per-sample noise of a sensor of noise density nd (unit/sqrt(Hz)) sampled at 100 Hz: nd
# times the square root of its 50 Hz bandwidth.
_BANDWIDTH_HZ = 50.0
_DEG = math.pi / 180.0

# The nominal iCub (iCubGenova04, the robot of iCubGazeboV2_5; docs/references.md
# [icub-hardware] has each source's file and commit).
NOMINAL = ICubHardware(
    period_s=0.01,  # YARP's 100 Hz ([authors-code])
    delay_ticks=1,
    seed=0,
    # The joints' AEA absolute magnetic encoders, 12 bit (robots-configuration,
    # iCubGenova04 *-mc_service.xml: eomc_enc_aea, resolution 4096).
    encoder_counts=4096,
    # iCubGenova04 reads joint velocity from the motor side (useMotorSpeedFbk 1): an
    # optical encoder of 14400 counts a motor revolution through the 100:1 harmonic drive
    # (robots-configuration, *-mc_service.xml and *-mec.xml), at the boards' 1 kHz
    # (icub-firmware EOemsControllerCfg.h).
    motor_encoder_counts=14400,
    gear_ratio=100.0,
    board_period_s=0.001,
    # Bosch BNO055 datasheet (BST-BNO055-DS000-14): gyroscope 0.014 deg/s/sqrt(Hz),
    # zero-rate offset +-1 deg/s; accelerometer 150 ug/sqrt(Hz), zero-g offset +-80 mg.
    gyro_noise_rad_s=0.014 * _DEG * math.sqrt(_BANDWIDTH_HZ),
    gyro_bias_rad_s=1.0 * _DEG,
    accel_noise_mps2=150e-6 * 9.81 * math.sqrt(_BANDWIDTH_HZ),
    accel_bias_mps2=0.080 * 9.81,
    # The Mahony filter's proportional gain of baseEstimatorV1 on iCubGenova04 (kp 0.7:
    # whole-body-estimators, fbe-analogsens.xml): a 1 / 0.7 s crossover.
    attitude_time_constant_s=1.0 / 0.7,
    # The iCub F/T sensor's resolution after calibration (icub-tech documentation, "F/T
    # Sensors", table 2: 0.25 N, 0.005 N m), taken as its noise (no deviation is given)
    # and as the residual offset once wholeBodyDynamics has calibrated it at start-up.
    ft_force_noise_N=0.25,
    ft_torque_noise_Nm=0.005,
    ft_force_offset_N=0.25,
    ft_torque_offset_Nm=0.005,
    # The boards close the torque loop at 1 kHz (icub-firmware EOemsControllerCfg.h) and
    # iCubGenova04's legs run it on feed-forward (kp 0, ki 0); no bandwidth is published:
    # one period of the 1 kHz loop.
    torque_time_constant_s=0.001,
    # Viscous: IIT's simulator of this robot (whole-body-controllers, iCubGazeboV2_5
    # configRobotSim.m: 0.2 N m s/rad, ankles 0.6), on top of the URDF's damping the plant
    # already has. Coulomb: none is identified for the iCub (icub-models issue 32 is open)
    # and IIT's simulator has none; 0.5 N m made the arms hunt against the delayed joint
    # damping (wrists 1.6-2.5 rad/s rms seated, measured), so the nominal is 0 and the
    # mechanism is JointFriction's.
    friction={
        "ankle": JointFriction(0.0, 0.6),
        "hip": JointFriction(0.0, 0.2),
        "knee": JointFriction(0.0, 0.2),
        "torso": JointFriction(0.0, 0.2),
        "shoulder": JointFriction(0.0, 0.2),
        "elbow": JointFriction(0.0, 0.2),
        "wrist": JointFriction(0.0, 0.2),
        "neck": JointFriction(0.0, 0.2),
    },
    friction_scale=1.0,
    # iCub's whole-body torque control drives 23 joints: torso, shoulders, elbows, legs
    # (Nori et al. 2015, Sec. 2); the neck and the wrists stay in position mode. With the
    # tick's delay, the torque-driven wrists oscillated until the robot fell (measured).
    position_mode=("neck", "wrist"),
    # The hands' contact detector: robotology's base estimator detects the feet's with
    # Schmitt triggers on their F/T force (make/break thresholds and a stable time:
    # whole-body-estimators, fbe-analogsens.xml); the hands' make threshold sits above
    # the hand estimate's error with nobody pulling (99th percentile 4.4 N over the
    # unassisted stand-up, measured), far below a helper's 10-25 N a hand.
    hand_contact_make_N=5.0,
    hand_contact_break_N=2.5,
    hand_contact_time_s=0.1,
)


def hardware(config: HardwareConfig) -> ICubHardware:
    """The nominal iCub with config's rate, delay, seed and scales."""
    n = NOMINAL
    return dataclasses.replace(
        n,
        period_s=1.0 / config.rate_hz,
        delay_ticks=config.delay_ticks,
        seed=config.seed,
        ft_force_noise_N=n.ft_force_noise_N * config.ft_noise_scale,
        ft_torque_noise_Nm=n.ft_torque_noise_Nm * config.ft_noise_scale,
        ft_force_offset_N=n.ft_force_offset_N * config.ft_noise_scale,
        ft_torque_offset_Nm=n.ft_torque_offset_Nm * config.ft_noise_scale,
        gyro_bias_rad_s=n.gyro_bias_rad_s * config.imu_bias_scale,
        accel_bias_mps2=n.accel_bias_mps2 * config.imu_bias_scale,
        friction_scale=config.friction_scale,
    )
