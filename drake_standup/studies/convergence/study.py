"""The study: simulates on Dask the cases OUT/runs/ does not hold yet, compares them, chooses
the step and writes convergence.json, convergence.md and convergence.png."""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass
from pathlib import Path

from drake_standup.config import SCENARIO_DIR
from drake_standup.studies.convergence.cases import (
    Case,
    case_inputs,
    scenario_duration_s,
    study_cases,
)
from drake_standup.studies.convergence.choice import choose, config_table, evaluate
from drake_standup.studies.convergence.comparison import (
    COM_DEVIATION_M,
    COM_FINAL_M,
    CONTACT_THRESHOLD_N,
    PAD_SPLIT_PCT,
    PEAK_TORQUE_REL,
    SOLE_CHATTER_N,
    STANDUP_TIME_ABS_S,
    STANDUP_TIME_REL,
    STATE_ENTRY_S,
)
from drake_standup.studies.convergence.figures import draw_figure
from drake_standup.studies.convergence.report import markdown
from drake_standup.studies.convergence.runs import is_cached, load_run, run_case


@dataclass
class StudyResult:
    """What run_study did: the records and choice, the runs simulated and reused, the wall
    time of the simulating part (s), and the files written (json, md, png)."""

    records: list[dict]
    choice: dict | None
    computed: int
    reused: int
    wall_s: float
    files: list[Path]


def run_study(
    scenarios: list[str],
    steps_ms: list[float],
    out_dir: Path,
    *,
    workers: int = 2,
    address: str | None = None,
    fresh: bool = False,
    progress: bool = True,
    overrides: list | tuple = (),
    controller_ms: float | None = None,
) -> StudyResult:
    """Simulates what OUT/runs/ does not hold yet, compares, chooses, reports;
    overrides: (key path, value) pairs set in every run's scenario (--set);
    controller_ms: the controller at this period at every step (--controller-ms)."""
    from drake_standup.outputs.json_files import write_json
    from drake_standup.studies.cluster import run_on_cluster

    out_dir = Path(out_dir)
    runs_dir = out_dir / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    texts = {s: (SCENARIO_DIR / f"{s}.yaml").read_text() for s in scenarios}
    durations = {s: scenario_duration_s(s, texts[s]) for s in scenarios}
    cases = study_cases(scenarios, steps_ms, controller_ms)
    inputs = {c: case_inputs(c, texts[c.scenario], durations[c.scenario], overrides) for c in cases}
    todo = [c for c in cases if fresh or not is_cached(runs_dir / c.name, inputs[c])]
    # Longest first, so that two workers finish together.
    todo.sort(key=lambda c: -durations[c.scenario] / (c.step_s * (1 + c.factor)))
    if progress and len(todo) < len(cases):
        print(f"reusing {len(cases) - len(todo)} of {len(cases)} runs from {runs_dir}", flush=True)

    for case in todo:  # not finished until its worker says so
        (runs_dir / case.name / "inputs.json").unlink(missing_ok=True)

    def on_result(case: Case, metrics: dict | None, lost: BaseException | None) -> dict:
        if lost is not None:
            metrics = {"success": False, "failure_reason": f"cluster: {lost!r}"[:300]}
            write_json(runs_dir / case.name / "metrics.json", metrics)
        return metrics

    t0 = time.perf_counter()
    if todo:
        tasks = _tasks(todo, texts, durations, inputs, runs_dir, overrides)
        run_on_cluster(
            tasks,
            on_result,
            workers=workers,
            address=address,
            label="convergence",
            progress=progress,
        )
    wall_s = time.perf_counter() - t0

    runs = {c: load_run(runs_dir / c.name) for c in cases}
    records = evaluate(cases, runs)
    for record, case in zip(records, cases):
        record["inputs"] = inputs[case]
        record["reused"] = case not in todo
    choice = choose(records, scenarios)
    study = _study(
        records,
        choice,
        scenarios,
        steps_ms,
        durations,
        overrides,
        wall_s=wall_s,
        todo=todo,
        cases=cases,
    )
    files = [out_dir / "convergence.json", out_dir / "convergence.md", out_dir / "convergence.png"]
    write_json(files[0], _inf_as_text(study))
    files[1].write_text(markdown(records, choice, wall_s if todo else None, overrides))
    draw_figure(records, files[2])
    return StudyResult(records, choice, len(todo), len(cases) - len(todo), wall_s, files)


def _tasks(
    todo: list[Case],
    texts: dict[str, str],
    durations: dict[str, float],
    inputs: dict[Case, dict],
    runs_dir: Path,
    overrides: list | tuple,
) -> list[tuple]:
    """run_on_cluster's tasks: (case, key, run_case, its arguments) of each case to run."""
    return [
        (
            c,
            f"convergence-{c.name}-{inputs[c]['hash']}",
            # run_case takes inputs and overrides by keyword (the tasks' arguments go
            # positionally: passing them so failed every run with a TypeError).
            functools.partial(run_case, inputs=inputs[c], overrides=list(overrides)),
            (
                texts[c.scenario],
                f"scenarios/{c.scenario}.yaml",
                c.step_s,
                c.controller_period_s,
                durations[c.scenario],
                str((runs_dir / c.name).resolve()),
            ),
        )
        for c in todo
    ]


def _study(
    records: list[dict],
    choice: dict | None,
    scenarios: list[str],
    steps_ms: list[float],
    durations: dict[str, float],
    overrides: list | tuple,
    *,
    wall_s: float,
    todo: list[Case],
    cases: list[Case],
) -> dict:
    """convergence.json's content: the bounds, the study's inputs, the choice and every run."""
    return {
        "issue": 11,
        "bounds": {
            "standup_time_rel": STANDUP_TIME_REL,
            "standup_time_abs_s": STANDUP_TIME_ABS_S,
            "state_entry_s": STATE_ENTRY_S,
            "com_deviation_m": COM_DEVIATION_M,
            "com_final_m": COM_FINAL_M,
            "pad_split_pct": PAD_SPLIT_PCT,
            "peak_torque_rel": PEAK_TORQUE_REL,
            "sole_chatter_N": SOLE_CHATTER_N,
            "contact_threshold_N": CONTACT_THRESHOLD_N,
        },
        "scenarios": {s: {"duration_s": durations[s]} for s in scenarios},
        "steps_ms": sorted(steps_ms),
        "overrides": [[path, value] for path, value in overrides],
        "configurations": config_table(records),
        "choice": choice,
        "study_wall_s": wall_s,
        "simulated": len(todo),
        "reused": len(cases) - len(todo),
        "runs": records,
    }


def _inf_as_text(x):
    """Infinite errors (an event in one run only) as "inf": JSON has no
    infinity, and json_safe's null would read as "not measured"."""
    if isinstance(x, dict):
        return {k: _inf_as_text(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_inf_as_text(v) for v in x]
    if isinstance(x, float) and math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x
