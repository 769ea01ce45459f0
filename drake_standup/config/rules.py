"""Bounds and accepted values of every field (RULES), the keys that name joints of the
robot model (JOINT_TABLES), and the checks across fields.

validate(scenario) is the one check of a scenario, of what the types alone cannot say:
RULES, the checks across fields, the robot model's names and the chair file
(config/inputs.py); every message is one line naming the key path and what it accepts.
"""

import copy
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass

import yaml
from pydrake.common.yaml import yaml_dump_typed
from pydrake.systems.analysis import GetIntegrationSchemes

from drake_standup.config.body import TONES
from drake_standup.config.chair import SEAT_BOARD_M, ChairConfig
from drake_standup.config.controller import MODEL_LIBRARIES, MOMENTUM_INTEGRAL_AXES, QP_SOLVERS
from drake_standup.config.cycle import SIT_DOWN_TRIGGERS, check_sit_down
from drake_standup.config.errors import ScenarioError
from drake_standup.config.hardware import HARDWARE
from drake_standup.config.inputs import ModelNames, check_chair_file, check_robot_model
from drake_standup.config.phases import (
    PHASES,
    RETURNS_TO,
    SEAT_HOLDS,
    SEAT_PADS,
    WHEN_HINDERED,
)
from drake_standup.config.recording import FRAMES, load_recording
from drake_standup.config.scenario import REFLECTED_INERTIA, Scenario


@dataclass(frozen=True)
class Range:
    """Numbers from low to high; an open end excluded."""

    low: float = 0.0
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    text: str = ""  # what an error says is accepted, if more than the bounds
    integer: bool = False  # whole numbers only

    def accepts(self, x) -> bool:
        if self.integer and float(x) != int(x):
            return False
        above = x > self.low if self.low_open else x >= self.low
        return above and (x < self.high if self.high_open else x <= self.high)

    def __str__(self) -> str:
        if self.text:
            return self.text
        if self.high == math.inf:
            return f"a number {'>' if self.low_open else '>='} {self.low:g}"
        left, right = "(["[not self.low_open], ")]"[not self.high_open]
        return f"a number in {left}{self.low:g}, {self.high:g}{right}"


INTERVAL = "interval"  # two numbers [low, high] with low < high
POSITIVE, NON_NEGATIVE, FRACTION = Range(low_open=True), Range(), Range(high=1.0)
# The controller acts at the plant's steps (controller_period_s is a whole multiple of
# plant.time_step), and the integrator's steps and the convergence study follow them.
PLANT_STEP = Range(
    low_open=True,
    text="a discrete plant's step, a number > 0 s (0, a continuous plant, cannot run the "
    "controller: it acts at the plant's steps)",
)

# What the values at some key paths accept: a Range (of each entry of a list too), a length
# n (a list of n entries), INTERVAL or a tuple of accepted strings. The key paths are
# patterns separated by spaces, '*' standing for any part of a name and '[*]' for any list
# index. Checked in this order (tests/config/test_config.py: every pattern names a key).
RULES: list[tuple[Range | int | str | tuple[str, ...], str]] = [
    (FRAMES, "human.recorded.frame"),
    (TONES, "human.body.tone"),
    # An adult the anthropometric table scales to (issue 32). m, kg.
    (Range(low=1.5, high=1.95), "human.body.height_m"),
    (Range(low=45.0, high=110.0), "human.body.mass_kg"),
    (("left", "right"), "human.pulls[*].hand"),
    (("velocity", "path"), "human.reactive.guide"),
    (REFLECTED_INERTIA, "robot.reflected_inertia"),
    (HARDWARE, "robot.hardware"),
    # The robot's own rate: 25-1000 Hz (YARP ran the authors' at 100 Hz). Hz.
    (Range(low=25.0, high=1000.0), "hardware.rate_hz"),
    (Range(low=1.0, high=3.0, text="1, 2 or 3", integer=True), "hardware.delay_ticks"),
    (Range(low=0.0, high=5.0), "hardware.*_scale"),
    (PLANT_STEP, "hardware.plant_time_step_s"),
    (("hands", "time"), "standup.trigger"),
    (SIT_DOWN_TRIGGERS, "standup.sit_down.trigger"),
    (
        Range(low=1.0, high=100.0, text="a whole number 1-100", integer=True),
        "standup.sit_down.times",
    ),
    (RETURNS_TO, "phases.*.returns_to"),
    (PHASES, "phases.*.posture_as"),
    (SEAT_PADS, "phases.*.load[*]"),
    (SEAT_HOLDS, "phases.*.seat_hold phases.*.seat_hold_sat_back"),
    (SEAT_PADS, "phases.*.unload[*]"),
    (WHEN_HINDERED, "phases.*.when_hindered"),
    (QP_SOLVERS, "controller.qp_solver"),
    (MOMENTUM_INTEGRAL_AXES, "controller.angular_momentum_integral_axes"),
    (MODEL_LIBRARIES, "controller.model_library"),
    (tuple(GetIntegrationSchemes()), "simulator.integration_scheme"),
    (("point", "hydroelastic", "hydroelastic_with_fallback"), "plant.contact_model"),
    (("", "tamsi", "sap", "similar", "lagged"), "plant.discrete_contact_approximation"),
    (("triangle", "polygon"), "plant.contact_surface_representation"),
    (
        POSITIVE,
        "duration_s log_period_s controller_period_s simulator.max_step_size "
        "robot.effort_limit_Nm robot.visual_max_faces visualization.*period_s "
        "human.pulls[*].duration_s human.reactive.duration_s human.reactive.force_cap_N "
        "human.body.grip_* "
        "human.reactive.pace_mps advancement.eps advancement.psi_ddot_filter_s "
        "advancement.full_help_pull_N "
        "phases.*.segment_psi phases.*.com_height_m standup.update_period_s "
        "standup.standing_pull_usage_limit standup.gentle_pull_force_N "
        "controller.momentum_weight controller.*_time_constant_s "
        "controller.joint_limit_horizon_s controller.joint_braking_rad_per_s2 "
        "controller.arm_speed_limit_rad_per_s "
        "controller.*friction_coefficient* "
        "controller.*_max_normal_force_N controller.torque_limit_Nm controller.help_* "
        "controller.mass_scale_bounds compliance.virtual_mass_kg compliance.stiffness_N_per_m "
        "fall.max_com_horizontal_m perturbation.pushes[*].duration_s perturbation.*_scale "
        "perturbation.hand_wrench_noise_period_s plant.penetration_allowance "
        "plant.stiction_tolerance simulator.accuracy chair.seat_height_m chair.cushion.* "
        "chair.friction",
    ),
    (
        NON_NEGATIVE,
        "human.pulls[*].start_s human.pulls[*].ramp_s standup.gentle_pull_time_s "
        "human.reactive.start_s human.reactive.ramp_s human.reactive.stiffness_N_per_m "
        "human.reactive.reaction_time_s "
        "human.reactive.damping_Ns_per_m human.reactive.travel_m "
        "human.reactive.path_corner_radius_m human.reactive.lead_min_m "
        "human.reactive.ease_com_rise_m advancement.alpha_*_mps2 advancement.lag_tolerance_m "
        "standup.*_s standup.*_N standup.sit_down.stand_s standup.sit_down.seated_s "
        "standup.sit_down.at_s standup.sit_down.touch_gap_m "
        "standup.sit_down.*_N phases.*.unload_s phases.*.load_s phases.*.sink_m "
        "phases.*.trunk_leads_by phases.*.exit.* phases.*.com_kp_per_s2 "
        "controller.*_weight controller.*_weight_s controller.contact_velocity_gain_per_s "
        "controller.*weight_by_joint.* controller.*_kp_* controller.*_kd_* controller.*_ki_* "
        "controller.*_damping_ratio controller.posture_limit_margin_rad controller.*_N "
        "compliance.damping_ratio compliance.max_offset_m "
        "controller.lean_max_* controller.mass_estimation_filter_s seat_hold.* "
        "fall.max_qp_failure_streak_s "
        "perturbation.pushes[*].start_s perturbation.hand_wrench_noise_N "
        "perturbation.noise_seed hardware.seed plant.sap_near_rigid_threshold "
        "simulator.target_realtime_rate "
        "simulator.start_time fall.min_root_height_m",
    ),
    (PLANT_STEP, "plant.time_step"),
    (Range(low=1.0, high=2.0, text="1 or 2", integer=True), "controller.posture_filter_stages"),
    (Range(high=3.0), "controller.carried_limb_weight_exponent"),
    # How far the hips sit behind the seat's edge, the feet stand in front of it: within
    # a leg's length. m.
    (
        Range(low=-0.2, high=0.5),
        "initial.hips_behind_seat_edge_m initial.feet_ahead_of_seat_edge_m",
    ),
    (Range(low=1.0), "advancement.psi_dot_upper"),
    # Where the seat's release waits for the CoM, about the thigh pads: within a thigh's
    # length of them. m.
    (Range(low=-0.3, high=0.3), "phases.*.unload_when phases.*.com_x_over_soles_m"),
    # An absolute end x of the CoM: within a metre of the world's origin (the chair's). m.
    (Range(low=-1.0, high=1.0), "phases.*.com_x_m"),
    (Range(high=1.0, high_open=True), "advancement.taper_from_progress"),
    (Range(high=1.0, high_open=True), "controller.stance_from_progress"),
    (
        FRACTION,
        "standup.guard_off_ratio standup.reseat_above_thigh_load "
        "controller.stance_vertical_weight_scale controller.posture_led_com_weight_scale "
        "controller.posture_led_fade_progress",
    ),
    (2, "human.reactive.path_xz_m[*]"),
    (
        3,
        "initial.base_* visualization.*_xyz_m chair.xyz_m human.pulls[*].force_N "
        "human.reactive.target_velocity_mps phases.*.com_delta_m phases.*.com_kp_per_s2 "
        "perturbation.pushes[*].force_N compliance.max_offset_m",
    ),
    (
        INTERVAL,
        "human.reactive.ease_com_rise_m controller.*_cop_*_m controller.mass_scale_bounds",
    ),
]


def _pattern(rule: str) -> re.Pattern:
    text = re.escape(rule).replace(r"\[\*\]", r"\[\d+\]").replace(r"\*", r"[^.\[]*")
    return re.compile(text)


_COMPILED = [(_pattern(rule), accepted) for accepted, rules in RULES for rule in rules.split()]

# Key paths (patterns as in RULES) whose mapping keys, or list entries, name joints of
# robot.model: checked against the joints of its URDF, so that no unknown name reaches
# the plant.
JOINT_TABLES = (
    "initial.joints_rad",
    "controller.posture_weight_by_joint",
    "controller.stance_posture_weight_by_joint",
    "controller.stance_arm_weight_by_joint",
    "phases.*.posture_rad",
    "controller.seat_hinge_joints",
)
_JOINT_TABLES = [_pattern(table) for table in JOINT_TABLES]


def _nodes(data, steps: tuple = (), leaves: bool = False) -> Iterator[tuple[list, object]]:
    """(key path steps, value) of every node of plain data (leaves: of every leaf only;
    an empty list is a leaf)."""
    kind = dict if isinstance(data, dict) else list if isinstance(data, list) else None
    items = list(data.items() if kind is dict else enumerate(data) if kind else ())
    if steps and not (leaves and items):
        yield list(steps), data
    for key, value in items:
        yield from _nodes(value, (*steps, key), leaves)


def _format(steps: list[str | int]) -> str:
    return "".join(f"[{s}]" if isinstance(s, int) else f".{s}" for s in steps)[1:]


def _check(key: str, value, accepted) -> None:
    if value is None:  # an optional value left out
        return
    if isinstance(value, float) and not math.isfinite(value):
        raise ScenarioError(f"{key}: {value} is not finite; accepted: a finite number")
    if isinstance(value, list) and isinstance(accepted, Range | tuple):
        for i, item in enumerate(value):
            _check(f"{key}[{i}]", item, accepted)
    elif isinstance(accepted, tuple):
        if value not in accepted:
            raise ScenarioError(f"{key}: '{value}' unknown; accepted: {' | '.join(accepted)}")
    elif isinstance(accepted, int):
        if len(value) != accepted:
            raise ScenarioError(
                f"{key}: {len(value)} values; accepted: a list of {accepted} numbers"
            )
    elif accepted == INTERVAL:
        if len(value) != 2 or not value[0] < value[1]:
            raise ScenarioError(f"{key}: {value}; accepted: [low, high] with low < high")
    elif accepted is not None and not accepted.accepts(value):
        raise ScenarioError(f"{key}: {value}; accepted: {accepted}")


def validate(scenario: Scenario) -> Scenario:
    """The one check of a scenario before anything simulates: RULES, the checks across
    fields, the robot model's names (its frames, and every joint and body the scenario
    names), the chair file and the recorded helper's file. Raises ScenarioError (one
    line); returns scenario."""
    data = yaml.safe_load(yaml_dump_typed(scenario))
    _check_rules(data)
    _check_across_fields(scenario)
    _check_names(scenario, data, check_robot_model(scenario.robot.model))
    if scenario.chair.file:
        check_chair_file(scenario.chair.file)
    _check_plugins(scenario)
    if scenario.human.mode == "recorded":
        load_recording(scenario.human.recorded.file)
    if scenario.controller.model_library == "pinocchio":
        import importlib.util

        if importlib.util.find_spec("pinocchio") is None:
            raise ScenarioError(
                "controller.model_library: 'pinocchio' needs the optional package "
                "(pip install 'drake_standup[pinocchio]'); accepted: drake"
            )
    return scenario


def _check_plugins(scenario: Scenario) -> None:
    """advancement.law, human.mode, response and chair.kind name plug-ins that import and
    fit their interface (config/plugins.py: a registered name, module:attribute or an entry
    point); the chair is made and its model checked (config/chair_kind.py)."""
    from drake_standup.config.chair_kind import make_chair
    from drake_standup.config.plugins import resolve

    resolve("laws", scenario.advancement.law)
    resolve("helpers", scenario.human.mode)
    resolve("responses", scenario.response)
    make_chair(scenario.chair)


def _check_rules(data: dict) -> None:
    """Every value of data (the scenario as plain YAML data) against RULES."""
    for steps, value in _nodes(data):
        key = _format(steps)
        _check(key, value, None)
        for pattern, accepted in _COMPILED:
            if pattern.fullmatch(key):
                _check(key, value, accepted)


def _check_names(scenario: Scenario, data: dict, names: ModelNames) -> None:
    """The joints of JOINT_TABLES and the pushed bodies vs the robot model's."""
    model = scenario.robot.model
    for steps, table in _nodes(data):
        key = _format(steps)
        if any(pattern.fullmatch(key) for pattern in _JOINT_TABLES):
            unknown = sorted(set(table) - set(names.joints))
            if unknown:
                raise ScenarioError(
                    f"{key}: unknown joint(s) {', '.join(unknown)}; accepted: the joints of "
                    f"{model}: {', '.join(names.joints)}"
                )
    reduced = scenario.robot.reduced
    bodies = names.bodies(reduced)
    for i, push in enumerate(scenario.perturbation.pushes):
        if push.body in bodies:
            continue
        what = "unknown"
        if push.body in names.links:  # a massless link of the reduced model
            what = "is a frame of the reduced model (robot.reduced: true), not a body"
        raise ScenarioError(
            f"perturbation.pushes[{i}].body: '{push.body}' {what}; accepted: the bodies of "
            f"{model}{' reduced' if reduced else ''}: {', '.join(bodies)}"
        )


def is_whole_multiple(period: float, step: float) -> bool:
    """period is step times a whole number >= 1 (to round-off): a controller period the
    plant's step grid carries (the plant reads its actuation input only at its steps)."""
    ratio = period / step
    return ratio >= 1.0 - 1e-9 and abs(ratio - round(ratio)) <= 1e-6


def _check_across_fields(scenario: Scenario) -> None:
    """What one value says of another: the controller's period on the plant's step grid,
    the pulls' ramps, the reactive helper's path and leads."""
    # The controller's period is a whole multiple of the plant's step: the plant reads its
    # actuation input only at its own steps, so a faster controller is wasted work and a
    # period off the plant's grid jitters.
    step, period = scenario.plant.time_step, scenario.controller_period_s
    if scenario.robot.hardware == "icub":
        _check_hardware_rate(scenario)
    if not is_whole_multiple(period, step):
        raise ScenarioError(
            f"controller_period_s: {period}; accepted: a whole multiple of plant.time_step "
            f"({step}), e.g. {step} or {2 * step}"
        )
    _check_cushion(scenario.chair)
    check_sit_down(scenario)
    for i, pull in enumerate(scenario.human.pulls):
        if 2 * pull.ramp_s > pull.duration_s:
            raise ScenarioError(
                f"human.pulls[{i}].ramp_s: {pull.ramp_s}; accepted: at most half of "
                f"duration_s ({pull.duration_s / 2})"
            )
    reactive = scenario.human.reactive
    if not reactive.path_xz_m:
        raise ScenarioError(
            "human.reactive.path_xz_m: empty; accepted: a list of [forward, up] waypoints, m"
        )
    previous = [0.0, 0.0]
    for i, point in enumerate(reactive.path_xz_m):
        if math.dist(point, previous) < 1e-3:
            raise ScenarioError(
                f"human.reactive.path_xz_m[{i}]: {point}; accepted: a waypoint at least 1 mm "
                f"from the one before ({previous}; the path starts at [0, 0])"
            )
        previous = point
    if not reactive.lead_max_m >= reactive.lead_min_m:
        raise ScenarioError(
            f"human.reactive.lead_max_m: {reactive.lead_max_m}; accepted: a number >= "
            f"lead_min_m ({reactive.lead_min_m})"
        )


def _check_hardware_rate(scenario: Scenario) -> None:
    """Under robot.hardware: icub the robot's rate and plant step are hardware's
    (with_hardware sets them when a scenario is loaded)."""
    hardware = scenario.hardware
    for key, value, wanted in (
        ("controller_period_s", scenario.controller_period_s, 1.0 / hardware.rate_hz),
        ("plant.time_step", scenario.plant.time_step, hardware.plant_time_step_s),
    ):
        if abs(value - wanted) > 1e-12:
            raise ScenarioError(
                f"{key}: {value}; accepted: {wanted:g} under robot.hardware: icub (set "
                "hardware.rate_hz and hardware.plant_time_step_s instead)"
            )


def with_hardware(scenario: Scenario) -> Scenario:
    """scenario with its rate and plant step the hardware's under robot.hardware: icub
    (controller_period_s = 1 / hardware.rate_hz, plant.time_step =
    hardware.plant_time_step_s); under ideal, scenario itself."""
    if scenario.robot.hardware != "icub":
        return scenario
    scenario = copy.deepcopy(scenario)
    scenario.controller_period_s = 1.0 / scenario.hardware.rate_hz
    scenario.plant.time_step = scenario.hardware.plant_time_step_s
    return scenario


def _check_cushion(chair: ChairConfig) -> None:
    """A cushion lies on the seat board (SEAT_BOARD_M), within the seat's height."""
    if chair.cushion is None or chair.file:
        return
    room = chair.seat_height_m - SEAT_BOARD_M
    if not chair.cushion.thickness_m < room:
        raise ScenarioError(
            f"chair.cushion.thickness_m: {chair.cushion.thickness_m:g}; accepted: a number "
            f"in (0, {room:g}) m, under the seat's height ({chair.seat_height_m:g} m) less "
            f"its board ({SEAT_BOARD_M:g} m)"
        )
