"""The time-step convergence study (issue 11): how coarse may the plant and controller step?
`drake-standup convergence --help` (cli.py's docstring) says what it runs and writes.

cases.py       the study's cases (scenario, plant step, controller multiple) and their inputs
runs.py        one case simulated into its folder, and the folder read back (the run cache)
comparison.py  a run against a reference: issue 11's bounds, the errors, the per-run verdict
choice.py      every run against its references, the per-configuration table, the choice
report.py      convergence.md
figures.py     convergence.png
study.py       the study on Dask: what is not cached, then compare, choose, write
cli.py         the command line (main)
"""

from drake_standup.studies.convergence.cases import (
    SCENARIOS,
    STEPS_MS,
    Case,
    case_inputs,
    study_cases,
)
from drake_standup.studies.convergence.choice import choose, config_table, evaluate
from drake_standup.studies.convergence.cli import main
from drake_standup.studies.convergence.comparison import (
    BOUNDS,
    COM_DEVIATION_M,
    compare,
    count_crossings,
    entry_time_error,
    max_com_deviation,
    seated_split,
    standup_time_bound_s,
    with_fine_reference,
)
from drake_standup.studies.convergence.figures import draw_figure
from drake_standup.studies.convergence.report import markdown
from drake_standup.studies.convergence.runs import RunData, is_cached, load_run, run_case
from drake_standup.studies.convergence.study import StudyResult, run_study

__all__ = [
    "BOUNDS",
    "COM_DEVIATION_M",
    "SCENARIOS",
    "STEPS_MS",
    "Case",
    "RunData",
    "StudyResult",
    "case_inputs",
    "choose",
    "compare",
    "config_table",
    "count_crossings",
    "draw_figure",
    "entry_time_error",
    "evaluate",
    "is_cached",
    "load_run",
    "main",
    "markdown",
    "max_com_deviation",
    "run_case",
    "run_study",
    "seated_split",
    "standup_time_bound_s",
    "study_cases",
    "with_fine_reference",
]
