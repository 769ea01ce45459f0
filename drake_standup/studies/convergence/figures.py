"""convergence.png: the errors over their bounds, the extra contact crossings and the speed,
against the plant step."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from drake_standup.studies.convergence.choice import study_rate_ms

PANELS = (
    ("standup_time", "stand-up time error / max(2%, 0.03 s)"),
    ("state_entries", "state entry error / 0.05 s"),
    ("com_deviation", "max CoM deviation / 5 mm"),
    ("com_final", "final CoM error / 2 mm"),
    ("pad_split", "seated load-share error / 5%"),
    ("peak_torque", "peak torque error / 15%"),
    ("sole_chatter", "sole chatter error / 15 N"),
)
FLOOR, CEILING = 1e-3, 1e2  # the log axis' range; exact zeros and infinities land on its ends


def draw_figure(records: list[dict], path: Path) -> None:
    """The errors over their bounds (log y; 1 = the bound), the extra contact
    crossings, and the speed, against the plant step; one colour per scenario,
    circles and lines with the controller at the step, squares at twice it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenarios = list(dict.fromkeys(r["scenario"] for r in records))
    colors = {s: f"C{i}" for i, s in enumerate(scenarios)}
    steps = sorted({r["step_ms"] for r in records})
    # Side by side, not on top of each other: a small shift per scenario.
    shift = {s: 1.0 + 0.025 * (i - (len(scenarios) - 1) / 2) for i, s in enumerate(scenarios)}
    fig, axes = plt.subplots(3, 3, figsize=(13, 10.5), sharex=True)
    axes = axes.ravel()

    def series(scenario: str, factor: int, value, with_reference: bool) -> tuple[list, list]:
        sel = [
            r
            for r in records
            if r["scenario"] == scenario
            and (1 if r["base"] else 2) == factor  # 2: the controller at twice the step
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
        _bound_panel(ax, records, key, title)
    ax = axes[len(PANELS)]
    plot(ax, lambda r: r["errors"]["extra_crossings"], log=False)
    ax.axhline(0.0, color="red", ls="--", lw=1)
    ax.set_title("extra 5 N load/unload crossings\n(worst pad group, vs 1 ms)", fontsize=10)
    ax = axes[len(PANELS) + 1]
    plot(ax, lambda r: r["raw"]["realtime_factor"], log=False, errors=False)
    ax.axhline(1.0, color="gray", ls=":", lw=1)
    ax.set_title("speed: simulated s / wall s", fontsize=10)
    ax.set_ylim(bottom=0)
    _step_axes(axes, steps)
    _legend_and_note(fig, scenarios, colors, study_rate_ms(records))
    fig.tight_layout(rect=(0, 0.02, 1, 0.95))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _bound_panel(ax, records: list[dict], key: str, title: str) -> None:
    """An error panel's log y axis, its bound (1) shaded beyond, and its title."""
    ax.set_yscale("log")
    # Up to the ceiling only where an event happened in one run only.
    values = [r["normalised"][key] for r in records if not r.get("reference")]
    top = max([v for v in values if v is not None] + [3.0])
    top = CEILING * 1.4 if math.isinf(top) else min(2.0 * top, CEILING * 1.4)
    ax.set_ylim(FLOOR * 0.7, top)
    ax.axhline(1.0, color="red", ls="--", lw=1)
    ax.axhspan(1.0, top, color="red", alpha=0.05)
    ax.set_title(title, fontsize=10)


def _step_axes(axes, steps: list[float]) -> None:
    """The plant steps on every panel's log x axis, labelled on the bottom row."""
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xticks(steps)
        ax.set_xticklabels([f"{s:g}" for s in steps])
        ax.minorticks_off()
        ax.grid(alpha=0.3, which="both")
    for ax in axes[-3:]:
        ax.set_xlabel("plant step (ms)")


def _legend_and_note(
    fig, scenarios: list[str], colors: dict[str, str], controller_ms: float | None
) -> None:
    """The legend (scenarios, controller periods, bound) on top, what the axes' ends mean
    below; controller_ms: the study's fixed controller period (--controller-ms), if any."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=colors[s], marker="o", label=s) for s in scenarios]
    if controller_ms is None:
        handles += [
            Line2D([], [], color="k", marker="o", label="controller at the plant step"),
            Line2D([], [], color="k", marker="s", mfc="none", ls="none", label="controller at 2x"),
        ]
    else:
        handles.append(
            Line2D([], [], color="k", marker="o", label=f"controller at {controller_ms:g} ms")
        )
    handles.append(Line2D([], [], color="red", ls="--", label="bound (issue 11)"))
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
