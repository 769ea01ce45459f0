"""The study's verdict: each run against its scenario's references, the per-configuration
table, and the chosen plant step and controller period."""

from __future__ import annotations

import statistics

from drake_standup.studies.convergence.cases import REFERENCE_STEP_MS, Case, same_family
from drake_standup.studies.convergence.comparison import (
    BOUNDS,
    compare,
    is_missing,
    summary,
    with_fine_reference,
)
from drake_standup.studies.convergence.runs import RunData


def evaluate(cases: list[Case], runs: dict[Case, RunData]) -> list[dict]:
    """Each run against the same scenario's run at REFERENCE_STEP_MS (or the
    smallest step, where that was not run), and, where a finer run exists,
    against it too (with_fine_reference): raw numbers, errors and passes."""
    records = []
    for case in cases:
        own = sorted((c for c in cases if same_family(case, c)), key=lambda c: c.step_ms)
        ref_case = next((c for c in own if c.step_ms == REFERENCE_STEP_MS), own[0])
        fine_case = own[0] if own[0].step_ms < ref_case.step_ms else None
        result = compare(runs[case], runs[ref_case])
        if fine_case is not None and case not in (ref_case, fine_case):
            result = with_fine_reference(
                result,
                compare(runs[case], runs[fine_case]),
                compare(runs[ref_case], runs[fine_case]),
            )
        records.append(
            {
                "scenario": case.scenario,
                "step_ms": case.step_ms,
                "controller_period_ms": case.controller_period_ms,
                "factor": case.factor,
                "rate_ms": case.rate_ms,
                "base": case.base,
                "run": case.name,
                "reference": case == ref_case,
                "fine": case == fine_case,
                "raw": summary(runs[case]),
                **result,
            }
        )
    return records


def study_rate_ms(records: list[dict]) -> float | None:
    """The study's fixed controller period (--controller-ms), or None."""
    return next((r["rate_ms"] for r in records if r.get("rate_ms") is not None), None)


def median_or_none(values) -> float | None:
    """The median of the measured values (None and non-finite left out); None if none is."""
    values = [v for v in values if not is_missing(v)]
    return statistics.median(values) if values else None


def config_table(records: list[dict]) -> list[dict]:
    """One row per (plant step, controller multiple): does every scenario pass,
    the median speed, the summed wall time; by step, then multiple."""
    rows = []
    for config in sorted({(r["step_ms"], r["factor"]) for r in records}):
        sel = [r for r in records if (r["step_ms"], r["factor"]) == config]
        rows.append(
            {
                "step_ms": config[0],
                "factor": config[1],
                "controller_period_ms": config[0] * config[1],
                "base": all(r["base"] for r in sel),
                "scenarios": sorted(r["scenario"] for r in sel),
                "all_pass": all(r["pass"] for r in sel),
                "all_pass_strict": all(r["strict_pass"] for r in sel),
                "failing": sorted(r["scenario"] for r in sel if not r["pass"]),
                "bounds_failed": [b for b in BOUNDS if any(b in r["failed"] for r in sel)],
                "median_realtime_factor": median_or_none(r["raw"]["realtime_factor"] for r in sel),
                "wall_time_s": sum(r["raw"]["wall_time_s"] or 0.0 for r in sel),
            }
        )
    return rows


def choose(records: list[dict], scenarios: list[str]) -> dict | None:
    """The largest plant step at which every scenario passes; at that step the
    controller at twice the step only if it passes too and its runs took less
    wall time in all. None when no configuration passes for every scenario."""
    rows = [
        r
        for r in config_table(records)
        if r["all_pass"]
        and r["step_ms"] >= REFERENCE_STEP_MS
        and set(scenarios) <= set(r["scenarios"])
    ]
    if not rows:
        return None
    step = max(r["step_ms"] for r in rows)
    at_step = sorted((r for r in rows if r["step_ms"] == step), key=lambda r: r["factor"])
    best = at_step[0]
    for row in at_step[1:]:
        if row["wall_time_s"] < best["wall_time_s"]:
            best = row
    failing_below = [
        r
        for r in config_table(records)
        if REFERENCE_STEP_MS <= r["step_ms"] < step and r["base"] and not r["all_pass"]
    ]
    return {
        "step_ms": best["step_ms"],
        "controller_period_ms": best["controller_period_ms"],
        "factor": best["factor"],
        "median_realtime_factor": best["median_realtime_factor"],
        # A smaller step that fails makes the choice a lucky pass, not convergence.
        "smaller_steps_failing_ms": [r["step_ms"] for r in failing_below],
    }
