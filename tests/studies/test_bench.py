"""The benchmark's JSON summary on a tiny run (the figures themselves are not checked:
a benchmark, not a test)."""

from __future__ import annotations

import contextlib
import io
import json
import math
import pstats
import statistics

import pytest

from drake_standup.config import Scenario
from drake_standup.control.controller import TIMING
from drake_standup.studies import bench

DURATION_S = 0.05
REPEAT = 2
PLANT_STEPS = 20
TINY = [
    "--duration",
    str(DURATION_S),
    "--plant-duration",
    str(DURATION_S),
    "--repeat",
    str(REPEAT),
    "--plant-steps",
    str(PLANT_STEPS),
    "--no-run-diagram",
]
RUNS = ("plant_seat_hold", "closed_loop_recording", "closed_loop")
COLUMNS = [name.removesuffix("_s") + "_us" for name in TIMING]


def _positive(x) -> bool:
    return isinstance(x, float) and math.isfinite(x) and x > 0.0


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """One tiny benchmark: its stdout, stderr and --out file."""
    out = tmp_path_factory.mktemp("bench") / "bench.json"
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = bench.main([*TINY, "--out", str(out)])
    return code, stdout.getvalue(), stderr.getvalue(), out


def test_stdout_is_one_json_document_and_out_holds_it(tiny):
    code, stdout, stderr, out = tiny
    assert code == 0
    summary = json.loads(stdout)  # nothing else on stdout
    assert json.loads(out.read_text()) == summary
    for name in RUNS:
        assert name in stderr  # progress went to stderr


def test_rates_medians_and_ratios(tiny):
    summary = json.loads(tiny[1])
    for name in RUNS:
        run = summary[name]
        rates = run["sim_s_per_wall_s"]
        assert len(rates["values"]) == run["repetitions"] == REPEAT
        assert all(_positive(v) for v in rates["values"])
        assert rates["min"] <= rates["median"] <= rates["max"]
        assert rates["median"] == pytest.approx(statistics.median(rates["values"]))
        assert rates["min"] == min(rates["values"]) and rates["max"] == max(rates["values"])
        assert run["sim_time_s"] == pytest.approx([DURATION_S] * REPEAT)
        # The loop is part of the call; the rate is simulated over loop time.
        for sim_s, loop_s, call_s, rate in zip(
            run["sim_time_s"], run["loop_wall_s"], run["call_wall_s"], rates["values"]
        ):
            assert 0.0 < loop_s < call_s
            assert rate == pytest.approx(sim_s / loop_s)
    median = {name: summary[name]["sim_s_per_wall_s"]["median"] for name in RUNS}
    assert summary["ratio_closed_loop_recording_to_plant_seat_hold"] == pytest.approx(
        median["closed_loop_recording"] / median["plant_seat_hold"]
    )
    assert summary["ratio_closed_loop_to_plant_seat_hold"] == pytest.approx(
        median["closed_loop"] / median["plant_seat_hold"]
    )
    assert summary["duration_s"] == {"closed_loop": DURATION_S, "plant_seat_hold": DURATION_S}


def test_closed_loop_runs_report_whether_they_stood_up(tiny):
    summary = json.loads(tiny[1])
    assert "stood_up" not in summary["plant_seat_hold"]
    for name in ("closed_loop_recording", "closed_loop"):
        stood = summary[name]["stood_up"]
        assert len(stood) == REPEAT
        for run in stood:
            # 0.05 s is far too short to stand: the failure must say so.
            assert run["success"] is False and run["standup_time_s"] is None
            assert run["failure_reason"]
    assert all(n > 0 for n in summary["closed_loop_recording"]["recording_bytes"])
    assert "recording_bytes" not in summary["closed_loop"]


def test_controller_tick_split(tiny):
    summary = json.loads(tiny[1])
    for name in ("closed_loop", "closed_loop_recording"):
        split = summary["controller_tick"][name]
        # One tick per controller period started before the end (t = 0, p, 2p, ...)
        # plus the initialization tick, each run.
        period = Scenario().controller_period_s
        assert split["ticks"] == REPEAT * (math.ceil(DURATION_S / period - 1e-9) + 1)
        for column in COLUMNS:
            stats = split[column]
            assert 0.0 < stats["median"] <= stats["p95"]
            assert stats["mean"] > 0.0
        # The parts are disjoint pieces of the tick: their means add to at most the
        # total's mean (means add; medians need not).
        parts = sum(split[column]["mean"] for column in COLUMNS[:-1])
        total = split[COLUMNS[-1]]["mean"]
        assert parts <= total * (1 + 1e-9)
        assert split["unaccounted_us"]["mean"] == pytest.approx(total - parts, rel=1e-6)
        # How much of the tick the named parts cover is a timing, the benchmark's to
        # report (it read under half once on the loaded machine), not a test's.


def test_controller_share_of_the_loop(tiny):
    """The ticks' summed compute time is part of the loop's wall time (share in
    (0, 1)); wall per plant step = loop wall / (simulated time / step)."""
    summary = json.loads(tiny[1])
    assert summary["run_diagram"] is None  # --no-run-diagram
    for name in ("closed_loop", "closed_loop_recording"):
        share = summary["controller_share"][name]
        assert 0.0 < share["controller_share_of_loop_wall"] < 1.0
        step = share["plant_time_step_s"]
        walls = summary[name]["loop_wall_s"]
        sims = summary[name]["sim_time_s"]
        expected = statistics.median(1e6 * w / (t / step) for w, t in zip(walls, sims))
        assert share["loop_wall_per_plant_step_us"] == pytest.approx(expected)


def test_plant_step_model_build_memory_and_machine(tiny):
    summary = json.loads(tiny[1])
    step = summary["plant_step"]
    assert step["step_s"] == Scenario().plant.time_step
    bare, whole = step["plant_and_scene_graph_us"], step["seat_hold_diagram_us"]
    for stats in (bare, whole):
        assert stats["steps"] == PLANT_STEPS
        assert 0.0 < stats["median"] <= stats["p95"]
    # Not compared with each other: the Python systems the seat-hold diagram adds now
    # cost less than the shared machine's noise (775 against 780 us, reversed, in CI).

    build = summary["model_build"]
    assert build["meshes_converted_cold"] > 0  # the cold cache really converted meshes
    assert build["cold_cache_s"] > build["warm_cache_s"] > 0.0

    assert summary["peak_rss_mb"] > 50.0
    machine = summary["machine"]
    assert machine["nproc"] >= 1 and machine["drake"] and machine["python"]
    assert summary["profile"] is None
    assert set(summary["load_average_1_5_15"]) == {"start", "end"}
    git = summary["git"]
    assert len(git["diff_sha1"]) == 40 and isinstance(git["changed_during_bench"], bool)
    assert _positive(summary["bench_wall_s"])


@pytest.mark.parametrize(
    "argv",
    [["--repeat", "0"], ["--duration", "-1"], ["--plant-steps", "x"], ["--bogus"]],
)
def test_bad_arguments_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        bench.main(argv)
    assert exit_info.value.code == 2
    assert capsys.readouterr().out == ""


def test_missing_scenario_is_one_error_line(tmp_path, capsys):
    assert bench.main(["--scenario", str(tmp_path / "nope.yaml")]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("error: ") and captured.err.count("\n") == 1


def test_profile_writes_a_loadable_profile(tmp_path, capsys):
    path = tmp_path / "prof" / "run.prof"
    argv = [*TINY, "--repeat", "1", "--profile", str(path)]
    assert bench.main(argv) == 0
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary["profile"]["prof"] == str(path)
    assert str(path) in captured.err
    stats = pstats.Stats(str(path))
    assert stats.total_calls > 0
    assert any(func[2] == "simulate" for func in stats.stats)
    text = path.with_suffix(".txt").read_text()
    assert "by cumulative" in text and "by tottime" in text
    assert _positive(summary["profile"]["sim_s_per_wall_s_under_profiler"])


@pytest.mark.parametrize(
    ("flag", "where"),
    [("--out", "under a file"), ("--profile", "under a file"), ("--out", "a folder")],
)
def test_an_output_file_that_cannot_be_written_is_one_error_line_before_any_run(
    flag, where, tmp_path, capsys, monkeypatch
):
    in_the_way = tmp_path / "file"
    in_the_way.write_text("")
    path = in_the_way / "bench.json" if where == "under a file" else tmp_path
    monkeypatch.setattr(bench, "time_model_build", lambda _: pytest.fail("ran before the check"))
    assert bench.main([*TINY, flag, str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    (line,) = captured.err.splitlines()  # one line: no traceback
    expected = f"'{in_the_way}' is a file" if where == "under a file" else f"'{path}' is a folder"
    assert line.startswith(f"error: {flag}: {expected}; accepted: ")
