"""The drake-standup command (drake_standup/cli.py): subcommands, --set, and bad input as
one 'error:' line with exit code 2, whatever the input's source."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from drake_standup.cli import COMMANDS, main
from drake_standup.config import parse_scenario

REPO = Path(__file__).resolve().parent.parent


def _cli(capsys, argv: list[str]) -> tuple[int, str, str]:
    """main(argv) in this process: (exit code, stdout, stderr); argparse's exits included."""
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    out, err = capsys.readouterr()
    return code, out, err


# Bad input -> (where it is written, its text, what the one error line must name).
SCENARIO, SWEEP, ARGS = "scenario file", "sweep file", "command line"
BAD = {
    "unknown_key": (SCENARIO, "robot:\n  foo: 1\n", "robot.foo: unknown key"),
    "wrong_type": (SCENARIO, "duration_s: abc\n", "duration_s: 'abc'; accepted: a number"),
    "list_for_a_number": (SCENARIO, "duration_s: [1, 2]\n", "duration_s: [1, 2]"),
    "unknown_solver": (SCENARIO, "controller:\n  qp_solver: foo\n", "controller.qp_solver"),
    "negative_weight": (
        SCENARIO,
        "controller:\n  momentum_weight: -5\n",
        "controller.momentum_weight: -5.0; accepted",
    ),
    "negative_gain": (
        SCENARIO,
        "controller:\n  com_kp_seated_per_s2: [60, -1, 5]\n",
        "controller.com_kp_seated_per_s2[1]: -1.0; accepted: a number >= 0",
    ),
    "gain_not_a_list": (
        SCENARIO,
        "controller:\n  com_kp_standing_per_s2: 30\n",
        "controller.com_kp_standing_per_s2: 30; accepted: a list",
    ),
    "empty_cop_box": (
        SCENARIO,
        "controller:\n  foot_cop_x_m: [0.1, -0.05]\n",
        "controller.foot_cop_x_m: [0.1, -0.05]; accepted: [low, high] with low < high",
    ),
    "unknown_joint_in_a_weight": (
        SCENARIO,
        "duration_s: 0.01\ncontroller:\n  posture_weight_by_joint: {no_such_joint: 1.0}\n",
        "controller.posture_weight_by_joint: unknown joint(s) no_such_joint",
    ),
    "unknown_contact_model": (
        SCENARIO,
        "plant:\n  contact_model: soft\n",
        "plant.contact_model: 'soft' unknown",
    ),
    "sweep_unknown_key": (SWEEP, "base: assisted\ngrids: {}\n", "sweep.grids: unknown key"),
    "sweep_bad_draw": (
        SWEEP,
        "base: assisted\nrandom: {duration_s: {gauss: [1, 2]}}\n",
        "random[0].draw: {'gauss': [1, 2]}",
    ),
    "sweep_value_out_of_range": (
        SWEEP,
        "base: assisted\ngrid: {advancement.psi_dot_upper: [2.0, 0.5]}\n",
        "advancement.psi_dot_upper: 0.5; accepted: a number >= 1",
    ),
    "sweep_unknown_solver": (
        SWEEP,
        "base: assisted\noverrides: {controller.qp_solver: cplex}\n",
        "controller.qp_solver: 'cplex' unknown",
    ),
    "set_without_equals": (ARGS, ["run", "--set", "advancement.psi_dot_upper"], "--set"),
    "set_unknown_path": (ARGS, ["run", "--set", "advancement.speed=2"], "advancement.speed"),
    "set_wrong_type": (
        ARGS,
        ["run", "--set", "advancement.psi_dot_upper=fast"],
        "advancement.psi_dot_upper: 'fast'",
    ),
    "set_out_of_range": (
        ARGS,
        ["run", "--set", "controller.joint_limit_weight=-1"],
        "controller.joint_limit_weight: -1.0",
    ),
    "set_index_out_of_range": (
        ARGS,
        ["run", "--scenario", "unassisted", "--set", "human.pulls[0].ramp_s=1"],
        "index 0 out of range",
    ),
    "negative_duration": (ARGS, ["run", "--duration", "-1"], "duration_s: -1.0"),
    "unknown_scenario": (ARGS, ["run", "--scenario", "nosuch"], "'nosuch' not found"),
    "unknown_sweep": (ARGS, ["sweep", "nosuch"], "'nosuch' not found"),
    "zero_workers": (ARGS, ["sweep", "assistance", "--workers", "0"], "--workers"),
    "unknown_command": (ARGS, ["fly"], "'fly': unknown command"),
    "live_without_meshcat": (ARGS, ["live", "--no-recording"], "--no-recording"),
}


@pytest.mark.parametrize(("where", "bad", "names"), list(BAD.values()), ids=list(BAD))
def test_bad_input_is_one_error_line_and_exit_2(tmp_path, capsys, where, bad, names):
    """Each bad input vs the contract: exit code 2, stderr exactly one 'error:' line that
    names what is wrong, nothing simulated or written."""
    out = tmp_path / "out"
    if where == ARGS:
        argv = bad + (["--no-recording", "--out", str(out)] if bad[0] == "run" else [])
    else:
        path = tmp_path / "bad.yaml"
        path.write_text(bad)
        command = ["run", "--scenario"] if where == SCENARIO else ["sweep"]
        argv = [*command, str(path), "--out", str(out)]
        argv += ["--no-recording"] if where == SCENARIO else []
    code, stdout, stderr = _cli(capsys, argv)
    assert code == 2, stderr
    lines = stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr
    assert names in lines[0]
    assert not (out / "metrics.json").exists() and not (out / "results.csv").exists()


def test_set_changes_the_simulated_value(tmp_path, capsys):
    """--set advancement.psi_dot_upper=2.0 on the shipped unassisted scenario (2.5 in its
    file): the run's scenario.yaml echo holds 2.0, every other value as the file has it,
    and the summary names the override."""
    shipped = yaml.safe_load((REPO / "scenarios" / "unassisted.yaml").read_text())
    assert shipped["advancement"]["psi_dot_upper"] == 2.5
    argv = ["run", "--scenario", "unassisted", "--set", "advancement.psi_dot_upper=2.0"]
    argv += ["--duration", "0.1", "--no-recording", "--out", str(tmp_path)]
    code, stdout, _ = _cli(capsys, argv)
    assert code == 0
    echo = parse_scenario((tmp_path / "scenario.yaml").read_text(), "echo")
    assert echo.advancement.psi_dot_upper == 2.0
    assert echo.duration_s == 0.1
    assert echo.standup.trigger == shipped["standup"]["trigger"] == "time"
    assert echo.human.pulls == []
    assert "set advancement.psi_dot_upper = 2.0" in stdout


def test_scenarios_lists_every_shipped_file(capsys):
    """`drake-standup scenarios` vs the repository's folders: every scenario and sweep,
    each with the first sentence of its leading comment."""
    code, stdout, _ = _cli(capsys, ["scenarios"])
    assert code == 0
    # The two sections, each from its heading (a scenario and a sweep may share a name:
    # scenarios/cycle.yaml and sweeps/cycle.yaml).
    lines = stdout.splitlines()
    at = [i for i, x in enumerate(lines) if x.startswith("sweeps (")]
    assert len(at) == 1
    sections = {"scenarios": lines[: at[0]], "sweeps": lines[at[0] :]}
    for folder in ("scenarios", "sweeps"):
        for path in sorted((REPO / folder).glob("*.yaml")):
            first = path.read_text().splitlines()[0].lstrip("# ")
            (line,) = [x for x in sections[folder] if x.split()[:1] == [path.stem]]
            assert first.split()[0] in line and len(line.split()) > 3


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_has_help_with_an_example(capsys, command):
    """--help of each subcommand: exit 0, its usage under the drake-standup name, an
    example of the command itself."""
    code, stdout, _ = _cli(capsys, [command, "--help"])
    assert code == 0
    assert stdout.startswith(f"usage: drake-standup {command}")
    assert re.search(rf"example:\s+drake-standup {command}\b", stdout)


def test_no_command_lists_the_commands(capsys):
    code, stdout, _ = _cli(capsys, [])
    assert code == 2
    assert all(f"  {name} " in stdout for name in COMMANDS)


@pytest.mark.parametrize("module", ["drake_standup", "drake_standup.cli"])
def test_python_m_drake_standup_is_the_same_command(capsys, module):
    """`python -m drake_standup scenarios` (and `-m drake_standup.cli`, which once ran
    nothing) in a fresh process vs the command run here."""
    done = subprocess.run(
        [sys.executable, "-m", module, "scenarios"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout == _cli(capsys, ["scenarios"])[1]


@pytest.mark.parametrize(
    ("response", "said"),
    [
        ("advancement", "stood up in 2.38 s (3.42 s without advancement)"),
        ("stiff", "stood up in 3.52 s (response stiff: psi = t)"),
        ("advancement+stiff", "stood up in 2.38 s (responses advancement+stiff)"),
    ],
)
def test_the_summary_line_names_a_response_that_holds_psi_to_time(
    monkeypatch, capsys, tmp_path, response, said
):
    """The run's last line: with advancement, the psi = t run's time beside it; with
    stiff or compliant (psi = t, no such run) the response; with the live switch moved,
    the responses used."""
    import types

    import drake_standup.sim.simulate

    t = 3.52 if response == "stiff" else 2.38
    metrics = {
        "success": True,
        "failure_reason": None,
        "standup_time_s": t,
        "standup_time_s_without_advancement": 3.42 if response == "advancement" else t,
        "psi_final": 15.0,
        "sim_time_s": 15.0,
        "wall_time_s": 10.0,
        "realtime_factor": 1.5,
        "response": response,
    }
    fake = types.SimpleNamespace(metrics=metrics, files={})
    monkeypatch.setattr(drake_standup.sim.simulate, "simulate", lambda *a, **k: fake)
    assert main(["run", "--no-recording", "--out", str(tmp_path / "o")]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert (
        last == f"OK: {said}; psi_final 15.00; simulated 15.00 s in 10.0 s wall (1.50x real time)"
    )
