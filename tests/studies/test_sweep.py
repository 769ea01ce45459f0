"""Sweeps: sweep files, their expansion into runs, Dask runs, resume, tables."""

from __future__ import annotations

import math
import os
import socket
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from drake_standup.config import SCENARIO_DIR, apply_overrides, load_scenario
from drake_standup.studies.sweep import main, run_one, run_sweep
from drake_standup.studies.sweep_file import (
    MAX_RUNS,
    SweepError,
    check_run_count,
    columns,
    expand,
    load_sweep,
)
from drake_standup.studies.sweep_table import read_table, simulation_rows


def _write(tmp_path: Path, text: str, name: str = "sweep.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


GRID = """
name: g
base: scenarios/assisted.yaml
seed: 11
overrides:
  duration_s: 0.3
grid:
  - name: pull
    paths: ["human.pulls[*].force_N[0]", "human.pulls[*].force_N[2]"]
    values: [0, 10, 20]
  - path: advancement.psi_dot_upper
    values: [1.5, 2.5]
"""


def test_grid_expands_every_combination_onto_every_named_key(tmp_path):
    runs = expand(load_sweep(_write(tmp_path, GRID)))
    assert len(runs) == 3 * 2
    combos = [(r.params["pull"], r.params["advancement.psi_dot_upper"]) for r in runs]
    assert combos == [(f, u) for f in (0, 10, 20) for u in (1.5, 2.5)]
    base = load_scenario(SCENARIO_DIR / "assisted.yaml")
    for run in runs:
        paths = dict(run.overrides)
        # [*] named both pulls; both components x and z are set.
        for i in (0, 1):
            for c in (0, 2):
                assert paths[f"human.pulls[{i}].force_N[{c}]"] == run.params["pull"]
        assert paths["advancement.psi_dot_upper"] == run.params["advancement.psi_dot_upper"]
        assert paths["duration_s"] == 0.3
        # Applied to the base scenario, the overrides give exactly those values.
        scenario = apply_overrides(base, run.overrides)
        assert scenario.human.pulls[1].force_N == [run.params["pull"], 0.0, run.params["pull"]]
        assert scenario.human.pulls[0].hand == base.human.pulls[0].hand
    assert len({r.run_id for r in runs}) == len(runs)


def test_a_grid_entrys_companions_go_with_its_values(tmp_path):
    """with: the k-th value of each companion key goes with the entry's k-th value, in
    every combination, and is a column of its own."""
    text = GRID.replace(
        "    values: [0, 10, 20]\n",
        "    values: [0, 10, 20]\n    with: {standup.trigger: [time, hands, hands]}\n",
    )
    spec = load_sweep(_write(tmp_path, text))
    assert columns(spec) == ["pull", "standup.trigger", "advancement.psi_dot_upper"]
    runs = expand(spec)
    assert len(runs) == 3 * 2
    base = load_scenario(SCENARIO_DIR / "assisted.yaml")
    for run in runs:
        expected = "time" if run.params["pull"] == 0 else "hands"
        assert run.params["standup.trigger"] == expected
        assert apply_overrides(base, run.overrides).standup.trigger == expected


@pytest.mark.parametrize("companions", ["{standup.trigger: [time, hands]}", "[time]"])
def test_a_companion_list_of_the_wrong_length_is_one_error_line(tmp_path, companions):
    text = GRID.replace(
        "    values: [0, 10, 20]\n", f"    values: [0, 10, 20]\n    with: {companions}\n"
    )
    with pytest.raises(SweepError) as err:
        load_sweep(_write(tmp_path, text))
    assert "grid[0].with:" in str(err.value) and "one per entry of values" in str(err.value)
    assert "\n" not in str(err.value)


RANDOM = """
name: r
base: scenarios/assisted.yaml
seed: {seed}
samples: {samples}
random:
  - path: advancement.psi_dot_upper
    draw: {{uniform: [1.0, 3.0]}}
  - path: robot.model
    draw: {{choice: [iCubGazeboV2_5, iCubGazeboV2_7]}}
perturbations:
  push: {{body: chest, start_s: {{uniform: [3, 7]}}, duration_s: 0.2,
          magnitude_N: {{uniform: [0, 100]}}, azimuth_deg: {{uniform: [0, 360]}}}}
  mass_scale: {{normal: [1.0, 0.05]}}
  hand_wrench_noise_N: 1.5
"""


def test_seeded_random_draws_are_reproducible_and_per_run(tmp_path):
    def runs(seed, samples):
        path = _write(tmp_path, RANDOM.format(seed=seed, samples=samples), f"r{seed}{samples}.yaml")
        return expand(load_sweep(path))

    a, b = runs(5, 40), runs(5, 40)
    assert [r.overrides for r in a] == [r.overrides for r in b]
    assert [r.run_id for r in a] == [r.run_id for r in b]
    # Run k's draws depend on (seed, k) only: a longer sweep starts the same.
    assert [r.overrides for r in runs(5, 10)] == [r.overrides for r in a[:10]]
    other = runs(6, 40)
    assert all(r.params != o.params for r, o in zip(a, other))

    upper = np.array([r.params["advancement.psi_dot_upper"] for r in a])
    assert upper.min() >= 1.0 and upper.max() <= 3.0 and np.ptp(upper) > 1.0
    assert {r.params["robot.model"] for r in a} == {"iCubGazeboV2_5", "iCubGazeboV2_7"}
    for run in a:
        p = run.params
        (push,) = dict(run.overrides)["perturbation.pushes"]
        # The push force is magnitude times the unit vector of the azimuth.
        az = math.radians(p["push_azimuth_deg"])
        expected = p["push_magnitude_N"] * np.array([math.cos(az), math.sin(az), 0.0])
        np.testing.assert_allclose(push["force_N"], expected, atol=1e-12)
        assert 3 <= push["start_s"] <= 7 and push["duration_s"] == 0.2
        # The impulse column: magnitude times duration, N s.
        assert p["push_impulse_Ns"] == pytest.approx(p["push_magnitude_N"] * 0.2)
        assert p["hand_wrench_noise_N"] == 1.5
        assert dict(run.overrides)["perturbation.noise_seed"] >= 0
    # Distinct noise seeds per run, and mass draws spread like N(1, 0.05).
    assert len({dict(r.overrides)["perturbation.noise_seed"] for r in a}) == len(a)
    masses = np.array([r.params["mass_scale"] for r in a])
    assert abs(masses.mean() - 1.0) < 0.03 and 0.02 < masses.std() < 0.09


def test_the_helpers_campaigns_draw_each_hand_over_the_envelope_and_share_their_helpers():
    """helpers and helpers_interaction: 48 runs each, the same helpers (same seed), only
    the law differs; each hand's pull drawn on its own, inside issue 21's envelope
    (-18..25 N forward, +-25 N sideways, 0..25 N up, ramps 0.1-1 s); models: every model
    of icub-models with the scene's frames, alone and at 15 N per hand."""
    import icub_models

    from drake_standup.config.inputs import missing_scene_frames

    tangent, interaction = (expand(load_sweep(n)) for n in ("helpers", "helpers_interaction"))
    assert len(tangent) == len(interaction) == 48
    for a, b in zip(tangent, interaction):
        assert a.params == b.params
        laws = {dict(r.overrides).get("advancement.law") for r in (a, b)}
        assert laws == {None, "interaction"}
    left = np.array([[r.params[f"left_f{c}_N"] for c in "xyz"] for r in tangent])
    right = np.array([[r.params[f"right_f{c}_N"] for c in "xyz"] for r in tangent])
    for forces in (left, right):
        assert forces[:, 0].min() >= -18.0 and forces[:, 0].max() <= 25.0
        assert np.abs(forces[:, 1]).max() <= 25.0
        assert forces[:, 2].min() >= 0.0 and forces[:, 2].max() <= 25.0
        assert (forces[:, 0] < 0).sum() >= 8  # backward pulls are drawn
    assert not np.allclose(left, right)  # each hand on its own
    ramps = [r.params[f"{h}_ramp_s"] for r in tangent for h in ("left", "right")]
    assert min(ramps) >= 0.1 and max(ramps) <= 1.0
    models = expand(load_sweep("models"))
    standing = {m for m in icub_models.get_robot_names() if not missing_scene_frames(m)}
    assert {r.params["robot_model"] for r in models} == standing
    assert {r.params["pull_force_N"] for r in models} == {0, 15}


@pytest.mark.parametrize(
    "text, message",
    [
        ("base: scenarios/nope.yaml\n", "base: 'scenarios/nope.yaml' not found"),
        ("base: scenarios/assisted.yaml\ngrids: {}\n", "sweep.grids: unknown key"),
        (
            "base: scenarios/assisted.yaml\ngrid: {advancement.speed: [1]}\n",
            "advancement.speed: unknown key; accepted: enabled, law",
        ),
        (
            "base: scenarios/assisted.yaml\ngrid: {'human.pulls[4].force_N[0]': [1]}\n",
            "index 4 out of range",
        ),
        (
            "base: scenarios/seated.yaml\ngrid: {'human.pulls[*].force_N[0]': [1]}\n",
            "names no key of the base scenario",
        ),
        (
            "base: scenarios/assisted.yaml\ngrid: {advancement.psi_dot_upper: [0.5]}\n",
            "advancement.psi_dot_upper: 0.5; accepted: a number >= 1",
        ),
        (
            "base: scenarios/assisted.yaml\ngrid: {robot.model: [iCubNope]}\n",
            "robot.model: unknown model 'iCubNope'",
        ),
        (
            "base: scenarios/assisted.yaml\nrandom: {duration_s: {gauss: [1, 2]}}\n",
            "{uniform: [low, high]}",
        ),
        ("base: scenarios/assisted.yaml\nsamples: 0\n", "samples: 0; accepted"),
        (
            "base: scenarios/assisted.yaml\nfigures: [{kind: pie, x: a, y: b}]\n",
            "figures[0].kind: 'pie'; accepted: line | rate | scatter",
        ),
        (
            "base: scenarios/assisted.yaml\nfigures: [{kind: rate, x: a, y: b, range: [2, 1]}]\n",
            "figures[0].range: [2, 1]; accepted: [low, high]",
        ),
        (
            "base: scenarios/assisted.yaml\nfigures: [{kind: rate, x: a, y: b, lines: [{x: 1}]}]\n",
            "figures[0].lines: [{'x': 1}]; accepted: a list of {x or y: number, label: text}",
        ),
    ],
)
def test_bad_sweep_files_fail_with_one_line_naming_the_key(tmp_path, text, message):
    path = _write(tmp_path, text)
    with pytest.raises(SweepError) as err:
        expand(load_sweep(path))
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_cli_bad_input_is_one_error_line_and_exit_2(tmp_path, capsys):
    assert main([str(tmp_path / "missing.yaml")]) == 2
    assert main([str(_write(tmp_path, GRID)), "--workers", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all(line.startswith("error: ") for line in err)
    assert "missing.yaml' not found" in err[0] and "--workers: 0" in err[1]


@pytest.mark.parametrize(
    "text, field",
    [
        # Expanded, 10^12 runs would take years (each run is checked, ~0.1 s) or exhaust
        # the memory; 100^10 grid combinations likewise.
        ("base: assisted\nsamples: 1000000000000\n", "samples: 1000000000000; accepted"),
        # Each factor within the bound, their product not: 20,000 runs, half an hour to
        # expand.
        (
            "base: assisted\nsamples: 10000\ngrid: {advancement.psi_dot_upper: [1.5, 2.5]}\n",
            "grid x samples: 2 advancement.psi_dot_upper x 10000 samples = 20000 runs",
        ),
        (
            "base: assisted\ngrid:\n"
            + "".join(
                f"  - {{name: p{i}, path: advancement.psi_dot_upper, values: {[1.5] * 100}}}\n"
                for i in range(10)
            ),
            "grid x samples: 100 p0 x 100 p1",
        ),
    ],
    ids=["samples", "samples_and_grid", "grid"],
)
def test_a_run_count_no_sweep_means_is_refused_at_once(tmp_path, text, field):
    """Through `python -m drake_standup sweep` in a fresh process: exit 2 and one error
    line naming the field, within seconds: refused from the sizes, before expansion (which
    would outlast the timeout, or the memory)."""
    path = _write(tmp_path, text)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "drake_standup", "sweep", str(path), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
        check=False,
    )
    elapsed = time.perf_counter() - t0
    assert done.returncode == 2, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {field}"), lines
    assert str(MAX_RUNS) in lines[0]
    assert elapsed < 30.0  # the process's imports included; the check itself is immediate
    assert not (tmp_path / "o").exists()


def test_the_run_count_bound_counts_grid_times_samples(tmp_path):
    spec = load_sweep(_write(tmp_path, GRID))  # 3 x 2 grid combinations
    assert check_run_count(spec) == 6
    most = MAX_RUNS // 6
    assert check_run_count(replace(spec, samples=most)) == 6 * most
    with pytest.raises(SweepError, match=f"= {6 * (most + 1)} runs; accepted: at most"):
        check_run_count(replace(spec, samples=most + 1))
    with pytest.raises(SweepError, match=f"samples: {MAX_RUNS + 1}; accepted"):
        check_run_count(replace(spec, samples=MAX_RUNS + 1, grid=[]))


# Four short runs, one of which fails at once: its fall bound is above the
# seated root (0.38 m), so the monitor ends it as a fall.
SMALL = """
name: small
base: scenarios/assisted.yaml
seed: 3
samples: 2
overrides:
  duration_s: 0.25
grid:
  - name: min_root_height_m
    path: fall.min_root_height_m
    values: [0.1, 0.5]
random:
  - name: psi_dot_upper
    path: advancement.psi_dot_upper
    draw: {uniform: [1.0, 3.0]}
perturbations:
  hand_wrench_noise_N: 1.0
  push: {body: chest, start_s: 0.1, duration_s: 0.1, magnitude_N: 20.0,
         azimuth_deg: {uniform: [0, 360]}}
figures:
  - {kind: line, x: psi_dot_upper, y: psi_final}
  - {kind: rate, x: min_root_height_m, y: success, bins: 2}
"""


def test_small_sweep_on_a_local_cluster_then_resume(tmp_path):
    spec = load_sweep(_write(tmp_path, SMALL))
    out = tmp_path / "out"
    result = run_sweep(spec, out, workers=2, progress=False)
    assert result.computed == 4
    rows = read_table(result.table)
    assert [r["index"] for r in rows] == [0, 1, 2, 3]
    for row, run in zip(rows, result.runs):
        assert row["run_id"] == run.run_id
        assert row["psi_dot_upper"] == pytest.approx(run.params["psi_dot_upper"], rel=1e-12)
        assert row["sim_time_s"] is not None
        if row["min_root_height_m"] == 0.5:
            # Recorded with its reason; the sweep went on.
            assert row["success"] is False
            assert row["failure_reason"].startswith("fall: root_link height 0.3")
            assert row["sim_time_s"] < 0.01
        else:
            # 0.25 s seated: not up yet (psi = t before the stand-up starts).
            assert row["failure_reason"] == "did not stand up"
            assert row["sim_time_s"] == pytest.approx(0.25)
            assert row["psi_final"] == pytest.approx(0.25, abs=1e-9)
    # A worker's run equals the same run simulated here, in this process.
    direct = run_one(spec.base_text, result.runs[0].overrides)
    for key in ("com_final_m", "psi_final", "max_abs_torque_Nm", "contact_force_total_N"):
        got = [v for k, v in rows[0].items() if k == key or k.startswith(key + "[")]
        want = np.atleast_1d(direct[key])
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    assert len(result.figures) == 2 and all(p.stat().st_size > 10_000 for p in result.figures)

    # Resume: drop one run's record; only that run is simulated again.
    before = simulation_rows(result.table)
    records = sorted((out / "runs").glob("*.json"))
    assert len(records) == 4
    kept = {p: p.stat().st_mtime_ns for p in records[1:]}
    records[0].unlink()
    again = run_sweep(spec, out, workers=1, progress=False)
    assert again.computed == 1
    assert all(p.stat().st_mtime_ns == t for p, t in kept.items())
    assert simulation_rows(again.table) == before
    # Nothing left to do: no cluster is even started.
    t0 = time.perf_counter()
    assert run_sweep(spec, out, progress=False).computed == 0
    assert time.perf_counter() - t0 < 5


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_explicit_scheduler_at_an_address_gives_the_same_table(tmp_path):
    """A real cluster of one machine: `dask scheduler` and `dask worker`
    processes on localhost, reached by address; same table as LocalCluster."""
    spec_path = _write(tmp_path, SMALL)
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker"]
    env = dict(os.environ)
    procs = [
        subprocess.Popen(
            dask + ["--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    ]
    try:
        time.sleep(2.0)
        procs.append(
            subprocess.Popen(
                worker
                + [
                    address,
                    "--nworkers",
                    "2",
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                    "--host",
                    "127.0.0.1",
                ],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        assert main([str(spec_path), "--address", address, "--out", str(tmp_path / "a")]) == 0
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            proc.wait(timeout=30)
    assert main([str(spec_path), "--workers", "2", "--out", str(tmp_path / "b")]) == 0
    a = simulation_rows(tmp_path / "a" / "results.csv")
    b = simulation_rows(tmp_path / "b" / "results.csv")
    assert len(a) == 4 and a == b


def test_sweep_bench_runs_the_same_sweep_on_each_worker_count(tmp_path, capsys):
    """The throughput benchmark's mechanics (not its numbers: no timing test)."""
    import json

    from drake_standup.studies import sweep_bench

    spec = _write(tmp_path, SMALL)
    out = tmp_path / "bench"
    assert sweep_bench.main(["--spec", str(spec), "--workers", "1", "2", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert set(summary["workers"]) == {"1", "2"}
    for n in ("1", "2"):
        assert summary["workers"][n]["runs"] == 4
        assert (out / f"workers_{n}" / "results.csv").is_file()
    assert summary["workers"]["1"]["throughput_vs_first"] == 1.0
    assert summary["same_results_for_every_worker_count"] is True


def test_a_rate_figure_draws_its_reference_lines(tmp_path):
    """The lines of a figure end up on the axes, at their x (matplotlib's own record)."""
    from unittest import mock

    from drake_standup.studies.sweep_figures import Figure, draw_figure

    records = [
        {
            "index": i,
            "run_id": f"r{i}",
            "params": {"push_impulse_Ns": 2.0 * i},
            "metrics": {"success": i < 3},
        }
        for i in range(6)
    ]
    fig = Figure(
        kind="rate",
        x="push_impulse_Ns",
        y="success",
        bins=3,
        lines=[{"x": 9.3, "label": "LIP, forward"}],
    )
    import matplotlib.axes

    with mock.patch.object(
        matplotlib.axes.Axes, "axvline", wraps=None, autospec=True, side_effect=None
    ) as axvline:
        path = draw_figure(fig, records, tmp_path)
    assert path is not None and path.exists()
    assert [call.args[1] for call in axvline.call_args_list] == [9.3]


def test_a_scatter_figure_plots_each_run_that_stood_and_its_horizontal_lines(tmp_path):
    """scatter: each run that stood up at (x, y), one call per group, the others as
    crosses on the x axis; a {y, label} line drawn horizontal (matplotlib's own record)."""
    from unittest import mock

    import matplotlib.axes

    from drake_standup.studies.sweep_figures import Figure, draw_figure

    records = [
        {
            "index": i,
            "run_id": f"r{i}",
            "params": {"grip_N": 10.0 + i, "guide": "path" if i % 2 else "velocity"},
            "metrics": {"success": i != 4, "standup_time_s": 3.0 + 0.1 * i},
        }
        for i in range(6)
    ]
    fig = Figure(
        kind="scatter",
        x="grip_N",
        y="standup_time_s",
        group="guide",
        lines=[{"y": 3.71, "label": "alone"}],
    )
    with (
        mock.patch.object(matplotlib.axes.Axes, "axhline", autospec=True) as axhline,
        mock.patch.object(matplotlib.axes.Axes, "plot", autospec=True, wraps=None) as plot,
    ):
        plot.return_value = [mock.Mock(get_color=lambda: "k")]
        path = draw_figure(fig, records, tmp_path)
    assert path is not None and path.exists()
    assert [call.args[1] for call in axhline.call_args_list] == [3.71]
    drawn = [(list(c.args[1]), list(c.args[2])) for c in plot.call_args_list]
    assert drawn == [
        ([11.0, 13.0, 15.0], [3.1, 3.3, 3.5]),  # path
        ([10.0, 12.0], [3.0, 3.2]),  # velocity, stood
        ([14.0], [0.0]),  # velocity, run 4 did not stand
    ]
