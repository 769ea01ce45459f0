"""The registry of plug-ins: advancement laws, helpers, chairs and responses, by name. The
public face is drake_standup.plugins.

A scenario names a plug-in three ways, tried in this order:

    module:attribute    an object importable from the Python path (mylab.laws:gated_law)
    a registered name   the shipped ones (SHIPPED), or registered by `register`
    an entry point      of the group drake_standup.<kind> of an installed distribution

The shipped ones are named as entry points are, module:attribute, and load as they do, all
of them the first time any name is resolved.

An installed package makes its names known through its pyproject:

    [project.entry-points."drake_standup.laws"]
    gated = "mylab.laws:gated_law"

Every failure is a PluginError: one line naming the scenario key, what is wrong and what
the key accepts (cli.py prints it as `error: ...`, exit code 2).
"""

from __future__ import annotations

import importlib
import importlib.metadata
import inspect
import os
import sys
from dataclasses import dataclass
from typing import Any

from drake_standup.config.errors import ScenarioError

# Each kind of plug-in and the scenario key that names one.
KINDS = {
    "laws": "advancement.law",
    "helpers": "human.mode",
    "chairs": "chair.kind",
    "responses": "response",
}
ENTRY_POINT_GROUP = "drake_standup.{kind}"
# The shipped plug-ins, by kind and name, and each kind's check of an object (what is wrong
# with it as one, or None), each as module:attribute.
SHIPPED = {
    "laws": {
        "tangent": "drake_standup.standup.laws:tangent_law",
        "interaction": "drake_standup.standup.laws:interaction_law",
    },
    "helpers": {
        "scripted": "drake_standup.helper.hands:HumanWrenchSource",
        "reactive": "drake_standup.helper.hands:HumanWrenchSource",
        "body": "drake_standup.helper.body_control:body_helper",
        "recorded": "drake_standup.helper.recorded:make_recorded_helper",
    },
    "chairs": {"standard": "drake_standup.world.chair:standard_chair"},
    "responses": {
        "advancement": "drake_standup.config.responses:ADVANCEMENT",
        "stiff": "drake_standup.config.responses:STIFF",
        "compliant": "drake_standup.config.responses:COMPLIANT",
    },
}
CHECKS = {
    "laws": "drake_standup.standup.laws:check_law",
    "helpers": "drake_standup.helper.plugin:check_helper",
    "chairs": "drake_standup.config.plugins:check_chair",
    "responses": "drake_standup.config.responses:check_response",
}
# Their descriptions where the object's docstring does not fit `drake-standup list`.
_DESCRIPTIONS = {
    ("responses", "advancement"): "psi runs ahead of time while the pull helps (the paper's)",
    ("responses", "stiff"): "psi = t, the pull compensated in full",
    ("responses", "compliant"): "psi = t, the CoM reference yielding to the pull",
    ("helpers", "scripted"): "the scenario's pulls, trapezoids in time",
    ("helpers", "reactive"): "a partner guiding each hand from what they saw of the robot, "
    "late, through an arm's impedance",
}


class PluginError(ScenarioError):
    """A plug-in that cannot be used; one line naming the key (a ScenarioError: exit 2)."""


@dataclass(frozen=True)
class Plugin:
    """A resolved plug-in: its name as the scenario gives it, the object, where it came
    from (the distribution that registered it, 'entry point <dist>' or 'module') and one
    line saying what it is."""

    name: str
    obj: Any
    origin: str
    description: str


_REGISTERED: dict[str, dict[str, Plugin]] = {kind: {} for kind in KINDS}
_RESOLVED: dict[tuple[str, str], Plugin] = {}
_shipped_loaded = False


def register(kind: str, name: str, obj: Any, description: str = "", origin: str = "") -> None:
    """Makes obj known as name among kind's plug-ins (a name already taken is refused)."""
    _check_kind(kind)
    if ":" in name or not name:
        raise ValueError(f"register: '{name}' is not a plug-in name (no ':', not empty)")
    if name in _REGISTERED[kind] and _REGISTERED[kind][name].obj is not obj:
        raise ValueError(f"register: {kind} '{name}' is registered already")
    text = description or _first_line(obj)
    _REGISTERED[kind][name] = Plugin(name, obj, origin or _origin_of(obj), text)


def resolve(kind: str, spec: str) -> Plugin:
    """The plug-in spec names (module docstring's order); a PluginError if it cannot be used.
    Resolved once per process: a sweep's runs ask for the same few names."""
    _check_kind(kind)
    _load_shipped()
    found = _RESOLVED.get((kind, spec))
    if found is None:
        found = _find(kind, spec)
        problem = _import(KINDS[kind], CHECKS[kind])(found.obj)
        if problem:
            raise PluginError(f"{KINDS[kind]}: '{spec}' {problem}")
        _RESOLVED[(kind, spec)] = found
    return found


def registered(kind: str) -> dict[str, Plugin]:
    """Every name kind's plug-ins go by without module:attribute: the registered ones and
    the installed entry points (loaded, so that a broken one shows as such)."""
    _check_kind(kind)
    _load_shipped()
    names = dict(_REGISTERED[kind])
    for point in _entry_points(kind):
        if point.name in names:
            continue
        try:
            names[point.name] = _from_entry_point(kind, point)
        except PluginError as err:
            names[point.name] = Plugin(point.name, None, _dist_of(point), f"broken: {err}")
    return names


def accepted(kind: str) -> str:
    """What kind's key accepts, for a message."""
    return f"{' | '.join(registered(kind))}, or module:attribute"


def _find(kind: str, spec: str) -> Plugin:
    key = KINDS[kind]
    if not isinstance(spec, str) or not spec:
        raise PluginError(f"{key}: {spec!r}; accepted: {accepted(kind)}")
    if ":" in spec:
        if os.getcwd() not in sys.path:  # a module in the current folder, as `python -m`
            sys.path.append(os.getcwd())
        return Plugin(spec, _import(key, spec), "module", "")
    if spec in _REGISTERED[kind]:
        return _REGISTERED[kind][spec]
    for point in _entry_points(kind):
        if point.name == spec:
            return _from_entry_point(kind, point)
    raise PluginError(f"{key}: '{spec}' is not a known name; accepted: {accepted(kind)}")


def _import(key: str, spec: str) -> Any:
    """The object spec = 'module:attribute' (attribute may be dotted) names."""
    module_name, _, attribute = spec.partition(":")
    if not module_name or not attribute:
        raise PluginError(f"{key}: '{spec}' is not module:attribute; accepted: e.g. mylab.laws:law")
    try:
        obj = importlib.import_module(module_name)
    except Exception as err:  # noqa: BLE001 - whatever the user's module raises, one line
        reason = " ".join(f"{type(err).__name__}: {err}".split())[:200]
        raise PluginError(
            f"{key}: '{spec}': module '{module_name}' does not import ({reason}); accepted: "
            "a module on the Python path (installed, or in the current folder)"
        ) from None
    for part in attribute.split("."):
        if not hasattr(obj, part):
            raise PluginError(
                f"{key}: '{spec}': '{module_name}' has no attribute '{attribute}'; accepted: "
                "a name the module defines"
            )
        obj = getattr(obj, part)
    return obj


def _entry_points(kind: str) -> list:
    return list(importlib.metadata.entry_points(group=ENTRY_POINT_GROUP.format(kind=kind)))


def _from_entry_point(kind: str, point) -> Plugin:
    origin = f"entry point of {_dist_of(point)}"
    obj = _import(KINDS[kind], point.value)
    return Plugin(point.name, obj, origin, _first_line(obj))


def _dist_of(point) -> str:
    dist = getattr(point, "dist", None)
    return dist.name if dist is not None else "an installed package"


def _origin_of(obj: Any) -> str:
    module = getattr(obj, "__module__", "") or ""
    return module.split(".")[0] or "?"


def _first_line(obj: Any) -> str:
    doc = (getattr(obj, "__doc__", None) or "").strip()
    return " ".join(doc.split("\n\n")[0].split())  # its first paragraph, on one line


def call_problem(obj: Any, arguments: int, usage: str) -> str | None:
    """What keeps obj from being called as usage with `arguments` positional arguments
    (None: nothing; an object whose signature cannot be read is tried at its first call)."""
    if not callable(obj):
        return f"is a {type(obj).__name__}, not callable; accepted: {usage}"
    try:
        signature = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    try:
        signature.bind(*(None,) * arguments)
    except TypeError:
        return f"has the signature {signature}; accepted: {usage}"
    return None


def check_chair(obj: Any) -> str | None:
    """What is wrong with obj as a chair maker (None: nothing)."""
    return call_problem(obj, 1, "chair(config) -> ChairModel")


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"kind '{kind}'; accepted: {', '.join(KINDS)}")


def _load_shipped() -> None:
    """SHIPPED registered, once: each imported as module:attribute, as anyone's."""
    global _shipped_loaded
    if _shipped_loaded:
        return
    _shipped_loaded = True
    for kind, names in SHIPPED.items():
        for name, spec in names.items():
            obj = _import(KINDS[kind], spec)
            register(kind, name, obj, _DESCRIPTIONS.get((kind, name), ""), "drake_standup")
