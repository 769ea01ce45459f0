"""`python -m drake_standup.convergence`: the same as `drake-standup convergence`."""

import sys

from drake_standup.convergence.cli import main

sys.exit(main())
