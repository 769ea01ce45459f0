"""`python -m drake_standup.studies.convergence`: the same as `drake-standup convergence`."""

import sys

from drake_standup.studies.convergence.cli import main

sys.exit(main())
