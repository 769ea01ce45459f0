"""The advancement law: the paper's, its gates, and the interface a law of your own has.

psi(0) = 0 and, while the human's interaction helps,
    psi_dot = min{ psi_dot_upper, max{ 1, ratio } }
with ([tirupachuri2019]; t = d_psi x_d the path tangent, Omega f the CoM acceleration the
measured hand wrenches cause, xdot the measured CoM velocity):
    tangent law (the paper's proposition):   ratio = xdot.t / (|t|^2 + eps)
    interaction law (the authors' code):     ratio = (xdot.Omega f)(t.Omega f)
                                                     / ((t.Omega f)^2 + eps)
The interaction helps when alpha = t.Omega f / |t| (the part of Omega f along
the desired velocity) exceeds alpha_min; otherwise, and with advancement
disabled, or with a response other than advancement (config.RESPONSES), psi_dot = 1
and psi = t. psi therefore never runs backwards nor
faster than psi_dot_upper.

Lead gate (ours, on by default): the law also waits until the CoM is not behind
its reference along the path, lead = (x - x_d).t/|t| >= -lag_tolerance. The
ratio sets the reference's speed to the CoM's; with a finite-gain tracker,
advancing while the CoM lags closes a positive loop (x_d ahead -> K_P pushes ->
the CoM speeds up -> psi runs further ahead), which in our closed loop threw the
robot forward at the start of state 4. Advancing only on a lead keeps the
reference where the help has already brought the robot.

Graded gates (ours): the paper's law is on or off (alpha > alpha_min). With a
tracker that follows its reference (feed-forward xd_ddot), xdot = psi_dot t, so
ratio = psi_dot: any psi_dot sustains itself, and the smallest helpful pull ran
psi_dot to its bound (5 N per hand: 2.47 of 2.5; the stand-up time jumped 0.87 s
between 0 and 5 N, measured). So the law's excess over 1 is weighted,

    psi_dot = 1 + w g s (clip(ratio, 1, upper) - 1),
    w = min(1, (alpha - alpha_min) / (alpha_full - alpha_min)),
    g = min(1, 1 + lead / lag_tolerance)   (0 at a lag of lag_tolerance),
    s = 1 - smoothstep((progress - taper_from) / (1 - taper_from))   (segment's end),

and with ratio = psi_dot + e (e: the CoM's speed-up the help causes, in psi
units) the rate settles at psi_dot - 1 = e w g / (1 - w g): growing with the
help, the paper's law (w = g = s = 1) from alpha_full on, psi = t without help.
The taper s returns psi_dot to 1 before each segment ends (a rise ending at
psi_dot 2.5 drove the knees onto their stop, measured).

A law is a plug-in (config/plugins.py, docs/extending.md): any callable
law(inputs: LawInputs) -> float, the rate psi_dot it asks for now; the two above are
registered by name (tangent_law, interaction_law) as anyone's. TrajectoryAdvancement
(advancement.py) calls it each time its inputs change, holds psi_dot = 1 where the
stand-up's phase does not advance, where the response is not advancement or
advancement.enabled is false, bounds the rate to [0, psi_dot_upper] and filters it
(psi_ddot_filter_s) before psi integrates it. A rate that is not one finite number >= 0
ends the run with one `error:` line naming the law.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from drake_standup.config import AdvancementConfig
from drake_standup.config.plugins import PluginError, call_problem
from drake_standup.control.smooth import smoothstep
from drake_standup.standup.com_path import leaned

_MISSING = object()


def for_robot(config: AdvancementConfig, mass_kg: float) -> AdvancementConfig:
    """config with alpha_full_mps2 derived where it is None: the CoM acceleration
    full_help_pull_N on each hand along the path gives a robot of mass_kg."""
    if config.alpha_full_mps2 is not None:
        return config
    return dataclasses.replace(config, alpha_full_mps2=2.0 * config.full_help_pull_N / mass_kg)


def helpfulness(tangent: np.ndarray, omega_f: np.ndarray, eps: float) -> float:
    """alpha: Omega f projected on the desired direction (0 where the path stops)."""
    t2 = float(tangent @ tangent)
    if t2 <= eps:
        return 0.0
    return float(tangent @ omega_f) / math.sqrt(t2)


def lead(
    com: np.ndarray, x_d: np.ndarray, tangent: np.ndarray, lean: np.ndarray | None = None
) -> float:
    """How far the CoM is ahead of its target along the path, m: of x_d leaned as the
    controller leans it (com_path.leaned; None: not leaned). Against the bare x_d, the lean
    the controller asks for read as a lag: braced, the CoM target stands 1.3 cm lower, and
    the gate held psi = t through a rise the pull helped (issue 60's lagging partner)."""
    norm = float(np.linalg.norm(tangent))
    if norm <= 0.0:
        return 0.0
    target = x_d if lean is None else leaned(x_d, lean)
    return float((com - target) @ tangent) / norm


def psi_dot_law(
    config: AdvancementConfig,
    com_velocity: np.ndarray | Callable[[], np.ndarray],
    omega_f: np.ndarray,
    tangent: np.ndarray,
    lead_m: float | Callable[[], float] = 0.0,
    progress: float | Callable[[], float] = 0.0,
    *,
    ratio_of: Callable | None = None,
) -> tuple[float, float]:
    """(psi_dot, alpha) by the shipped laws' gates around ratio_of (tangent_ratio or
    interaction_ratio; None: config.law's); lead_m feeds the lead gate
    (or a function giving it, called only when the gate decides); progress: how far
    along its segment the reference is (0-1), for the taper at the segment's end. The
    CoM velocity and the progress may be functions too, called only where the law acts.

    psi_dot = 1 + w(alpha) g(lead) (clip(ratio, 1, upper) - 1): the paper's law where
    the help is full (w = g = 1), psi = t where there is none; the weights grade the
    paper's on/off gates (module docstring)."""
    alpha = helpfulness(tangent, omega_f, config.eps)
    if not config.enabled or alpha <= config.alpha_min_mps2:
        return 1.0, alpha
    if callable(progress):
        progress = progress()
    weight = 1.0
    if config.alpha_full_mps2 > config.alpha_min_mps2:
        weight = min(
            1.0,
            (alpha - config.alpha_min_mps2) / (config.alpha_full_mps2 - config.alpha_min_mps2),
        )
    if progress > config.taper_from_progress:
        r = (progress - config.taper_from_progress) / (1.0 - config.taper_from_progress)
        weight *= 1.0 - smoothstep(r)
        if weight <= 0.0:
            return 1.0, alpha
    if config.lead_gate:
        if callable(lead_m):
            lead_m = lead_m()
        if lead_m < 0.0:
            if lead_m <= -config.lag_tolerance_m:
                return 1.0, alpha
            weight *= 1.0 + lead_m / config.lag_tolerance_m
    if callable(com_velocity):
        com_velocity = com_velocity()
    ratio = (ratio_of or _RATIOS.get(config.law, tangent_ratio))(
        config, com_velocity, omega_f, tangent
    )
    return 1.0 + weight * (min(config.psi_dot_upper, max(1.0, ratio)) - 1.0), alpha


def tangent_ratio(
    config: AdvancementConfig, com_velocity: np.ndarray, omega_f: np.ndarray, tangent: np.ndarray
) -> float:
    """The paper's proposition: the CoM's speed along the path tangent, in psi units."""
    return float(com_velocity @ tangent) / (float(tangent @ tangent) + config.eps)


def interaction_ratio(
    config: AdvancementConfig, com_velocity: np.ndarray, omega_f: np.ndarray, tangent: np.ndarray
) -> float:
    """The authors' code: the same ratio measured along Omega f."""
    along = float(tangent @ omega_f)
    return float(com_velocity @ omega_f) * along / (along * along + config.eps)


_RATIOS = {"tangent": tangent_ratio, "interaction": interaction_ratio}


class LawInputs:
    """What an advancement law reads, in the world frame W (x forward, z up), SI units.
    Each value is read from the diagram the first time the law asks for it (a law that
    reads little costs little).

    time_s            the simulated time, s
    psi, psi_dot      the free parameter and its rate now (psi = t while nobody helps)
    x_d_W             the CoM reference x_d(psi), m (3,)
    tangent_W         the path's tangent d x_d / d psi, m (3,): the direction help counts along
    progress          how far along its segment the reference is, 0-1
    state             the stand-up state, 1 seated ... 4 standing
    com_W             the CoM, m (3,)
    com_velocity_W    its velocity, m/s (3,)
    hand_wrenches_W   the hands' measured wrenches (12,): [torque_l, force_l, torque_r,
                      force_r], N m and N, as the wrist F/T sensors give them
    omega_f_W         the CoM acceleration those wrenches cause, m/s^2 (3,) ([tirupachuri2019])
    alpha             omega_f along the path's unit tangent, m/s^2 (the paper's helpfulness)
    lead_m            how far the CoM is ahead of its reference along the path, m
    config            the scenario's advancement section (AdvancementConfig)
    """

    __slots__ = ("config", "time_s", "_read", "_values")

    def __init__(self, config: AdvancementConfig, time_s: float, read: Callable[[str], Any]):
        """read(name): the value of input name (a LawInputs field), called at most once."""
        self.config = config
        self.time_s = time_s
        self._read = read
        self._values: dict[str, Any] = {}

    @classmethod
    def of(cls, config: AdvancementConfig, time_s: float = 0.0, **values: Any) -> LawInputs:
        """Inputs from plain values (tests, a law tried by hand); alpha and lead_m are
        worked out from the others where not given."""
        data = {k: np.asarray(v, dtype=float) if np.ndim(v) else v for k, v in values.items()}
        inputs = cls(config, time_s, lambda name: inputs.derived(name))
        inputs._values.update(data)
        return inputs

    def _get(self, name: str) -> Any:
        value = self._values.get(name, _MISSING)
        if value is _MISSING:
            value = self._values[name] = self._read(name)
        return value

    def __getattr__(self, name: str) -> Any:
        if name in FIELDS:
            return self._get(name)
        raise AttributeError(f"LawInputs has no '{name}'; it has: {', '.join(FIELDS)}")

    def derived(self, name: str) -> Any:
        """alpha and lead_m from the other inputs (what read gives for them)."""
        if name == "alpha":
            return helpfulness(self.tangent_W, self.omega_f_W, self.config.eps)
        if name == "lead_m":
            return lead(self.com_W, self.x_d_W, self.tangent_W)
        raise KeyError(f"LawInputs: '{name}' was not given")


FIELDS = (
    "psi",
    "psi_dot",
    "x_d_W",
    "tangent_W",
    "progress",
    "state",
    "com_W",
    "com_velocity_W",
    "hand_wrenches_W",
    "omega_f_W",
    "alpha",
    "lead_m",
)


def tangent_law(inputs: LawInputs) -> float:
    """The paper's proposition: psi_dot = clip(xdot . t / (|t|^2 + eps), 1, upper), gated."""
    return _gated(inputs, tangent_ratio)


def interaction_law(inputs: LawInputs) -> float:
    """The authors' code: the same ratio measured along Omega f, gated."""
    return _gated(inputs, interaction_ratio)


def _gated(inputs: LawInputs, ratio_of: Callable) -> float:
    """psi_dot_law's graded gates (advancement.py) around ratio_of, reading each input only
    where the gates need it."""
    return psi_dot_law(
        inputs.config,
        lambda: inputs.com_velocity_W,
        inputs.omega_f_W,
        inputs.tangent_W,
        lambda: inputs.lead_m,
        lambda: inputs.progress,
        ratio_of=ratio_of,
    )[0]


def check_law(obj: Any) -> str | None:
    """What is wrong with obj as a law (None: nothing): callable with one argument."""
    return call_problem(obj, 1, "law(inputs) -> float, inputs a drake_standup.plugins.LawInputs")


def checked_rate(value: Any, spec: str, time_s: float) -> float:
    """value as psi_dot: one finite number >= 0; else a PluginError naming the law."""
    if np.shape(value) != () or isinstance(value, (str, bytes)):
        what = f"shape {np.shape(value)}" if not isinstance(value, (str, bytes)) else "a string"
        raise PluginError(
            f"advancement.law: '{spec}' returned {what} at t = {time_s:.3f} s; accepted: one "
            "number, psi_dot"
        )
    try:
        rate = float(value)
    except (TypeError, ValueError):
        rate = math.nan
    if not math.isfinite(rate) or rate < 0.0:
        raise PluginError(
            f"advancement.law: '{spec}' returned {value!r} at t = {time_s:.3f} s; accepted: a "
            "finite psi_dot >= 0"
        )
    return rate
