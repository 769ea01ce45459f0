"""The robot's three answers to the same helpers, side by side (the paper's introduction):

    drake-standup compare [--helpers NAME ...] [--responses R ...] [--workers N]
                          [--address ADDR] [--out DIR]

Each helper is named as --scenario names a scenario (a YAML path or a shipped scenario's
name, e.g. reactive) or as SWEEP#K, run K of a sweep (e.g. helpers#3: the fourth random
helper of the helpers campaign). Every helper runs once per response (config.RESPONSES:
advancement, stiff, compliant), on the Dask cluster the sweeps use (cluster.py); each run
is saved at once under OUT/runs/, and a comparison started again skips what it finds.

Writes OUT/results.csv (a row per helper and response: helper, response, then every
metric), OUT/results.md (the table a reader looks at: stand-up time, how much sooner than
stiff, what the helper spent, how far the CoM strayed from its path and, where a person's
body helps, their peak shoulder and lumbar torques and joint effort) and
OUT/comparison.png (the same four quantities per helper and response).
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from drake_standup.config.arguments import (
    OneLineErrorParser,
    add_set_argument,
    parse_set,
    positive_int,
)
from drake_standup.studies.sweep_table import finite_number

# The scripted pull, the reactive partner, the person's body (issue 32), the lateral and
# the hindering pull, and four random helpers of the helpers campaign (issue 23).
DEFAULT_HELPERS = (
    "assisted",
    "reactive",
    "body",
    "lateral",
    "hindering",
    "helpers#0",
    "helpers#1",
    "helpers#2",
    "helpers#3",
)
# What the table and the figure show of each run: (metric, heading, unit, scale).
SHOWN = (
    ("standup_time_s", "stand-up time", "s", 1.0),
    ("helper_work_J", "helper work", "J", 1.0),
    ("helper_peak_force_N", "peak hand force", "N", 1.0),
    ("path_deviation_max_m", "path deviation", "cm", 100.0),
)
EXAMPLE = "example: drake-standup compare --helpers reactive assisted --out out/compare"


class CompareError(ValueError):
    """A bad helper or response name: one line."""


@dataclass(frozen=True)
class Helper:
    """A helper to compare the responses on: a scenario's text and overrides."""

    name: str
    base_text: str
    overrides: tuple  # ((key path, value), ...)


def resolve_helper(name: str) -> Helper:
    """A helper by name: a scenario (path or shipped name), or SWEEP#K, run K of a sweep."""
    from drake_standup.config import ScenarioError, read_text_file
    from drake_standup.config.resources import find, shipped

    sweep, hash_sign, index = name.partition("#")
    if hash_sign:
        from drake_standup.studies.sweep_file import SweepError, expand, load_sweep

        try:
            spec = load_sweep(sweep)
        except SweepError as err:
            raise CompareError(f"--helpers {name}: {err}") from None
        runs = expand(spec)
        if not index.isdigit() or int(index) >= len(runs):
            raise CompareError(
                f"--helpers {name}: run '{index}' of sweep {spec.name}; accepted: "
                f"0 to {len(runs) - 1}"
            )
        return Helper(name, spec.base_text, tuple(runs[int(index)].overrides))
    found = find("scenarios", name)
    accepted = (
        f"a scenario YAML file, a shipped scenario ({', '.join(shipped('scenarios'))}) or "
        f"SWEEP#K, run K of a sweep ({', '.join(shipped('sweeps'))})"
    )
    try:
        text = read_text_file(found or name, "--helpers", accepted)
    except ScenarioError as err:
        raise CompareError(str(err)) from None
    return Helper(name, text, ())


def check_responses(names: list[str]) -> list[str]:
    """names, each a response the registry resolves (a shipped one, yours by name or
    module:attribute), without repeats."""
    from drake_standup.config.plugins import PluginError, resolve

    for name in names:
        try:
            resolve("responses", name)
        except PluginError as err:
            raise CompareError(f"--responses {name}: {str(err).partition(': ')[2]}") from None
    return list(dict.fromkeys(names))


def _runs(helpers: list[Helper], responses: list[str], extra: tuple = ()) -> list[dict]:
    """A run per helper and response: its record without metrics; extra: (key path,
    value) overrides on every run (--set), after the helper's."""
    from drake_standup.config import parse_scenario
    from drake_standup.studies.sweep_file import run_key

    runs = []
    for helper in helpers:
        for response in responses:
            overrides = [*helper.overrides, *extra, ("response", response)]
            parse_scenario(helper.base_text, helper.name, overrides)  # checked before the cluster
            runs.append(
                {
                    "index": len(runs),
                    "run_id": run_key(helper.base_text, overrides),
                    "params": {"helper": helper.name, "response": response},
                    "base_text": helper.base_text,
                    "overrides": overrides,
                }
            )
    return runs


def run_compare(
    helpers: list[Helper],
    responses: list[str],
    out_dir: Path,
    *,
    workers: int = 2,
    address: str | None = None,
    progress: bool = True,
    extra: tuple = (),
) -> list[dict]:
    """Simulates what out_dir/runs/ does not hold yet; writes the table, Markdown and
    figure; returns the records (params, metrics) in helper-then-response order."""
    from drake_standup.studies.sweep import run_one, run_resumable

    runs = _runs(helpers, responses, extra)
    records, _ = run_resumable(
        runs,
        Path(out_dir) / "runs",
        run_id=lambda run: run["run_id"],
        record_of=dict,
        task=lambda run: (run_one, (run["base_text"], run["overrides"])),
        label="compare",
        workers=workers,
        address=address,
        progress=progress,
    )
    ordered = [records[run["run_id"]] for run in runs]
    write_outputs(ordered, Path(out_dir))
    return ordered


def write_outputs(records: list[dict], out_dir: Path) -> dict[str, Path]:
    """results.csv, results.md and comparison.png of the records, in out_dir."""
    from drake_standup.studies.sweep_table import write_table

    paths = {
        "table": out_dir / "results.csv",
        "markdown": out_dir / "results.md",
        "figure": out_dir / "comparison.png",
    }
    write_table(paths["table"], records, ["helper", "response"])
    paths["markdown"].write_text(markdown(records))
    draw(records, paths["figure"])
    return paths


def _by_helper(records: list[dict]) -> dict[str, dict[str, dict]]:
    """helper -> response -> metrics."""
    table: dict[str, dict[str, dict]] = {}
    for r in records:
        table.setdefault(r["params"]["helper"], {})[r["params"]["response"]] = r["metrics"]
    return table


def sooner_than_stiff(
    metrics: dict, stiff: dict | None, key: str = "standup_time_s"
) -> float | None:
    """How much sooner than stiff the run stood up (key: or sat down, sit_down_time_s),
    a fraction of stiff's time (None where either did not succeed)."""
    if stiff is None or not (metrics.get("success") and stiff.get("success")):
        return None
    mine, theirs = finite_number(metrics.get(key)), finite_number(stiff.get(key))
    return None if mine is None or not theirs else 1.0 - mine / theirs


def markdown(records: list[dict]) -> str:
    """The comparison as a Markdown table: a row per helper and response (waited: how
    long a pull against the stand-up held it back; the stand-up time runs from its
    restart)."""
    head = "| helper | response | stood up | stand-up time (s) | sooner than stiff |"
    head += " waited (s) | helper work (J) | positive work (J) | peak hand force (N) |"
    head += " impulse (N s) | path deviation (cm) | person's peak shoulder (N m) |"
    head += " person's peak lumbar (N m) | person's effort (N^2 m^2 s) |"
    # A cycle's sit-down (docs/sit_down.md), where a run sat down.
    by_helper = _by_helper(records)
    cycle = any(
        m.get("sit_down_time_s") is not None for rs in by_helper.values() for m in rs.values()
    )
    if cycle:
        head += " sit-down time (s) | sit-down sooner than stiff | landing peak / seated |"
    lines = [head, "|" + "---|" * (17 if cycle else 14)]

    def cell(value, fmt: str, scale: float = 1.0) -> str:
        number = finite_number(value)
        return "" if number is None else format(scale * number, fmt)

    for helper, responses in by_helper.items():
        for response, m in responses.items():
            sooner = sooner_than_stiff(m, responses.get("stiff")) if response != "stiff" else None
            stood = "yes" if m.get("success") else f"no: {m.get('failure_reason')}"
            lines.append(
                f"| {helper} | {response} | {stood} | {cell(m.get('standup_time_s'), '.2f')} | "
                f"{'' if sooner is None else f'{round(100 * sooner):+d} %'} | "
                f"{cell(m.get('held_back_s'), '.1f')} | "
                f"{cell(m.get('helper_work_J'), '.1f')} | "
                f"{cell(m.get('helper_positive_work_J'), '.1f')} | "
                f"{cell(m.get('helper_peak_force_N'), '.1f')} | "
                f"{cell(m.get('helper_impulse_Ns'), '.0f')} | "
                f"{cell(m.get('path_deviation_max_m'), '.1f', 100.0)} | "
                f"{cell(m.get('helper_peak_shoulder_torque_Nm'), '.1f')} | "
                f"{cell(m.get('helper_peak_lumbar_torque_Nm'), '.0f')} | "
                f"{cell(m.get('helper_effort_Nm2s'), '.0f')} |"
                + (_cycle_cells(m, responses.get("stiff"), response, cell) if cycle else "")
            )
    return "\n".join(lines) + "\n"


def _cycle_cells(m: dict, stiff: dict | None, response: str, cell) -> str:
    """The sit-down's cells of a row (markdown)."""
    sooner = None if response == "stiff" else sooner_than_stiff(m, stiff, "sit_down_time_s")
    return (
        f" {cell(m.get('sit_down_time_s'), '.2f')} | "
        f"{'' if sooner is None else f'{round(100 * sooner):+d} %'} | "
        f"{cell(m.get('landing_peak_ratio'), '.2f')} |"
    )


def draw(records: list[dict], path: Path) -> None:
    """Four panels (SHOWN), grouped bars: a group per helper, a bar per response; a run
    that did not stand up is a red cross on the axis instead of a bar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    table = _by_helper(records)
    helpers = list(table)
    responses = list(dict.fromkeys(r["params"]["response"] for r in records))
    colors = {"advancement": "tab:blue", "stiff": "tab:gray", "compliant": "tab:orange"}
    width = 0.8 / max(len(responses), 1)
    x = np.arange(len(helpers))
    fig, axes = plt.subplots(2, 2, figsize=(11.0, 7.0), sharex=True)
    for ax, (metric, heading, unit, scale) in zip(axes.ravel(), SHOWN):
        for k, response in enumerate(responses):
            at = x + (k - (len(responses) - 1) / 2) * width
            values, failed = [], []
            for i, helper in enumerate(helpers):
                m = table[helper].get(response, {})
                value = finite_number(m.get(metric))
                values.append(np.nan if value is None else scale * value)
                if not m.get("success"):
                    failed.append(at[i])
            ax.bar(at, values, width, label=response, color=colors.get(response))
            if failed:
                ax.plot(failed, [0.0] * len(failed), "x", color="tab:red", ms=9, mew=2)
        ax.set_title(f"{heading} ({unit})", fontsize=10)
        ax.grid(axis="y", alpha=0.3)
    for ax in axes[1]:
        ax.set_xticks(x, helpers, rotation=30, ha="right", fontsize=8)
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="upper right", ncol=3, fontsize=8)
    fig.text(
        0.01,
        0.005,
        "a bar per response and helper (the same pull or partner for each response); "
        "red x: did not stand up (reason in results.csv). Stand-up time: from the "
        "stand-up's start;\nhelper work: the integral of F . v over both hands; path "
        "deviation: the CoM's largest distance to the reference path x_d(psi).",
        fontsize=7,
    )
    fig.suptitle("The robot's response to the same helpers: advancement, stiff, compliant", x=0.4)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def summary(records: list[dict]) -> list[str]:
    """Console lines: the runs, and per helper how much sooner advancement was than stiff."""
    stood = sum(bool(r["metrics"].get("success")) for r in records)
    lines = [f"compare: {len(records)} runs, {stood} stood up, {len(records) - stood} did not"]
    for helper, responses in _by_helper(records).items():
        parts = []
        for response, m in responses.items():
            t = finite_number(m.get("standup_time_s"))
            work = finite_number(m.get("helper_work_J"))
            text = f"{response} " + ("did not stand up" if not m.get("success") else f"{t:.2f} s")
            if work is not None:
                text += f" ({work:.1f} J)"
            parts.append(text)
        line = f"  {helper}: " + ", ".join(parts)
        if "advancement" in responses:
            sooner = sooner_than_stiff(responses["advancement"], responses.get("stiff"))
            if sooner is not None:
                line += f"; advancement {round(100 * sooner)} % sooner than stiff"
        spares = spares_most(responses)
        if spares is not None:
            line += f"; spares the person most: {spares}"
        lines.append(line)
    return lines


def spares_most(responses: dict[str, dict]) -> str | None:
    """Of the responses that stood up with a person's body helping, the one that cost the
    person the least joint effort (helper_effort_Nm2s); None without a body."""
    efforts = {
        response: finite_number(m.get("helper_effort_Nm2s"))
        for response, m in responses.items()
        if m.get("success")
    }
    efforts = {response: e for response, e in efforts.items() if e is not None}
    return min(efforts, key=efforts.get) if efforts else None


def main(
    argv: list[str] | None = None, prog: str = "python -m drake_standup.studies.compare"
) -> int:
    parser = OneLineErrorParser(
        prog=prog,
        description=__doc__,
        epilog=EXAMPLE,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--helpers",
        nargs="+",
        default=list(DEFAULT_HELPERS),
        metavar="NAME",
        help="scenarios (paths or shipped names) or SWEEP#K (run K of a sweep); default: "
        + " ".join(DEFAULT_HELPERS),
    )
    parser.add_argument(
        "--responses",
        nargs="+",
        default=None,
        metavar="R",
        help="the responses to compare (default: advancement stiff compliant)",
    )
    add_set_argument(
        parser, "override one value of every helper's scenario, e.g. robot.hardware=icub"
    )
    parser.add_argument(
        "--workers", type=positive_int, default=2, help="LocalCluster worker processes (2)"
    )
    parser.add_argument(
        "--address", default=None, help="Dask scheduler address (default: a LocalCluster)"
    )
    parser.add_argument(
        "--out", type=Path, default=Path("out/compare"), help="output directory (out/compare)"
    )
    args = parser.parse_args(argv)

    from drake_standup.config import RESPONSES, ScenarioError, check_output_dir

    try:
        responses = check_responses(args.responses or list(RESPONSES))
        helpers = [resolve_helper(name) for name in dict.fromkeys(args.helpers)]
        extra = tuple(parse_set(text) for text in args.overrides)
        _runs(helpers, responses, extra)
        out = check_output_dir(args.out, "--out")
    except (CompareError, ScenarioError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    try:
        records = run_compare(
            helpers, responses, out, workers=args.workers, address=args.address, extra=extra
        )
    except OSError as err:
        print(f"error: --address {args.address}: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: run records in {out / 'runs'}; the same command resumes from there",
            file=sys.stderr,
        )
        return 130
    for name in ("results.csv", "results.md", "comparison.png"):
        print(f"wrote {name}: {out / name}")
    print(*summary(records), sep="\n")
    print(f"in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
