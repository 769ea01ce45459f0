"""Scenario loading and validation (drake_standup.config, run_diagram.py).

Each bad scenario is written here, so the key it breaks is known; the error
must be a ScenarioError whose message is one line naming that key path.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import icub_models
import pytest
import yaml

from drake_standup.config import (
    RULES,
    Scenario,
    ScenarioError,
    apply_overrides,
    load_scenario,
    parse_scenario,
)

REPO = Path(__file__).resolve().parents[2]
SEATED = REPO / "scenarios" / "seated.yaml"


def test_load_seated_scenario():
    """scenarios/seated.yaml vs the values it spells out, with defaults for the rest."""
    scenario = load_scenario(SEATED)
    assert isinstance(scenario, Scenario)
    assert scenario.robot.model == "iCubGazeboV2_5"
    assert scenario.duration_s == 5.0
    assert scenario.plant.time_step == Scenario().plant.time_step


def test_yaml_overrides_defaults(tmp_path):
    """Values from a written file vs what was written (nested and top level)."""
    path = tmp_path / "ok.yaml"
    path.write_text("duration_s: 2.5\nrobot:\n  reduced: false\n  effort_limit_Nm: 40\n")
    scenario = load_scenario(path)
    assert scenario.duration_s == 2.5
    assert scenario.robot.reduced is False
    assert scenario.robot.effort_limit_Nm == 40.0
    assert scenario.robot.model == Scenario().robot.model


# Bad YAML -> text that the one-line message must contain (the key path).
BAD = {
    "unknown_top_level_key": ("duration_s: 1.0\nfoo: 1\n", "foo"),
    "unknown_nested_key": ("robot:\n  foo: 1\n", "robot.foo"),
    "wrong_type": ('duration_s: "abc"\n', "duration_s"),
    "negative": ("duration_s: -1.0\n", "duration_s"),
    "zero": ("duration_s: 0\n", "duration_s"),
    "nan": ("duration_s: .nan\n", "duration_s"),
    "nested_inf": ("initial:\n  base_xyz_m: [0.0, .inf, 0.4]\n", "initial.base_xyz_m[1]"),
    "unknown_model": ("robot:\n  model: NoSuchRobot\n", "robot.model"),
    "reflected_inertia_yaml_boolean": (
        "robot:\n  reflected_inertia: on\n",
        "robot.reflected_inertia",
    ),
    "reflected_inertia_unknown": (
        "robot:\n  reflected_inertia: motors\n",
        "robot.reflected_inertia",
    ),
    "nan_in_drake_config": ("plant:\n  time_step: .nan\n", "plant.time_step"),
    "controller_faster_than_plant": (
        "plant:\n  time_step: 0.005\ncontroller_period_s: 0.001\n",
        "controller_period_s",
    ),
    "controller_off_the_plant_grid": (
        "plant:\n  time_step: 0.004\ncontroller_period_s: 0.006\n",
        "controller_period_s",
    ),
    "zero_integrator_step": ("simulator:\n  max_step_size: 0\n", "simulator.max_step_size"),
    "taper_past_the_end": (
        "advancement:\n  taper_from_progress: 1.5\n",
        "advancement.taper_from_progress",
    ),
    "negative_alpha_full": (
        "advancement:\n  alpha_full_mps2: -0.1\n",
        "advancement.alpha_full_mps2",
    ),
    "negative_hindering_threshold": (
        "standup:\n  hindering_force_threshold_N: -3.0\n",
        "standup.hindering_force_threshold_N",
    ),
}


@pytest.mark.parametrize(("text", "key"), list(BAD.values()), ids=list(BAD))
def test_bad_scenario_raises_one_line_error_naming_key(tmp_path, text, key):
    """ScenarioError message vs the key path broken in the written YAML."""
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    message = str(info.value)
    assert "\n" not in message
    assert key in message


def test_unknown_model_lists_accepted_names(tmp_path):
    """The robot.model error vs icub_models.get_robot_names(): every name is listed."""
    path = tmp_path / "bad.yaml"
    path.write_text("robot:\n  model: NoSuchRobot\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    for name in icub_models.get_robot_names():
        assert name in str(info.value)


def test_missing_file(tmp_path):
    """A missing scenario file: one-line ScenarioError naming the path."""
    path = tmp_path / "nonexistent.yaml"
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    message = str(info.value)
    assert "\n" not in message
    assert str(path) in message


@pytest.mark.parametrize(
    "args",
    [
        ["--duration", "-1"],
        ["--scenario", "/nonexistent.yaml"],
        ["--duration", "nan"],
        ["--duration", "abc"],
    ],
    ids=["negative_duration", "missing_scenario", "nan_duration", "non_numeric_duration"],
)
def test_cli_rejects_bad_input(args):
    """run_diagram.py exit code and stderr vs the CLI contract: 2, one 'error:' line."""
    proc = subprocess.run(
        [sys.executable, "run_diagram.py", *args],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error:")
    assert proc.stdout == ""


def test_cli_rejects_wrongly_typed_scenario(tmp_path):
    """run_diagram.py on duration_s: "abc" vs the CLI contract: exit 2, one 'error:' line."""
    path = tmp_path / "bad.yaml"
    path.write_text('duration_s: "abc"\n')
    proc = subprocess.run(
        [sys.executable, "run_diagram.py", "--scenario", str(path)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.splitlines()) == 1, proc.stderr
    assert proc.stderr.startswith("error:")


@pytest.mark.parametrize(
    ("time_step", "period"), [(0.001, 0.001), (0.002, 0.004), (0.004, 0.008), (0.001, 0.01)]
)
def test_controller_period_on_the_plant_grid_is_accepted(tmp_path, time_step, period):
    """Whole multiples of the plant step (1x, 2x, 10x) load, values unchanged."""
    path = tmp_path / "ok.yaml"
    path.write_text(f"plant:\n  time_step: {time_step}\ncontroller_period_s: {period}\n")
    scenario = load_scenario(path)
    assert (scenario.plant.time_step, scenario.controller_period_s) == (time_step, period)


@pytest.mark.parametrize(
    "document, section, guide",
    [
        ("README.md", "## Scenarios", "path"),  # the README's example sets the path guide
        ("docs/outputs.md", "## Scenario files", "velocity"),  # the defaults
    ],
)
def test_the_documented_scenario_examples_parse(document, section, guide):
    """The README's keys and docs/outputs.md's full list are valid scenarios (keeps both
    true)."""
    from docs_check import scenario_block

    scenario = parse_scenario(scenario_block(REPO / document, section))
    assert scenario.phases.rise.com_height_erect and scenario.phases.rise.com_height_m is None
    assert scenario.phases.forward.unload_when == 0.015
    assert scenario.human.reactive.guide == guide


def _every_key(scenario: Scenario) -> list[tuple[str, object]]:
    """(key path, value) of every value of scenario, from its YAML dump."""
    from pydrake.common.yaml import yaml_dump_typed

    found = []

    def walk(prefix: str, value) -> None:
        found.append((prefix, value))
        items = value.items() if isinstance(value, dict) else ()
        items = enumerate(value) if isinstance(value, list) else items
        for key, item in items:
            walk(f"{prefix}[{key}]" if isinstance(key, int) else f"{prefix}.{key}", item)

    for key, value in yaml.safe_load(yaml_dump_typed(scenario)).items():
        walk(key, value)
    return found


def _full_scenario() -> Scenario:
    """The assisted scenario with one of everything: a pull, a push, a torque limit, an
    absolute end height and x, a cushion and the robot's place on the seat."""
    return apply_overrides(
        load_scenario("assisted"),
        [
            ("perturbation.pushes", [{"body": "chest"}]),
            ("controller.torque_limit_Nm", 50.0),
            ("phases.rise.com_height_m", 0.575),
            ("phases.lift_off.com_x_m", 0.23),
            ("chair.cushion", {"modulus_Pa": 1e5}),
            ("initial.hips_behind_seat_edge_m", 0.16),
            ("initial.feet_ahead_of_seat_edge_m", 0.04),
            ("standup.sit_down.trigger", "time"),
            ("standup.sit_down.at_s", 9.0),
            ("phases.lower.exit.thighs_within_m", 0.03),
        ],
    )


def test_every_rule_names_a_key():
    """Each pattern of RULES vs the key paths of a scenario that has every kind of entry:
    a pattern that names nothing (a typo, a renamed field) checks nothing."""
    keys = [key for key, _ in _every_key(_full_scenario())]
    for _, patterns in RULES:
        for pattern in patterns.split():
            regex = re.escape(pattern).replace(r"\[\*\]", r"\[\d+\]").replace(r"\*", r"[^.\[]*")
            assert any(re.fullmatch(regex, key) for key in keys), pattern


# Values no rule bounds, and why: angles and names that only the model can check (the
# joint limits clamp the posture targets; the names are checked against the model's URDF:
# config.JOINT_TABLES, the pushed bodies), the model and the chair file (config/inputs.py),
# lead_max_m (checked against lead_min_m), the plug-ins' names (the registry resolves them:
# rules._check_plugins, tests/plugins), the recorded helper's file (config/recording.py).
UNBOUNDED = (
    r"advancement\.law|human\.mode|chair\.kind|response|robot\.model|chair\.file"
    r"|human\.recorded\.file"
    r"|initial\.joints_rad\..*|phases\.\w+\.posture_rad\..*"
    r"|phases\.\w+\.base_pitch_rad"
    r"|controller\.seat_hinge_joints\[\d+\]|perturbation\.pushes\[\d+\]\.body"
    r"|human\.reactive\.lead_max_m"
)


def test_every_number_and_name_is_checked_by_a_rule_or_named_unbounded():
    """Every leaf of the scenario that is not true/false vs RULES: bounded by a rule (of
    itself or of its list), or in UNBOUNDED; the controller's settings included."""
    keys = _every_key(_full_scenario())
    patterns = [
        re.escape(p).replace(r"\[\*\]", r"\[\d+\]").replace(r"\*", r"[^.\[]*")
        for _, text in RULES
        for p in text.split()
    ]
    for key, value in keys:
        if isinstance(value, dict | list | bool):
            continue
        covered = any(re.fullmatch(p, k) for p in patterns for k in (key, key.rsplit("[", 1)[0]))
        assert covered or re.fullmatch(UNBOUNDED, key), key


def test_the_pinocchio_model_without_its_package_is_a_one_line_error(monkeypatch):
    """controller.model_library: pinocchio needs the optional package: without it, one
    ScenarioError line naming the key and the accepted value."""
    import dataclasses
    import importlib.util

    from drake_standup.config import Scenario, ScenarioError
    from drake_standup.config.rules import validate

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "pinocchio" else real(name, *a),
    )
    base = Scenario()
    scenario = dataclasses.replace(
        base, controller=dataclasses.replace(base.controller, model_library="pinocchio")
    )
    with pytest.raises(ScenarioError) as info:
        validate(scenario)
    assert "controller.model_library" in str(info.value) and "\n" not in str(info.value)
    validate(base)  # drake, the default, needs nothing more
