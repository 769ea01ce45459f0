"""RobotSensors: what the iCub's sensors read of the plant (robot.hardware: icub).

The world's side of the robot's senses: the only system under icub that reads the plant's
state and forces (the estimator and the controller read it). Each output is what a sensor
would send over YARP at a tick, with its resolution, noise and offset:

    encoder_positions   (n_j, rad) the joints' absolute encoders, quantized
    encoder_velocities  (n_j, rad/s) the joints' velocities as the motor boards give them:
                        the motor encoder's count rate through the gearbox
    imu                 (6) the waist IMU's [gyroscope (rad/s); accelerometer (m/s^2)] in
                        its own frame: Drake's Gyroscope and Accelerometer plus white
                        noise and a constant bias
    ft_wrenches         (36) the six F/T sensors (hardware.FT_JOINTS), each [torque (N m);
                        force (N)] on the sensor's child side at its joint's child frame,
                        in that frame: the plant's reaction force at the weld it sits on,
                        plus white noise and a residual offset

The noise is a function of the tick's index and the seed (hardware.seed): the same
seed, the same run; each tick's draw is independent of the others.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.ports.caching import declare_cached
from drake_standup.senses.hardware import FT_JOINTS, ICubHardware

# Streams of the noise generator (the seed's second word): per tick, and once a run.
_TICK, _CONSTANT = 1, 2


def quantize(q: np.ndarray, counts: int) -> np.ndarray:
    """q (rad) as an absolute encoder of counts a revolution reads it."""
    step = 2.0 * np.pi / counts
    return np.round(q / step) * step


def quantize_rate(v: np.ndarray, hw: ICubHardware) -> np.ndarray:
    """Joint velocities (rad/s) as the motor boards give them: the motor encoder's counts
    over one period of the boards' loop, through the gearbox."""
    step = 2.0 * np.pi / (hw.motor_encoder_counts * hw.gear_ratio) / hw.board_period_s
    return np.round(v / step) * step


def constant_errors(hw: ICubHardware) -> dict[str, np.ndarray]:
    """The run's constant sensor errors, drawn once from the seed: the gyroscope's and
    the accelerometer's bias (3 each, each component in +-the bound) and each F/T
    sensor's residual offset (36, [torque; force] a sensor)."""
    rng = np.random.default_rng([hw.seed, _CONSTANT])
    bound = np.concatenate(
        [
            np.full(3, hw.gyro_bias_rad_s),
            np.full(3, hw.accel_bias_mps2),
            np.tile(np.r_[np.full(3, hw.ft_torque_offset_Nm), np.full(3, hw.ft_force_offset_N)], 6),
        ]
    )
    draw = bound * rng.uniform(-1.0, 1.0, bound.size)
    return {"imu": draw[:6], "ft": draw[6:]}


def tick_noise(hw: ICubHardware, tick: int) -> dict[str, np.ndarray]:
    """The white noise of tick (its index) for the IMU (6) and the F/T sensors (36)."""
    rng = np.random.default_rng([hw.seed, _TICK, tick])
    sigma = np.concatenate(
        [
            np.full(3, hw.gyro_noise_rad_s),
            np.full(3, hw.accel_noise_mps2),
            np.tile(np.r_[np.full(3, hw.ft_torque_noise_Nm), np.full(3, hw.ft_force_noise_N)], 6),
        ]
    )
    draw = sigma * rng.standard_normal(sigma.size)
    return {"imu": draw[:6], "ft": draw[6:]}


class RobotSensors(LeafSystem):
    """Inputs robot_state (the robot's true [q; v]), reaction_forces (the plant's),
    gyroscope and accelerometer (Drake's sensors at the waist IMU); outputs of the
    module docstring, each computed once a tick (a cache on time and the inputs)."""

    def __init__(self, plant: MultibodyPlant, instance, hw: ICubHardware):
        super().__init__()
        self._hw = hw
        self._nq_base = 7  # the quaternion floating base's coordinates, first in q
        nx = plant.num_multibody_states(instance)
        self._nj = plant.num_positions(instance) - self._nq_base
        self._ft = [int(plant.GetJointByName(name, instance).index()) for name in FT_JOINTS]
        self._constant = constant_errors(hw)
        self._state = self.DeclareVectorInputPort("robot_state", nx)
        self._reactions = self.DeclareAbstractInputPort(
            "reaction_forces", plant.get_reaction_forces_output_port().Allocate()
        )
        self._gyro = self.DeclareVectorInputPort("gyroscope", 3)
        self._accel = self.DeclareVectorInputPort("accelerometer", 3)
        self._noise = declare_cached(self, "sensor noise", self._calc_noise, {self.time_ticket()})
        self.DeclareVectorOutputPort(
            "encoder_positions",
            self._nj,
            self._CalcEncoders,
            prerequisites_of_calc={self._state.ticket()},
        )
        self.DeclareVectorOutputPort(
            "encoder_velocities",
            self._nj,
            self._CalcVelocities,
            prerequisites_of_calc={self._state.ticket()},
        )
        self.DeclareVectorOutputPort(
            "imu",
            6,
            self._CalcImu,
            prerequisites_of_calc={
                self._gyro.ticket(),
                self._accel.ticket(),
                self._noise.ticket(),
            },
        )
        self.DeclareVectorOutputPort(
            "ft_wrenches",
            36,
            self._CalcFt,
            prerequisites_of_calc={self._reactions.ticket(), self._noise.ticket()},
        )

    def _calc_noise(self, context: Context) -> dict[str, np.ndarray]:
        return tick_noise(self._hw, int(round(context.get_time() / self._hw.period_s)))

    def _CalcEncoders(self, context: Context, output: BasicVector) -> None:
        q = self._state.Eval(context)[self._nq_base : self._nq_base + self._nj]
        output.SetFromVector(quantize(q, self._hw.encoder_counts))

    def _CalcVelocities(self, context: Context, output: BasicVector) -> None:
        nq = self._nq_base + self._nj
        v = self._state.Eval(context)[nq + 6 : nq + 6 + self._nj]
        output.SetFromVector(quantize_rate(v, self._hw))

    def _CalcImu(self, context: Context, output: BasicVector) -> None:
        true = np.concatenate([self._gyro.Eval(context), self._accel.Eval(context)])
        output.SetFromVector(true + self._constant["imu"] + self._noise.Eval(context)["imu"])

    def _CalcFt(self, context: Context, output: BasicVector) -> None:
        forces = self._reactions.Eval(context)
        true = np.concatenate(
            [np.r_[forces[j].rotational(), forces[j].translational()] for j in self._ft]
        )
        output.SetFromVector(true + self._constant["ft"] + self._noise.Eval(context)["ft"])
