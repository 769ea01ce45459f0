"""convergence.md: the per-run table, the per-configuration table and the choice, in
Markdown for the README."""

from __future__ import annotations

import math

from drake_standup.studies.convergence.choice import config_table, median_or_none, study_rate_ms


def fmt(value, scale: float = 1.0, digits: int = 2) -> str:
    """value * scale with digits decimals; "-" when not measured, "inf" when infinite."""
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


def markdown(
    records: list[dict],
    choice: dict | None,
    wall_s: float | None = None,
    overrides: list | tuple = (),
) -> str:
    """convergence.md: the per-run table, the per-configuration summary, the choice;
    overrides: the study's --set pairs, named above the tables."""
    lines = []
    if overrides:
        settings = ", ".join(f"`{path}={value}`" for path, value in overrides)
        lines += [f"Every run with {settings} (`--set`).", ""]
    rate_ms = study_rate_ms(records)
    reference = (
        f"plant at 1 ms, the controller at {rate_ms:g} ms as in every run (--controller-ms)"
        if rate_ms is not None
        else "plant and controller at 1 ms"
    )
    lines += [
        f"Each run against the same scenario's 1 ms run ({reference}). "
        "Bounds (issue 11): stand-up time within max(2%, 0.03 s), state entries within "
        "0.05 s, CoM within 5 mm at every logged instant, final CoM within 2 mm, seated "
        "pad-group load shares within 5%, peak torque within 15%, the soles' chatter "
        "(sole_force_chatter_N) within 15 N (issue 60), no more 5 N load/unload "
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
        "seated split err (%) | vs 0.5 ms | peak torque err (%) | sole chatter (N) | "
        "chatter err (N) | crossings (1 ms) | QP fails | "
        "sim s / wall s | wall (s) | pass |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    refs = {r["scenario"]: r for r in records if r.get("reference")}
    lines += [_run_row(r, refs, records) for r in records]
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
            f"{fmt(row['median_realtime_factor'])} | {row['wall_time_s']:.0f} |"
        )
    lines.append("")
    lines.append(choice_sentence(choice, records))
    if wall_s is not None:
        lines.append(f"Study wall time: {wall_s / 60:.1f} min.")
    return "\n".join(lines) + "\n"


def _run_row(r: dict, refs: dict[str, dict], records: list[dict]) -> str:
    """The per-run table's row of run r; refs: each scenario's reference run."""
    raw, err = r["raw"], r["errors"]
    ref = refs.get(r["scenario"])
    ref_cross = _crossings_total(ref["raw"]["contact_crossings"]) if ref else None
    cross = _crossings_total(raw["contact_crossings"])
    reason = raw["failure_reason"] or "?"
    stood = "yes" if raw["success"] else ("no" if reason == "did not stand up" else f"no: {reason}")
    mark = _verdict(r)
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
    return (
        f"| {r['scenario']} | {r['step_ms']:g} / {r['controller_period_ms']:g} | {stood} | "
        f"{fmt(raw['standup_time_s'])} | {fmt(err['standup_time_s'], digits=3)} | "
        f"{fmt(err['state_entries_s'], digits=3)} | {fmt(err['com_deviation_m'], 1e3, 1)} | "
        f"{fmt(fine.get('com_deviation_m'), 1e3, 1)} | "
        f"{fmt(err['com_final_m'], 1e3, 1)} | {fmt(err['pad_split_pct'], digits=1)} | "
        f"{fmt(fine.get('pad_split_pct'), digits=1)} | "
        f"{fmt(err['peak_torque_rel'], 100.0, 1)} | "
        f"{fmt(raw.get('sole_force_chatter_N'), digits=1)} | "
        f"{fmt(err.get('sole_chatter_N'), digits=1)} | "
        f"{'-' if cross is None else cross} ({'-' if ref_cross is None else ref_cross}) | "
        f"{raw['qp_failures']} | {fmt(raw['realtime_factor'])} | "
        f"{fmt(raw['wall_time_s'], digits=0)} | {mark} |"
    )


def _verdict(r: dict) -> str:
    """The pass column of run r."""
    if r.get("reference"):
        return "ref"
    if r.get("fine"):
        return "finer"
    if not r["pass"]:
        return "**no**: " + ", ".join(r["failed"])
    if r["strict_pass"]:
        return "yes"
    return "yes (" + ", ".join(r["strict_failed"]) + ")"


def choice_sentence(choice: dict | None, records: list[dict]) -> str:
    """convergence.md's last line: the chosen step and its speed against the reference's."""
    if choice is None:
        return "No step passes for every scenario (not even the reference: see the runs)."
    ref_speed = median_or_none(r["raw"]["realtime_factor"] for r in records if r.get("reference"))
    text = (
        f"Chosen: plant {choice['step_ms']:g} ms, controller {choice['controller_period_ms']:g} ms "
        f"(the largest step at which every scenario passes; median "
        f"{fmt(choice['median_realtime_factor'])}x real time against {fmt(ref_speed)}x at the "
        "reference)."
    )
    if choice["smaller_steps_failing_ms"]:
        failing = ", ".join(f"{s:g}" for s in choice["smaller_steps_failing_ms"])
        text += f" Warning: smaller steps fail ({failing} ms)."
    return text
