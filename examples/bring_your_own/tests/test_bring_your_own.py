"""The example's plug-ins: the law against hand-worked values, both names by entry point,
and each driving a stand-up (slow). Needs the example installed:
pip install -e examples/bring_your_own."""

import subprocess
import sys

import numpy as np
import pytest

bring_your_own = pytest.importorskip("bring_your_own")

from bring_your_own.laws import GAIN_S2_PER_M, gated_law  # noqa: E402

from drake_standup.config import SCENARIO_DIR, AdvancementConfig, load_scenario  # noqa: E402
from drake_standup.config.arguments import parse_set  # noqa: E402
from drake_standup.plugins import LawInputs, registered  # noqa: E402

CONFIG = AdvancementConfig()


def _inputs(**values):
    base = {"alpha": 0.5, "lead_m": 0.0, "progress": 0.1}
    return LawInputs.of(CONFIG, **{**base, **values})


def test_the_gated_law_against_hand_worked_values():
    """1 + GAIN (alpha - alpha_min) within the gates; 1 without help or with the CoM
    lagging; half the excess half-way through the taper; the bound on top."""
    excess = GAIN_S2_PER_M * (0.5 - CONFIG.alpha_min_mps2)
    assert gated_law(_inputs()) == pytest.approx(1.0 + excess)
    assert gated_law(_inputs(alpha=CONFIG.alpha_min_mps2)) == 1.0
    assert gated_law(_inputs(lead_m=-2.0 * CONFIG.lag_tolerance_m)) == 1.0
    half = CONFIG.taper_from_progress + 0.5 * (1.0 - CONFIG.taper_from_progress)
    assert gated_law(_inputs(progress=half)) == pytest.approx(1.0 + 0.5 * excess)
    assert gated_law(_inputs(alpha=10.0)) == CONFIG.psi_dot_upper


def test_the_law_reads_alpha_from_the_path_and_the_pull():
    """alpha worked out from tangent_W and omega_f_W when not given: the pull's CoM
    acceleration along the path's unit tangent."""
    inputs = LawInputs.of(
        CONFIG,
        tangent_W=[0.1, 0.0, 0.0],
        omega_f_W=[0.4, 0.0, 0.3],
        lead_m=0.0,
        progress=0.0,
    )
    assert inputs.alpha == pytest.approx(0.4)
    assert gated_law(inputs) == pytest.approx(1.0 + GAIN_S2_PER_M * (0.4 - 0.05))


def test_the_entry_points_are_listed():
    """Installed, the example's names are the registry's and `drake-standup list` shows them."""
    assert registered("laws")["gated"].obj is gated_law
    assert "bring-your-own" in registered("helpers")["sway"].origin
    listing = subprocess.run(
        [sys.executable, "-m", "drake_standup", "list"], capture_output=True, text=True, check=True
    ).stdout
    assert "gated" in listing and "sway" in listing


def _run(*overrides):
    from drake_standup.sim.simulate import simulate

    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml", [parse_set(o) for o in overrides])
    return simulate(scenario, None, record=False, progress=False, baseline=False).metrics


@pytest.mark.slow
def test_the_law_by_entry_point_and_by_module_attribute_is_one_law():
    """Named both ways, or registered as the shipped laws are, the law gives the same run
    to the last bit, and it stands up sooner than psi = t under the same pull."""
    from drake_standup.plugins import register

    register("laws", "gated_in_the_package", gated_law)  # as if added to the package
    by_name = _run("advancement.law=gated")
    by_path = _run("advancement.law=bring_your_own.laws:gated_law")
    inside = _run("advancement.law=gated_in_the_package")
    stiff = _run("advancement.enabled=false")
    assert by_name["success"] and by_path["success"]
    for key in ("standup_time_s", "psi_final", "sole_force_chatter_N"):
        assert by_name[key] == by_path[key] == inside[key]
    assert by_name["standup_time_s"] < stiff["standup_time_s"] - 0.1


@pytest.mark.slow
def test_the_swaying_helper_stands_the_robot_up():
    """The example's helper, by its entry point name, with the example's law."""
    metrics = _run("human.mode=sway", "advancement.law=gated")
    assert metrics["success"], metrics["failure_reason"]
    assert np.isfinite(metrics["standup_time_s"])


@pytest.mark.slow
def test_the_lab_chair_and_the_recorded_pull_stand_the_robot_up_sooner():
    """The lab's mesh chair (its 0.23 m seat read from the mesh) and its recorded pull,
    replayed, with the example's law: it stands up, sooner than with psi = t."""
    from bring_your_own import LAB_CHAIR, LAB_PULL

    lab = (
        f"chair.file={LAB_CHAIR}",
        "human.mode=recorded",
        f"human.recorded.file={LAB_PULL}",
        "advancement.law=gated",
    )
    scenario = load_scenario(SCENARIO_DIR / "assisted.yaml", [parse_set(o) for o in lab])
    assert scenario.chair.seat_height_m == pytest.approx(0.23)
    helped = _run(*lab)
    plain = _run(*lab, "advancement.enabled=false")
    assert helped["success"] and plain["success"]
    assert helped["standup_time_s"] < plain["standup_time_s"] - 0.3


def _cli(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "drake_standup", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=900,
    )


@pytest.mark.slow
def test_a_sweep_on_two_dask_workers_runs_the_law_by_both_names(tmp_path):
    """The law by entry point and by module:attribute on two worker processes: the same
    stand-up, psi and chatter in results.csv."""
    import csv

    sweep = tmp_path / "laws.yaml"
    sweep.write_text(
        "name: laws\nbase: assisted\nseed: 1\noverrides:\n  duration_s: 8.0\n"
        "grid:\n  - name: law\n    path: advancement.law\n"
        '    values: [gated, "bring_your_own.laws:gated_law"]\n'
    )
    done = _cli("sweep", str(sweep), "--workers", "2", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    with open(tmp_path / "out" / "results.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["law"] for r in rows] == ["gated", "bring_your_own.laws:gated_law"]
    assert rows[0]["success"] == rows[1]["success"] == "True"
    for key in ("standup_time_s", "psi_final", "sole_force_chatter_N"):
        assert rows[0][key] == rows[1][key]


@pytest.mark.slow
def test_compare_runs_the_law_against_stiff(tmp_path):
    """drake-standup compare with the example's law: advancement stands up sooner than
    stiff under the default pull."""
    import csv

    out = tmp_path / "cmp"
    done = _cli(
        "compare", "--helpers", "assisted", "--responses", "advancement", "stiff",
        "--set", "advancement.law=gated", "--workers", "2", "--out", str(out), cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    with open(out / "results.csv") as f:
        times = {r["response"]: float(r["standup_time_s"]) for r in csv.DictReader(f)}
    assert times["advancement"] < times["stiff"] - 0.3
