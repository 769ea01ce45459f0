"""The pieces every command's argument parser shares: the one-line error parser, --set's
'key.path=value', and argparse types for counts and durations.

Low in the package: it imports nothing of it but config (and that only when a --set is
parsed), so that the commands and cli.py can all import it and cli.py stays light.
"""

from __future__ import annotations

import argparse
import math
import sys


class OneLineErrorParser(argparse.ArgumentParser):
    """argparse, but a bad argument is one 'error:' line and exit code 2."""

    def error(self, message: str) -> None:
        print(f"error: {message}; see --help", file=sys.stderr)
        sys.exit(2)


def parse_set(text: str) -> tuple[str, object]:
    """--set's 'key.path=value' (the value in YAML: 2.0, time, [1, 0, 2]) -> (path, value)."""
    import yaml

    from drake_standup.config import ScenarioError

    path, equals, value = text.partition("=")
    try:
        if equals and path.strip():
            return path.strip(), yaml.safe_load(value)
    except yaml.YAMLError:
        pass
    raise ScenarioError(
        f"--set {text}: accepted: key.path=VALUE (YAML), e.g. advancement.eps=1.0e-4"
    )


def add_set_argument(parser, help_text: str) -> None:
    """The repeatable --set KEY.PATH=VALUE option (into args.overrides, parse_set each)."""
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY.PATH=VALUE",
        help=help_text,
    )


def positive_int(text: str) -> int:
    """An argparse type: a count >= 1."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def positive_float(text: str) -> float:
    """An argparse type: a finite number of seconds > 0."""
    value = float(text)
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, got {text}")
    return value
