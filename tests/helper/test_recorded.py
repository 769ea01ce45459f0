"""The recorded helper (human.mode: recorded): the CSV loader on written files (known
values, optional torques, extra columns), the replay's linear interpolation against
values worked out by hand, the hand frame's rotation against a rotation written out by
hand, torques reaching the plant, each bad file as one ScenarioError line (in process and
through the command line), the shipped recording as its generator writes it, and (slow)
scenarios/recorded.yaml standing up as scenarios/assisted.yaml does."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import FixedOffsetFrame, SpatialInertia

from drake_standup.config import SCENARIO_DIR, HumanConfig, ScenarioError, load_scenario
from drake_standup.config.recording import (
    REQUIRED,
    WRENCH_COLUMNS,
    RecordedHelperConfig,
    load_recording,
)
from drake_standup.helper.hands import scripted_forces
from drake_standup.helper.recorded import (
    RecordedWrenchSource,
    make_recorded_helper,
    write_scripted_recording,
)
from drake_standup.robot.icub import add_icub

REPO = Path(__file__).resolve().parents[2]
HEADER = ",".join(REQUIRED)
# Three samples: the left hand's x force and the right hand's z force change, the rest
# hold (N); interpolated, left_fx at 0.25 s is 1 + (3 - 1) * 0.25 / 0.5 = 2.0.
SAMPLES = "0.0,1,0,0,0,0,-2\n0.5,3,0,0,0,0,4\n2.0,0,5,0,0,0,4\n"


def _csv(tmp_path: Path, text: str, name: str = "rec.csv") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _column(name: str) -> int:
    return WRENCH_COLUMNS.index(name)


# --- the loader ---------------------------------------------------------------------------


def test_the_loader_reads_the_columns_by_name_in_the_replays_order(tmp_path):
    """Forces land in hand_wrenches_W's layout [torque_l, force_l, torque_r, force_r];
    absent torques are zero; an extra column and spaces after the commas are ignored."""
    text = "note, right_fz_N, time_s, left_fx_N, left_fy_N, left_fz_N, right_fx_N, right_fy_N\n"
    text += "a, 6, 0.0, 1, 2, 3, 4, 5\nb, 12, 0.1, 2, 4, 6, 8, 10\n"
    recording = load_recording(str(_csv(tmp_path, text)))
    np.testing.assert_array_equal(recording.times_s, [0.0, 0.1])
    expected = np.zeros((2, 12))
    expected[0, [3, 4, 5, 9, 10, 11]] = [1, 2, 3, 4, 5, 6]
    expected[1] = 2 * expected[0]
    np.testing.assert_array_equal(recording.wrenches, expected)
    assert not recording.wrenches.flags.writeable  # the cached samples stay as read


def test_the_loader_reads_torques_where_given(tmp_path):
    """Two torque columns given, the other four zero."""
    text = f"{HEADER},left_ty_Nm,right_tz_Nm\n0,1,2,3,4,5,6,0.5,-0.25\n1,1,2,3,4,5,6,0.5,-0.25\n"
    wrenches = load_recording(str(_csv(tmp_path, text))).wrenches
    np.testing.assert_array_equal(wrenches[0], [0, 0.5, 0, 1, 2, 3, 0, 0, -0.25, 4, 5, 6])


def test_the_shipped_recording_is_found_by_its_name_from_anywhere(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    recording = load_recording("recordings/default_pull.csv")
    assert recording.times_s[0] == 0.0 and len(recording.times_s) == 15001


def test_the_shipped_recording_is_what_its_generator_writes(tmp_path):
    """recordings/default_pull.csv is tools/record_default_pull.py's output from the
    default scenario's pulls as they are now (rewrite it when they change)."""
    path = tmp_path / "pull.csv"
    write_scripted_recording(SCENARIO_DIR / "assisted.yaml", path)
    assert path.read_bytes() == (REPO / "recordings" / "default_pull.csv").read_bytes()


# --- the replay ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def icub():
    plant = MultibodyPlant(0.0)
    robot = add_icub(plant, visuals=False)
    plant.Finalize()
    return plant, robot


def _source(plant, robot, path: Path | str, frame: str = "world") -> RecordedWrenchSource:
    config = HumanConfig(mode="recorded", recorded=RecordedHelperConfig(str(path), frame))
    return make_recorded_helper(plant, robot, config)


def _context(source: RecordedWrenchSource, t: float, state=None):
    """source's context at time t, its robot_state input fixed (zeros if not given)."""
    context = source.CreateDefaultContext()
    port = source.GetInputPort("robot_state")
    port.FixValue(context, np.zeros(port.size()) if state is None else state)
    context.SetTime(t)
    return context


def _wrenches(source: RecordedWrenchSource, t: float, state=None) -> np.ndarray:
    return source.GetOutputPort("hand_wrenches_W").Eval(_context(source, t, state))


@pytest.mark.parametrize(
    ("t", "left_fx", "left_fy", "right_fz"),
    [
        (-0.1, 0.0, 0.0, 0.0),  # before the first sample: nobody pulls
        (0.0, 1.0, 0.0, -2.0),  # on a sample: the sample
        (0.25, 2.0, 0.0, 1.0),  # 1 + 2 * 0.25 / 0.5; -2 + 6 * 0.25 / 0.5
        (0.5, 3.0, 0.0, 4.0),
        (1.0, 2.0, 5.0 / 3.0, 4.0),  # 3 - 3 * 0.5 / 1.5; 5 * 0.5 / 1.5
        (2.0, 0.0, 5.0, 4.0),  # the last sample
        (2.001, 0.0, 0.0, 0.0),  # after it: let go
    ],
)
def test_the_replay_interpolates_linearly_and_is_zero_outside(
    tmp_path, icub, t, left_fx, left_fy, right_fz
):
    source = _source(*icub, _csv(tmp_path, f"{HEADER}\n{SAMPLES}"))
    expected = np.zeros(12)
    expected[[_column("left_fx_N"), _column("left_fy_N"), _column("right_fz_N")]] = [
        left_fx,
        left_fy,
        right_fz,
    ]
    np.testing.assert_allclose(_wrenches(source, t), expected, rtol=0, atol=1e-12)


def test_the_shipped_recording_replays_the_default_pull(icub):
    """On the 1 kHz samples and between them (linear ramps: exact but for the file's
    micronewtons), the default scenario's scripted forces."""
    source = _source(*icub, "recordings/default_pull.csv")
    pulls = load_scenario("assisted").human.pulls
    for t in (2.9995, 3.0, 3.0004, 3.2501, 3.4999, 7.0, 10.7502, 10.9999, 11.0, 14.0, 15.5):
        forces = _wrenches(source, t).reshape(2, 6)[:, 3:]
        np.testing.assert_allclose(forces, scripted_forces(pulls, t), rtol=0, atol=1e-6)


def _toy_hands(R_WB: RotationMatrix, R_BL: RotationMatrix, R_BR: RotationMatrix):
    """A plant of one free body carrying the two hand frames at the given rotations (a
    stand-in for Robot with their names), posed at R_WB; returns (plant, robot, state)."""
    plant = MultibodyPlant(0.0)
    toy = plant.AddModelInstance("toy")
    body = plant.AddRigidBody("palm", toy, SpatialInertia.SolidBoxWithMass(1.0, 0.1, 0.1, 0.1))
    names = {"l_hand": "l_hand_dh_frame", "r_hand": "r_hand_dh_frame"}
    for name, R in (("l_hand_dh_frame", R_BL), ("r_hand_dh_frame", R_BR)):
        plant.AddFrame(FixedOffsetFrame(name, body.body_frame(), RigidTransform(R, [0, 0.1, 0])))
    plant.Finalize()
    context = plant.CreateDefaultContext()
    plant.SetFreeBodyPose(context, body, RigidTransform(R_WB, [0.3, 0.0, 0.5]))
    robot = SimpleNamespace(
        model_instance=toy, frame=lambda p, name: p.GetFrameByName(names[name], toy)
    )
    return plant, robot, plant.GetPositionsAndVelocities(context, toy)


def test_hand_frame_samples_are_rotated_by_the_hand_frames_orientation(tmp_path):
    """frame: hand. The body yawed 90 degrees, the left hand frame on it pitched 90
    degrees, the right one as the body: R_WL = Rz(90) Ry(90), R_WR = Rz(90), written out
    here. A left force and torque along its hand's x end up along the world's -z; the
    right hand's y force along the world's -x, its x torque along the world's y."""
    Rz = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    Ry = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    plant, robot, state = _toy_hands(
        RotationMatrix(RollPitchYaw(0, 0, math.pi / 2)),
        RotationMatrix(RollPitchYaw(0, math.pi / 2, 0)),
        RotationMatrix(),
    )
    # Left: force (1, 0, 0), torque (0.5, 0, 0); right: force (0, 2, 0), torque (0.25, 0, 0).
    text = f"{HEADER},left_tx_Nm,right_tx_Nm\n0,1,0,0,0,2,0,0.5,0.25\n1,1,0,0,0,2,0,0.5,0.25\n"
    source = _source(plant, robot, _csv(tmp_path, text), frame="hand")
    w = _wrenches(source, 0.5, state).reshape(2, 6)
    R_WL, R_WR = Rz @ Ry, Rz
    np.testing.assert_allclose(w[0, :3], R_WL @ [0.5, 0, 0], atol=1e-12)
    np.testing.assert_allclose(w[0, 3:], R_WL @ [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(w[1, :3], R_WR @ [0.25, 0, 0], atol=1e-12)
    np.testing.assert_allclose(w[1, 3:], R_WR @ [0, 2, 0], atol=1e-12)
    np.testing.assert_allclose(w.ravel(), [0, 0, -0.5, 0, 0, -1, 0, 0.25, 0, -2, 0, 0], atol=1e-12)


def test_the_plant_gets_the_torques_and_forces_at_the_hand_frames(tmp_path, icub):
    """spatial_forces carries the recorded torque too, at the hand frame's origin; no
    entry once the recording is over."""
    plant, robot = icub
    text = f"{HEADER},left_tz_Nm\n0,1,2,3,0,0,0,0.5\n1,1,2,3,0,0,0,0.5\n"
    source = _source(plant, robot, _csv(tmp_path, text))
    context = _context(source, 0.5)
    (applied,) = source.GetOutputPort("spatial_forces").Eval(context)  # the left hand only
    frame = robot.frame(plant, "l_hand")
    assert applied.body_index == frame.body().index()
    np.testing.assert_array_equal(applied.p_BoBq_B, frame.GetFixedPoseInBodyFrame().translation())
    np.testing.assert_array_equal(applied.F_Bq_W.rotational(), [0, 0, 0.5])
    np.testing.assert_array_equal(applied.F_Bq_W.translational(), [1, 2, 3])
    context.SetTime(1.5)
    assert source.GetOutputPort("spatial_forces").Eval(context) == []


# --- bad recordings -----------------------------------------------------------------------

BAD = {
    "missing_file": (None, "not found"),
    "no_header": ("", "has no header row"),
    "missing_columns": (
        "time_s,left_fx_N,left_fy_N,left_fz_N\n0,1,2,3\n1,1,2,3\n",
        "misses column(s) right_fx_N, right_fy_N, right_fz_N",
    ),
    "column_twice": (
        f"{HEADER},time_s\n0,1,2,3,4,5,6,0\n1,1,2,3,4,5,6,1\n",
        "names column time_s twice",
    ),
    "time_repeats": (
        f"{HEADER}\n0,1,2,3,4,5,6\n0.5,1,2,3,4,5,6\n0.5,1,2,3,4,5,6\n",
        "row 4: time_s 0.5 is not after the row before's (0.5)",
    ),
    "time_goes_back": (
        f"{HEADER}\n0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n0.5,1,2,3,4,5,6\n",
        "row 4: time_s 0.5 is not after the row before's (1.0)",
    ),
    "not_a_number": (
        f"{HEADER}\n0,1,2,3,4,5,6\n1,1,2,abc,4,5,6\n",
        "row 3, column left_fz_N: 'abc' is not a number",
    ),
    "nan": (
        f"{HEADER}\n0,1,2,3,4,5,6\n1,1,2,3,4,nan,6\n",
        "row 3, column right_fy_N: 'nan' is not finite",
    ),
    "inf_torque": (
        f"{HEADER},right_tx_Nm\n0,1,2,3,4,5,6,0\n1,1,2,3,4,5,6,-inf\n",
        "row 3, column right_tx_Nm: '-inf' is not finite",
    ),
    "short_row": (f"{HEADER}\n0,1,2,3,4,5,6\n1,1,2,3,4\n", "row 3, column right_fy_N: empty"),
    "one_row": (f"{HEADER}\n0,1,2,3,4,5,6\n", "has 1 row of samples, fewer than 2"),
    "header_only": (f"{HEADER}\n", "has 0 rows of samples, fewer than 2"),
}


def _bad_file(tmp_path: Path, text: str | None) -> str:
    return str(tmp_path / "absent.csv") if text is None else str(_csv(tmp_path, text))


@pytest.mark.parametrize(("text", "problem"), list(BAD.values()), ids=list(BAD))
def test_a_bad_recording_is_one_error_line_naming_the_key_and_problem(tmp_path, text, problem):
    """Validation (load_scenario) refuses it before anything is built."""
    name = _bad_file(tmp_path, text)
    with pytest.raises(ScenarioError) as info:
        load_scenario("recorded", [("human.recorded.file", name)])
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"human.recorded.file: '{name}' {problem}; accepted: ")


def test_recorded_mode_without_a_file_is_an_error_and_other_modes_ignore_it(tmp_path):
    with pytest.raises(ScenarioError, match=r"^human.recorded.file: '' names no file; accepted"):
        load_scenario("recorded", [("human.recorded.file", "")])
    missing = str(tmp_path / "absent.csv")
    assert load_scenario("assisted", [("human.recorded.file", missing)]).human.mode == "scripted"
    with pytest.raises(ScenarioError, match=r"^human.recorded.frame: 'forearm' unknown; "):
        load_scenario("recorded", [("human.recorded.frame", "forearm")])


def test_a_bad_recording_on_the_command_line_is_one_error_line_and_exit_2(tmp_path):
    """`python -m drake_standup run` in a fresh process: exit code 2, one 'error:' line,
    no traceback, nothing written."""
    _csv(tmp_path, f"{HEADER}\n0,1,2,3,4,5,6\n1,1,2,x,4,5,6\n", "bad.csv")
    argv = ["run", "--scenario", "recorded", "--set", "human.recorded.file=bad.csv"]
    done = subprocess.run(
        [sys.executable, "-m", "drake_standup", *argv, "--no-recording", "--out", "o"],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(REPO)},
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""
    (line,) = done.stderr.splitlines()
    assert line.startswith(
        "error: human.recorded.file: 'bad.csv' row 3, column left_fz_N: 'x' is not a number; "
        "accepted: a CSV file"
    )
    assert not (tmp_path / "o").exists()


# --- the stand-up -------------------------------------------------------------------------


@pytest.mark.slow
def test_the_recorded_default_pull_stands_up_as_the_scripted_one():
    """scenarios/recorded.yaml (the default pull, replayed from its 1 kHz log) against
    scenarios/assisted.yaml: the same stand-up time within 0.01 s."""
    from drake_standup.sim.simulate import simulate

    times = {}
    for name in ("assisted", "recorded"):
        metrics = simulate(
            load_scenario(SCENARIO_DIR / f"{name}.yaml"), None, record=False, progress=False
        ).metrics
        assert metrics["success"], metrics["failure_reason"]
        times[name] = metrics["standup_time_s"]
    print(f"stand-up times: {times}")
    assert times["recorded"] == pytest.approx(times["assisted"], abs=0.01)


def test_the_diagram_builds_the_recorded_helper_for_its_mode():
    """human.mode: recorded wires RecordedWrenchSource to the station: the plant gets the
    recording's forces (the default pull's 7.5 N forward and up per hand at 3.25 s)."""
    from drake_standup.sim.diagram import build_diagram

    built = build_diagram(load_scenario("recorded"))
    human = built.diagram.GetSubsystemByName("human")
    assert isinstance(human, RecordedWrenchSource)
    plant = built.station.scene.plant
    root = built.diagram.CreateDefaultContext()
    root.SetTime(3.25)
    applied = plant.get_applied_spatial_force_input_port().Eval(plant.GetMyContextFromRoot(root))
    assert len(applied) == 2
    for force in applied:
        np.testing.assert_allclose(force.F_Bq_W.translational(), [7.5, 0.0, 7.5], atol=1e-9)
