"""Scenario: every number a run uses, and the one place that checks a run's inputs.

scenario.py    the typed sections of a scenario (robot, human, advancement, standup, ...)
controller.py  the whole-body controller's gains, weights and limits
loading.py     a YAML file and overrides into those dataclasses (Drake's yaml_load_typed)
rules.py       the bounds and accepted values of every field, the keys naming joints, the
               checks across fields, and validate: the one check of a scenario
inputs.py      the files, folders and robot names a user gives (read_text_file, the chair
               file, the robot model's frames, check_output_dir)
recording.py   human.recorded: the recorded helper's settings, its CSV file read and checked
errors.py      ScenarioError: one line naming the key or file
"""

from drake_standup.config.chair import ChairConfig, InitialPose, chair_file
from drake_standup.config.controller import MODEL_LIBRARIES, QP_SOLVERS, ControllerConfig
from drake_standup.config.errors import ScenarioError
from drake_standup.config.hardware import HARDWARE, HardwareConfig
from drake_standup.config.inputs import check_output_dir, read_text_file
from drake_standup.config.loading import (
    apply_overrides,
    expand_key_path,
    load_scenario,
    parse_scenario,
)
from drake_standup.config.rules import (
    JOINT_TABLES,
    RULES,
    Range,
    is_whole_multiple,
    validate,
    with_hardware,
)
from drake_standup.config.scenario import (
    DEFAULT_SCENARIO,
    EFFORT_LIMIT_NM,
    RESPONSES,
    SCENARIO_DIR,
    AdvancementConfig,
    ComplianceConfig,
    FallConfig,
    HumanConfig,
    PerturbationConfig,
    Pull,
    Push,
    ReactiveHumanConfig,
    RobotConfig,
    Scenario,
    SeatHoldConfig,
    StandupConfig,
    VisualizationConfig,
)

__all__ = [
    "DEFAULT_SCENARIO",
    "EFFORT_LIMIT_NM",
    "JOINT_TABLES",
    "MODEL_LIBRARIES",
    "QP_SOLVERS",
    "RULES",
    "SCENARIO_DIR",
    "AdvancementConfig",
    "RESPONSES",
    "ChairConfig",
    "ComplianceConfig",
    "ControllerConfig",
    "FallConfig",
    "HardwareConfig",
    "HARDWARE",
    "HumanConfig",
    "InitialPose",
    "PerturbationConfig",
    "Pull",
    "Push",
    "Range",
    "ReactiveHumanConfig",
    "RobotConfig",
    "Scenario",
    "ScenarioError",
    "SeatHoldConfig",
    "StandupConfig",
    "VisualizationConfig",
    "apply_overrides",
    "chair_file",
    "check_output_dir",
    "expand_key_path",
    "load_scenario",
    "parse_scenario",
    "read_text_file",
    "validate",
    "with_hardware",
    "is_whole_multiple",
]
