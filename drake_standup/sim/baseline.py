"""The psi = t run of a scenario, beside the main run, in a Python process of its own.

It gives figure_advancement.png its faded reference and metrics.json its
standup_time_s_without_advancement; on two cores it costs no wall time. The scenario
goes to the process as YAML, signals.npz and metrics.json come back through a temporary
folder. Where that process fails (a notice gives its last error line), the run is
simulated here instead.

    python -m drake_standup.sim.baseline --baseline-dir DIR --controller NAME --chunk S
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from pydrake.common.yaml import yaml_dump_typed

from drake_standup.config import Scenario, parse_scenario
from drake_standup.config.plugins import resolve
from drake_standup.outputs.json_files import write_metrics
from drake_standup.outputs.signals import load_signals, write_signals
from drake_standup.sim.diagram import on_step_grid
from drake_standup.sim.runner import RunResult, advance, collect, finished, prepare


def needs_baseline(scenario: Scenario) -> bool:
    """Whether psi could advance: the advancement response, advancement on and somebody
    pulling. Otherwise the run is its own psi = t run."""
    human = scenario.human
    pulled = human.mode != "scripted" or bool(human.pulls)
    advances = resolve("responses", scenario.response).obj.advances
    return advances and scenario.advancement.enabled and pulled


def simulate_quietly(scenario: Scenario, controller: str, chunk_s: float) -> RunResult:
    """A run to its end with no recording, no progress and no files."""
    run = prepare(scenario, None, controller=controller)
    chunk_s = on_step_grid(chunk_s, scenario.plant.time_step)
    chunk = 0
    while not finished(run):
        chunk += 1
        advance(run, chunk * chunk_s)
    return collect(run)


class Baseline:
    """The psi = t run of scenario in its own process, started at construction."""

    def __init__(self, scenario: Scenario, controller: str, chunk_s: float):
        self._scenario = copy.deepcopy(scenario)
        self._scenario.advancement.enabled = False
        self._controller = controller
        self._chunk_s = chunk_s
        self._dir = Path(tempfile.mkdtemp(prefix="drake_standup_baseline_"))
        (self._dir / "scenario.yaml").write_text(yaml_dump_typed(self._scenario))
        command = [sys.executable, "-m", "drake_standup.sim.baseline", "--baseline-dir"]
        command += [str(self._dir), "--controller", controller, "--chunk", repr(chunk_s)]
        self._stderr = open(self._dir / "stderr.txt", "w")  # noqa: SIM115 - closed in result()
        # The child imports this very package, installed or not.
        env = dict(os.environ)
        package_root = str(Path(__file__).resolve().parents[2])
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [package_root, env.get("PYTHONPATH")]))
        self._process = subprocess.Popen(
            command,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=self._stderr,
            env=env,
        )

    def result(self) -> RunResult:
        try:
            returncode = self._process.wait()
            self._stderr.close()
            if returncode == 0:
                return RunResult(
                    json.loads((self._dir / "metrics.json").read_text()),
                    signals=load_signals(self._dir / "signals.npz"),
                )
            lines = (self._dir / "stderr.txt").read_text().strip().splitlines()
            print(
                f"notice: the psi = t run's process failed ({lines[-1] if lines else returncode});"
                " simulating it here",
                file=sys.stderr,
            )
            return simulate_quietly(self._scenario, self._controller, self._chunk_s)
        finally:
            shutil.rmtree(self._dir, ignore_errors=True)

    def cancel(self) -> None:
        self._process.kill()
        self._process.wait()
        self._stderr.close()
        shutil.rmtree(self._dir, ignore_errors=True)


def main(argv: list[str]) -> int:
    """The psi = t run's process (see Baseline)."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--baseline-dir", type=Path, required=True)
    parser.add_argument("--controller", required=True)
    parser.add_argument("--chunk", type=float, required=True)
    args = parser.parse_args(argv)
    scenario = parse_scenario((args.baseline_dir / "scenario.yaml").read_text(), "baseline")
    result = simulate_quietly(scenario, args.controller, args.chunk)
    write_signals(args.baseline_dir / "signals.npz", result.signals)
    write_metrics(args.baseline_dir / "metrics.json", result.metrics)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
