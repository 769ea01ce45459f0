"""What every command line of the project shares (no heavy imports here:
run_diagram.py parses its arguments before it loads Drake)."""

from __future__ import annotations

import argparse
import sys


class OneLineErrorParser(argparse.ArgumentParser):
    """argparse, but a bad argument is one 'error:' line and exit code 2."""

    def error(self, message: str) -> None:
        print(f"error: {message}; see --help", file=sys.stderr)
        sys.exit(2)
