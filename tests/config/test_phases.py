"""The phase table (phases.py): its defaults are the sources' numbers, a scenario's
phases: section sets it, and the older keys that spelled parts of it (config/legacy.py)
keep loading with their meaning."""

from __future__ import annotations

import pytest
import yaml

from drake_standup.config import Scenario, ScenarioError, apply_overrides, parse_scenario
from drake_standup.config.legacy import LEGACY
from drake_standup.config.phases import PHASES, PhaseTable, posture

# [authors-code]'s posture rows (state 2 with the probe's torso pitch 1.0, [early-probe]).
AUTHORS_POSTURES = {
    "forward": [1.5402, 0.1594, -1.7365, -0.2814, -1.6455, 0.4363, 0.5862, 0.2473, 1.0],
    "lift_off": [1.1097, 0.0122, -0.8365, -0.0714, -1.4615, 0.4363, 0.1545, 0.2018, 0.0611],
    "rise": [0.2094, 0.1047, -0.1745, -0.0349, -1.6455, 0.4363, 0.5862, 0.2473, 0.0],
}

# What an older file (and every run's scenario.yaml before the phase table) said, with
# the values it had by default.
OLDER = """
standup:
  balance_time_s: 3.0
  segment_psi: [1.5, 0.5, 1.8]
  state2_com_delta_m: [0.1277, 0.0, 0.0]
  state3_com_delta_m: [0.04, 0.0, 0.0]
  standing_com_height_m: 0.575
  feet_force_2to3_N: 150.0
  min_time_state2_s: 0.0
  com_ahead_of_heels_m: 0.03
  foot_force_3to4_N: 95.0
  min_time_state3_s: 0.0
  seat_release_s: 0.5
  seat_unload_s: 0.2
controller:
  com_kp_seated_per_s2: [60.0, 40.0, 5.0]
  com_kp_standing_per_s2: [60.0, 40.0, 30.0]
  base_pitch_by_state_rad: [0.0, 0.4, 0.3, 0.0]
  seat_hinge_from_state: 2
  lean_states: [3, 4]
"""


def test_the_defaults_are_the_sources_numbers():
    table = PhaseTable()
    assert [table.phase(k) for k in range(1, 5)] == list(table)
    # [authors-code]'s, but state 3 over 0.7 s, not 0.5 s: its forward acceleration put the CoP
    # past the soles' pads' middle third (issue 30, phases.py).
    assert [phase.segment_psi for phase in table][1:] == [1.5, 0.7, 1.8]
    assert table.forward.com_delta_m == [0.1277, 0.0, 0.0]
    assert table.lift_off.com_delta_m == [0.04, 0.0, 0.0]
    assert table.seated.exit.min_time_s == 3.0 and table.seated.exit.asked
    assert table.forward.exit.feet_force_N == 150.0
    assert table.lift_off.exit.each_foot_force_N == 95.0
    for name, row in AUTHORS_POSTURES.items():
        assert getattr(table, name).posture_rad == posture(row)
    assert posture(AUTHORS_POSTURES["rise"])["r_knee"] == -0.1745  # both sides alike
    assert not table.seated.posture_rad  # state 1 holds the posture it starts from
    assert [phase.advances for phase in table] == [False, True, True, True]
    assert [phase.when_hindered for phase in table] == ["wait", "sit_back", "step_back", "stand"]
    assert table.unloading_phase("buttocks") == 2 and table.unloading_phase("thighs") == 3


def test_an_older_file_gives_the_default_table():
    """Every older key at the value it had by default: the same table as no key at all,
    but for the standing height, which the older key sets absolute (0.575 m, where the
    default is now each model's erect height), and the forward displacement, which the
    older key measures from the seated CoM (the default now from the soles), and state 3's
    length and its thighs' release, which the older keys spell (0.5 s each; the defaults
    are now 0.7 s); the keys are gone from the loaded scenario (its scenario.yaml spells
    the table)."""
    older = parse_scenario(OLDER)
    expected = Scenario().phases
    expected.rise.com_height_m = 0.575
    expected.forward.com_x_over_soles_m = None
    expected.lift_off.segment_psi = 0.5
    expected.lift_off.unload_s = 0.5
    assert older.phases == expected
    assert not hasattr(older.standup, "segment_psi")
    assert not hasattr(older.controller, "lean_states")


@pytest.mark.parametrize(
    ("key", "value", "where", "expected"),
    [
        ("standup.balance_time_s", 1.0, ("seated", "exit.min_time_s"), 1.0),
        ("standup.segment_psi", [1.0, 0.4, 2.0], ("lift_off", "segment_psi"), 0.4),
        ("standup.segment_psi", [1.0, 0.4, 2.0], ("seated", "segment_psi"), 1.0),
        ("standup.state3_com_delta_m", [0.05, 0.0, 0.0], ("lift_off", "com_delta_m"), [0.05, 0, 0]),
        ("standup.standing_com_height_m", 0.56, ("rise", "com_height_m"), 0.56),
        ("standup.feet_force_2to3_N", 120.0, ("forward", "exit.feet_force_N"), 120.0),
        ("standup.foot_force_3to4_N", 80.0, ("lift_off", "exit.each_foot_force_N"), 80.0),
        ("standup.seat_release_s", 0.8, ("lift_off", "unload_s"), 0.8),
        ("standup.seat_unload_s", 0.3, ("forward", "unload_s"), 0.3),
        (
            "controller.com_kp_standing_per_s2",
            [50, 30, 20],
            ("rise", "com_kp_per_s2"),
            [50, 30, 20],
        ),
        (
            "controller.base_pitch_by_state_rad",
            [0.1, 0.2, 0.3, 0.4],
            ("rise", "base_pitch_rad"),
            0.4,
        ),
        ("controller.seat_hinge_from_state", 1, ("seated", "seat_hold"), "hinged"),
        ("controller.lean_states", [4], ("lift_off", "lean"), False),
    ],
)
def test_each_older_key_sets_its_entry_of_the_table(key, value, where, expected):
    """In a file and as an override (--set, a sweep's): the same entry."""
    section, name = key.split(".")
    from_file = parse_scenario(yaml.safe_dump({section: {name: value}}))
    overridden = apply_overrides(Scenario(), [(key, value)])
    for scenario in (from_file, overridden):
        phase = getattr(scenario.phases, where[0])
        target, _, leaf = where[1].rpartition(".")
        assert getattr(phase.exit if target else phase, leaf) == expected


def test_an_older_posture_merges_into_the_phases_posture():
    """controller.posture_state2_rad naming one joint changed that joint of the default
    table and kept the others, as the old key's mapping did."""
    scenario = parse_scenario("controller:\n  posture_state2_rad: {l_knee: -1.5}\n")
    expected = dict(PhaseTable().forward.posture_rad, l_knee=-1.5)
    assert scenario.phases.forward.posture_rad == expected
    # Absolute, as then: the plan moves no joint of it with the seated pose.
    assert PhaseTable().forward.posture_from_seated
    assert not scenario.phases.forward.posture_from_seated


def test_the_phases_section_sets_the_table():
    scenario = parse_scenario(
        "phases:\n  forward:\n    segment_psi: 2.0\n    exit: {feet_force_N: 120.0}\n"
    )
    assert scenario.phases.forward.segment_psi == 2.0
    assert scenario.phases.forward.exit.feet_force_N == 120.0
    assert scenario.phases.forward.exit.com_ahead_of_heels_m == 0.03  # the rest kept
    assert scenario.phases.lift_off == PhaseTable().lift_off


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "standup:\n  segment_psi: [1.5, 0.5]\n",
            "standup.segment_psi: [1.5, 0.5]; accepted: a list of 3 numbers",
        ),
        (
            "standup:\n  segment_psi: [1.5, -0.5, 1.8]\n",
            "standup.segment_psi[1]: -0.5; accepted: a number > 0",
        ),
        (
            "standup:\n  balance_time_s: -1\n",
            "standup.balance_time_s: -1.0; accepted: a number >= 0",
        ),
        (
            "controller:\n  lean_states: [5]\n",
            "controller.lean_states[0]: 5; accepted: a state number 1-4",
        ),
        (
            "standup:\n  seat_release_s: 0.8\nphases:\n  lift_off:\n    unload_s: 0.6\n",
            "standup.seat_release_s: also given as phases.lift_off.unload_s; accepted: one of them",
        ),
        ("phases:\n  rise:\n    when_hindered: run\n", "phases.rise.when_hindered: 'run' unknown"),
        ("phases:\n  forward:\n    unload: [knees]\n", "phases.forward.unload[0]: 'knees' unknown"),
        (
            "phases:\n  forward:\n    segment_psi: 0\n",
            "phases.forward.segment_psi: 0.0; accepted: a number > 0",
        ),
    ],
)
def test_a_bad_table_entry_is_one_line_naming_its_key(text, message):
    with pytest.raises(ScenarioError) as err:
        parse_scenario(text)
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_every_older_key_is_in_the_older_file_here():
    """OLDER (and the posture tables, tested above) spell every key config/legacy.py reads."""
    keys = {
        f"{section}.{name}" for section, names in yaml.safe_load(OLDER).items() for name in names
    }
    assert keys | {f"controller.posture_state{k}_rad" for k in (2, 3, 4)} == set(LEGACY)
    assert len(PHASES) == 4


@pytest.mark.parametrize(
    ("model", "height_m"), [("iCubGazeboV2_5", 0.5753), ("iCubGenova01", 0.553)]
)
def test_each_robot_rises_to_its_own_erect_height(model, height_m):
    """The rise ends, by default, at the erect CoM height of its posture on the robot at
    hand (scene.standing, resolved when the stand-up controller is made): the
    Gazebo model and a shorter-legged real one differ by 2 cm; a height set in the file
    stays as it is."""
    from pydrake.systems.framework import DiagramBuilder

    from drake_standup.config.phases import resolve_com_heights
    from drake_standup.world.scene import add_scene

    scenario = apply_overrides(Scenario(), [("robot.model", model)])
    scene = add_scene(DiagramBuilder(), scenario, pd_gains=None, visuals=False)
    table = resolve_com_heights(scenario.phases, scene.standing.erect_com_height_m)
    assert Scenario().phases.rise.com_height_m is None and table.unresolved_heights() == []
    assert table.rise.com_height_m == pytest.approx(height_m, abs=5e-4)
    assert scenario.phases.rise.com_height_m is None  # the scenario itself is not changed
    fixed = apply_overrides(scenario, [("phases.rise.com_height_m", 0.56)])
    assert resolve_com_heights(fixed.phases, lambda posture: 1.0).rise.com_height_m == 0.56


@pytest.mark.parametrize(("older", "now"), [("soft", "relaxed"), ("stiff", "firm")])
def test_an_older_tone_loads_under_its_new_name(tmp_path, older, now):
    """human.body.tone was soft or stiff (stiff also a response); files and --set keep
    loading with those words, as relaxed and firm."""
    from drake_standup.config import load_scenario, parse_scenario

    parsed = parse_scenario(f"human:\n  body:\n    tone: {older}\n")
    assert parsed.human.body.tone == now
    assert load_scenario(None, [("human.body.tone", older)]).human.body.tone == now
    assert parse_scenario(f"human:\n  body:\n    tone: {now}\n").human.body.tone == now
