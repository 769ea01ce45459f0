"""The icub-models URDF rewritten for Drake, once per process and cached on disk.

What prepare_urdf does to the published URDF, in order (icub.py adds the result to a plant):
  1. Converts its STL visuals to decimated OBJ in a cache (meshes.py); Drake
     reads no STL.
  2. Drops every URDF collision element: the task needs contact only where the
     robot meets chair and floor, given as primitives in models/icub_contact.yaml.
  3. Optionally ("reduced") removes the massless, visual-less links that hang
     on fixed joints (sensor and skin frames, about 170 of the 210 links) and
     returns each as a LeafFrame on its nearest kept ancestor, so every named
     frame survives while the tree Drake integrates shrinks to about 40 bodies
     (same mass matrix, CoM and frame poses; tests check it).
"""

import hashlib
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from pydrake.math import RigidTransform, RollPitchYaw

from drake_standup.config.inputs import frame_links, robot_names
from drake_standup.robot.meshes import cache_dir, converted_obj

DEFAULT_MODEL = "iCubGazeboV2_5"


class ModelError(ValueError):
    """Raised for a robot model that cannot be loaded (one-line message)."""


def original_urdf(model_name: str) -> Path:
    """Path of the URDF that icub-models installs for model_name."""
    import icub_models

    names = robot_names()
    if model_name not in names:
        raise ModelError(f"robot.model: unknown model '{model_name}'; accepted: {', '.join(names)}")
    return Path(icub_models.get_model_file(model_name))


def _pose(elem: ET.Element | None) -> RigidTransform:
    """Pose of a URDF <origin> (fixed-axis roll-pitch-yaw, as Drake's RPY)."""
    if elem is None:
        return RigidTransform()
    xyz = [float(s) for s in elem.get("xyz", "0 0 0").split()]
    rpy = [float(s) for s in elem.get("rpy", "0 0 0").split()]
    return RigidTransform(RollPitchYaw(rpy), xyz)


@dataclass
class LeafFrame:
    """A removed bare link, kept as a frame fixed on its nearest kept ancestor."""

    name: str
    parent_body: str
    X_PF: RigidTransform


@dataclass
class PreparedUrdf:
    """A Drake-ready URDF in the cache and the frames to re-attach after parsing."""

    path: Path
    leaf_frames: list[LeafFrame]


# prepare_urdf's results in this process, by its arguments and the cache directory.
_PREPARED: dict[tuple, PreparedUrdf] = {}


def prepare_urdf(
    model_name: str = DEFAULT_MODEL,
    *,
    reduce: bool = True,
    visuals: bool = True,
    visual_max_faces: int = 1000,
) -> PreparedUrdf:
    """Rewrites the icub-models URDF for Drake (see the module docstring).

    Once per process and arguments while the cached file exists: the rewrite
    (parse, mesh look-ups, serialise, hash) cost ~15 ms of every
    build_diagram, which a sweep pays for every run (measured)."""
    key = (model_name, reduce, visuals, visual_max_faces, str(cache_dir()))
    prepared = _PREPARED.get(key)
    if prepared is None or not prepared.path.exists():
        prepared = _PREPARED[key] = _prepare_urdf(
            model_name, reduce=reduce, visuals=visuals, visual_max_faces=visual_max_faces
        )
    return PreparedUrdf(prepared.path, list(prepared.leaf_frames))


def _prepare_urdf(
    model_name: str, *, reduce: bool, visuals: bool, visual_max_faces: int
) -> PreparedUrdf:
    src = original_urdf(model_name)
    share_icub = src.parent.parent.parent  # .../share/iCub (package://iCub/)
    tree = ET.parse(src)
    robot = tree.getroot()

    for tag in ("gazebo", "sensor"):
        for elem in robot.findall(tag):
            robot.remove(elem)

    links = {link.get("name"): link for link in robot.findall("link")}
    for link in links.values():
        for col in link.findall("collision"):
            link.remove(col)
        for vis in link.findall("visual"):
            mesh = vis.find("geometry/mesh")
            if not visuals:
                link.remove(vis)
            elif mesh is not None:
                uri = mesh.get("filename")
                stl = share_icub / uri.removeprefix("package://iCub/")
                scale = [float(s) for s in mesh.get("scale", "1 1 1").split()]
                mesh.set("filename", str(converted_obj(stl, scale, visual_max_faces)))
                mesh.attrib.pop("scale", None)

    leaf_frames: list[LeafFrame] = []
    if reduce:
        leaf_frames = _remove_bare_subtrees(robot, links)

    digest = hashlib.sha1(ET.tostring(robot)).hexdigest()[:12]
    kind = "reduced" if reduce else "full"
    out = cache_dir() / "urdf" / f"{model_name}-{kind}-{digest}.urdf"
    if not out.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
        # Write then rename: a half-written file must never look cached.
        tmp = out.with_name(f"{out.name}.{os.getpid()}.tmp")
        tree.write(tmp)
        tmp.replace(out)
    return PreparedUrdf(out, leaf_frames)


def _remove_bare_subtrees(robot: ET.Element, links: dict[str, ET.Element]) -> list[LeafFrame]:
    """Removes every subtree of bare links on fixed joints; returns their frames."""
    joints = robot.findall("joint")
    children: dict[str, list[ET.Element]] = {name: [] for name in links}
    parent_joint: dict[str, ET.Element] = {}
    for joint in joints:
        children[joint.find("parent").get("link")].append(joint)
        parent_joint[joint.find("child").get("link")] = joint

    def child_of(joint: ET.Element) -> str:
        return joint.find("child").get("link")

    frames_only = frame_links(robot)

    def removable(name: str) -> bool:
        return name in frames_only

    frames: list[LeafFrame] = []

    def collect(name: str, kept: str, X_KL: RigidTransform) -> None:
        frames.append(LeafFrame(name, kept, X_KL))
        for j in children[name]:
            collect(child_of(j), kept, X_KL @ _pose(j.find("origin")))

    for joint in joints:
        parent = joint.find("parent").get("link")
        if removable(child_of(joint)) and not removable(parent):
            collect(child_of(joint), parent, _pose(joint.find("origin")))
    removed = {f.name for f in frames}
    for joint in joints:
        if child_of(joint) in removed:
            robot.remove(joint)
    for name in removed:
        robot.remove(links[name])
    return frames
