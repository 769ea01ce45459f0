"""A sweep's figures, drawn from its run records as its sweep file asks (sweep_file.Figure):
line (mean of a metric per parameter value, one line per group), rate (a metric's rate
per bin of a parameter) or scatter (a metric per run against a random parameter)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drake_standup.studies.sweep_file import Figure
from drake_standup.studies.sweep_table import finite_number, table_rows


def _order(value):
    """Sorts numbers numerically and before anything else."""
    return (0, value, "") if isinstance(value, (int, float)) else (1, 0, str(value))


def draw_figure(fig: Figure, records: list[dict], out_dir: Path) -> Path | None:
    """line: mean y per x value (one line per group; runs that did not stand
    up drawn as crosses on the x axis); rate: mean of y (e.g. success) per x bin,
    with the number of runs per bin; scatter: y of each run that stood up against its
    x (one marker per group), the others as crosses on the x axis."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = table_rows(records)
    if not rows or fig.x not in rows[0]:
        return None
    fig_obj, ax = plt.subplots(figsize=(6.4, 4.2))
    markers = "osD^v<>p"
    if fig.kind == "scatter":
        _scatter(ax, fig, rows, markers)
    elif fig.kind == "line":
        for k, (g, sel) in enumerate(_groups(fig, rows)):
            xs = sorted({r[fig.x] for r in sel}, key=_order)
            stood = [(r[fig.x], finite_number(r.get(fig.y))) for r in sel if r.get("success")]
            mean = [
                np.mean([y for x, y in stood if x == at and y is not None] or [np.nan]) for at in xs
            ]
            label = f"{fig.group} = {g}" if fig.group else None
            (line,) = ax.plot(xs, mean, marker=markers[k % len(markers)], label=label)
            # Failed runs: a cross at their value, or on the x axis without one.
            failed = [
                (r[fig.x], finite_number(r.get(fig.y)) or 0.0) for r in sel if not r.get("success")
            ]
            if failed:
                ax.plot(*zip(*failed), "x", color=line.get_color(), ms=10, mew=2)
        if fig.group:
            ax.legend(fontsize=8)
        ax.set_ylabel(fig.y)
        # Below the x axis' label, where no data point can lie under it.
        ax.text(
            0.0,
            -0.2,
            "lines: mean over runs that stood up; x: a run that failed, at its value or,\n"
            "without one, on the x axis (reason in results.csv)",
            transform=ax.transAxes,
            fontsize=7,
            va="top",
        )
    else:
        xs = np.array([r[fig.x] for r in rows], dtype=float)
        ys = np.array([float(bool(r.get(fig.y))) for r in rows])
        low, high = fig.range or (xs.min(), xs.max())
        edges = np.linspace(low, high, fig.bins + 1)
        which = np.clip(np.digitize(xs, edges[1:-1]), 0, fig.bins - 1)
        counts = np.bincount(which, minlength=fig.bins)
        filled = counts > 0  # empty bins get no bar
        rates = np.bincount(which, weights=ys, minlength=fig.bins)[filled] / counts[filled]
        centres = (0.5 * (edges[:-1] + edges[1:]))[filled]
        width = 0.9 * (edges[1] - edges[0])
        ax.bar(centres, rates, width=width, color="tab:blue", alpha=0.7, edgecolor="tab:blue")
        for c, r, n in zip(centres, rates, counts[filled]):
            ax.text(c, r + 0.02, f"n={n}", ha="center", fontsize=8)
        ax.set_ylim(0, 1.15)
        ax.set_ylabel(f"{fig.y} rate")
    _reference_lines(ax, fig)
    ax.set_xlabel(fig.x)
    ax.set_title(fig.title or f"{fig.y} vs {fig.x}", fontsize=10)
    ax.grid(alpha=0.3)
    fig_obj.tight_layout()
    path = out_dir / f"{fig.y}_vs_{fig.x}.png".replace("/", "_")
    fig_obj.savefig(path, dpi=110)
    plt.close(fig_obj)
    return path


def _groups(fig: Figure, rows: list[dict]) -> list[tuple]:
    """(value, its rows) per value of fig.group in order; one (None, every row) without."""
    if not fig.group:
        return [(None, rows)]
    values = sorted({row.get(fig.group) for row in rows}, key=_order)
    return [(g, [r for r in rows if r.get(fig.group) == g]) for g in values]


def _scatter(ax, fig: Figure, rows: list[dict], markers: str) -> None:
    """y of each run that stood up against its x, a marker per group; the others as
    crosses on the x axis."""
    for k, (g, sel) in enumerate(_groups(fig, rows)):
        stood = [(r[fig.x], finite_number(r.get(fig.y))) for r in sel if r.get("success")]
        stood = [(x, y) for x, y in stood if y is not None]
        label = f"{fig.group} = {g}" if fig.group else None
        marker = markers[k % len(markers)]
        (dots,) = ax.plot(*(zip(*stood) if stood else ([], [])), marker, label=label)
        failed = [r[fig.x] for r in sel if not r.get("success")]
        if failed:
            ax.plot(failed, [0.0] * len(failed), "x", color=dots.get_color(), ms=10, mew=2)
    if fig.group:
        ax.legend(fontsize=8)
    ax.set_ylabel(fig.y)


def _reference_lines(ax, fig: Figure) -> None:
    """The figure's lines: {x, label} vertical, {y, label} horizontal."""
    for k, line in enumerate(fig.lines):
        if "y" in line:  # horizontal, labelled at the left end
            ax.axhline(line["y"], color="tab:red", ls="--", lw=1.2)
            ax.text(
                0.01,
                line["y"],
                f"{line['label']}",
                transform=ax.get_yaxis_transform(),
                color="tab:red",
                fontsize=8,
                va="bottom",
            )
            continue
        ax.axvline(line["x"], color="tab:red", ls="--", lw=1.2)
        ax.text(
            line["x"],
            0.98 - 0.07 * k,
            f" {line['label']}",
            transform=ax.get_xaxis_transform(),
            color="tab:red",
            fontsize=8,
            va="top",
        )
