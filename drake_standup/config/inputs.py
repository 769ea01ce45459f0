"""The files, folders and robot names a user gives: each one checked before anything
simulates.

Every failure is a ScenarioError: one line naming the option or key, the value, and what
it accepts. rules.validate calls the checks of a scenario's own keys (chair.file: an SDF,
or a mesh read by config/chair_mesh.py; the robot model's frames, joints and bodies); the
entry points those of their options (--scenario and a sweep file through read_text_file,
--out through check_output_dir). load_scenario sets a mesh chair's seat height from the
mesh (config/chair_kind.py with_chair_seat).
"""

import contextlib
import functools
import logging
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import icub_models
import yaml
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config.chair import chair_file
from drake_standup.config.chair_mesh import (
    MIN_SEAT_DEPTH_M,
    MIN_SEAT_WIDTH_M,
    SEAT_HEIGHTS_M,
    ChairMesh,
    MeshError,
    is_mesh,
    read_chair_mesh,
)
from drake_standup.config.errors import ScenarioError
from drake_standup.config.resources import model_file

# --- Files and folders -------------------------------------------------------------------


def read_file_bytes(path: Path | str, key: str, accepted: str) -> bytes:
    """The bytes of the file at path; an error naming key if the file is missing, a
    folder or unreadable. accepted: what key accepts, for the message."""
    path = Path(path)
    if path.is_dir():
        raise ScenarioError(f"{key}: '{path}' is a folder; accepted: {accepted}")
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(f"{key}: file '{path}' not found; accepted: {accepted}") from None
    except OSError as err:
        raise ScenarioError(
            f"{key}: '{path}' cannot be read ({err.strerror}); accepted: a file this user can read"
        ) from None


def read_text_file(path: Path | str, key: str, accepted: str) -> str:
    """The text of the file at path (UTF-8, with or without a byte order mark); an error
    naming key if the file is missing, a folder, unreadable or not UTF-8 text. accepted:
    what key accepts, for the message."""
    path = Path(path)
    data = read_file_bytes(path, key, accepted)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = err.object[: err.start].count(b"\n") + 1
        raise ScenarioError(
            f"{key}: '{path}' is not UTF-8 text (byte 0x{err.object[err.start]:02x} on line "
            f"{line}); accepted: a text file saved as UTF-8"
        ) from None


def check_output_dir(path: Path | str, key: str = "--out") -> Path:
    """The output folder, created if missing; an error if it cannot be one (a file is in
    the way, or the folder cannot be created)."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise ScenarioError(f"{key}: '{path}' is a file; accepted: a folder") from None
    except NotADirectoryError:
        raise ScenarioError(
            f"{key}: '{path}' lies under a file; accepted: a folder path whose parents are folders"
        ) from None
    except OSError as err:
        raise ScenarioError(
            f"{key}: '{path}' cannot be created ({err.strerror}); accepted: a writable folder"
        ) from None
    return path


# --- The chair: an SDF file the scene welds to the world at its frame 'chair', or a mesh --

CHAIR_FRAME = "chair"
CHAIR_FILES = (
    "an SDF, OBJ or STL file path (absolute or relative to the current directory), or "
    "models/chair.sdf or models/chair_mesh.obj"
)
CHAIR_CONTENT = (
    f"an SDF file of one model with a link or frame named '{CHAIR_FRAME}' (the scene welds "
    "it to the world), e.g. models/chair.sdf"
)
_LOW, _HIGH = SEAT_HEIGHTS_M
CHAIR_MESH_CONTENT = (
    "a closed OBJ or STL mesh (m, z up, x forward) with an upward horizontal seat "
    f"{_LOW:g}-{_HIGH:g} m above its lowest point, at least {MIN_SEAT_DEPTH_M:g} m deep and "
    f"{MIN_SEAT_WIDTH_M:g} m wide, e.g. models/chair_mesh.obj"
)


def check_chair_file(name: str) -> Path:
    """chair.file's path, checked: a UTF-8 SDF file that Drake parses into one model with
    a frame named 'chair' that can be welded to the world, as scene.add_scene does; or a
    chair mesh (chair_mesh)."""
    path = chair_file(name)
    if is_mesh(path):
        chair_mesh(name)
        return path
    read_text_file(path, "chair.file", CHAIR_FILES)
    stat = path.stat()
    problem = sdf_problem(str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    if problem:
        raise ScenarioError(f"chair.file: '{name}' {problem}; accepted: {CHAIR_CONTENT}")
    return path


def chair_mesh(name: str) -> ChairMesh:
    """chair.file (an .obj or .stl) read as a chair mesh, and its seat
    (config/chair_mesh.py); a ScenarioError (one line) if it cannot be one."""
    path = chair_file(name)
    data = read_file_bytes(path, "chair.file", CHAIR_FILES)
    try:
        return _read_mesh(data, path.suffix.lower())
    except MeshError as err:
        raise ScenarioError(f"chair.file: '{name}' {err}; accepted: {CHAIR_MESH_CONTENT}") from None


@functools.lru_cache(maxsize=8)
def _read_mesh(data: bytes, suffix: str) -> ChairMesh:
    """Cached per file content: a sweep validates every run, and the scene reads it again."""
    return read_chair_mesh(data, suffix)


def add_sdf(parser: Parser, path: Path) -> list[ModelInstanceIndex]:
    """Adds the models of an SDF file. One that names no other file (no <uri>:
    meshes, includes) is parsed from its text: libsdformat loads its whole
    schema again for every file it opens but not for a string (measured: 21 ms
    against 0.5 ms for the floor; the two files were 70% of build_diagram).
    Files with a <uri> stay files, so that their relative paths resolve."""
    text = path.read_text(encoding="utf-8-sig")
    if "<uri>" in text:
        return parser.AddModels(str(path))
    return parser.AddModelsFromString(text, "sdf")


@functools.lru_cache(maxsize=32)
def sdf_problem(path: str, mtime_ns: int, size: int) -> str | None:
    """What keeps the SDF file at path from being the chair, or None; cached per file
    version (mtime_ns, size): a sweep validates every run (and chair_kind.py a chair
    plug-in's model)."""
    try:
        root = ET.fromstring(Path(path).read_text(encoding="utf-8-sig"))
    except ET.ParseError as err:
        return f"is not XML ({err})"
    tag = root.tag.rsplit("}", 1)[-1]
    if tag != "sdf":
        return f"is not SDF (its root element is <{tag}>, not <sdf>)"
    # A throwaway plant with a scene graph, so that the geometry is parsed too.
    plant, _ = AddMultibodyPlantSceneGraph(DiagramBuilder(), 0.0)
    try:
        with _drake_quiet():
            models = add_sdf(Parser(plant), Path(path))
    except Exception as err:  # noqa: BLE001 - Drake's parser raises RuntimeError and others
        return f"fails Drake's SDF parser ({_one_line(err)})"
    if len(models) != 1:
        names = ", ".join(plant.GetModelInstanceName(m) for m in models) or "none"
        return f"holds {len(models)} models ({names})"
    (model,) = models
    if not plant.HasFrameNamed(CHAIR_FRAME, model):
        frames = ", ".join(plant.get_frame(i).name() for i in plant.GetFrameIndices(model))
        return (
            f"has no frame named '{CHAIR_FRAME}' (model '{plant.GetModelInstanceName(model)}' "
            f"has: {frames})"
        )
    try:
        with _drake_quiet():
            plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(CHAIR_FRAME, model))
            plant.Finalize()
    except Exception as err:  # noqa: BLE001 - as above
        return f"cannot be welded to the world at its frame '{CHAIR_FRAME}' ({_one_line(err)})"
    return None


@contextlib.contextmanager
def _drake_quiet() -> Iterator[None]:
    """Drops Drake's log messages: what it warns about while the check parses a file it
    warns about again when the scene is built, and an error must stay one line."""
    logger = logging.getLogger("drake")
    logger.addFilter(_drop)
    try:
        yield
    finally:
        logger.removeFilter(_drop)


def _drop(record: logging.LogRecord) -> bool:
    return False


def _one_line(err: Exception, limit: int = 300) -> str:
    text = " ".join(str(err).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


# --- The robot model: the names the scene needs, and the names its URDF gives -------------

# Task frame -> model frame: the controller speaks of hands and soles (robot.Robot).
TASK_FRAMES = {
    "l_sole": "l_sole",
    "r_sole": "r_sole",
    "l_hand": "l_hand_dh_frame",
    "r_hand": "r_hand_dh_frame",
    "l_thigh": "l_upper_leg_contact",
    "r_thigh": "r_upper_leg_contact",
    "buttocks": "buttocks_contact",
    "seat": "seat_contact",
}
# The floating base: scene.set_seated_state poses it, control/terms.py starts the tree there.
BASE_LINK = "root_link"
CONTACT_FILE = model_file("icub_contact.yaml")


@functools.cache
def scene_frames() -> tuple[str, ...]:
    """The frames the scene needs of a robot model's URDF: the floating base, the task
    frames (TASK_FRAMES), and the frames models/icub_contact.yaml poses its pads and its own
    frames in; the frames that file adds are not the URDF's to have. (The joints and bodies
    a scenario names are checked at their keys: rules.JOINT_TABLES and
    perturbation.pushes[*].body.)"""
    contact = yaml.safe_load(CONTACT_FILE.read_text())
    added = {frame["name"] for frame in contact["frames"]}
    needed = [BASE_LINK, *TASK_FRAMES.values()]
    needed += [frame["parent"] for frame in contact["frames"]]
    needed += [shape["frame"] for shape in contact["shapes"]]
    return tuple(dict.fromkeys(name for name in needed if name not in added))


@dataclass(frozen=True)
class ModelNames:
    """The names a robot model's URDF gives the plant (robot.add_icub), in URDF order."""

    links: tuple[str, ...]  # every one a frame of the plant, reduced or not
    joints: tuple[str, ...]  # revolute ones: the actuated joints
    reduced_bodies: tuple[str, ...]  # the links that stay bodies with robot.reduced

    def bodies(self, reduced: bool) -> tuple[str, ...]:
        return self.reduced_bodies if reduced else self.links


def robot_names() -> list[str]:
    """Names accepted for robot.model: every model icub-models ships."""
    return sorted(icub_models.get_robot_names())


def frame_links(root: ET.Element) -> set[str]:
    """The links of a URDF (its root element) that become frames instead of bodies (the
    one rule: robot/urdf.py removes them, model_names counts them out): a link with
    neither mass nor visual on a fixed joint, all its children alike."""
    links = {link.get("name"): link for link in root.findall("link")}
    joints = root.findall("joint")
    parent_joint = {joint.find("child").get("link"): joint for joint in joints}
    children: dict[str, list[str]] = {name: [] for name in links}
    for joint in joints:
        children[joint.find("parent").get("link")].append(joint.find("child").get("link"))

    @functools.cache
    def becomes_frame(name: str) -> bool:
        joint, link = parent_joint.get(name), links[name]
        mass = link.find("inertial/mass")
        bare = link.find("visual") is None and (mass is None or float(mass.get("value", "0")) == 0)
        return (
            joint is not None
            and joint.get("type") == "fixed"
            and bare
            and all(becomes_frame(child) for child in children[name])
        )

    return {name for name in links if becomes_frame(name)}


@functools.cache
def model_names(model: str) -> ModelNames:
    """The names of model's URDF as icub-models installs it (robot.original_urdf), read as
    XML: no plant is built. Cached per model: a sweep validates every run."""
    root = ET.parse(icub_models.get_model_file(model)).getroot()
    links = [link.get("name") for link in root.findall("link")]
    frames = frame_links(root)
    return ModelNames(
        links=tuple(links),
        joints=tuple(
            j.get("name")
            for j in root.findall("joint")
            if j.get("type") in ("revolute", "continuous")
        ),
        reduced_bodies=tuple(name for name in links if name not in frames),
    )


def missing_scene_frames(model: str) -> list[str]:
    """The frames of scene_frames() that model's URDF lacks."""
    links = set(model_names(model).links)
    return [name for name in scene_frames() if name not in links]


def check_robot_model(model: str) -> ModelNames:
    """robot.model's names, checked: a model of icub-models whose URDF has every frame the
    scene needs (scene_frames)."""
    if model not in robot_names():
        raise ScenarioError(
            f"robot.model: unknown model '{model}'; accepted: {', '.join(robot_names())}"
        )
    missing = missing_scene_frames(model)
    if missing:
        fit = [name for name in robot_names() if not missing_scene_frames(name)]
        raise ScenarioError(
            f"robot.model: '{model}' lacks the frames the scene needs: {', '.join(missing)}; "
            f"accepted: {', '.join(fit)}"
        )
    return model_names(model)
