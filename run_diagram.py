#!/usr/bin/env python
"""Simulate the iCub stand-up scenario and write recording, metrics and diagram.

python run_diagram.py [--scenario PATH|NAME] [--set KEY.PATH=VALUE] [--out DIR] [--duration S]
                      [--no-recording] [--live]

The same as `drake-standup run` (drake_standup/cli.py).
"""

import sys

from drake_standup.cli import run_main

if __name__ == "__main__":
    sys.exit(run_main(prog="python run_diagram.py"))
