"""simulate(scenario, out_dir): one scenario to its end, with its files.

The run itself is runner.py's (prepare, advance, collect), shown as a progress bar; the
psi = t run beside it (baseline.py) gives the figure its faded reference; run_folder.py
writes the files. run_diagram.py, the benchmark and the sweeps call this.
"""

from __future__ import annotations

from pathlib import Path

from drake_standup.config import Scenario
from drake_standup.sim.baseline import Baseline, needs_baseline
from drake_standup.sim.diagram import on_step_grid
from drake_standup.sim.progress import ProgressBar
from drake_standup.sim.run_folder import write_run
from drake_standup.sim.runner import (
    RunResult,
    advance,
    collect,
    finished,
    make_meshcat,
    prepare,
)

__all__ = ["RunResult", "simulate"]


def simulate(
    scenario: Scenario,
    out_dir: Path | None = None,
    *,
    record: bool = True,
    progress: bool = True,
    baseline: bool = False,
    controller: str = "whole_body",
    chunk_s: float = 0.05,
) -> RunResult:
    """Simulates scenario; writes recording, metrics, figures and diagram into out_dir.

    baseline: also simulate the same scenario with advancement disabled (psi = t), for
    the faded reference of figure_advancement.png and the metric
    standup_time_s_without_advancement. Where nothing could advance psi (no human, or
    advancement already off) the run is its own baseline. controller: 'whole_body', or
    'seat_hold' (the plant-only benchmark).
    """
    pending = (
        Baseline(scenario, controller, chunk_s) if baseline and needs_baseline(scenario) else None
    )
    try:
        run = prepare(scenario, make_meshcat() if record else None, controller=controller)
        bar = ProgressBar(scenario.duration_s, "simulating") if progress else None
        chunk_s = on_step_grid(chunk_s, scenario.plant.time_step)
        chunk = 0
        while not finished(run):
            chunk += 1
            advance(run, chunk * chunk_s)
            if bar is not None:
                bar.update(run.time_s, f"{run.time_s / max(run.wall_time_s, 1e-9):.2f}x real time")
        if bar is not None:
            bar.close()
        result = collect(run)
    except BaseException:
        if pending is not None:
            pending.cancel()
        raise
    base = None
    if pending is not None:
        base = pending.result()
        result.metrics["standup_time_s_without_advancement"] = base.metrics.get("standup_time_s")
    if out_dir is not None:
        result.files = write_run(run, result, out_dir, base.signals if base else None)
    return result
