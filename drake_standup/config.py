"""Scenario: every number a run uses, with its unit and where it comes from.

A scenario is a YAML file loaded into the typed dataclasses below with Drake's
yaml_load_typed, so an unknown key or a wrong type is an error rather than a
silently ignored typo. Defaults live here and nowhere else; the YAML files in
scenarios/ override what they name.
"""


import math
from dataclasses import dataclass, field
from pathlib import Path

from pydrake.common.yaml import yaml_load_typed
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig

REPO_ROOT = Path(__file__).resolve().parent.parent
SCENARIO_DIR = REPO_ROOT / "scenarios"
DEFAULT_SCENARIO = SCENARIO_DIR / "seated.yaml"


class ScenarioError(ValueError):
    """A scenario that cannot run; the message is one line naming the key."""


def _seated_joints() -> dict[str, float]:
    # SPEC section 3 (authors' seated pose), with the feasibility probe's knee
    # (-1.7365 rad) and the ankle pitch that puts the soles flat on the floor
    # for that knee (SPEC section 7: the window for feet on the floor is narrow).
    legs = {
        "hip_pitch": 1.5908,
        "hip_roll": 0.2141,
        "hip_yaw": 0.0,
        "knee": -1.7365,
        "ankle_pitch": -0.1452,
        "ankle_roll": 0.0,
    }
    arms = {
        "shoulder_pitch": -0.6981,
        "shoulder_roll": 0.2094,
        "shoulder_yaw": 1.3963,
        "elbow": 0.5585,
    }
    joints = {f"{side}_{name}": q for side in "lr" for name, q in {**legs, **arms}.items()}
    joints.update(torso_pitch=0.0, torso_roll=0.0, torso_yaw=0.0)
    return joints


@dataclass
class RobotConfig:
    # Any name from icub_models.get_robot_names().
    model: str = "iCubGazeboV2_5"
    # Replace massless sensor/skin links by frames (SPEC 5: 3-10x faster terms).
    reduced: bool = True
    # Torque saturation of the authors' controller (SPEC 3), N m.
    effort_limit_Nm: float = 60.0
    # Triangles per visual mesh after decimation. Meshcat's HTML is 2.2 MB of
    # viewer, ~0.15 MB per simulated second of animation, plus the meshes: at
    # 1000 faces they take ~1.3 MB and a 15 s recording stays under 8 MB.
    visual_max_faces: int = 1000


@dataclass
class InitialPose:
    """Seated pose: floating base and joint angles by joint name."""

    # Base over the chair, height so that the sole pads touch the floor. m.
    base_xyz_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.39])
    # The iCub's root_link x axis points backwards: yaw pi faces the robot to +x.
    base_rpy_rad: list[float] = field(default_factory=lambda: [0.0, 0.0, math.pi])
    joints_rad: dict[str, float] = field(default_factory=_seated_joints)


@dataclass
class ChairConfig:
    # models/chair.sdf: seat top at 0.2195 m, where the seated pads rest.
    file: str = "models/chair.sdf"
    # Where the chair's model frame (floor, below the seat's front edge) stands.
    # The front edge sits behind the knees (x ~ 0.22 m seated). m.
    xyz_m: list[float] = field(default_factory=lambda: [0.16, 0.0, 0.0])


@dataclass
class SeatHoldConfig:
    """Joint-space hold: Drake's implicit joint PD plus gravity feed-forward.

    Holds the seated pose until the whole-body controller exists; also the
    near-zero-cost controller of the plant-only benchmark.
    """

    kp_Nm_per_rad: float = 100.0
    kd_Nms_per_rad: float = 4.0


@dataclass
class FallConfig:
    """Bounds that end a run early as a fall (success false, reason recorded)."""

    min_root_height_m: float = 0.25
    max_com_horizontal_m: float = 0.5


@dataclass
class VisualizationConfig:
    # Meshcat recording frame period; 30 fps keeps a 15 s HTML small. s.
    publish_period_s: float = 1.0 / 30.0
    # Camera position and target that frame the robot on its chair. m.
    camera_xyz_m: list[float] = field(default_factory=lambda: [0.85, -0.8, 0.65])
    target_xyz_m: list[float] = field(default_factory=lambda: [0.1, 0.0, 0.35])
    show_contact_forces: bool = True
    # Contact force arrows at 10 Hz: enough to read, and they cost the HTML
    # ~0.13 MB per simulated second at 30 Hz. s.
    contact_publish_period_s: float = 0.1


@dataclass
class Scenario:
    robot: RobotConfig = field(default_factory=RobotConfig)
    # Simulated time. s.
    duration_s: float = 5.0
    # Drake's own plant settings; 1 ms discrete 'similar' (SPEC 5: 'lagged' and
    # 'similar' ran 1.4-2.2x faster than real time, SAP 0.6x).
    plant: MultibodyPlantConfig = field(
        default_factory=lambda: MultibodyPlantConfig(
            time_step=0.001,
            discrete_contact_approximation="similar",
            contact_model="hydroelastic_with_fallback",
        )
    )
    # Drake's simulator settings; the plant is discrete, so the integrator only
    # matters for continuous states of our own systems. Run as fast as possible.
    simulator: SimulatorConfig = field(
        default_factory=lambda: SimulatorConfig(target_realtime_rate=0.0)
    )
    initial: InitialPose = field(default_factory=InitialPose)
    chair: ChairConfig = field(default_factory=ChairConfig)
    seat_hold: SeatHoldConfig = field(default_factory=SeatHoldConfig)
    fall: FallConfig = field(default_factory=FallConfig)
    visualization: VisualizationConfig = field(default_factory=VisualizationConfig)
    # Period of the signal loggers used by metrics and figures. s.
    log_period_s: float = 0.01


def load_scenario(path: str | Path | None = None) -> Scenario:
    """Loads and validates a scenario file; raises ScenarioError (one line)."""
    path = Path(path) if path is not None else DEFAULT_SCENARIO
    if not path.is_file():
        raise ScenarioError(
            f"scenario: file '{path}' not found; accepted: a YAML file, e.g. "
            f"{', '.join(str(p.relative_to(REPO_ROOT)) for p in sorted(SCENARIO_DIR.glob('*.yaml')))}"
        )
    try:
        scenario = yaml_load_typed(schema=Scenario, filename=str(path))
    except RuntimeError as err:
        raise ScenarioError(f"scenario {path}: {_first_line(err)}") from None
    validate(scenario)
    return scenario


def _first_line(err: Exception) -> str:
    return " ".join(str(err).split())


def _check_finite(prefix: str, obj) -> None:
    if isinstance(obj, float):
        if not math.isfinite(obj):
            raise ScenarioError(f"{prefix}: {obj} is not finite; accepted: a finite number")
    elif isinstance(obj, (list, tuple)):
        for i, item in enumerate(obj):
            _check_finite(f"{prefix}[{i}]", item)
    elif isinstance(obj, dict):
        for key, item in obj.items():
            _check_finite(f"{prefix}.{key}", item)
    elif hasattr(obj, "__dataclass_fields__"):
        for name in obj.__dataclass_fields__:
            _check_finite(f"{prefix}.{name}" if prefix else name, getattr(obj, name))


def validate(scenario: Scenario) -> None:
    """Checks what the types alone cannot; raises ScenarioError (one line)."""
    from drake_standup.robot import robot_names

    _check_finite("", scenario)
    if scenario.robot.model not in robot_names():
        raise ScenarioError(
            f"robot.model: unknown model '{scenario.robot.model}'; "
            f"accepted: {', '.join(robot_names())}"
        )
    _positive("duration_s", scenario.duration_s, allow_zero=False)
    _positive("plant.time_step", scenario.plant.time_step, allow_zero=True)
    _positive("robot.effort_limit_Nm", scenario.robot.effort_limit_Nm)
    _positive("log_period_s", scenario.log_period_s, allow_zero=False)
    _positive("visualization.publish_period_s", scenario.visualization.publish_period_s)
    for key, n in (("initial.base_xyz_m", 3), ("initial.base_rpy_rad", 3)):
        value = getattr(scenario.initial, key.split(".")[1])
        if len(value) != n:
            raise ScenarioError(f"{key}: {len(value)} values; accepted: a list of {n}")


def _positive(key: str, value: float, allow_zero: bool = False) -> None:
    if value < 0 or (value == 0 and not allow_zero):
        accepted = "a number >= 0" if allow_zero else "a number > 0"
        raise ScenarioError(f"{key}: {value}; accepted: {accepted}")
