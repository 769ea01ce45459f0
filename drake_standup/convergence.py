"""Time-step convergence study (issue 11): how coarse may the plant and controller step?

drake-standup convergence [--out DIR] [--workers N] [--scenarios NAME ...]
    [--steps-ms H ...] [--fresh] [--docs DIR]

A study, not a test. It simulates scenarios/NAME.yaml (assisted, unassisted,
lateral and seated by default) with the plant stepped at each of 0.5, 1, 2, 4, 5, 8
and 10 ms and the controller at the same period, plus, at 2, 4 and 5 ms, the
controller at twice the plant step ("does a slower controller over a finer plant
pay?"). Every run is compared with the same scenario's run at 1 ms against issue 11's
bounds (the constants below). A 0.5 ms run of each scenario says how converged
that reference is itself: a bound that the 1 ms run fails against the 0.5 ms
run measures the scenario's sensitivity (a guard or gate that a tiny change
flips), not the step's error. So a run passes a bound when it is within the
bound of the 1 ms run, or no further from the 0.5 ms run than the 1 ms run is;
the strict verdict (against 1 ms only) is reported beside it. The default step
is chosen: the largest plant step at which every scenario passes.

Runs go to a Dask LocalCluster of single-threaded worker processes (or the
scheduler at --address; the workers must then share OUT's file system). Each run
writes OUT/runs/<scenario>_<step ms>_<controller period / step>/ (metrics.json,
signals.npz, inputs.json) and is reused by the next start when its inputs (the
scenario's text, duration, plant step and controller period) are unchanged;
--fresh simulates every run again. A change of the code is not an input: after
one, use --fresh. At the end: OUT/convergence.json (every run's numbers, errors,
pass or fail per bound, and the choice), OUT/convergence.md (the tables for the
README) and OUT/convergence.png (the errors over their bounds and the speed
against the step).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import shutil
import statistics
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drake_standup.arguments import OneLineErrorParser
from drake_standup.config import SCENARIO_DIR
from drake_standup.outputs import group_normal_forces

# --- Issue 11's bounds --------------------------------------------------------
# A run passes when, against the same scenario's 1 ms run, every one of these
# holds (the bounds of issue 11):
# the stand-up time within 2% or 0.03 s, whichever is larger;
STANDUP_TIME_REL = 0.02
STANDUP_TIME_ABS_S = 0.03
# every state entered within 0.05 s of the 1 ms run;
STATE_ENTRY_S = 0.05
# the CoM within 5 mm of the 1 ms run's at every logged instant;
COM_DEVIATION_M = 0.005
# the final CoM within 2 mm;
COM_FINAL_M = 0.002
# each pad group's share of the seated load within 5% (relative);
PAD_SPLIT_PCT = 5.0
# the peak joint torque within 15% (relative);
PEAK_TORQUE_REL = 0.15
# no pad group loaded or unloaded (its normal force crossing 5 N, up or down)
# more often than at 1 ms, no more QP failures than at 1 ms, and the same
# success.
CONTACT_THRESHOLD_N = 5.0

BOUNDS = (
    "standup_time",
    "state_entries",
    "com_deviation",
    "com_final",
    "pad_split",
    "peak_torque",
    "contact_crossings",
    "qp_failures",
    "success",
)

SCENARIOS = ("assisted", "unassisted", "lateral", "seated")
# Seated, nothing happens after the settling: 5 s is enough (issue 11).
SEATED_DURATION_S = 5.0
STEPS_MS = (0.5, 1.0, 2.0, 4.0, 5.0, 8.0, 10.0)
# Issue 11's reference: every run is compared with the scenario's run here.
REFERENCE_STEP_MS = 1.0
# Plant steps also run with the controller at twice the step.
SLOW_CONTROLLER_STEPS_MS = (2.0, 4.0, 5.0)
SLOW_CONTROLLER_FACTOR = 2
# Normal forces below this total are "nothing on the contacts" (the first
# samples, before the first contact step): no split is defined there. N.
SPLIT_MIN_TOTAL_N = 1.0


# --- The runs -----------------------------------------------------------------


@dataclass(frozen=True)
class Case:
    """One run of the study: a scenario, a plant step, the controller's multiple."""

    scenario: str
    step_ms: float
    factor: int = 1  # controller period = factor * plant step

    @property
    def name(self) -> str:
        return f"{self.scenario}_{self.step_ms:g}_{self.factor}"

    @property
    def step_s(self) -> float:
        return self.step_ms / 1000.0

    @property
    def controller_period_ms(self) -> float:
        return self.factor * self.step_ms

    @property
    def controller_period_s(self) -> float:
        return self.controller_period_ms / 1000.0


def study_cases(scenarios: list[str], steps_ms: list[float]) -> list[Case]:
    """Every scenario at every step (controller at the step), plus the
    slow-controller variants at the steps of SLOW_CONTROLLER_STEPS_MS."""
    cases = []
    for name in scenarios:
        for step in sorted(steps_ms):
            cases.append(Case(name, step))
            if step in SLOW_CONTROLLER_STEPS_MS:
                cases.append(Case(name, step, SLOW_CONTROLLER_FACTOR))
    return cases


def scenario_duration_s(name: str, text: str) -> float:
    """The scenario's own duration; the seated scenario's SEATED_DURATION_S."""
    from drake_standup.config import parse_scenario

    return SEATED_DURATION_S if name == "seated" else parse_scenario(text, name).duration_s


def case_inputs(case: Case, scenario_text: str, duration_s: float) -> dict:
    """What a run's result depends on (bar the code), and its hash."""
    inputs = {
        "scenario": case.scenario,
        "scenario_sha256": hashlib.sha256(scenario_text.encode()).hexdigest(),
        "duration_s": duration_s,
        "plant_time_step_s": case.step_s,
        "controller_period_s": case.controller_period_s,
    }
    inputs["hash"] = hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:16]
    return inputs


RUN_FILES = ("metrics.json", "signals.npz", "inputs.json")


def is_cached(run_dir: Path, inputs: dict) -> bool:
    """run_dir holds a finished run of exactly these inputs."""
    if not all((run_dir / f).is_file() for f in RUN_FILES):
        return False
    try:
        return json.loads((run_dir / "inputs.json").read_text()).get("hash") == inputs["hash"]
    except (OSError, ValueError):
        return False


def run_case(
    scenario_text: str,
    where: str,
    step_s: float,
    controller_period_s: float,
    duration_s: float,
    out_dir: str,
    inputs: dict,
) -> dict:
    """Simulates one run into out_dir (in a Dask worker); returns its metrics.

    Never raises: a run that throws is success false and the reason, in
    metrics.json. A previous run's files go first, and inputs.json is written
    last, only when metrics.json and signals.npz are there: a run cut short is
    never taken for a finished one, nor its folder read as an older run's.
    """
    from drake_standup.config import parse_scenario, validate
    from drake_standup.outputs import json_safe
    from drake_standup.simulate import simulate

    run_dir = Path(out_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    for name in RUN_FILES:
        (run_dir / name).unlink(missing_ok=True)
    try:
        scenario = parse_scenario(scenario_text, where)
        scenario.plant.time_step = step_s
        scenario.controller_period_s = controller_period_s
        scenario.duration_s = duration_s
        validate(scenario)
        metrics = json_safe(simulate(scenario, run_dir, record=False, progress=False).metrics)
    except Exception as err:  # noqa: BLE001 - a run's failure is its result
        tail = traceback.format_exc().strip().splitlines()[-3:]
        reason = f"error: {type(err).__name__}: {' '.join(str(err).split())[:300]}"
        metrics = {"success": False, "failure_reason": reason, "traceback": " | ".join(tail)}
        (run_dir / "metrics.json").write_text(json.dumps(metrics, indent=1) + "\n")
        return metrics
    if not (run_dir / "signals.npz").is_file():
        metrics["failure_reason"] = metrics.get("failure_reason") or "no signals.npz written"
        return metrics
    (run_dir / "inputs.json").write_text(json.dumps(inputs, indent=1) + "\n")
    return metrics


# --- What a run is compared on ------------------------------------------------


@dataclass
class RunData:
    """A finished run: its metrics.json and its signals.npz (None if missing)."""

    metrics: dict
    signals: dict | None


def load_run(run_dir: Path) -> RunData:
    from drake_standup.outputs import load_signals

    metrics_path = Path(run_dir) / "metrics.json"
    metrics = json.loads(metrics_path.read_text()) if metrics_path.is_file() else {}
    signals_path = Path(run_dir) / "signals.npz"
    signals = load_signals(signals_path) if signals_path.is_file() else None
    return RunData(metrics, signals)


def seated_split(signals: dict) -> dict[str, float]:
    """Each group's share of the total normal force, averaged over the seated
    part of the run (state 1: before state 2, or the whole seated run)."""
    forces = group_normal_forces(signals)
    total = sum(forces.values())
    seated = (np.asarray(signals["state"]) == 1) & (total > SPLIT_MIN_TOTAL_N)
    if not seated.any():
        return {g: math.nan for g in forces}
    return {g: float(np.mean(f[seated] / total[seated])) for g, f in forces.items()}


def count_crossings(
    force_N: np.ndarray, threshold_N: float = CONTACT_THRESHOLD_N
) -> tuple[int, int]:
    """(loads, unloads): how often force_N rises above threshold_N and falls back."""
    above = np.asarray(force_N) > threshold_N
    up = int(np.count_nonzero(~above[:-1] & above[1:]))
    down = int(np.count_nonzero(above[:-1] & ~above[1:]))
    return up, down


def contact_crossings(signals: dict) -> dict[str, list[int]]:
    """Pad group -> [loads, unloads] over the whole run."""
    return {g: list(count_crossings(f)) for g, f in group_normal_forces(signals).items()}


def _time_key(times_s: np.ndarray) -> np.ndarray:
    """Sample times as integer microseconds, so equal grid points match exactly."""
    return np.round(np.asarray(times_s, dtype=float) * 1e6).astype(np.int64)


def max_com_deviation(
    times_s: np.ndarray, com_W: np.ndarray, ref_times_s: np.ndarray, ref_com_W: np.ndarray
) -> float:
    """max |com_W - ref_com_W| over the samples both runs hold (up to the shorter run). m."""
    _, i, j = np.intersect1d(_time_key(times_s), _time_key(ref_times_s), return_indices=True)
    if len(i) == 0:
        return math.inf
    return float(np.max(np.linalg.norm(np.asarray(com_W)[i] - np.asarray(ref_com_W)[j], axis=1)))


def _missing(value) -> bool:
    return value is None or (isinstance(value, float) and not math.isfinite(value))


def time_error(t, t_ref) -> float:
    """|t - t_ref|; 0 when neither happened, infinite when only one did. s."""
    if _missing(t) and _missing(t_ref):
        return 0.0
    if _missing(t) or _missing(t_ref):
        return math.inf
    return abs(float(t) - float(t_ref))


def entry_time_error(entries_s: list, ref_entries_s: list) -> float:
    """The largest state-entry time error over the states. s."""
    n = max(len(entries_s), len(ref_entries_s))
    pad = [None] * n
    entries_s = list(entries_s) + pad[len(entries_s) :]
    ref_entries_s = list(ref_entries_s) + pad[len(ref_entries_s) :]
    return max((time_error(a, b) for a, b in zip(entries_s, ref_entries_s)), default=0.0)


def standup_time_bound_s(ref_standup_time_s) -> float:
    """2% of the 1 ms run's stand-up time or 0.03 s, whichever is larger."""
    if _missing(ref_standup_time_s):
        return STANDUP_TIME_ABS_S
    return max(STANDUP_TIME_REL * float(ref_standup_time_s), STANDUP_TIME_ABS_S)


def relative_error(value, ref) -> float:
    if _missing(value) or _missing(ref):
        return 0.0 if _missing(value) and _missing(ref) else math.inf
    if ref == 0:
        return 0.0 if value == 0 else math.inf
    return abs(float(value) - float(ref)) / abs(float(ref))


def split_error_pct(split: dict[str, float], ref_split: dict[str, float]) -> float:
    """The largest relative error over the groups' mean shares of the seated load. %."""
    errors = [100.0 * relative_error(split.get(g), share) for g, share in ref_split.items()]
    return max(errors, default=0.0)


def summary(run: RunData) -> dict:
    """A run's raw numbers, as convergence.json records them."""
    m = run.metrics
    out = {
        "success": bool(m.get("success", False)),
        "failure_reason": m.get("failure_reason"),
        "standup_time_s": m.get("standup_time_s"),
        "state_entry_times_s": m.get("state_entry_times_s") or [],
        "com_final_m": m.get("com_final_m"),
        "max_abs_torque_Nm": m.get("max_abs_torque_Nm"),
        "qp_failures": m.get("qp_failures") or 0,
        "realtime_factor": m.get("realtime_factor"),
        "wall_time_s": m.get("wall_time_s"),
        "sim_time_s": m.get("sim_time_s"),
        "contact_normal_force_N": m.get("contact_normal_force_N"),
        "seated_split": None,
        "contact_crossings": None,
    }
    if run.signals is not None:
        out["seated_split"] = seated_split(run.signals)
        out["contact_crossings"] = contact_crossings(run.signals)
    return out


def compare(run: RunData, ref: RunData) -> dict:
    """run against the 1 ms run ref: its errors, each error over its bound, and
    which of issue 11's bounds hold (a quantity that cannot be measured, e.g.
    with signals.npz missing, is an infinite error)."""
    s, r = summary(run), summary(ref)
    errors: dict = {
        "standup_time_s": time_error(s["standup_time_s"], r["standup_time_s"]),
        "state_entries_s": entry_time_error(s["state_entry_times_s"], r["state_entry_times_s"]),
        "com_final_m": math.inf,
        "com_deviation_m": math.inf,
        "pad_split_pct": math.inf,
        "peak_torque_rel": relative_error(s["max_abs_torque_Nm"], r["max_abs_torque_Nm"]),
        "extra_crossings": math.inf,  # the most any group/direction exceeds the 1 ms run
        "extra_qp_failures": s["qp_failures"] - r["qp_failures"],
    }
    if s["com_final_m"] is not None and r["com_final_m"] is not None:
        diff = np.subtract(s["com_final_m"], r["com_final_m"])
        errors["com_final_m"] = float(np.linalg.norm(diff))
    if run.signals is not None and ref.signals is not None:
        errors["com_deviation_m"] = max_com_deviation(
            run.signals["time_s"],
            run.signals["com_W"],
            ref.signals["time_s"],
            ref.signals["com_W"],
        )
        errors["pad_split_pct"] = split_error_pct(s["seated_split"], r["seated_split"])
        ours, theirs = s["contact_crossings"], r["contact_crossings"]
        errors["extra_crossings"] = max(
            ours.get(g, [0, 0])[d] - theirs.get(g, [0, 0])[d]
            for g in set(ours) | set(theirs)
            for d in (0, 1)
        )
    standup_bound = standup_time_bound_s(r["standup_time_s"])
    normalised = {
        "standup_time": errors["standup_time_s"] / standup_bound,
        "state_entries": errors["state_entries_s"] / STATE_ENTRY_S,
        "com_deviation": errors["com_deviation_m"] / COM_DEVIATION_M,
        "com_final": errors["com_final_m"] / COM_FINAL_M,
        "pad_split": errors["pad_split_pct"] / PAD_SPLIT_PCT,
        "peak_torque": errors["peak_torque_rel"] / PEAK_TORQUE_REL,
    }
    passes = {key: value <= 1.0 for key, value in normalised.items()}
    passes["contact_crossings"] = errors["extra_crossings"] <= 0
    passes["qp_failures"] = errors["extra_qp_failures"] <= 0
    passes["success"] = s["success"] == r["success"]
    return {
        "errors": errors,
        "standup_time_bound_s": standup_bound,
        "normalised": normalised,
        "passes": passes,
        "failed": [b for b in BOUNDS if not passes[b]],
        "pass": all(passes.values()),
        "strict_failed": [b for b in BOUNDS if not passes[b]],
        "strict_pass": all(passes.values()),
    }


def with_fine_reference(result: dict, vs_fine: dict, reference_vs_fine: dict) -> dict:
    """result (a run against the 1 ms run) with each error bound also passed
    where the run is no further from the finer run than the 1 ms run is
    (vs_fine: the run against the finer run; reference_vs_fine: the 1 ms run
    against it). The count bounds (crossings, QP failures, success) stay
    against the 1 ms run."""
    passes = dict(result["passes"])
    for key, value in vs_fine["normalised"].items():
        passes[key] = passes[key] or value <= max(1.0, reference_vs_fine["normalised"][key])
    return {
        **result,
        "passes": passes,
        "failed": [b for b in BOUNDS if not passes[b]],
        "pass": all(passes.values()),
        "errors_vs_fine": vs_fine["errors"],
        "reference_errors_vs_fine": reference_vs_fine["errors"],
    }


# --- The choice ---------------------------------------------------------------


def _median(values) -> float | None:
    values = [v for v in values if not _missing(v)]
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
                "scenarios": sorted(r["scenario"] for r in sel),
                "all_pass": all(r["pass"] for r in sel),
                "all_pass_strict": all(r["strict_pass"] for r in sel),
                "failing": sorted(r["scenario"] for r in sel if not r["pass"]),
                "bounds_failed": [b for b in BOUNDS if any(b in r["failed"] for r in sel)],
                "median_realtime_factor": _median(r["raw"]["realtime_factor"] for r in sel),
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
        if REFERENCE_STEP_MS <= r["step_ms"] < step and r["factor"] == 1 and not r["all_pass"]
    ]
    return {
        "step_ms": best["step_ms"],
        "controller_period_ms": best["controller_period_ms"],
        "factor": best["factor"],
        "median_realtime_factor": best["median_realtime_factor"],
        # A smaller step that fails makes the choice a lucky pass, not convergence.
        "smaller_steps_failing_ms": [r["step_ms"] for r in failing_below],
    }


# --- Reports ------------------------------------------------------------------


def _fmt(value, scale: float = 1.0, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    if isinstance(value, float) and math.isnan(value):
        return "-"
    return f"{value * scale:.{digits}f}"


def _crossings_total(crossings: dict | None) -> int | None:
    if crossings is None:
        return None
    return sum(up + down for up, down in crossings.values())


def markdown(records: list[dict], choice: dict | None, wall_s: float | None = None) -> str:
    """convergence.md: the per-run table, the per-configuration summary, the choice."""
    lines = [
        "Each run against the same scenario's 1 ms run (plant and controller at 1 ms). "
        "Bounds (issue 11): stand-up time within max(2%, 0.03 s), state entries within "
        "0.05 s, CoM within 5 mm at every logged instant, final CoM within 2 mm, seated "
        "pad-group load shares within 5%, peak torque within 15%, no more 5 N load/unload "
        "crossings in any pad group, no more QP failures, the same success. The seated "
        "scenario (5 s) is meant not to stand up. Crossings: load + unload events summed "
        "over the pad groups (the 1 ms run's in brackets); the bound holds per group and "
        "direction. The 0.5 ms run checks the reference: CoM deviation and split error of "
        "each run against it, and (on the 1 ms row) the 1 ms run's own. A run passes a bound "
        "within it of the 1 ms run, or no further from the 0.5 ms run than the 1 ms run is: "
        "'yes (b)' passes bound b only that way (the scenario's sensitivity, not the step).",
        "",
        "| scenario | plant / ctrl (ms) | stood up | stand-up (s) | stand-up err (s) | "
        "entries err (s) | max CoM dev (mm) | vs 0.5 ms | final CoM err (mm) | "
        "seated split err (%) | vs 0.5 ms | peak torque err (%) | crossings (1 ms) | QP fails | "
        "sim s / wall s | wall (s) | pass |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    refs = {r["scenario"]: r for r in records if r.get("reference")}
    for r in records:
        raw, err = r["raw"], r["errors"]
        ref = refs.get(r["scenario"])
        ref_cross = _crossings_total(ref["raw"]["contact_crossings"]) if ref else None
        cross = _crossings_total(raw["contact_crossings"])
        reason = raw["failure_reason"] or "?"
        stood = (
            "yes" if raw["success"] else ("no" if reason == "did not stand up" else f"no: {reason}")
        )
        if r.get("reference"):
            mark = "ref"
        elif r.get("fine"):
            mark = "finer"
        elif not r["pass"]:
            mark = "**no**: " + ", ".join(r["failed"])
        elif r["strict_pass"]:
            mark = "yes"
        else:
            mark = "yes (" + ", ".join(r["strict_failed"]) + ")"
        fine = r.get("errors_vs_fine", {})
        if r.get("reference"):
            fine = next(
                (
                    q["reference_errors_vs_fine"]
                    for q in records
                    if q["scenario"] == r["scenario"] and "reference_errors_vs_fine" in q
                ),
                {},
            )
        lines.append(
            f"| {r['scenario']} | {r['step_ms']:g} / {r['controller_period_ms']:g} | {stood} | "
            f"{_fmt(raw['standup_time_s'])} | {_fmt(err['standup_time_s'], digits=3)} | "
            f"{_fmt(err['state_entries_s'], digits=3)} | {_fmt(err['com_deviation_m'], 1e3, 1)} | "
            f"{_fmt(fine.get('com_deviation_m'), 1e3, 1)} | "
            f"{_fmt(err['com_final_m'], 1e3, 1)} | {_fmt(err['pad_split_pct'], digits=1)} | "
            f"{_fmt(fine.get('pad_split_pct'), digits=1)} | "
            f"{_fmt(err['peak_torque_rel'], 100.0, 1)} | "
            f"{'-' if cross is None else cross} ({'-' if ref_cross is None else ref_cross}) | "
            f"{raw['qp_failures']} | {_fmt(raw['realtime_factor'])} | "
            f"{_fmt(raw['wall_time_s'], digits=0)} | {mark} |"
        )
    lines += [
        "",
        "| plant / ctrl (ms) | every scenario passes | strictly (vs 1 ms only) | failing | "
        "bounds failed | median sim s / wall s | wall, all scenarios (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in config_table(records):
        lines.append(
            f"| {row['step_ms']:g} / {row['controller_period_ms']:g} | "
            f"{'yes' if row['all_pass'] else 'no'} | "
            f"{'yes' if row['all_pass_strict'] else 'no'} | {', '.join(row['failing']) or '-'} | "
            f"{', '.join(row['bounds_failed']) or '-'} | "
            f"{_fmt(row['median_realtime_factor'])} | {row['wall_time_s']:.0f} |"
        )
    lines.append("")
    lines.append(choice_sentence(choice, records))
    if wall_s is not None:
        lines.append(f"Study wall time: {wall_s / 60:.1f} min.")
    return "\n".join(lines) + "\n"


def choice_sentence(choice: dict | None, records: list[dict]) -> str:
    if choice is None:
        return "No step passes for every scenario (not even the reference: see the runs)."
    ref_speed = _median(r["raw"]["realtime_factor"] for r in records if r.get("reference"))
    text = (
        f"Chosen: plant {choice['step_ms']:g} ms, controller {choice['controller_period_ms']:g} ms "
        f"(the largest step at which every scenario passes; median "
        f"{_fmt(choice['median_realtime_factor'])}x real time against {_fmt(ref_speed)}x at the "
        "reference)."
    )
    if choice["smaller_steps_failing_ms"]:
        failing = ", ".join(f"{s:g}" for s in choice["smaller_steps_failing_ms"])
        text += f" Warning: smaller steps fail ({failing} ms)."
    return text


PANELS = (
    ("standup_time", "stand-up time error / max(2%, 0.03 s)"),
    ("state_entries", "state entry error / 0.05 s"),
    ("com_deviation", "max CoM deviation / 5 mm"),
    ("com_final", "final CoM error / 2 mm"),
    ("pad_split", "seated load-share error / 5%"),
    ("peak_torque", "peak torque error / 15%"),
)
FLOOR, CEILING = 1e-3, 1e2  # the log axis' range; exact zeros and infinities land on its ends


def draw_figure(records: list[dict], path: Path) -> None:
    """The errors over their bounds (log y; 1 = the bound), the extra contact
    crossings, and the speed, against the plant step; one colour per scenario,
    circles and lines with the controller at the step, squares at twice it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    scenarios = list(dict.fromkeys(r["scenario"] for r in records))
    colors = {s: f"C{i}" for i, s in enumerate(scenarios)}
    steps = sorted({r["step_ms"] for r in records})
    # Side by side, not on top of each other: a small shift per scenario.
    shift = {s: 1.0 + 0.025 * (i - (len(scenarios) - 1) / 2) for i, s in enumerate(scenarios)}
    fig, axes = plt.subplots(2, 4, figsize=(15, 7.2), sharex=True)
    axes = axes.ravel()

    def series(scenario: str, factor: int, value, with_reference: bool) -> tuple[list, list]:
        sel = [
            r
            for r in records
            if r["scenario"] == scenario
            and r["factor"] == factor
            and (with_reference or not r.get("reference"))
        ]
        sel.sort(key=lambda r: r["step_ms"])
        return [r["step_ms"] * shift[scenario] for r in sel], [value(r) for r in sel]

    def plot(ax, value, log: bool, errors: bool = True) -> None:
        for s in scenarios:
            for factor, style in ((1, dict(marker="o", ls="-")), (2, dict(marker="s", ls="none"))):
                # Against itself the reference is 0 by construction: not drawn.
                x, y = series(s, factor, value, with_reference=not errors)
                if not x:
                    continue
                y = np.array([np.nan if v is None else v for v in y], dtype=float)
                if log:
                    y = np.clip(np.where(np.isinf(y), CEILING, y), FLOOR, CEILING)
                ax.plot(
                    x,
                    y,
                    color=colors[s],
                    ms=6 if factor == 1 else 8,
                    mfc=colors[s] if factor == 1 else "none",
                    mew=1.5,
                    lw=1.3,
                    **style,
                )

    for ax, (key, title) in zip(axes, PANELS):
        plot(ax, lambda r, key=key: r["normalised"][key], log=True)
        ax.set_yscale("log")
        # Up to the ceiling only where an event happened in one run only.
        values = [r["normalised"][key] for r in records if not r.get("reference")]
        top = max([v for v in values if v is not None] + [3.0])
        top = CEILING * 1.4 if math.isinf(top) else min(2.0 * top, CEILING * 1.4)
        ax.set_ylim(FLOOR * 0.7, top)
        ax.axhline(1.0, color="red", ls="--", lw=1)
        ax.axhspan(1.0, top, color="red", alpha=0.05)
        ax.set_title(title, fontsize=10)
    ax = axes[6]
    plot(ax, lambda r: r["errors"]["extra_crossings"], log=False)
    ax.axhline(0.0, color="red", ls="--", lw=1)
    ax.set_title("extra 5 N load/unload crossings\n(worst pad group, vs 1 ms)", fontsize=10)
    ax = axes[7]
    plot(ax, lambda r: r["raw"]["realtime_factor"], log=False, errors=False)
    ax.axhline(1.0, color="gray", ls=":", lw=1)
    ax.set_title("speed: simulated s / wall s", fontsize=10)
    ax.set_ylim(bottom=0)
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xticks(steps)
        ax.set_xticklabels([f"{s:g}" for s in steps])
        ax.minorticks_off()
        ax.grid(alpha=0.3, which="both")
    for ax in axes[4:]:
        ax.set_xlabel("plant step (ms)")
    handles = [Line2D([], [], color=colors[s], marker="o", label=s) for s in scenarios]
    handles += [
        Line2D([], [], color="k", marker="o", label="controller at the plant step"),
        Line2D([], [], color="k", marker="s", mfc="none", ls="none", label="controller at 2x"),
        Line2D([], [], color="red", ls="--", label="bound (issue 11)"),
    ]
    fig.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=9, frameon=False)
    fig.text(
        0.5,
        0.005,
        f"errors against each scenario's 1 ms run (at 0.5 ms: how far the 1 ms reference is "
        f"from a finer run); 0 is drawn at {FLOOR:g}, "
        f"'never happened in one of the two runs' at {CEILING:g}",
        ha="center",
        fontsize=8,
        color="0.3",
    )
    fig.tight_layout(rect=(0, 0.02, 1, 0.95))
    fig.savefig(path, dpi=110)
    plt.close(fig)


# --- The study ----------------------------------------------------------------


@dataclass
class StudyResult:
    records: list[dict]
    choice: dict | None
    computed: int
    reused: int
    wall_s: float
    files: list[Path]


def evaluate(cases: list[Case], runs: dict[Case, RunData]) -> list[dict]:
    """Each run against the same scenario's run at REFERENCE_STEP_MS (or the
    smallest step, where that was not run), and, where a finer run exists,
    against it too (with_fine_reference): raw numbers, errors and passes."""
    records = []
    for case in cases:
        own = sorted(
            (c for c in cases if c.scenario == case.scenario and c.factor == 1),
            key=lambda c: c.step_ms,
        )
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
                "run": case.name,
                "reference": case == ref_case,
                "fine": case == fine_case,
                "raw": summary(runs[case]),
                **result,
            }
        )
    return records


def run_study(
    scenarios: list[str],
    steps_ms: list[float],
    out_dir: Path,
    *,
    workers: int = 2,
    address: str | None = None,
    fresh: bool = False,
    progress: bool = True,
) -> StudyResult:
    """Simulates what OUT/runs/ does not hold yet, compares, chooses, reports."""
    from drake_standup.cluster import run_on_cluster
    from drake_standup.outputs import write_json

    out_dir = Path(out_dir)
    runs_dir = out_dir / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    texts = {s: (SCENARIO_DIR / f"{s}.yaml").read_text() for s in scenarios}
    durations = {s: scenario_duration_s(s, texts[s]) for s in scenarios}
    cases = study_cases(scenarios, steps_ms)
    inputs = {c: case_inputs(c, texts[c.scenario], durations[c.scenario]) for c in cases}
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
        tasks = [
            (
                c,
                f"convergence-{c.name}-{inputs[c]['hash']}",
                run_case,
                (
                    texts[c.scenario],
                    f"scenarios/{c.scenario}.yaml",
                    c.step_s,
                    c.controller_period_s,
                    durations[c.scenario],
                    str((runs_dir / c.name).resolve()),
                    inputs[c],
                ),
            )
            for c in todo
        ]
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
    study = {
        "issue": 11,
        "bounds": {
            "standup_time_rel": STANDUP_TIME_REL,
            "standup_time_abs_s": STANDUP_TIME_ABS_S,
            "state_entry_s": STATE_ENTRY_S,
            "com_deviation_m": COM_DEVIATION_M,
            "com_final_m": COM_FINAL_M,
            "pad_split_pct": PAD_SPLIT_PCT,
            "peak_torque_rel": PEAK_TORQUE_REL,
            "contact_threshold_N": CONTACT_THRESHOLD_N,
        },
        "scenarios": {s: {"duration_s": durations[s]} for s in scenarios},
        "steps_ms": sorted(steps_ms),
        "configurations": config_table(records),
        "choice": choice,
        "study_wall_s": wall_s,
        "simulated": len(todo),
        "reused": len(cases) - len(todo),
        "runs": records,
    }
    files = [out_dir / "convergence.json", out_dir / "convergence.md", out_dir / "convergence.png"]
    write_json(files[0], _inf_as_text(study))
    files[1].write_text(markdown(records, choice, wall_s if todo else None))
    draw_figure(records, files[2])
    return StudyResult(records, choice, len(todo), len(cases) - len(todo), wall_s, files)


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


# --- Command line -------------------------------------------------------------


def main(argv: list[str] | None = None, prog: str = "python -m drake_standup.convergence") -> int:
    parser = OneLineErrorParser(
        prog=prog,
        description=__doc__,
        epilog="example: drake-standup convergence --scenarios seated --steps-ms 1 4 --out out/c",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--out", type=Path, default=Path("out/convergence"), help="default out/convergence"
    )
    parser.add_argument(
        "--workers", type=int, default=2, help="LocalCluster worker processes (default 2)"
    )
    parser.add_argument(
        "--address", default=None, help="a Dask scheduler instead (workers must share OUT)"
    )
    parser.add_argument(
        "--scenarios",
        nargs="+",
        default=list(SCENARIOS),
        help="names in scenarios/ (default: %(default)s)",
    )
    parser.add_argument(
        "--steps-ms",
        nargs="+",
        type=float,
        default=list(STEPS_MS),
        help="plant steps, ms; 1 ms is the reference, a smaller one checks it "
        "(default: %(default)s)",
    )
    parser.add_argument("--fresh", action="store_true", help="simulate every run again")
    parser.add_argument(
        "--docs", type=Path, default=None, help="also copy convergence.md and .png into DIR"
    )
    args = parser.parse_args(argv)
    if args.workers < 1:
        print(f"error: --workers: {args.workers}; accepted: an integer >= 1", file=sys.stderr)
        return 2
    bad = [s for s in args.steps_ms if not (math.isfinite(s) and s > 0)]
    if bad:
        print(f"error: --steps-ms: {bad[0]}; accepted: steps > 0 (ms)", file=sys.stderr)
        return 2
    shipped = sorted(p.stem for p in SCENARIO_DIR.glob("*.yaml"))
    unknown = [s for s in args.scenarios if s not in shipped]
    if unknown:
        print(
            f"error: --scenarios: '{unknown[0]}' unknown; accepted: {', '.join(shipped)}",
            file=sys.stderr,
        )
        return 2
    scenarios = list(dict.fromkeys(args.scenarios))
    steps = sorted(set(args.steps_ms))
    try:
        result = run_study(
            scenarios, steps, args.out, workers=args.workers, address=args.address, fresh=args.fresh
        )
    except OSError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: finished runs are kept in {args.out / 'runs'}; "
            "the same command reuses them",
            file=sys.stderr,
        )
        return 130
    for path in result.files:
        print(f"wrote {path}")
    if args.docs is not None:
        args.docs.mkdir(parents=True, exist_ok=True)
        for path in result.files[1:]:
            shutil.copy2(path, args.docs / path.name)
            print(f"copied {path.name} to {args.docs}")
    n = len(result.records)
    work = (
        f"{result.computed} simulated in {result.wall_s / 60:.1f} min, {result.reused} reused"
        if result.computed
        else f"all {n} reused"
    )
    passed = sum(r["pass"] for r in result.records)
    choice = result.choice
    chosen = (
        f"chosen step: plant {choice['step_ms']:g} ms, controller "
        f"{choice['controller_period_ms']:g} ms ({_fmt(choice['median_realtime_factor'])}x real "
        "time median)"
        if choice
        else "no step passes for every scenario"
    )
    print(f"convergence: {n} runs ({work}), {passed} within issue 11's bounds; {chosen}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
