"""The recorded helper (human.mode: recorded): a person's hand wrenches replayed from a
CSV file (config/recording.py reads and checks it; its format: docs/helpers.md).

RecordedWrenchSource is a HandWrenchHelper (helper/plugin.py), with HumanWrenchSource's
ports: robot_state in (used only when the samples are in the hand frame); hand_wrenches_W
(12: [torque_l, force_l, torque_r, force_r]) and spatial_forces out. Each time its output
is computed it
interpolates the samples linearly at the context's time (zero before the first sample
and after the last), rotates them into the world if they are in the hand frame, and
applies torques as well as forces at the hand frame's origin.

write_scripted_recording writes a scenario's scripted pulls as such a file, sampled as a
force plate would log them: the shipped recordings/default_pull.csv is the default
scenario's pull (tools/record_default_pull.py), not a measurement of a person.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from drake_standup.config import HumanConfig, load_scenario
from drake_standup.config.recording import load_recording, write_recording
from drake_standup.helper.hands import TASK_FRAMES, scripted_forces
from drake_standup.helper.plugin import HandWrenchHelper
from drake_standup.robot.icub import Robot

# A force plate's rate: the shipped recording's samples. Hz.
PLATE_RATE_HZ = 1000.0
# A written recording's forces are rounded to this many decimals of a newton: far below
# a force plate's resolution, and a ramp's samples read as the decimals they are (0.03 N
# a millisecond on the default pull's, not 0.029999999999996696).
FORCE_DECIMALS = 6


class RecordedWrenchSource(HandWrenchHelper):
    """A recording's wrenches on the robot's hands, at the hand frames' origins: a helper
    as any plug-in's (helper/plugin.py), its hand_wrenches the recording's."""

    def __init__(self, plant: MultibodyPlant, robot: Robot, config: HumanConfig):
        super().__init__(plant, robot, config)
        recording = load_recording(config.recorded.file)
        self._times = recording.times_s
        # One row per column of hand_wrenches_W: what np.interp reads per column.
        self._columns = np.ascontiguousarray(recording.wrenches.T)
        self._in_hand = config.recorded.frame == "hand"
        self._context = plant.CreateDefaultContext()
        self._frames = [robot.frame(plant, name) for name in TASK_FRAMES]
        # In the world frame the wrenches are a function of time alone: the last time and
        # its wrenches (the integrator sets a step's end time twice, a change to Drake).
        self._last: tuple[float, np.ndarray] | None = None

    def sampled(self, t: float) -> np.ndarray:
        """(12,) the recording at time t in its own frame: each column interpolated
        linearly between the samples around t, zero outside the recording."""
        times = self._times
        return np.array(
            [np.interp(t, times, column, left=0.0, right=0.0) for column in self._columns]
        )

    def hand_wrenches(self, time_s: float, robot_state: np.ndarray) -> np.ndarray:
        """hand_wrenches_W (12,): the recording at time_s, in the world."""
        if self._in_hand:
            return self._to_world(robot_state, self.sampled(time_s))
        if self._last is None or self._last[0] != time_s:
            self._last = time_s, self.sampled(time_s)
        return self._last[1]

    def _to_world(self, robot_state: np.ndarray, wrenches_H: np.ndarray) -> np.ndarray:
        """wrenches_H (12,), each hand's torque and force in its hand frame, rotated by
        that frame's orientation in the world at robot_state (R_WH)."""
        plant, c = self.plant, self._context
        plant.SetPositionsAndVelocities(c, self.robot.model_instance, robot_state)
        wrenches = np.empty(12)
        for i, frame in enumerate(self._frames):
            R_WH = frame.CalcRotationMatrixInWorld(c).matrix()
            for part in (slice(6 * i, 6 * i + 3), slice(6 * i + 3, 6 * i + 6)):
                wrenches[part] = R_WH @ wrenches_H[part]
        return wrenches


def make_recorded_helper(
    plant: MultibodyPlant, robot: Robot, human_config: HumanConfig
) -> RecordedWrenchSource:
    """Replays a pull recorded in a CSV file (human.recorded: docs/helpers.md)."""
    return RecordedWrenchSource(plant, robot, human_config)


def write_scripted_recording(
    scenario: Path | str, path: Path | str, rate_hz: float = PLATE_RATE_HZ
) -> None:
    """The scripted pulls of a scenario file (human.pulls, world frame) written to path as
    a recording: sampled at rate_hz from t = 0 to the scenario's duration_s, as a force
    plate logs a trial; forces only, to the micronewton (FORCE_DECIMALS). Between its
    samples the replay interpolates linearly, so a pull whose ramps start and end on the
    samples replays as scripted (to 1e-6 N)."""
    loaded = load_scenario(scenario)
    times = np.arange(round(loaded.duration_s * rate_hz) + 1) / rate_hz
    forces = np.array([scripted_forces(loaded.human.pulls, t).ravel() for t in times])
    forces = np.round(forces, FORCE_DECIMALS) + 0.0  # + 0.0: no -0 in the file
    write_recording(path, times, forces)
