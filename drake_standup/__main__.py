"""python -m drake_standup COMMAND: the same as the drake-standup command (cli.py)."""

import sys

from drake_standup.cli import main

sys.exit(main())
