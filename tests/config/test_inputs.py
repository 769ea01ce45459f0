"""Every user input is checked in one place (drake_standup.config: inputs.py and rules.py)
before anything simulates.

Each bad input goes through the command line (cli.main in this process, and a subset
through `python -m drake_standup` in a fresh one): exit code 2, stderr exactly one
'error:' line naming the key or file, the value and what is accepted, no traceback, nothing
written. The good inputs next to them still pass, checked against what Drake builds.
"""

from __future__ import annotations

import errno
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import icub_models
import pytest
import yaml
from pydrake.common.yaml import yaml_dump_typed
from pydrake.multibody.plant import MultibodyPlant

from drake_standup.cli import main
from drake_standup.config import (
    JOINT_TABLES,
    ChairConfig,
    InitialPose,
    PerturbationConfig,
    Push,
    RobotConfig,
    Scenario,
    ScenarioError,
    apply_overrides,
    validate,
)
from drake_standup.config.inputs import check_chair_file, model_names, scene_frames
from drake_standup.robot.icub import ContactModel, Robot, add_icub
from drake_standup.world.perturbations import robot_body_names

REPO = Path(__file__).resolve().parents[2]
SHIPPED_CHAIR = REPO / "models" / "chair.sdf"
MODEL = "iCubGazeboV2_5"
THIGHS = "l_upper_leg_back_contact, r_upper_leg_back_contact"
# The models of icub-models whose URDF lacks frames the scene needs, and those frames: the
# thighs' contact frames (the older iCubs), or all but the hand's (the hand models).
LACKING = {
    "iCubGenova03": THIGHS,
    "iCubLisboa01": THIGHS,
    "iCubNancy01": THIGHS,
    "left_hand_mk3": f"root_link, l_sole, r_sole, l_hand_dh_frame, r_hand_dh_frame, {THIGHS}",
    "left_wrist_mk2": f"root_link, l_sole, r_sole, l_hand_dh_frame, r_hand_dh_frame, {THIGHS}",
}
FITTING = [name for name in sorted(icub_models.get_robot_names()) if name not in LACKING]

SDF = '<sdf version="1.9">{}</sdf>'
CHAIR_CONTENT = (
    "an SDF file of one model with a link or frame named 'chair' (the scene welds it to the "
    "world), e.g. models/chair.sdf"
)
CHAIR_FILES = (
    "an SDF, OBJ or STL file path (absolute or relative to the current directory), or "
    "models/chair.sdf or models/chair_mesh.obj"
)
UTF8 = "a text file saved as UTF-8"
LATIN1 = "duration_s: 1.0\n# café\n".encode("latin-1")


def _shipped(folder: str) -> str:
    return ", ".join(sorted(p.stem for p in (REPO / folder).glob("*.yaml")))


def _revolute_joints(model: str) -> str:
    """The revolute joints of model's URDF, in its order (read here with xml.etree)."""
    root = ET.parse(icub_models.get_model_file(model)).getroot()
    return ", ".join(j.get("name") for j in root.findall("joint") if j.get("type") == "revolute")


@pytest.fixture(scope="module")
def built() -> dict[bool, tuple[MultibodyPlant, Robot]]:
    """The default model as the scene adds it (visuals on), reduced and not."""
    plants = {}
    for reduce in (True, False):
        plant = MultibodyPlant(0.0)
        plants[reduce] = plant, add_icub(plant, MODEL, reduce=reduce, visuals=True)
    return plants


# Bad input -> (files to write: name -> text, bytes or None for a folder; the command line;
# the one error line). In the line, {scenarios}, {sweeps}, {models}, {joints} and {bodies}
# stand for the shipped scenarios and sweeps, the models with the scene's frames, the
# default model's joints and its reduced model's bodies.
RUN = ["run", "--no-recording", "--out", "o"]
BAD = {
    # 1. The scenario file (--scenario).
    "scenario_missing": (
        {},
        [*RUN, "--scenario", "missing.yaml"],
        "scenario: file 'missing.yaml' not found; accepted: a YAML file or a shipped "
        "scenario: {scenarios}",
    ),
    "scenario_folder": (
        {"adir": None},
        [*RUN, "--scenario", "adir"],
        "scenario: 'adir' is a folder; accepted: a YAML file or a shipped scenario: {scenarios}",
    ),
    "scenario_utf16": (
        {"utf16.yaml": b"\xff\xfed\x00u\x00"},
        [*RUN, "--scenario", "utf16.yaml"],
        f"scenario: 'utf16.yaml' is not UTF-8 text (byte 0xff on line 1); accepted: {UTF8}",
    ),
    "scenario_latin1": (
        {"latin1.yaml": LATIN1},
        [*RUN, "--scenario", "latin1.yaml"],
        f"scenario: 'latin1.yaml' is not UTF-8 text (byte 0xe9 on line 2); accepted: {UTF8}",
    ),
    "scenario_unreadable": (
        {},
        [*RUN, "--scenario", "/proc/self/mem"],
        f"scenario: '/proc/self/mem' cannot be read ({os.strerror(errno.EIO)}); accepted: a "
        "file this user can read",
    ),
    "scenario_not_yaml": (
        {"bad.yaml": "duration_s: [1\n"},
        [*RUN, "--scenario", "bad.yaml"],
        'scenario bad.yaml: not valid YAML (while parsing a flow sequence in "<unicode '
        "string>\", line 1, column 13: duration_s: [1 ^ expected ',' or ']', but got "
        "'<stream end>' in \"<unicode string>\", line 2, column 1: ^)",
    ),
    "scenario_not_a_mapping": (
        {"list.yaml": "- 1\n- 2\n"},
        [*RUN, "--scenario", "list.yaml"],
        "scenario list.yaml: [1, 2]; accepted: a mapping of robot, duration_s, plant, "
        "simulator, human, response, compliance, advancement, standup, phases, controller, "
        "controller_period_s, "
        "initial, chair, seat_hold, fall, hardware, perturbation, visualization, log_period_s",
    ),
    "response_unknown": (
        {},
        [*RUN, "--set", "response=rigid"],
        "response: 'rigid' is not a known name; accepted: advancement | stiff | compliant, or "
        "module:attribute",
    ),
    "compliance_negative_stiffness": (
        {},
        [*RUN, "--set", "compliance.stiffness_N_per_m=-5"],
        "compliance.stiffness_N_per_m: -5.0; accepted: a number > 0",
    ),
    # 2. The chair file (chair.file).
    "chair_missing": (
        {},
        [*RUN, "--set", "chair.file=nope.sdf"],
        f"chair.file: file 'nope.sdf' not found; accepted: {CHAIR_FILES}",
    ),
    "chair_folder": (
        {"adir": None},
        [*RUN, "--set", "chair.file=adir"],
        f"chair.file: 'adir' is a folder; accepted: {CHAIR_FILES}",
    ),
    "chair_latin1": (
        {"chair.sdf": "<!-- café -->".encode("latin-1")},
        [*RUN, "--set", "chair.file=chair.sdf"],
        f"chair.file: 'chair.sdf' is not UTF-8 text (byte 0xe9 on line 1); accepted: {UTF8}",
    ),
    "chair_plain_text": (
        {"chair.txt": "a chair\n"},
        [*RUN, "--set", "chair.file=chair.txt"],
        f"chair.file: 'chair.txt' is not XML (syntax error: line 1, column 0); accepted: "
        f"{CHAIR_CONTENT}",
    ),
    "chair_xml_not_sdf": (
        {"robot.sdf": '<robot name="chair"><link name="chair"/></robot>'},
        [*RUN, "--set", "chair.file=robot.sdf"],
        f"chair.file: 'robot.sdf' is not SDF (its root element is <robot>, not <sdf>); "
        f"accepted: {CHAIR_CONTENT}",
    ),
    "chair_fails_drake": (
        {"broken.sdf": SDF.format('<model name="x"><link name="chair"><foo/></link></model>')},
        [*RUN, "--set", "chair.file=broken.sdf"],
        "chair.file: 'broken.sdf' fails Drake's SDF parser (<data-string>:1: error: At XML "
        'path /sdf/model[@name="x"]/link[@name="chair"]/foo: XML Element[foo], child of '
        "element[link], not defined in SDF. Copying[foo] as children of [link].); accepted: "
        f"{CHAIR_CONTENT}",
    ),
    "chair_missing_mesh": (
        {
            "mesh.sdf": SDF.format(
                '<model name="x"><link name="chair"><visual name="v"><geometry><mesh>'
                "<uri>nope.obj</uri></mesh></geometry></visual></link></model>"
            )
        },
        [*RUN, "--set", "chair.file=mesh.sdf"],
        "chair.file: 'mesh.sdf' fails Drake's SDF parser (/{cwd}/mesh.sdf:1: error: URI "
        f"'nope.obj' resolved to '{{cwd}}/nope.obj' which does not exist.); accepted: "
        f"{CHAIR_CONTENT}",
    ),
    "chair_no_chair_frame": (
        {"stool.sdf": SDF.format('<model name="stool"><link name="seat"/></model>')},
        [*RUN, "--set", "chair.file=stool.sdf"],
        "chair.file: 'stool.sdf' has no frame named 'chair' (model 'stool' has: seat, "
        f"__model__); accepted: {CHAIR_CONTENT}",
    ),
    "chair_two_models": (
        {
            "two.sdf": SDF.format(
                '<world name="w"><model name="a"><link name="chair"/></model>'
                '<model name="b"><link name="chair"/></model></world>'
            )
        },
        [*RUN, "--set", "chair.file=two.sdf"],
        f"chair.file: 'two.sdf' holds 2 models (a, b); accepted: {CHAIR_CONTENT}",
    ),
    "chair_welded_already": (
        {
            "welded.sdf": SDF.format(
                '<model name="x"><link name="chair"/><joint name="j" type="fixed">'
                "<parent>world</parent><child>chair</child></joint></model>"
            )
        },
        [*RUN, "--set", "chair.file=welded.sdf"],
        "chair.file: 'welded.sdf' cannot be welded to the world at its frame 'chair' "
        "(AddJoint(): This LinkJointGraph already has joint 'j' (model instance 2) connecting "
        "link 'world' to link 'chair'. Therefore adding joint 'world_welds_to_chair' (model "
        "instance 2) connecting link 'world' to link 'chair' is not allowed.); accepted: "
        f"{CHAIR_CONTENT}",
    ),
    # 3. The sweep file (drake-standup sweep PATH) and the base scenario it names.
    "sweep_missing": (
        {},
        ["sweep", "missing.yaml"],
        "sweep: file 'missing.yaml' not found; accepted: a YAML file or a shipped sweep: {sweeps}",
    ),
    "sweep_folder": (
        {"adir": None},
        ["sweep", "adir"],
        "sweep: 'adir' is a folder; accepted: a YAML file or a shipped sweep: {sweeps}",
    ),
    "sweep_latin1": (
        {"latin1.yaml": LATIN1},
        ["sweep", "latin1.yaml"],
        f"sweep: 'latin1.yaml' is not UTF-8 text (byte 0xe9 on line 2); accepted: {UTF8}",
    ),
    "sweep_not_yaml": (
        {"bad.yaml": "base: [assisted\n"},
        ["sweep", "bad.yaml"],
        'sweep bad.yaml: not valid YAML (while parsing a flow sequence in "<unicode '
        "string>\", line 1, column 7: base: [assisted ^ expected ',' or ']', but got "
        "'<stream end>' in \"<unicode string>\", line 2, column 1: ^)",
    ),
    "sweep_not_a_mapping": (
        {"list.yaml": "- assisted\n"},
        ["sweep", "list.yaml"],
        "sweep list.yaml: ['assisted']; accepted: a mapping of name, base, seed, samples, "
        "overrides, grid, random, perturbations, figures",
    ),
    "sweep_base_latin1": (
        {"latin1.yaml": LATIN1, "sweep.yaml": "base: latin1.yaml\n"},
        ["sweep", "sweep.yaml"],
        f"base: 'latin1.yaml' is not UTF-8 text (byte 0xe9 on line 2); accepted: {UTF8}",
    ),
    # 4. The output folder (--out), refused before anything simulates.
    "run_out_is_a_file": (
        {"afile": "x"},
        ["run", "--no-recording", "--out", "afile"],
        "--out: 'afile' is a file; accepted: a folder",
    ),
    "run_out_under_a_file": (
        {"afile": "x"},
        ["run", "--no-recording", "--out", "afile/sub"],
        "--out: 'afile/sub' lies under a file; accepted: a folder path whose parents are folders",
    ),
    "sweep_out_is_a_file": (
        {"afile": "x"},
        ["sweep", "assistance", "--out", "afile"],
        "--out: 'afile' is a file; accepted: a folder",
    ),
    # 5. A plant this controller cannot run.
    "continuous_plant": (
        {},
        [*RUN, "--set", "plant.time_step=0"],
        "plant.time_step: 0.0; accepted: a discrete plant's step, a number > 0 s (0, a "
        "continuous plant, cannot run the controller: it acts at the plant's steps)",
    ),
    "continuous_plant_in_a_file": (
        {"continuous.yaml": "plant:\n  time_step: 0.0\ncontroller_period_s: 0.01\n"},
        [*RUN, "--scenario", "continuous.yaml"],
        "plant.time_step: 0.0; accepted: a discrete plant's step, a number > 0 s (0, a "
        "continuous plant, cannot run the controller: it acts at the plant's steps)",
    ),
    # 6. Robot models whose URDF lacks frames the scene needs.
    **{
        f"model_{name}": (
            {},
            [*RUN, "--set", f"robot.model={name}"],
            f"robot.model: '{name}' lacks the frames the scene needs: {missing}; "
            "accepted: {models}",
        )
        for name, missing in LACKING.items()
    },
    # A rise no robot makes: a CoM height above the model's own CoM standing straight (in
    # the phase's arms, scene.check_com_heights, checked as the station is built, before
    # the first step), or not above the floor (config.rules).
    "rise_com_height_unreachable": (
        {},
        [*RUN, "--set", "phases.rise.com_height_m=5.0"],
        "phases.rise.com_height_m: 5.0; accepted: a number > 0 and <= 0.601 (m: "
        "iCubGazeboV2_5's CoM standing straight, 0.581, + 0.02)",
    ),
    # The bound is the model's: 0.59 m is within iCubGazeboV2_5's reach, not iCubGenova01's.
    "rise_com_height_beyond_this_model": (
        {},
        [
            *RUN,
            "--scenario",
            "unassisted",
            "--set",
            "robot.model=iCubGenova01",
            "--set",
            "phases.rise.com_height_m=0.59",
        ],
        "phases.rise.com_height_m: 0.59; accepted: a number > 0 and <= 0.579 (m: "
        "iCubGenova01's CoM standing straight, 0.559, + 0.02)",
    ),
    "rise_com_height_zero": (
        {},
        [*RUN, "--set", "phases.rise.com_height_m=0"],
        "phases.rise.com_height_m: 0.0; accepted: a number > 0",
    ),
    "rise_com_height_negative": (
        {},
        [*RUN, "--set", "phases.rise.com_height_m=-0.5"],
        "phases.rise.com_height_m: -0.5; accepted: a number > 0",
    ),
    # 7. Joint and body names the model does not have.
    "unknown_initial_joint": (
        {},
        [*RUN, "--set", "initial.joints_rad={l_knee: -1.7, l_kne: -1.7}"],
        "initial.joints_rad: unknown joint(s) l_kne; accepted: the joints of iCubGazeboV2_5: "
        "{joints}",
    ),
    "unknown_posture_joint": (
        {"posture.yaml": "phases:\n  lift_off:\n    posture_rad: {l_elbow: 0.3, elbow: 0.3}\n"},
        [*RUN, "--scenario", "posture.yaml"],
        "phases.lift_off.posture_rad: unknown joint(s) elbow; accepted: the joints of "
        "iCubGazeboV2_5: {joints}",
    ),
    # An older file's key (config/legacy.py) is read into the phase table, which is named.
    "unknown_posture_joint_older_key": (
        {"posture.yaml": "controller:\n  posture_state3_rad: {l_elbow: 0.3, elbow: 0.3}\n"},
        [*RUN, "--scenario", "posture.yaml"],
        "phases.lift_off.posture_rad: unknown joint(s) elbow; accepted: the joints of "
        "iCubGazeboV2_5: {joints}",
    ),
    "unknown_arm_weight_joint": (
        {},
        [*RUN, "--set", "controller.stance_arm_weight_by_joint={l_wrist: 7.0}"],
        "controller.stance_arm_weight_by_joint: unknown joint(s) l_wrist; accepted: the joints "
        "of iCubGazeboV2_5: {joints}",
    ),
    "unknown_seat_hinge_joint": (
        {},
        [*RUN, "--set", "controller.seat_hinge_joints=[l_hip, r_hip_pitch]"],
        "controller.seat_hinge_joints: unknown joint(s) l_hip; accepted: the joints of "
        "iCubGazeboV2_5: {joints}",
    ),
    "unknown_push_body": (
        {},
        [*RUN, "--set", "perturbation.pushes=[{body: torso}]"],
        "perturbation.pushes[0].body: 'torso' unknown; accepted: the bodies of iCubGazeboV2_5 "
        "reduced: {bodies}",
    ),
    "push_on_a_frame_of_the_reduced_model": (
        {},
        [*RUN, "--set", "perturbation.pushes=[{body: chest}, {body: l_hand_dh_frame}]"],
        "perturbation.pushes[1].body: 'l_hand_dh_frame' is a frame of the reduced model "
        "(robot.reduced: true), not a body; accepted: the bodies of iCubGazeboV2_5 reduced: "
        "{bodies}",
    ),
    "sweep_push_on_an_unknown_body": (
        {"pushes.yaml": "base: assisted\nperturbations:\n  push: {body: spine, magnitude_N: 10}\n"},
        ["sweep", "pushes.yaml"],
        "run 0 ({{'push_start_s': 5.0, 'push_duration_s': 0.2, 'push_magnitude_N': 10, "
        "'push_impulse_Ns': 2.0, 'push_azimuth_deg': 0.0, 'push_elevation_deg': 0.0}}): "
        "perturbation.pushes[0].body: 'spine' unknown; accepted: the bodies of "
        "iCubGazeboV2_5 reduced: {bodies}",
    ),
    # A run count no sweep means, refused from the sizes before any run is expanded
    # (tests/studies/test_sweep.py times it); the total counts the grid's combinations too.
    "sweep_too_many_samples": (
        {"many.yaml": "base: assisted\nsamples: 100000000\n"},
        ["sweep", "many.yaml"],
        "samples: 100000000; accepted: an integer from 1 to 10000 (runs in one sweep)",
    ),
    "sweep_grid_times_samples_too_many_runs": (
        {
            "many.yaml": "base: assisted\nsamples: 2000\ngrid:\n"
            "  advancement.psi_dot_upper: [1.5, 2.5]\n  fall.min_root_height_m: [0.1, 0.2, 0.3]\n"
        },
        ["sweep", "many.yaml"],
        "grid x samples: 2 advancement.psi_dot_upper x 3 fall.min_root_height_m x 2000 samples "
        "= 12000 runs; accepted: at most 10000 runs in one sweep",
    ),
    # 6. The comparison of responses (drake-standup compare).
    "compare_unknown_helper": (
        {},
        ["compare", "--helpers", "nobody"],
        "--helpers: file 'nobody' not found; accepted: a scenario YAML file, a shipped "
        "scenario ({scenarios}) or SWEEP#K, run K of a sweep ({sweeps})",
    ),
    "compare_run_beyond_the_sweep": (
        {},
        ["compare", "--helpers", "helpers#48"],
        "--helpers helpers#48: run '48' of sweep helpers; accepted: 0 to 47",
    ),
    "compare_unknown_response": (
        {},
        ["compare", "--responses", "stiff", "rigid"],
        "--responses rigid: 'rigid' is not a known name; accepted: advancement | stiff | "
        "compliant, or module:attribute",
    ),
}
# One of each kind through `python -m drake_standup` in a fresh process as well.
IN_A_FRESH_PROCESS = [
    "scenario_utf16",
    "chair_xml_not_sdf",
    "chair_fails_drake",
    "sweep_not_yaml",
    "run_out_under_a_file",
    "continuous_plant",
    "model_iCubGenova03",
    "unknown_seat_hinge_joint",
    "compare_run_beyond_the_sweep",
    "sweep_too_many_samples",
    "rise_com_height_unreachable",
]


def _expected(line: str, cwd: Path, built) -> str:
    plant, robot = built[True]
    return "error: " + line.format(
        scenarios=_shipped("scenarios"),
        sweeps=_shipped("sweeps"),
        models=", ".join(FITTING),
        joints=_revolute_joints(MODEL),
        bodies=", ".join(robot_body_names(plant, robot)),
        cwd=cwd,
    )


def _write(cwd: Path, files: dict) -> None:
    for name, content in files.items():
        path = cwd / name
        if content is None:
            path.mkdir()
        elif isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)


def _assert_one_error_line(code, stdout: str, stderr: str, expected: str, cwd: Path) -> None:
    assert "Traceback" not in stderr
    assert code == 2, stderr
    assert stderr.splitlines() == [expected]
    assert stdout == ""
    assert not list(cwd.rglob("metrics.json")) and not list(cwd.rglob("results.csv"))


@pytest.mark.parametrize(("files", "argv", "line"), list(BAD.values()), ids=list(BAD))
def test_bad_input_is_one_error_line_and_exit_2(
    tmp_path, monkeypatch, capfd, built, files, argv, line
):
    """cli.main on each bad input, run from a folder holding its files: exit code 2 and
    the one error line, on the process's stderr (capfd: Drake's own output included)."""
    _write(tmp_path, files)
    monkeypatch.chdir(tmp_path)
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    stdout, stderr = capfd.readouterr()
    _assert_one_error_line(code, stdout, stderr, _expected(line, tmp_path, built), tmp_path)


@pytest.mark.parametrize("name", IN_A_FRESH_PROCESS)
def test_bad_input_through_python_m_drake_standup(tmp_path, built, name):
    """The same bad inputs through the real command, in a fresh process."""
    files, argv, line = BAD[name]
    _write(tmp_path, files)
    env = {**os.environ, "PYTHONPATH": str(REPO)}  # this checkout's package
    done = subprocess.run(
        [sys.executable, "-m", "drake_standup", *argv],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    expected = _expected(line, tmp_path, built)
    _assert_one_error_line(done.returncode, done.stdout, done.stderr, expected, tmp_path)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads a file whatever its mode")
def test_a_scenario_without_read_permission(tmp_path, capfd):
    path = tmp_path / "secret.yaml"
    path.write_text("duration_s: 1.0\n")
    path.chmod(0)
    assert main([*RUN, "--scenario", str(path)]) == 2
    assert capfd.readouterr().err.splitlines() == [
        f"error: scenario: '{path}' cannot be read (Permission denied); accepted: a file this "
        "user can read"
    ]


# --- The good inputs next to the bad ones -----------------------------------------------


def test_the_shipped_chair_and_a_copy_of_it_pass(tmp_path, monkeypatch):
    """models/chair.sdf by its shipped name, a copy by its absolute path and by a path
    relative to the current folder: each validates, and names the file the scene loads."""
    assert check_chair_file("models/chair.sdf").resolve() == SHIPPED_CHAIR
    copy = tmp_path / "my_chair.sdf"
    copy.write_text(SHIPPED_CHAIR.read_text())
    scenario = apply_overrides(Scenario(), [("chair.file", str(copy))])
    assert check_chair_file(scenario.chair.file) == copy
    monkeypatch.chdir(tmp_path)
    scenario = validate(Scenario(chair=ChairConfig(file="my_chair.sdf")))
    assert check_chair_file(scenario.chair.file) == Path("my_chair.sdf")


def test_a_chair_frame_and_drake_warnings_pass_quietly(tmp_path, caplog):
    """A 'chair' that is a frame (not a link) passes, and what Drake warns about while the
    check parses the file is not logged (the scene's build warns once)."""
    path = tmp_path / "frame.sdf"
    model = '<link name="seat"><velocity_decay/></link><frame name="chair" attached_to="seat"/>'
    path.write_text(SDF.format(f'<model name="stool">{model}</model>'))
    with caplog.at_level("DEBUG", logger="drake"):
        assert check_chair_file(str(path)) == path
    assert [r.getMessage() for r in caplog.records if r.name == "drake"] == []


def test_a_changed_chair_file_is_checked_again(tmp_path):
    """The check is cached per file version: the same path, rewritten, is parsed again."""
    path = tmp_path / "chair.sdf"
    path.write_text(SHIPPED_CHAIR.read_text())
    check_chair_file(str(path))
    path.write_text(SDF.format('<model name="x"><link name="stool"/></model>'))
    os.utime(path, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns + 10**9))
    with pytest.raises(ScenarioError, match="has no frame named 'chair'"):
        check_chair_file(str(path))


@pytest.mark.parametrize("model", sorted(icub_models.get_robot_names()))
def test_a_model_validates_exactly_when_the_scene_can_be_built_on_it(model):
    """validate vs Drake: for every model of icub-models, validate passes if and only if
    add_icub (with the contact model's frames) builds it and every task frame, every
    default joint table's joint and the default push body resolve in the plant."""
    scenario = Scenario(
        robot=RobotConfig(model=model), perturbation=PerturbationConfig(pushes=[Push("chest")])
    )
    try:
        validate(scenario)
        valid = True
    except ScenarioError as err:
        assert str(err).startswith(f"robot.model: '{model}' lacks the frames the scene needs")
        valid = False
    try:
        plant = MultibodyPlant(0.0)
        robot = add_icub(plant, model, visuals=False)
        plant.Finalize()
        for task in Robot.TASK_FRAMES:
            robot.frame(plant, task)
        for _, table in _joint_tables(scenario):
            for name in table:
                plant.GetJointByName(name, robot.model_instance)
        plant.GetBodyByName("chest", robot.model_instance)
        builds = True
    except RuntimeError:
        builds = False
    assert valid == builds
    assert valid == (model in FITTING)


@pytest.mark.parametrize("reduce", [True, False], ids=["reduced", "full"])
def test_the_bodies_validate_accepts_are_the_built_plants(built, reduce):
    """model_names' bodies (read from the URDF's XML) vs the bodies of the robot Drake
    builds with robot.reduced: the same names in the same order."""
    plant, robot = built[reduce]
    assert list(model_names(MODEL).bodies(reduce)) == robot_body_names(plant, robot)
    assert set(model_names(MODEL).joints) == set(robot.joint_names)


def test_the_reduction_rule_on_a_model_with_massless_moving_links():
    """iCubGenova03 has massless links on revolute joints and massless links with visuals,
    which the default model has not (both stay bodies): model_names' reduced bodies vs
    Drake's plant of it (built without the contact frames it lacks)."""
    plant = MultibodyPlant(0.0)
    robot = add_icub(plant, "iCubGenova03", reduce=True, visuals=True, contact=ContactModel())
    bodies = robot_body_names(plant, robot)
    assert {"l_wrist_1", "torso_2", "neck_1"} <= set(bodies)
    assert list(model_names("iCubGenova03").bodies(True)) == bodies


def test_the_scene_frames_are_frames_of_the_built_plant(built):
    """scene_frames() vs the default model Drake builds: each one a frame of the robot,
    and every task frame either one of them or a frame the contact file adds on them."""
    plant, robot = built[True]
    for name in scene_frames():
        assert plant.HasFrameNamed(name, robot.model_instance), name
    assert set(Robot.TASK_FRAMES.values()) <= set(scene_frames()) | {
        "l_upper_leg_contact",
        "r_upper_leg_contact",
        "buttocks_contact",
        "seat_contact",
    }


def test_known_names_and_a_body_of_the_full_model_pass():
    """Joint tables with the model's own joints, and a push on a link that is a body of the
    full model (robot.reduced: false) though a frame of the reduced one, validate."""
    scenario = apply_overrides(
        Scenario(),
        [
            ("robot.reduced", False),
            ("controller.posture_weight_by_joint", {"l_knee": 2.0, "torso_yaw": 1.0}),
            ("controller.seat_hinge_joints", ["l_hip_roll", "r_hip_roll"]),
            ("perturbation.pushes", [{"body": "l_hand_dh_frame"}]),
        ],
    )
    assert scenario.perturbation.pushes[0].body == "l_hand_dh_frame"
    assert scenario.controller.seat_hinge_joints == ["l_hip_roll", "r_hip_roll"]


def _joint_tables(scenario: Scenario) -> list[tuple[str, object]]:
    """(key path, value) of every key of scenario that a JOINT_TABLES pattern names."""
    found = []

    def walk(key: str, value) -> None:
        if any(re.fullmatch(regex, key) for regex in patterns):
            found.append((key, value))
        items = value.items() if isinstance(value, dict) else ()
        items = enumerate(value) if isinstance(value, list) else items
        for step, item in items:
            walk(f"{key}[{step}]" if isinstance(step, int) else f"{key}.{step}", item)

    patterns = [
        re.escape(p).replace(r"\[\*\]", r"\[\d+\]").replace(r"\*", r"[^.\[]*") for p in JOINT_TABLES
    ]
    for key, value in yaml.safe_load(yaml_dump_typed(scenario)).items():
        walk(key, value)
    return found


def test_every_joint_table_names_a_key():
    """Each JOINT_TABLES pattern vs the key paths of the default scenario: a pattern that
    names nothing (a typo, a renamed field) checks nothing; each names joints (a mapping
    or a list of names)."""
    tables = _joint_tables(Scenario(initial=InitialPose(joints_rad={"l_knee": -1.7})))
    for pattern in JOINT_TABLES:
        regex = re.escape(pattern).replace(r"\[\*\]", r"\[\d+\]").replace(r"\*", r"[^.\[]*")
        assert any(re.fullmatch(regex, key) for key, _ in tables), pattern
    assert all(isinstance(table, dict | list) for _, table in tables)
    # Empty only where a phase holds the posture it starts from, and in the sit-down's
    # phases, which return to the postures the stand-up recorded (phases.py).
    empty = [key for key, table in tables if not table]
    assert empty == [f"phases.{name}.posture_rad" for name in ("seated", "lower", "land", "settle")]
