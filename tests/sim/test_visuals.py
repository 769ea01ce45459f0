"""The helper's visuals (visuals.py): what Meshcat was last told, against the plant's
own kinematics and the pull; and that they are in a normal run's recording."""

from __future__ import annotations

import base64
import re

import msgpack
import numpy as np
from pydrake.math import RigidTransform
from test_live import _click, _Live, _quick, _set_pull

from drake_standup.config import SCENARIO_DIR, load_scenario
from drake_standup.sim.live import STAND_UP
from drake_standup.sim.simulate import simulate
from drake_standup.sim.visuals import (
    ARROW_HEAD_M,
    COM_SIDE_OFFSET_M,
    PREFIX,
    PSI_DOT_M,
    PULL_M_PER_N,
)


def _transform(meshcat, path: str) -> RigidTransform:
    matrix = msgpack.unpackb(meshcat._GetPackedTransform(path))["matrix"]
    return RigidTransform(np.array(matrix).reshape(4, 4).T)


def _property(meshcat, path: str, name: str):
    return msgpack.unpackb(meshcat._GetPackedProperty(path, name))["value"]


def test_arrows_spheres_lamp_and_bars_show_the_pull_com_state_and_psi_dot():
    """Each hand's arrow starts at the hand frame's origin (the plant's kinematics),
    points along the pull and is |f| PULL_M_PER_N long; an unpulled hand has none;
    the spheres sit at the CoM and at x_d (offset sideways); the lamp of the current
    state alone is lit; the psi_dot bar is PSI_DOT_M psi_dot tall."""
    live = _Live(_quick())
    _set_pull(live.meshcat, (12.0, 9.0), (0.0, 0.0))
    _click(live.meshcat, STAND_UP)  # state 2 from 0.2 s
    # To a publish time (every 40 ms) past the balance time and the pull's first step.
    live.advance(0.24)
    m, plant, robot = live.meshcat, live.plant, live.built.station.robot
    hand = robot.frame(plant, "l_hand").CalcPoseInWorld(live.plant_context).translation()
    arrow = _transform(m, f"{PREFIX}/pull/left")
    np.testing.assert_allclose(arrow.translation(), hand, atol=1e-12)
    np.testing.assert_allclose(arrow.rotation().col(2), [0.8, 0.0, 0.6], atol=1e-12)
    length = 15.0 * PULL_M_PER_N
    assert _transform(m, f"{PREFIX}/pull/left/head").translation()[2] == length
    assert _property(m, f"{PREFIX}/pull/left/shaft/scaled", "scale")[2] == length - ARROW_HEAD_M[0]
    assert _property(m, f"{PREFIX}/pull/left", "visible") is True
    assert _property(m, f"{PREFIX}/pull/right", "visible") is False

    com = plant.CalcCenterOfMassPositionInWorld(live.plant_context, [robot.model_instance])
    side = np.array([0.0, COM_SIDE_OFFSET_M, 0.0])
    np.testing.assert_allclose(_transform(m, f"{PREFIX}/com").translation(), com + side)
    x_d = live.output("x_d_W")
    np.testing.assert_allclose(_transform(m, f"{PREFIX}/com_reference").translation(), x_d + side)

    state = int(live.output("standup_state")[0])
    assert state == 2
    for k in range(1, 5):
        assert _property(m, f"{PREFIX}/state/{k}", "visible") is (k == state)
    psi_dot = live.output("psi_dot")[0]
    assert _property(m, f"{PREFIX}/psi_dot/bar/scaled", "scale")[2] == PSI_DOT_M * psi_dot


def test_a_normal_runs_recording_holds_the_arrows(tmp_path):
    """recording.html of the assisted scenario (pull from 0.1 s) carries the pull's
    arrows, the spheres and the bars. The arrows' and the bar's own paths (their
    shapes hang below them) are named only by the animation's tracks: a normal run
    sends nothing live while it records."""
    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml")
    scenario.duration_s = 0.4
    for pull in scenario.human.pulls:
        pull.start_s = 0.1
    simulate(scenario, tmp_path, progress=False)
    paths = _recorded_paths((tmp_path / "recording.html").read_text())
    for path in ("pull/left", "pull/right", "com_reference", "psi_dot/bar", "state/1"):
        assert f"{PREFIX}/{path}" in paths


def _recorded_paths(html: str) -> set[str]:
    """Every scene path the page's embedded commands (base64 msgpack) name, objects and
    animation tracks alike."""
    found = set()

    def walk(x) -> None:
        if isinstance(x, dict):
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
        elif isinstance(x, str) and x.startswith("/"):
            found.add(x)

    for data in re.findall(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)", html):
        walk(msgpack.unpackb(base64.b64decode(data), strict_map_key=False))
    return found


def _angle_deg(eye: np.ndarray, target: np.ndarray, point: np.ndarray) -> float:
    a, b = target - eye, point - eye
    return float(np.degrees(np.arccos(a @ b / np.linalg.norm(a) / np.linalg.norm(b))))


def test_the_camera_frames_the_robot_and_a_kneeling_person():
    """With a person's body helping, the default camera sees both the robot's default
    target and the person (each within 30 deg of its axis; Meshcat's field of view is
    75 deg high) side by side: the person at most 0.15 m nearer the camera than the
    robot, where the default view has them 0.3 m or more in front of it (it looked at
    the robot through the person). Without a person, or where the scenario sets the
    camera, the scenario's pose is kept."""
    from drake_standup.config.scenario import VisualizationConfig
    from drake_standup.sim.visuals import camera_pose

    vis = VisualizationConfig()
    robot = np.array(vis.target_xyz_m)
    eye, target = camera_pose(vis, None)
    assert eye.tolist() == vis.camera_xyz_m and target.tolist() == vis.target_xyz_m

    def nearer(eye: np.ndarray, person: np.ndarray) -> float:
        return float(np.linalg.norm(robot - eye) - np.linalg.norm(person - eye))

    for x in (0.7, 0.9, 1.2):  # where a short, a tall and a far person kneel
        person = np.array([x, 0.0, 0.55])  # their chest, kneeling
        assert nearer(np.array(vis.camera_xyz_m), person) >= 0.3
        eye, target = camera_pose(vis, RigidTransform([x, 0.0, 0.0]))
        assert _angle_deg(eye, target, robot) < 30.0
        assert _angle_deg(eye, target, person) < 30.0
        assert nearer(eye, person) <= 0.15
    vis.camera_xyz_m = [2.0, 0.0, 1.0]
    eye, _ = camera_pose(vis, RigidTransform([0.9, 0.0, 0.0]))
    assert eye.tolist() == [2.0, 0.0, 1.0]
