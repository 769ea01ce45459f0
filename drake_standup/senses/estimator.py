"""RobotEstimator: what the robot knows of itself, from its sensors alone (robot.hardware: icub).

Once a tick, from the encoders, the waist IMU and the six F/T sensors (sensors.py):

    joints      positions as the joints' absolute encoders read them; velocities as the
                motor boards give them (sensors.py: the motor encoders' count rate)
    IMU         its biases calibrated at start-up, seated still (hw.imu_calibration_s):
                the gyroscope's against the neck's turn, the accelerometer's against
                gravity at the legs' attitude (uncalibrated, the gyroscope's 1 deg/s made
                the CoM velocity err 8.2 mm/s RMS; calibrated, 3.8: measured)
    attitude    the IMU's: the gyroscope integrated, pulled toward the accelerometer's
                gravity with time constant attitude_time_constant_s (complementary)
    base        legged odometry, as robotology's base estimator: the supporting sole stays
                where it was when it took the load, so the base pose is the sole's pose
                less the legs' kinematics; its tilt blended with the IMU's by their
                variances (encoders' resolution along the leg against the attitude
                filter's bias); the angular velocity the gyroscope's; the linear one the
                sole's standing still
    wrenches    each piece's external wrench (subtrees.py) from the F/T sensors less the
                piece's own dynamics at the estimated state and accelerations over the tick:
                the hands' wrenches and each pad's force (wholeBodyDynamics' idea); a
                hand's wrench is zero until its contact is made and then fades in
                (_hand_contacts), so the advancement reads the estimate's error with
                nobody pulling as no pull

Outputs (state outputs: what one tick computed is what the controller reads at the next):
robot_state (the estimate, [q; v] as the plant's, its positions moved on by the velocities
to when the torques computed from it act (_predicted): at 100 Hz the tick's latency made
the soles chatter, 138 N against 35 N at 250 Hz, measured), hand_wrenches_W (12,
payloads.HAND_WRENCHES), pad_forces_W (3 a pad, the station's pad order), imu_attitude_W (4,
the attitude filter's quaternion of the base, for the figures).
The estimator starts from the robot's known seated pose (its world frame set at its feet).
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import Context, DiscreteValues, LeafSystem

from drake_standup.robot.icub import velocity_start
from drake_standup.robot.spatial import cross, exp_rotation, rotation_vector
from drake_standup.senses.hardware import FT_JOINTS, IMU_FRAME, ICubHardware
from drake_standup.senses.subtrees import RobotPieces, wrench_at

_HANDS = ("l_hand", "r_hand")
_SOLES = ("l_sole", "r_sole")


class RobotEstimator(LeafSystem):
    """The module docstring's system, every hw.period_s."""

    def __init__(self, plant, robot, hw: ICubHardware, x0: np.ndarray, pads: list[str]):
        """plant: the robot's own model (the controller's); x0: its seated state; pads: the
        pads' frames in the station's pad order."""
        super().__init__()
        self._plant, self._hw = plant, hw
        self._instance = robot.model_instance
        self._context = plant.CreateDefaultContext()
        self._nq = plant.num_positions(self._instance)
        self._nv = plant.num_velocities(self._instance)
        self._nj = self._nq - 7
        self._pieces = RobotPieces(plant, self._instance, list(FT_JOINTS))
        self._hands = [robot.frame(plant, h) for h in _HANDS]
        self._soles = [robot.frame(plant, s) for s in _SOLES]
        self._imu_frame = plant.GetFrameByName(IMU_FRAME, self._instance)
        self._v_start = velocity_start(plant, self._instance)
        self._pad_piece = [
            self._pieces.piece_of(plant.GetFrameByName(f, self._instance).body().name())
            for f in pads
        ]
        self._hand_piece = [self._pieces.piece_of(f.body().name()) for f in self._hands]
        # The tilt stays the legs' after the IMU's calibration too: the variances leave out
        # the accelerometer's reading of the robot's own motion, and weighted by them
        # (0.32) the base's position erred 3.4 mm RMS against 2.6 and the reactive run's
        # soles chattered 84 N against 27 (measured).
        self._tilt_weight = _tilt_weight(hw)
        self._gravity = -plant.gravity_field().gravity_vector()  # what the accelerometer reads
        x0 = np.asarray(x0, dtype=float)
        plant.SetPositionsAndVelocities(self._context, self._instance, x0)
        X_WF = self._soles[0].CalcPoseInWorld(self._context)
        n_pads = len(pads)
        self._x = self.DeclareDiscreteState(x0)
        # [started, anchor sole (0 left, 1 right), anchor's p (3) and quaternion (4)]
        anchor = np.r_[0.0, 0.0, X_WF.translation(), X_WF.rotation().ToQuaternion().wxyz()]
        self._anchor = self.DeclareDiscreteState(anchor)
        # The attitude filter's R_WS, the IMU frame's (its first: the seated pose's).
        R_WS = self._imu_frame.CalcPoseInWorld(self._context).rotation()
        self._attitude = self.DeclareDiscreteState(R_WS.ToQuaternion().wxyz())
        self._hands_state = self._declare(12)
        self._touch = self._declare(6)
        self._pads_state = self._declare(3 * n_pads)
        self._last_wrenches = self._declare(6 * len(self._pieces.pieces))  # the last tick's
        # [samples, sum of gyro (3), sum of accelerometer less gravity (3), done]
        self._calibration = self._declare(8)
        self._encoders = self.DeclareVectorInputPort("encoder_positions", self._nj)
        self._velocities = self.DeclareVectorInputPort("encoder_velocities", self._nj)
        self._imu = self.DeclareVectorInputPort("imu", 6)
        self._ft = self.DeclareVectorInputPort("ft_wrenches", 36)
        self.DeclareStateOutputPort("robot_state", self._x)
        self.DeclareStateOutputPort("hand_wrenches_W", self._hands_state)
        self.DeclareStateOutputPort("pad_forces_W", self._pads_state)
        self.DeclareStateOutputPort("imu_attitude_W", self._attitude)
        self.DeclarePeriodicDiscreteUpdateEvent(hw.period_s, 0.0, self._Update)

    def _declare(self, n: int):
        return self.DeclareDiscreteState(np.zeros(n))

    def _Update(self, context: Context, out: DiscreteValues) -> None:
        T = self._hw.period_s
        get = context.get_discrete_state
        x_prev = get(self._x).value()
        anchor = get(self._anchor).value().copy()
        q_j = self._encoders.Eval(context)
        calibration = get(self._calibration).value().copy()
        imu = self._imu.Eval(context) - _biases(calibration)
        started = anchor[0] > 0.5
        v_prev = x_prev[self._nq :]
        v_j = self._velocities.Eval(context)
        R_WS = self._attitude_step(get(self._attitude).value(), imu, T)
        R_WB, p_WB, R_BS = self._base_pose(q_j, R_WS, anchor)
        w_W, v_Bo, w_joints_W = self._base_velocity(
            R_WB, p_WB, q_j, R_BS @ imu[:3], v_j, int(anchor[1])
        )
        if self._calibrate(calibration, context.get_time(), imu, R_WB @ R_BS, w_joints_W):
            R_WS = R_WB @ R_BS  # the attitude filter starts again, unbiased, at the legs'
        v = np.r_[w_W, v_Bo, v_j]
        # The accelerations over the tick, unfiltered, as the F/T sensors are: a filter on
        # one and not the other (3 Hz) made the arms' estimated wrench lag their motion, and
        # the arms oscillated against the controller's compensation (measured).
        vdot = (v - v_prev) / T if started else np.zeros(self._nv)
        # The positions are the estimate's already (_base_velocity set them).
        self._plant.SetVelocities(self._context, self._instance, v)
        raw = self._pieces.external_wrenches(self._context, vdot, self._ft.Eval(context))
        wrenches = self._two_tick_mean(raw, get(self._last_wrenches).value(), started)
        pads = np.concatenate([wrenches[k, 3:] for k in self._pad_piece])
        hands = np.concatenate(
            [
                wrench_at(wrenches[k], frame.CalcPoseInWorld(self._context).translation())
                for k, frame in zip(self._hand_piece, self._hands, strict=True)
            ]
        )
        touch = self._hand_contacts(get(self._touch).value(), hands)
        hands = hands * np.repeat(touch[4:6], 6)
        anchor[0] = 1.0
        self._switch_anchor(anchor, wrenches)
        out.set_value(self._touch, touch)
        out.set_value(self._calibration, calibration)
        out.set_value(self._x, self._predicted(R_WB, p_WB, q_j, v))
        out.set_value(self._anchor, anchor)
        out.set_value(self._attitude, RotationMatrix(R_WS).ToQuaternion().wxyz())
        out.set_value(self._hands_state, hands)
        out.set_value(self._pads_state, pads)
        out.set_value(self._last_wrenches, raw.ravel())

    @staticmethod
    def _two_tick_mean(raw: np.ndarray, last: np.ndarray, started: bool) -> np.ndarray:
        """The pieces' wrenches averaged over this tick and the last: a zero at the
        controller's Nyquist rate. Each tick's wrench carries the error of its own
        acceleration (a mean over the tick against the sensors' instant), which the torques
        computed from it change at the next tick; unaveraged, that loop rang at 50 Hz
        (the soles' left-right split alternating by 11 N, chatter 72 N on the default run;
        averaged, 3 N and 34 N: measured)."""
        return (raw + last.reshape(raw.shape)) / 2.0 if started else raw

    def _predicted(self, R_WB, p_WB, q_j, v) -> np.ndarray:
        """The state in the middle of the tick over which the torques computed from it act,
        delay_ticks + 1/2 ticks on (the measurements' latency compensated): the positions
        moved on by the velocities (sole chatter 138 N without, 53 N to the tick's start,
        32 N to its middle; measured on the default run)."""
        h = self._hw.latency_s
        R = exp_rotation(v[:3] * h) @ R_WB
        quat = RotationMatrix(R).ToQuaternion().wxyz()
        return np.r_[quat, p_WB + v[3:6] * h, q_j + v[6:] * h, v]

    def _hand_contacts(self, touch: np.ndarray, hands: np.ndarray) -> np.ndarray:
        """Each hand's contact, a Schmitt trigger on its estimated force (as robotology's
        estimators detect the feet's): made once the force stays above
        hand_contact_make_N for hand_contact_time_s, broken once it stays below
        hand_contact_break_N as long; the wrench's weight then ramps to 1 (or 0) over
        hand_contact_time_s, so that no make or break steps the controller's input
        (a step of the make threshold, 5 N a hand, otherwise). touch: [contact (2), time
        past the threshold (2), weight (2)]."""
        hw, T = self._hw, self._hw.period_s
        touch = touch.copy()
        for i in range(2):
            force = float(np.linalg.norm(hands[6 * i + 3 : 6 * i + 6]))
            crossing = (
                force < hw.hand_contact_break_N if touch[i] else force > hw.hand_contact_make_N
            )
            touch[2 + i] = touch[2 + i] + T if crossing else 0.0
            if touch[2 + i] >= hw.hand_contact_time_s - 1e-9:
                touch[i], touch[2 + i] = 1.0 - touch[i], 0.0
            step = T / hw.hand_contact_time_s
            touch[4 + i] = (
                min(1.0, touch[4 + i] + step) if touch[i] else max(0.0, touch[4 + i] - step)
            )
        return touch

    def _calibrate(
        self, calibration: np.ndarray, t: float, imu: np.ndarray, R_WS, w_joints_W
    ) -> bool:
        """The IMU's biases from the robot seated still over hw.imu_calibration_s: the
        gyroscope's mean less the turn of the joints between base and IMU (w_joints_W:
        the neck's, which its position loop keeps moving by a few 0.01 rad/s), and the
        accelerometer's mean less gravity in the IMU frame at the legs' attitude (their
        tilt is the IMU's share of it, small before calibration). calibration is updated
        in place; True at the tick the biases are set."""
        if calibration[7] > 0.5:
            return False
        start, end = self._hw.imu_calibration_s
        if t < start - 1e-9:
            return False
        if t < end - 1e-9:
            calibration[0] += 1.0
            calibration[1:4] += imu[:3] - R_WS.T @ w_joints_W
            calibration[4:7] += imu[3:] - R_WS.T @ self._gravity
            return False
        calibration[7] = 1.0
        return True

    def imu_biases(self, context: Context) -> np.ndarray:
        """The IMU's biases [gyroscope (3), accelerometer (3)] as calibrated (0 until then)."""
        return _biases(context.get_discrete_state(self._calibration).value())

    def _attitude_step(self, wxyz: np.ndarray, imu: np.ndarray, T: float) -> np.ndarray:
        """The attitude filter's next R_WS: the gyroscope's rotation over T, then a turn of
        T / time constant of the way toward the accelerometer's up."""
        R = RotationMatrix(Quaternion(wxyz / np.linalg.norm(wxyz))).matrix()
        R = R @ exp_rotation(imu[:3] * T)
        up = R @ imu[3:]
        norm = float(np.linalg.norm(up))
        if norm > 0.0:
            k = min(1.0, T / self._hw.attitude_time_constant_s)
            R = exp_rotation(k * cross(up / norm, np.array([0.0, 0.0, 1.0]))) @ R
        return R

    def _base_pose(
        self, q_j: np.ndarray, R_WS: np.ndarray, anchor: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The base's pose (R_WB, p_WB) from the anchored sole and the legs, its tilt blended
        with the IMU's (module docstring); and R_BS, the IMU frame in the base."""
        plant, c = self._plant, self._context
        plant.SetPositions(c, self._instance, np.r_[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, q_j])
        X_BF = self._soles[int(anchor[1])].CalcPoseInWorld(c)
        R_BS = self._imu_frame.CalcPoseInWorld(c).rotation().matrix()
        R_WF = RotationMatrix(Quaternion(anchor[5:9] / np.linalg.norm(anchor[5:9]))).matrix()
        R_kin = R_WF @ X_BF.rotation().matrix().T
        delta = rotation_vector(R_WS @ R_BS.T @ R_kin.T)
        delta[2] = 0.0  # the yaw is the legs': the IMU's gyroscope drifts about gravity
        R_WB = exp_rotation(self._tilt_weight * delta) @ R_kin
        p_WB = anchor[2:5] - R_WB @ X_BF.translation()
        return R_WB, p_WB, R_BS

    def _base_velocity(
        self, R_WB, p_WB, q_j, w_S_B: np.ndarray, v_j, sole: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The base's angular velocity (the gyroscope's, w_S_B in the base frame, less the
        joints' share between base and IMU), its origin's velocity that keeps the
        anchored sole still, and that joints' share, all in W."""
        plant, c = self._plant, self._context
        quat = RotationMatrix(R_WB).ToQuaternion().wxyz()
        plant.SetPositions(c, self._instance, np.r_[quat, p_WB, q_j])
        world = plant.world_frame()
        start = self._v_start
        J_imu = plant.CalcJacobianAngularVelocity(
            c, JacobianWrtVariable.kV, self._imu_frame, world, world
        )[:, start : start + self._nv]
        w_joints_W = J_imu[:, 6:] @ v_j
        w_W = R_WB @ w_S_B - w_joints_W
        J = plant.CalcJacobianTranslationalVelocity(
            c, JacobianWrtVariable.kV, self._soles[sole], np.zeros(3), world, world
        )[:, start : start + self._nv]
        return w_W, -(J[:, :3] @ w_W + J[:, 6:] @ v_j), w_joints_W

    def _switch_anchor(self, anchor: np.ndarray, wrenches: np.ndarray) -> None:
        """Moves the anchor to the other sole once it carries four times the anchored
        sole's load (hysteresis: a foot that merely shares the load keeps it), latching
        where that sole is now."""
        loads = [wrenches[self._pieces.piece_of(f.body().name()), 5] for f in self._soles]
        now = int(anchor[1])
        other = 1 - now
        if loads[other] > 4.0 * max(loads[now], 0.0) and loads[other] > 0.0:
            X = self._soles[other].CalcPoseInWorld(self._context)
            anchor[1] = other
            anchor[2:5] = X.translation()
            anchor[5:9] = X.rotation().ToQuaternion().wxyz()


def _biases(calibration: np.ndarray) -> np.ndarray:
    """The IMU's biases of a calibration state (_calibrate): the sums' means once done."""
    if calibration[7] < 0.5:
        return np.zeros(6)
    return calibration[1:7] / max(calibration[0], 1.0)


def _tilt_weight(hw: ICubHardware) -> float:
    """The IMU's share of the base's tilt, by inverse variances: the legs' tilt errs by
    the encoders' quantization along the six joints from sole to base (uniform, step /
    sqrt(12) each); the attitude filter's by the gyroscope's bias over its time constant
    and the accelerometer's bias over g."""
    step = 2.0 * math.pi / hw.encoder_counts
    legs = math.sqrt(6.0) * step / math.sqrt(12.0)
    imu = hw.gyro_bias_rad_s * hw.attitude_time_constant_s + hw.accel_bias_mps2 / 9.81
    imu = max(imu, hw.gyro_noise_rad_s * math.sqrt(hw.attitude_time_constant_s * hw.period_s))
    return legs**2 / (legs**2 + imu**2)
