"""The command line: `drake-standup COMMAND` (also `python -m drake_standup COMMAND`).

Commands: run (one scenario: recording, metrics, figures), sweep, compare (the robot's
responses side by side), bench, convergence and scenarios (what the package ships).
Each command's module does the work; this one parses arguments and turns a bad input
into one 'error:' line and exit code 2. No heavy imports here: a command parses its
arguments before it loads Drake.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from drake_standup.config.arguments import OneLineErrorParser, add_set_argument, parse_set

# Command -> (module with main(argv, prog), one line of help).
COMMANDS = {
    "run": ("drake_standup.cli", "simulate one scenario: recording, metrics, figures"),
    "live": ("drake_standup.cli", "be the helper: run paced at real time, pull from the page"),
    "sweep": (
        "drake_standup.studies.sweep",
        "many runs on Dask: a grid, random draws, perturbations",
    ),
    "compare": (
        "drake_standup.studies.compare",
        "advancement, stiff and compliant on the same helpers",
    ),
    "bench": (
        "drake_standup.studies.bench",
        "how fast the stand-up simulates, and where time goes",
    ),
    "convergence": ("drake_standup.studies.convergence", "the plant-step convergence study"),
    "scenarios": ("drake_standup.cli", "list the shipped scenarios and sweeps"),
    "list": ("drake_standup.cli", "plug-ins by kind: laws, helpers, chairs, responses"),
}


def main(argv: list[str] | None = None) -> int:
    """drake-standup COMMAND [ARGS]: hands ARGS to the command's own parser."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] in ("-h", "--help"):
        width = max(map(len, COMMANDS))
        lines = [f"  {name:<{width}}  {text}" for name, (_, text) in COMMANDS.items()]
        print("usage: drake-standup COMMAND [--help] [ARGS]\n\ncommands:", *lines, sep="\n")
        print("\nexample: drake-standup run --scenario unassisted --duration 4 --no-recording")
        return 0 if argv else 2
    name, rest = argv[0], argv[1:]
    if name not in COMMANDS:
        print(
            f"error: '{name}': unknown command; accepted: {' | '.join(COMMANDS)}", file=sys.stderr
        )
        return 2
    prog = f"drake-standup {name}"
    if name == "run":
        return run_main(rest, prog)
    if name == "live":  # run --live
        return run_main(["--live", *rest], prog)
    if name == "scenarios":
        return scenarios_main(rest, prog)
    if name == "list":
        return list_main(rest, prog)
    return importlib.import_module(COMMANDS[name][0]).main(rest, prog=prog)


# --- run ---------------------------------------------------------------------------------


def run_parser(prog: str) -> OneLineErrorParser:
    """The run command's arguments (run_diagram.py's too)."""
    parser = OneLineErrorParser(
        prog=prog,
        description="Simulate the iCub stand-up scenario and write recording, metrics, "
        "figures and diagram.",
        epilog=(
            "example:\n  drake-standup live --scenario unassisted --duration 60 --out out/me"
            if prog.endswith(" live")
            else "example:\n  drake-standup run --scenario unassisted --set "
            "advancement.psi_dot_upper=2.0 --duration 4 --no-recording --out out/try"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--scenario",
        default=None,
        help="a scenario YAML file, or a shipped scenario's name, e.g. unassisted "
        "(default: assisted; `drake-standup scenarios` lists them)",
    )
    add_set_argument(
        parser,
        "override one scenario value (YAML), e.g. advancement.psi_dot_upper=2.0 or "
        "human.pulls[0].force_N=[20, 0, 20]; repeatable",
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
        "(drake_standup/sim/live.py); without --duration until Stop or Ctrl-C (at most 300 s)",
    )
    return parser


def run_main(argv: list[str] | None = None, prog: str = "drake-standup run") -> int:
    args = run_parser(prog).parse_args(argv)
    if args.live and args.no_recording:
        print("error: --no-recording: not with --live (the live page is Meshcat)", file=sys.stderr)
        return 2

    from drake_standup.config import ScenarioError, check_output_dir, load_scenario

    # Every input checked here, before anything is built or simulated (config.validate).
    try:
        overrides = [parse_set(text) for text in args.overrides]
        duration = [] if args.duration is None else [("duration_s", args.duration)]
        scenario = load_scenario(args.scenario, overrides + duration)
        check_output_dir(args.out, "--out")
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2

    from drake_standup.sim.simulate import simulate

    # The checks that need the robot's geometry (scene.check_com_heights) run as the
    # station is built, before the first step: the same one line and exit code 2.
    try:
        if args.live:
            from drake_standup.sim.live import run_live

            result = run_live(scenario, args.out, args.duration)
        else:
            result = simulate(scenario, args.out, record=not args.no_recording, baseline=True)
    except ScenarioError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    m = result.metrics
    for name, path in result.files.items():
        print(f"wrote {name}: {path}")
    for path, value in overrides:
        print(f"set {path} = {value}")
    if m.get("standup_time_s") is not None:
        outcome = f"stood up in {m['standup_time_s']:.2f} s"
        response = m.get("response", "advancement")
        if response in ("stiff", "compliant"):
            outcome += f" (response {response}: psi = t)"
        elif "+" in response:  # the live page's switch moved
            outcome += f" (responses {response})"
        elif m.get("standup_time_s_without_advancement") is not None:
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


# --- scenarios ---------------------------------------------------------------------------


def scenarios_main(argv: list[str] | None = None, prog: str = "drake-standup scenarios") -> int:
    OneLineErrorParser(
        prog=prog,
        description="List the shipped scenarios and sweeps, each with its one-line "
        "description; run one by its name.",
        epilog="example:\n  drake-standup scenarios\n  drake-standup run --scenario seated",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args(argv)
    from drake_standup.config.resources import data_root, description, shipped

    for folder, command in (("scenarios", "run --scenario"), ("sweeps", "sweep")):
        print(f"{folder} ({data_root() / folder}; drake-standup {command} NAME):")
        for name, path in shipped(folder).items():
            print(f"  {name:<12} {description(path)}")
    return 0


# --- list --------------------------------------------------------------------------------


def list_main(argv: list[str] | None = None, prog: str = "drake-standup list") -> int:
    OneLineErrorParser(
        prog=prog,
        description="List the plug-ins each scenario key can name: the shipped ones and "
        "those installed packages register by entry point (docs/extending.md).",
        epilog="example:\n  drake-standup list\n  drake-standup run --set "
        "advancement.law=interaction",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args(argv)
    from drake_standup.config.plugins import ENTRY_POINT_GROUP, KINDS, registered

    for kind, key in KINDS.items():
        group = ENTRY_POINT_GROUP.format(kind=kind)
        print(f"{kind} ({key}: a name below, or module:attribute; entry points: {group}):")
        for name, plugin in registered(kind).items():
            print(f"  {name:<12} {plugin.description} [{plugin.origin}]")
    return 0


if __name__ == "__main__":  # python -m drake_standup.cli COMMAND, as python -m drake_standup
    sys.exit(main())
