#!/usr/bin/env python
"""Simulate the iCub stand-up scenario and write recording, metrics and diagram.

python run_diagram.py [--scenario PATH] [--out DIR] [--duration S] [--no-recording] [--live]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from drake_standup.cli import OneLineErrorParser


def main(argv: list[str] | None = None) -> int:
    parser = OneLineErrorParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--scenario",
        type=Path,
        default=None,
        help="scenario YAML (default: scenarios/assisted.yaml)",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("out"), help="output directory (default: out/)"
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=None,
        help="simulated seconds (overrides the scenario's duration_s)",
    )
    parser.add_argument(
        "--no-recording", action="store_true", help="skip Meshcat and recording.html (faster)"
    )
    parser.add_argument(
        "--live",
        action="store_true",
        help="be the helper: paced at real time, pull the hands from the Meshcat page "
        "(drake_standup/live.py); without --duration until Stop or Ctrl-C (at most 300 s)",
    )
    args = parser.parse_args(argv)
    if args.live and args.no_recording:
        print("error: --no-recording: not with --live (the live page is Meshcat)", file=sys.stderr)
        return 2

    from drake_standup.config import DEFAULT_SCENARIO, ScenarioError, load_scenario, validate

    try:
        scenario = load_scenario(args.scenario or DEFAULT_SCENARIO)
        if args.duration is not None:
            if not math.isfinite(args.duration) or args.duration <= 0:
                raise ScenarioError(
                    f"--duration: {args.duration}; accepted: a number of seconds > 0"
                )
            scenario.duration_s = args.duration
            validate(scenario)
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2

    if args.live:
        from drake_standup.live import run_live

        result = run_live(scenario, args.out, args.duration)
    else:
        from drake_standup.simulate import simulate

        result = simulate(scenario, args.out, record=not args.no_recording, baseline=True)
    m = result.metrics
    for name, path in result.files.items():
        print(f"wrote {name}: {path}")
    if m.get("standup_time_s") is not None:
        outcome = f"stood up in {m['standup_time_s']:.2f} s"
        if m.get("standup_time_s_without_advancement") is not None:
            outcome += f" ({m['standup_time_s_without_advancement']:.2f} s without advancement)"
        elif "standup_time_s_without_advancement" in m:
            outcome += " (did not stand up without advancement)"
    else:
        outcome = "did not stand up"
    status = "OK" if m["success"] else f"FAILED ({m['failure_reason']})"
    print(
        f"{status}: {outcome}; psi_final {m.get('psi_final', float('nan')):.2f}; "
        f"simulated {m['sim_time_s']:.2f} s in {m['wall_time_s']:.1f} s wall "
        f"({m['realtime_factor']:.2f}x real time)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
