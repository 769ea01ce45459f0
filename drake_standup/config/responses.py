"""The robot's response to a pull (the scenario's `response`): which of the controller's
answers to it act. A response is a plug-in (config/plugins.py): the shipped three below,
or a Response of your own, by name or module:attribute (docs/extending.md).

The run's responses are numbered: the shipped three in RESPONSES' order, then the
scenario's own if it is none of them (response_names). That number is what the
controller's port `response` carries, what the live page's switch sets and what
signals.npz logs (`response`, with the names in `responses`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from drake_standup.config.scenario import RESPONSES


@dataclass(frozen=True)
class Response:
    """What the robot does with a pull.

    advances           psi runs ahead of time while the pull helps (advancement.law)
    lets_help_through  the pull's helpful part f_par goes through the momentum task; the
                       rest is compensated (else all of the pull is compensated)
    yields             the CoM target yields to the pull through the admittance of the
                       scenario's compliance: section
    """

    advances: bool
    lets_help_through: bool
    yields: bool


ADVANCEMENT = Response(advances=True, lets_help_through=True, yields=False)
"""The paper's: psi runs ahead of time while the pull helps, and the help goes through."""
STIFF = Response(advances=False, lets_help_through=False, yields=False)
"""psi = t and the pull compensated in full: the CoM tracks its time reference."""
COMPLIANT = Response(advances=False, lets_help_through=False, yields=True)
"""psi = t, and the CoM reference yields to the pull through an admittance."""


# The shipped responses in RESPONSES' order: what the codes 0, 1, 2 do.
SHIPPED = (ADVANCEMENT, STIFF, COMPLIANT)
# Whether each shipped code lets psi advance.
SHIPPED_ADVANCES = tuple(response.advances for response in SHIPPED)


def response_names(response: str) -> tuple[str, ...]:
    """The run's responses by number: RESPONSES, then response if it is none of them."""
    return RESPONSES if response in RESPONSES else (*RESPONSES, response)


def responses_of(names: tuple[str, ...]) -> tuple[Response, ...]:
    """The Response of each name (config/plugins.py resolves them)."""
    from drake_standup.config.plugins import resolve

    return tuple(resolve("responses", name).obj for name in names)


def check_response(obj: Any) -> str | None:
    """What is wrong with obj as a response (None: nothing)."""
    if isinstance(obj, Response):
        return None
    return (
        f"is a {type(obj).__name__}; accepted: a drake_standup.config.responses.Response"
        "(advances, lets_help_through, yields)"
    )
