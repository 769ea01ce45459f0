"""Older scenario keys that the phase table (phases.py) replaced, read into it.

Before the phase table, parts of it were keys of standup: and controller: (a run's
scenario.yaml from then spells out all of them). Old files and overrides keep loading
and keep their meaning: where a YAML layer sets one of the keys below, it is checked
under its own name, taken out, and written into the layer's phases: section before
Drake's loader reads the layer (a mapping there merges into the phase's, as it did
into the old key's).
"""

import math
from collections.abc import Callable

from drake_standup.config.errors import ScenarioError
from drake_standup.config.phases import PHASES
from drake_standup.config.rules import NON_NEGATIVE, POSITIVE, Range

_STATES = range(1, len(PHASES) + 1)

# Key -> (its kind: 'number', an int n (a list of n numbers), 'states' (a list of state
# numbers), 'state' (one state number) or 'joints' (joint name -> rad); the bounds of its
# numbers (None: any finite number); the phase-table entries it sets, as {state: {field
# path: value}} from its value). The bounds are the ones the key had.
_Writes = Callable[[object], dict[int, dict[str, object]]]
_LEGACY: dict[str, tuple[object, _Writes]] = {
    "standup.balance_time_s": ("number", lambda v: {1: {"exit.min_time_s": v}}),
    # The sit-back's return to the seat took the state-2 segment's length.
    "standup.segment_psi": (
        3,
        lambda v: (
            {1: {"segment_psi": v[0]}, 2: {"segment_psi": v[0]}}
            | {3: {"segment_psi": v[1]}, 4: {"segment_psi": v[2]}}
        ),
    ),
    # An older file's forward displacement is from where the CoM sits, whatever the seat.
    "standup.state2_com_delta_m": (
        3,
        lambda v: {2: {"com_delta_m": v, "com_x_over_soles_m": None}},
    ),
    "standup.state3_com_delta_m": (3, lambda v: {3: {"com_delta_m": v}}),
    "standup.standing_com_height_m": ("number", lambda v: {4: {"com_height_m": v}}),
    "standup.feet_force_2to3_N": ("number", lambda v: {2: {"exit.feet_force_N": v}}),
    "standup.min_time_state2_s": ("number", lambda v: {2: {"exit.min_time_s": v}}),
    "standup.com_ahead_of_heels_m": ("number", lambda v: {2: {"exit.com_ahead_of_heels_m": v}}),
    "standup.foot_force_3to4_N": ("number", lambda v: {3: {"exit.each_foot_force_N": v}}),
    "standup.min_time_state3_s": ("number", lambda v: {3: {"exit.min_time_s": v}}),
    "standup.seat_release_s": ("number", lambda v: {3: {"unload_s": v}}),
    "standup.seat_unload_s": ("number", lambda v: {2: {"unload_s": v}}),
    "controller.com_kp_seated_per_s2": (
        3,
        lambda v: {1: {"com_kp_per_s2": v}, 2: {"com_kp_per_s2": v}},
    ),
    "controller.com_kp_standing_per_s2": (
        3,
        lambda v: {3: {"com_kp_per_s2": v}, 4: {"com_kp_per_s2": v}},
    ),
    "controller.base_pitch_by_state_rad": (
        4,
        lambda v: {k: {"base_pitch_rad": v[k - 1]} for k in _STATES},
    ),
    "controller.seat_hinge_from_state": (
        "state",
        lambda v: {k: {"seat_hold": "hinged" if k >= v else "held"} for k in _STATES},
    ),
    # An old file's postures are absolute (the plan moved none with the seated pose then).
    "controller.posture_state2_rad": (
        "joints",
        lambda v: {2: {"posture_rad": v, "posture_from_seated": False}},
    ),
    "controller.posture_state3_rad": (
        "joints",
        lambda v: {3: {"posture_rad": v, "posture_from_seated": False}},
    ),
    "controller.posture_state4_rad": ("joints", lambda v: {4: {"posture_rad": v}}),
    "controller.lean_states": ("states", lambda v: {k: {"lean": k in v} for k in _STATES}),
}


_POSITIVE_KEYS = ("standup.segment_psi", "standup.standing_com_height_m")
_UNBOUNDED_KEYS = ("controller.base_pitch_by_state_rad", "controller.posture_state")
LEGACY = {
    key: (
        kind,
        POSITIVE
        if key in _POSITIVE_KEYS
        else None
        if key.startswith(_UNBOUNDED_KEYS)
        else NON_NEGATIVE,
        writes,
    )
    for key, (kind, writes) in _LEGACY.items()
}


# Older values of a key, renamed so that one word means one thing (issue 47: a person's
# tone was soft or stiff, beside the robot's response stiff).
LEGACY_VALUES = {("human", "body", "tone"): {"soft": "relaxed", "stiff": "firm"}}


def _renamed_values(raw: dict) -> dict:
    """raw with each older value of LEGACY_VALUES under its new name (raw not changed)."""
    for path, names in LEGACY_VALUES.items():
        node = raw
        for key in path[:-1]:
            node = node.get(key) if isinstance(node, dict) else None
        value = node.get(path[-1]) if isinstance(node, dict) else None
        if isinstance(value, str) and value in names:
            raw = _with(raw, path, names[value])
    return raw


def _with(raw: dict, path: tuple[str, ...], value) -> dict:
    """A copy of raw along path with path's leaf set to value."""
    head, *rest = path
    copy = dict(raw)
    copy[head] = _with(raw[head], tuple(rest), value) if rest else value
    return copy


def read_legacy(raw: dict) -> dict:
    """raw (one YAML layer, plain data) with every older key moved into its phases:
    section and every older value renamed (LEGACY_VALUES); raw itself is not changed.
    Raises ScenarioError for an older key whose value is not of its kind, or that the
    layer also sets under its phase-table name."""
    raw = _renamed_values(raw)
    found = [
        (key, raw[section][name])
        for key in LEGACY
        for section, name in [key.split(".")]
        if isinstance(raw.get(section), dict) and name in raw[section]
    ]
    if not found:
        return raw
    raw = {k: (dict(v) if isinstance(v, dict) else v) for k, v in raw.items()}
    phases = raw.get("phases")
    if phases is not None and not isinstance(phases, dict):
        return raw  # the loader names the phases: key that is not a mapping
    given = {
        (name, path): True
        for name, phase in (phases or {}).items()
        if isinstance(phase, dict)
        for path in _paths(phase)
    }
    phases = raw["phases"] = {name: _copy(phase) for name, phase in (phases or {}).items()}
    for key, value in found:
        kind, bounds, writes = LEGACY[key]
        _check_kind(key, value, kind, bounds)
        section, name = key.split(".")
        del raw[section][name]
        for state, entries in writes(value).items():
            phase = PHASES[state - 1]
            for path, entry in entries.items():
                if (phase, path) in given:
                    raise ScenarioError(
                        f"{key}: also given as phases.{phase}.{path}; accepted: one of them "
                        f"({key} is the older name of phase-table entries)"
                    )
                node = phases.setdefault(phase, {})
                *parents, leaf = path.split(".")
                for parent in parents:
                    node = node.setdefault(parent, {})
                node[leaf] = entry
    return raw


def _paths(data: dict, prefix: str = "") -> list[str]:
    """The leaf key paths of a mapping (a nested mapping's keys joined by '.')."""
    paths = []
    for key, value in data.items():
        path = f"{prefix}{key}"
        paths += _paths(value, path + ".") if isinstance(value, dict) else [path]
        if isinstance(value, dict):
            paths.append(path)
    return paths


def _copy(data):
    return {k: _copy(v) for k, v in data.items()} if isinstance(data, dict) else data


def _number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _check_kind(key: str, value, kind, bounds: Range | None) -> None:
    """One line naming key (or its entry) if value is not of its kind or out of its
    bounds, as config/rules.py words it."""
    if kind in ("number", "state"):
        ok = _number(value) and math.isfinite(value)
        accepted = "a number" if kind == "number" else "a state number 1-4"
        if ok and kind == "state":
            ok = value in _STATES
        if not ok:
            raise ScenarioError(f"{key}: {value!r}; accepted: {accepted}")
        if bounds is not None and not bounds.accepts(value):
            raise ScenarioError(f"{key}: {float(value)}; accepted: {bounds}")
    elif kind == "joints":
        if not (isinstance(value, dict) and all(_number(v) for v in value.values())):
            raise ScenarioError(f"{key}: {value!r}; accepted: a mapping of joint name to rad")
    else:
        n = None if kind == "states" else kind
        if not (isinstance(value, list) and (n is None or len(value) == n)):
            accepted = "a list of state numbers 1-4" if n is None else f"a list of {n} numbers"
            raise ScenarioError(f"{key}: {value!r}; accepted: {accepted}")
        for i, entry in enumerate(value):
            _check_kind(f"{key}[{i}]", entry, "state" if n is None else "number", bounds)
