"""Plug-ins: your own advancement law and helper, by name (issue 61; docs/extending.md).

    from drake_standup.plugins import LawInputs, register

    def gated_law(inputs: LawInputs) -> float:
        return 1.5 if inputs.alpha > 0.3 else 1.0

    register("laws", "gated", gated_law)      # or name it mylab.laws:gated_law

config/plugins.py resolves a scenario's names (shipped, registered, module:attribute,
entry points); standup/laws.py says what a law receives, helper/plugin.py what a helper is.
"""

from drake_standup.config.plugins import (
    ENTRY_POINT_GROUP,
    KINDS,
    Plugin,
    PluginError,
    register,
    registered,
    resolve,
)
from drake_standup.helper.plugin import HandWrenchHelper
from drake_standup.standup.laws import LawInputs

__all__ = [
    "ENTRY_POINT_GROUP",
    "KINDS",
    "HandWrenchHelper",
    "LawInputs",
    "Plugin",
    "PluginError",
    "register",
    "registered",
    "resolve",
]
