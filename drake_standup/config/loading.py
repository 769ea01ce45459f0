"""Loading a scenario: a YAML file, and overrides, into the typed dataclasses.

A scenario is a YAML file loaded into the typed dataclasses of config/scenario.py with
Drake's yaml_load_typed, so an unknown key or a wrong type is an error rather than a
silently ignored typo. Overrides (a sweep's, or `--set key.path=value` on the command
line) are one more YAML layer through the same loader. What the types alone cannot say
(bounds, accepted values, lengths) is checked by config/rules.py.
"""

import dataclasses
import re
import reprlib
import typing
from collections.abc import Iterable
from pathlib import Path

import yaml
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed

from drake_standup.config.chair_kind import with_chair_seat
from drake_standup.config.errors import ScenarioError
from drake_standup.config.inputs import read_text_file
from drake_standup.config.legacy import read_legacy
from drake_standup.config.resources import find, shipped
from drake_standup.config.rules import _format, _nodes, _pattern, validate, with_hardware
from drake_standup.config.scenario import DEFAULT_SCENARIO, Scenario


def load_scenario(path: str | Path | None = None, overrides: Iterable = ()) -> Scenario:
    """Loads a scenario file (a path, or the name of a shipped scenario), applies overrides
    [(key path, value)] and validates; raises ScenarioError (one line)."""
    found = find("scenarios", path) if path is not None else DEFAULT_SCENARIO
    accepted = f"a YAML file or a shipped scenario: {', '.join(shipped('scenarios'))}"
    text = read_text_file(found or path, "scenario", accepted)
    return parse_scenario(text, str(found), overrides)


def parse_scenario(text: str, where: str = "scenario", overrides: Iterable = ()) -> Scenario:
    """A scenario from YAML text (where: its name in error messages), with overrides."""
    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise ScenarioError(f"scenario {where}: not valid YAML ({_one_line(err)})") from None
    if not isinstance(raw, dict | None):
        raise ScenarioError(
            f"scenario {where}: {reprlib.repr(raw)}; accepted: a mapping of "
            f"{', '.join(_fields(Scenario))}"
        )
    return apply_overrides(_load(raw or {}, Scenario()), overrides)


def apply_overrides(scenario: Scenario, overrides: Iterable) -> Scenario:
    """A copy of scenario with each (key path, value) set, validated (and, with a mesh
    chair, chair.seat_height_m set from the mesh).

    The overrides are one more YAML layer: the top-level keys they touch, written out
    whole with the values set, loaded by yaml_load_typed with scenario as the defaults:
    the typed parser, and the errors, of a scenario file. A key path is names joined by
    '.' with [index] for list entries, e.g. human.pulls[0].force_N[2].
    """
    data, layer = _plain(scenario), {}
    for path, value in overrides:
        top = _set(data, path, value)
        layer[top] = data[top]
    scenario = validate(with_hardware(_load(layer, scenario)))
    # The chair's seat height is the made chair's (a mesh's, a plug-in's: chair_kind.py).
    return dataclasses.replace(scenario, chair=with_chair_seat(scenario.chair))


def expand_key_path(scenario: Scenario, path: str) -> list[str]:
    """The concrete key paths a path names in scenario ([*]: every entry of a list)."""
    if "[*]" not in path:
        return [path]
    keys = (_format(steps) for steps, _ in _nodes(_plain(scenario)))
    return [key for key in keys if _pattern(path).fullmatch(key)]


# --- Drake's loader, and errors that name the key path -----------------------------------


def _load(raw: dict, defaults: Scenario) -> Scenario:
    """yaml_load_typed of raw (plain YAML data) over defaults. Drake's own errors do not say
    where (nor do its ValueErrors name a key), so on failure each leaf of raw is loaded
    alone to find the key path to name."""
    raw = read_legacy(raw)
    try:
        text = yaml.safe_dump(raw, sort_keys=False)
        return yaml_load_typed(schema=Scenario, data=text, defaults=defaults)
    except Exception as err:  # RuntimeError, ValueError, TypeError, AttributeError, ...
        for steps, value in _nodes(raw, leaves=True):
            try:
                yaml_load_typed(schema=Scenario, data=yaml.safe_dump(_nest(steps, value)))
            except Exception:
                raise ScenarioError(_type_error(steps, raw)) from None
        raise ScenarioError(f"scenario: {_one_line(err)}") from None


def _type_error(steps: list, raw: dict) -> str:
    """The message for the leaf at steps that Drake's loader rejected: an unknown key, or
    a value of the wrong type (named at the first step the schema has no room for)."""
    schema, value = Scenario, raw
    for depth, step in enumerate(steps):
        fields, origin = _fields(schema), typing.get_origin(schema)
        if isinstance(step, str) and fields is not None:
            if step not in fields:
                return f"{_format(steps[: depth + 1])}: unknown key; accepted: {', '.join(fields)}"
            schema = fields[step]
        elif origin is (list if isinstance(step, int) else dict):
            schema = typing.get_args(schema)[-1]  # list[T], dict[str, T]: T
        else:
            steps = steps[:depth]
            break
        value = value[step]
    return f"{_format(steps)}: {value!r}; accepted: {_type_name(schema)}"


def _type_name(schema) -> str:
    if (fields := _fields(schema)) is not None:
        return f"a mapping of {', '.join(fields)}"
    names = {float: "a number", int: "an integer", bool: "true or false", str: "a string"}
    origin = typing.get_origin(schema)
    return names.get(schema) or {list: "a list", dict: "a mapping"}.get(origin, str(schema))


def _fields(schema) -> dict[str, typing.Any] | None:
    """Field name -> type of one of our dataclasses or of one of Drake's config structs."""
    if hasattr(schema, "__dataclass_fields__"):
        return typing.get_type_hints(schema)
    if hasattr(schema, "__fields__"):
        return {f.name: f.type for f in schema.__fields__}
    return None


def _plain(scenario: Scenario) -> dict:
    """scenario as plain YAML data (dicts, lists, numbers, strings)."""
    return yaml.safe_load(yaml_dump_typed(scenario))


def _nest(steps: list, value):
    """The smallest document that holds value at steps (a list entry as a 1-entry list)."""
    for step in reversed(steps):
        value = [value] if isinstance(step, int) else {step: value}
    return value


def _one_line(err: Exception) -> str:
    return " ".join(str(err).split())


# --- Key paths: 'human.pulls[0].force_N[0]' ---------------------------------------------

_KEY_PATH = re.compile(r"[A-Za-z_]\w*(\[\d+\])*(\.[A-Za-z_]\w*(\[\d+\])*)*")


def _set(data: dict, path: str, value) -> str:
    """Sets the value at a key path of plain data; returns the path's first name. A mapping
    may gain a key (Drake's loader then names one its schema lacks), a list no entry."""
    if not _KEY_PATH.fullmatch(path):
        raise ScenarioError(
            f"key path '{path}': accepted: names joined by '.', each with an optional [index]"
            ", e.g. human.pulls[0].force_N[0]"
        )
    steps = [int(s) if s.isdigit() else s for s in re.findall(r"[^.\[\]]+", path)]
    node = data
    for depth, step in enumerate(steps):
        where = _format(steps[:depth]) or "scenario"
        if not isinstance(node, list if isinstance(step, int) else dict):
            kind = {list: "a list", dict: "a mapping"}.get(type(node), "a value")
            raise ScenarioError(f"key path '{path}': {where} is {kind}")
        if isinstance(step, int) and step >= len(node):
            raise ScenarioError(
                f"key path '{path}': index {step} out of range; {where} has {len(node)} entries"
            )
        parent, node = node, node[step] if isinstance(step, int) else node.setdefault(step, {})
    parent[steps[-1]] = value
    return steps[0]
