"""The plug-in registry (config/plugins.py), the law's interface (standup/laws.py) and the
helper's (helper/plugin.py): names resolved three ways, bad plug-ins as one error line with
exit code 2, and a law outside the package equal to the same law inside it."""

from __future__ import annotations

import math
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from drake_standup.config import SCENARIO_DIR, AdvancementConfig, load_scenario
from drake_standup.config.arguments import parse_set
from drake_standup.config.plugins import PluginError, register, registered, resolve
from drake_standup.standup.laws import (
    LawInputs,
    checked_rate,
    interaction_law,
    psi_dot_law,
    tangent_law,
)

REPO = Path(__file__).resolve().parents[2]
CONFIG = AdvancementConfig(alpha_full_mps2=0.6)


def test_the_shipped_names_resolve_to_the_shipped_objects():
    assert resolve("laws", "tangent").obj is tangent_law
    assert resolve("laws", "interaction").obj is interaction_law
    helpers = registered("helpers")
    assert {"scripted", "reactive", "body"} <= set(helpers)
    assert helpers["body"].obj.adds_body


def test_module_attribute_resolves_a_law_outside_the_package():
    import lab_laws

    assert resolve("laws", "lab_laws:constant").obj is lab_laws.constant


def test_a_registered_name_resolves_and_a_taken_one_is_refused():
    def mine(inputs):
        return 1.0

    register("laws", "test_mine", mine)
    assert resolve("laws", "test_mine").obj is mine
    with pytest.raises(ValueError, match="registered already"):
        register("laws", "test_mine", lambda inputs: 1.0)


def test_an_entry_point_resolves(monkeypatch):
    """An installed distribution's entry point, by its name (importlib.metadata stubbed)."""
    point = types.SimpleNamespace(
        name="from_ep", value="lab_laws:constant", dist=types.SimpleNamespace(name="labdist")
    )
    monkeypatch.setattr(
        "importlib.metadata.entry_points",
        lambda group: [point] if group == "drake_standup.laws" else [],
    )
    found = resolve("laws", "from_ep")
    assert found.obj.__name__ == "constant" and "labdist" in found.origin
    assert "from_ep" in registered("laws")


@pytest.mark.parametrize(
    ("spec", "says"),
    [
        ("no_such_law", "is not a known name; accepted: tangent | interaction"),
        ("no_such_module_xyz:law", "module 'no_such_module_xyz' does not import"),
        ("lab_laws:missing", "'lab_laws' has no attribute 'missing'"),
        ("lab_laws:two_arguments", "has the signature (inputs, other); accepted: law(inputs)"),
        ("lab_laws:NOT_CALLABLE", "is a float, not callable"),
        ("lab_laws", "is not a known name"),
    ],
)
def test_a_bad_law_is_one_line_naming_the_key(spec, says):
    with pytest.raises(PluginError) as err:
        resolve("laws", spec)
    text = str(err.value)
    assert text.startswith("advancement.law: ") and says in text and "\n" not in text


def test_a_bad_helper_is_one_line_naming_the_key():
    with pytest.raises(PluginError, match=r"^human.mode: 'lab_laws:two_arguments' has the sig"):
        resolve("helpers", "lab_laws:two_arguments")


@pytest.mark.parametrize(
    ("value", "says"),
    [
        (math.nan, "returned nan"),
        (math.inf, "returned inf"),
        (-0.5, "returned -0.5"),
        ((1.0, 2.0), "returned shape (2,)"),
        (np.ones((1, 1)), "returned shape (1, 1)"),
        ("1.0", "returned a string"),
        (None, "returned None"),
    ],
)
def test_a_rate_that_is_not_one_finite_number_is_refused(value, says):
    with pytest.raises(PluginError) as err:
        checked_rate(value, "lab:law", 1.25)
    assert says in str(err.value) and "at t = 1.250 s" in str(err.value)


def test_a_rate_is_returned_as_a_float():
    assert checked_rate(np.float64(1.5), "x:y", 0.0) == 1.5
    assert checked_rate(2, "x:y", 0.0) == 2.0


def test_law_inputs_work_out_alpha_and_the_lead():
    """alpha: omega_f along the unit tangent; lead: the CoM ahead of x_d along it."""
    inputs = LawInputs.of(
        CONFIG,
        tangent_W=[0.0, 0.0, 0.2],
        omega_f_W=[0.3, 0.0, 0.4],
        com_W=[0.1, 0.0, 0.45],
        x_d_W=[0.1, 0.0, 0.4],
    )
    assert inputs.alpha == pytest.approx(0.4)
    assert inputs.lead_m == pytest.approx(0.05)
    with pytest.raises(AttributeError, match="LawInputs has no 'nope'"):
        _ = inputs.nope
    with pytest.raises(KeyError, match="'psi' was not given"):
        _ = inputs.psi


@pytest.mark.parametrize("law", [tangent_law, interaction_law])
def test_the_shipped_laws_are_the_gated_law_of_the_paper(law):
    """Through LawInputs, each shipped law gives what psi_dot_law gives for its ratio."""
    rng = np.random.default_rng(7)
    name = "tangent" if law is tangent_law else "interaction"
    config = AdvancementConfig(alpha_full_mps2=0.6, law=name)
    for _ in range(50):
        v, omega_f, tangent = rng.normal(0, 0.3, (3, 3))
        lead, progress = rng.uniform(-0.02, 0.02), rng.uniform(0, 1)
        inputs = LawInputs.of(
            config,
            com_velocity_W=v,
            omega_f_W=omega_f,
            tangent_W=tangent,
            lead_m=lead,
            progress=progress,
        )
        expected = psi_dot_law(config, v, omega_f, tangent, lead, progress)[0]
        assert law(inputs) == expected


def _bad_law_run(spec: str, tmp_path: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            str(REPO / "run_diagram.py"),
            "--no-recording",
            "--duration",
            "5.0",
            "--set",
            f"advancement.law={spec}",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        cwd=REPO / "tests" / "plugins",
        timeout=600,
    )


@pytest.mark.parametrize(
    ("spec", "says"),
    [
        ("no_such_module_xyz:law", "does not import"),
        ("lab_laws:two_arguments", "has the signature"),
        ("lab_laws:returns_nan", "returned nan at t = "),
        ("lab_laws:returns_pair", "returned shape (2,) at t = "),
    ],
)
def test_run_diagram_refuses_a_bad_law_with_one_line_and_exit_2(spec, says, tmp_path):
    """Before the run (the import, the signature) or at the law's first call (its value,
    once the rise advances): one `error:` line, exit code 2, no traceback."""
    done = _bad_law_run(spec, tmp_path)
    assert done.returncode == 2, done.stderr
    errors = [line for line in done.stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and errors[0].startswith("error: advancement.law: ")
    assert says in errors[0] and "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines()[-1] == errors[0]  # after the progress bar only


def _metrics(*overrides: str) -> dict:
    from drake_standup.sim.simulate import simulate

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml", [parse_set(o) for o in overrides])
    return simulate(scenario, None, record=False, progress=False, baseline=False).metrics


@pytest.mark.slow
def test_a_law_outside_the_package_runs_as_the_same_law_inside_it():
    """The shipped tangent law named by module:attribute from outside the package gives the
    shipped run to the last bit, and a law of its own (psi_dot 1.3 while helped) stands
    up between psi = t and the shipped law."""
    shipped = _metrics()
    outside = _metrics("advancement.law=lab_laws:copy_of_tangent")
    for key in ("standup_time_s", "psi_final", "sole_force_chatter_N", "com_tracking_rms_m"):
        assert outside.get(key) == shipped.get(key), key
    constant = _metrics("advancement.law=lab_laws:constant")
    plain = _metrics("advancement.enabled=false")
    assert constant["success"]
    assert shipped["standup_time_s"] < constant["standup_time_s"] < plain["standup_time_s"]


def _chair_scenario(kind: str):
    return load_scenario(SCENARIO_DIR / "assisted.yaml", [("chair.kind", kind)])


def test_a_chair_plugin_sets_the_seat_height_the_plan_reads():
    assert _chair_scenario("lab_chairs:tall_stool").chair.seat_height_m == 0.25
    assert _chair_scenario("lab_chairs:box_again").chair.seat_height_m == 0.2195


@pytest.mark.parametrize(
    ("kind", "says"),
    [
        ("lab_chairs:not_a_model", "made a str; accepted: ChairModel"),
        ("lab_chairs:floating_seat", "made a seat 2.0 m high"),
        ("lab_chairs:no_chair_frame", "has no frame named 'chair'"),
        ("lab_laws:two_arguments", "accepted: chair(config) -> ChairModel"),
        ("no_such_chair", "is not a known name; accepted: standard"),
    ],
)
def test_a_bad_chair_is_one_line_naming_the_key(kind, says):
    with pytest.raises(PluginError) as err:
        _chair_scenario(kind)
    text = str(err.value)
    assert text.startswith("chair.kind: ") and says in text and "\n" not in text


@pytest.mark.slow
def test_the_box_chair_made_by_a_plugin_is_the_shipped_chair():
    """The standard chair and the same chair made outside the package: the same run."""
    shipped = _metrics()
    outside = _metrics("chair.kind=lab_chairs:box_again")
    for key in ("standup_time_s", "psi_final", "sole_force_chatter_N", "com_tracking_rms_m"):
        assert outside[key] == shipped[key], key


def _helper_output(mode: str, t: float):
    """The helper mode builds, in its own context at time t: (hand_wrenches_W, the applied
    spatial forces)."""
    from drake_standup.sim.diagram import build_diagram

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml", [("human.mode", mode)])
    built = build_diagram(scenario)
    human = built.diagram.GetSubsystemByName("human")
    context = human.CreateDefaultContext()
    context.SetTime(t)
    nx = human.get_input_port(0).size()
    human.GetInputPort("robot_state").FixValue(context, np.zeros(nx))
    wrenches = human.GetOutputPort("hand_wrenches_W").Eval(context)
    forces = human.GetOutputPort("spatial_forces").Eval(context)
    return wrenches, forces


def test_a_helper_plugin_pulls_the_hands_it_says():
    """docs/extending.md's helper: nothing before 3 s, 15 N forward and up on each hand
    after, as wrenches and as the plant's applied forces (at the hand frames)."""
    before, applied = _helper_output("lab_helpers:Steady", 2.0)
    assert not np.any(before) and applied == []
    after, applied = _helper_output("lab_helpers:Steady", 4.0)
    expected = np.zeros(12)
    expected[[3, 5, 9, 11]] = 15.0
    np.testing.assert_array_equal(after, expected)
    assert len(applied) == 2
    np.testing.assert_array_equal(applied[0].F_Bq_W.translational(), [15.0, 0.0, 15.0])


def test_a_helper_plugin_torque_reaches_the_plant():
    wrenches, applied = _helper_output("lab_helpers:Twisting", 2.0)
    assert len(applied) == 1
    np.testing.assert_array_equal(applied[0].F_Bq_W.rotational(), [0.0, 0.0, 2.0])
    np.testing.assert_array_equal(wrenches[:3], [0.0, 0.0, 2.0])


def test_a_helper_without_the_ports_or_the_shape_is_one_line():
    with pytest.raises(PluginError, match=r"^human.mode: 'lab_helpers:portless' built a system"):
        _helper_output("lab_helpers:portless", 0.0)
    with pytest.raises(PluginError, match=r"gave shape \(6,\) at t = 0.000 s; accepted: \(12,\)"):
        _helper_output("lab_helpers:WrongShape", 0.0)


def test_a_bad_response_is_one_line_naming_the_key():
    with pytest.raises(PluginError) as err:
        resolve("responses", "lab_responses:NOT_A_RESPONSE")
    assert str(err.value).startswith("response: 'lab_responses:NOT_A_RESPONSE' is a int;")


def test_a_response_of_its_own_is_numbered_after_the_shipped_ones():
    from drake_standup.config.responses import response_names

    assert response_names("stiff") == ("advancement", "stiff", "compliant")
    own = "lab_responses:ADVANCE_AND_YIELD"
    assert response_names(own) == ("advancement", "stiff", "compliant", own)


def _run(*overrides: str):
    from drake_standup.sim.simulate import simulate

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml", [parse_set(o) for o in overrides])
    return simulate(scenario, None, record=False, progress=False, baseline=False)


@pytest.mark.slow
def test_a_response_of_its_own_acts_as_its_flags_say():
    """The shipped stiff response by another name gives the stiff run; a response that
    advances and yields moves psi ahead of time and the CoM reference off its path, and
    signals.npz names it after the shipped three."""
    stiff = _run("response=stiff")
    again = _run("response=lab_responses:STIFF_AGAIN")
    for key in ("standup_time_s", "psi_final", "sole_force_chatter_N", "com_tracking_rms_m"):
        assert again.metrics[key] == stiff.metrics[key], key
    both = _run("response=lab_responses:ADVANCE_AND_YIELD")
    assert both.metrics["success"]
    assert both.metrics["psi_final"] > stiff.metrics["psi_final"] + 0.5
    assert np.abs(both.signals["compliance_offset_W"]).max() > 1e-3
    assert not np.any(stiff.signals["compliance_offset_W"])
    assert list(both.signals["responses"])[3] == "lab_responses:ADVANCE_AND_YIELD"
    assert set(both.signals["response"]) == {3}
    assert both.metrics["response"] == "lab_responses:ADVANCE_AND_YIELD"


@pytest.mark.slow
def test_a_sweep_on_two_workers_imports_a_law_from_the_current_folder(tmp_path):
    """docs/extending.md's walk-through: a law in a module of the folder the sweep starts
    in, not installed, imported by each Dask worker process (its own path: the registry
    adds the current folder)."""
    import csv

    (tmp_path / "walk_law.py").write_text(
        "def faster(inputs):\n"
        "    return 1.3 if inputs.alpha > inputs.config.alpha_min_mps2 else 1.0\n"
    )
    sweep = tmp_path / "laws.yaml"
    sweep.write_text(
        "name: laws\nbase: assisted\nseed: 1\noverrides:\n  duration_s: 8.0\n"
        "grid:\n  - name: law\n    path: advancement.law\n"
        '    values: [tangent, "walk_law:faster"]\n'
    )
    done = subprocess.run(
        [sys.executable, "-m", "drake_standup", "sweep", str(sweep), "--workers", "2"]
        + ["--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    with open(tmp_path / "out" / "results.csv") as f:
        rows = {r["law"]: r for r in csv.DictReader(f)}
    assert rows["walk_law:faster"]["success"] == "True", rows["walk_law:faster"]
    assert float(rows["walk_law:faster"]["standup_time_s"]) > float(
        rows["tangent"]["standup_time_s"]
    )
