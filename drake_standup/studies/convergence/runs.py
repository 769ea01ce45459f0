"""One case's run, in a Dask worker, into its folder, and the folder read back: the on-disk
cache of finished runs."""

from __future__ import annotations

import json
import traceback
from dataclasses import dataclass
from pathlib import Path

RUN_FILES = ("metrics.json", "signals.npz", "inputs.json")


def is_cached(run_dir: Path, inputs: dict) -> bool:
    """run_dir holds a finished run of exactly these inputs."""
    if not all((run_dir / f).is_file() for f in RUN_FILES):
        return False
    try:
        return json.loads((run_dir / "inputs.json").read_text()).get("hash") == inputs["hash"]
    except (OSError, ValueError):
        return False


def with_steps(scenario, step_s: float, controller_period_s: float):
    """scenario with its plant step and controller period set; under robot.hardware: icub
    through the hardware's rate and step, which decide them there (config/rules.py)."""
    from drake_standup.config import with_hardware

    if scenario.robot.hardware == "icub":
        scenario.hardware.plant_time_step_s = step_s
        scenario.hardware.rate_hz = 1.0 / controller_period_s
        return with_hardware(scenario)
    scenario.plant.time_step = step_s
    scenario.controller_period_s = controller_period_s
    return scenario


def run_case(
    scenario_text: str,
    where: str,
    step_s: float,
    controller_period_s: float,
    duration_s: float,
    out_dir: str,
    *,
    inputs: dict,
    overrides: list | tuple = (),
) -> dict:
    """Simulates one run into out_dir (in a Dask worker); returns its metrics.

    Never raises: a run that throws is success false and the reason, in
    metrics.json. A previous run's files go first, and inputs.json is written
    last, only when metrics.json and signals.npz are there: a run cut short is
    never taken for a finished one, nor its folder read as an older run's.
    """
    from drake_standup.config import parse_scenario, validate
    from drake_standup.outputs.json_files import json_safe
    from drake_standup.sim.simulate import simulate

    run_dir = Path(out_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    for name in RUN_FILES:
        (run_dir / name).unlink(missing_ok=True)
    try:
        scenario = parse_scenario(scenario_text, where, overrides)
        scenario = with_steps(scenario, step_s, controller_period_s)
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


@dataclass
class RunData:
    """A finished run: its metrics.json and its signals.npz (None if missing)."""

    metrics: dict
    signals: dict | None


def load_run(run_dir: Path) -> RunData:
    """The run in run_dir as its files hold it ({} and None for what is missing)."""
    from drake_standup.outputs.signals import load_signals

    metrics_path = Path(run_dir) / "metrics.json"
    metrics = json.loads(metrics_path.read_text()) if metrics_path.is_file() else {}
    signals_path = Path(run_dir) / "signals.npz"
    signals = load_signals(signals_path) if signals_path.is_file() else None
    return RunData(metrics, signals)
