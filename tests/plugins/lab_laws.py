"""Laws outside the package, named by module:attribute in tests/plugins (the tests folder is
on the Python path: pyproject's pytest pythonpath)."""

import math

from drake_standup.standup.laws import LawInputs, tangent_law


def copy_of_tangent(inputs: LawInputs) -> float:
    """The shipped tangent law, by another name: the plug-in path must change nothing."""
    return tangent_law(inputs)


def constant(inputs: LawInputs) -> float:
    """psi runs at 1.3 t while the pull helps: a law that reads alpha only."""
    return 1.3 if inputs.alpha > inputs.config.alpha_min_mps2 else 1.0


def returns_nan(inputs: LawInputs) -> float:
    return math.nan


def returns_pair(inputs: LawInputs):
    return (1.0, 2.0)


def two_arguments(inputs, other):
    return 1.0


NOT_CALLABLE = 3.0
