"""The files, folders and robot names a user gives: each one checked before anything
simulates.

Every failure is a ScenarioError: one line naming the option or key, the value, and what
it accepts. rules.validate calls the checks of a scenario's own keys (chair.file); the
entry points those of their options (--scenario and a sweep file through read_text_file,
--out through check_output_dir).
"""

import contextlib
import functools
import logging
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config.errors import ScenarioError
from drake_standup.config.scenario import chair_file

# --- Files and folders -------------------------------------------------------------------


def read_text_file(path: Path | str, key: str, accepted: str) -> str:
    """The text of the file at path (UTF-8, with or without a byte order mark); an error
    naming key if the file is missing, a folder, unreadable or not UTF-8 text. accepted:
    what key accepts, for the message."""
    path = Path(path)
    if path.is_dir():
        raise ScenarioError(f"{key}: '{path}' is a folder; accepted: {accepted}")
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(f"{key}: file '{path}' not found; accepted: {accepted}") from None
    except OSError as err:
        raise ScenarioError(
            f"{key}: '{path}' cannot be read ({err.strerror}); accepted: a file this user can read"
        ) from None
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


# --- The chair: an SDF file the scene welds to the world at its frame 'chair' -------------

CHAIR_FRAME = "chair"
CHAIR_FILES = (
    "an SDF file path (absolute or relative to the current directory), or models/chair.sdf"
)
CHAIR_CONTENT = (
    f"an SDF file of one model with a link or frame named '{CHAIR_FRAME}' (the scene welds "
    "it to the world), e.g. models/chair.sdf"
)


def check_chair_file(name: str) -> Path:
    """chair.file's path, checked: a UTF-8 SDF file that Drake parses into one model with
    a frame named 'chair' that can be welded to the world, as scene.add_scene does."""
    path = chair_file(name)
    read_text_file(path, "chair.file", CHAIR_FILES)
    stat = path.stat()
    problem = _sdf_problem(str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    if problem:
        raise ScenarioError(f"chair.file: '{name}' {problem}; accepted: {CHAIR_CONTENT}")
    return path


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
def _sdf_problem(path: str, mtime_ns: int, size: int) -> str | None:
    """What keeps the SDF file at path from being the chair, or None; cached per file
    version (mtime_ns, size): a sweep validates every run."""
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
