"""Live pacing benchmark: does the live mode keep real time while a helper pulls?

    python -m drake_standup.studies.live_bench [--scenario NAME] [--duration S] [--pull FWD UP]
                                       [--from S] [--browser] [--out DIR]

A benchmark, not a test. It runs the live mode (live.run_session) in this process. A
scripted helper sets the page's sliders, both hands together, to --pull (N forward, N
up) from --from seconds of wall time after the simulation starts, between the loop's
chunks as a person's page would. With --browser, a headless Chromium (Debian's
`chromium`, software WebGL) renders the page at the same time, as a person's browser
would on the same machine. It prints every "behind real time" report of the pacing and
one JSON summary: the loop's rate against real time, the lowest reported rate, the
stand-up time and whether the robot stood up.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from drake_standup.config import ScenarioError, load_scenario
from drake_standup.config.arguments import OneLineErrorParser, positive_float
from drake_standup.sim.live import (
    AXES,
    SLIDERS,
    TOGETHER,
    LiveSession,
    make_live_meshcat,
    run_session,
)
from drake_standup.sim.runner import Run


class ScriptedHelper(LiveSession):
    """A LiveSession whose helper is a script: both hands pulled by (forward, up) N from
    start_s of wall time after the loop's first chunk on."""

    def __init__(self, scenario, meshcat, pull_N: tuple[float, float], start_s: float, report):
        super().__init__(scenario, meshcat, report=report)
        self._pull = pull_N
        self._start_s = start_s
        self._t0: float | None = None
        self.pulled_at_s: float | None = None  # simulated time when the sliders were set

    def after_chunk(self, run: Run) -> bool:
        now = time.perf_counter()
        if self._t0 is None:
            self._t0 = now
        if self.pulled_at_s is None and now - self._t0 >= self._start_s:
            self.meshcat.SetSliderValue(TOGETHER, 1.0)
            for axis, force in zip(AXES, self._pull, strict=True):
                self.meshcat.SetSliderValue(SLIDERS["left", axis], float(force))
            self.pulled_at_s = run.simulator.get_context().get_time()
        return super().after_chunk(run)


def main(argv: list[str] | None = None) -> int:
    parser = OneLineErrorParser(
        prog="python -m drake_standup.studies.live_bench",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--scenario", default="assisted", help="default assisted")
    parser.add_argument("--duration", type=positive_float, default=8.0, help="simulated s")
    parser.add_argument(
        "--pull",
        type=float,
        nargs=2,
        default=[15.0, 15.0],
        metavar=("FWD", "UP"),
        help="N per hand, both hands together (default 15 15)",
    )
    parser.add_argument(
        "--from", dest="start_s", type=float, default=2.5, help="wall s before the pull"
    )
    parser.add_argument("--browser", action="store_true", help="render the page in Chromium")
    parser.add_argument("--out", type=Path, default=None, help="the run's files (default: tmp)")
    args = parser.parse_args(argv)
    try:
        scenario = load_scenario(args.scenario)
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    browser = shutil.which("chromium") if args.browser else None
    if args.browser and browser is None:
        print("error: --browser: no chromium on PATH; accepted: Debian's chromium", file=sys.stderr)
        return 2
    scenario.duration_s = args.duration
    scenario.simulator.target_realtime_rate = 1.0
    reports: list[str] = []

    def report(line: str) -> None:
        reports.append(line)
        print(line, file=sys.stderr, flush=True)

    meshcat = make_live_meshcat()
    session = ScriptedHelper(scenario, meshcat, tuple(args.pull), args.start_s, report)
    page = None
    if browser is not None:
        page = subprocess.Popen(
            [
                browser,
                "--headless=new",
                "--no-sandbox",
                "--enable-unsafe-swiftshader",
                "--window-size=1280,800",
                "--remote-debugging-port=0",
                meshcat.web_url(),
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    out = args.out or Path(tempfile.mkdtemp(prefix="live_bench_"))
    try:
        result = run_session(scenario, session, out)
    finally:
        if page is not None:
            page.terminate()
            page.wait(timeout=10)
    rates = [float(m.group(1)) for line in reports if (m := re.search(r"([\d.]+)x", line))]
    m = result.metrics
    summary = {
        "scenario": args.scenario,
        "browser": browser is not None,
        "pull_N_per_hand": args.pull,
        "pulled_at_sim_s": session.pulled_at_s,
        "sim_time_s": m["sim_time_s"],
        "loop_realtime_factor": m["realtime_factor"],
        "behind_reports": len(rates),
        "lowest_reported_rate": min(rates) if rates else None,
        "success": m["success"],
        "standup_time_s": m.get("standup_time_s"),
        "out": str(out),
    }
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
