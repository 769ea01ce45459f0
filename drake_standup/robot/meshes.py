"""STL -> OBJ conversion for Drake, with decimation for display.

Drake reads no STL (RobotLocomotion/drake#19408), so every mesh the iCub URDF
names is converted once into a cache directory outside the repository and
reused afterwards. The meshes are only used for illustration (the robot's
collision geometry is a set of primitives, see robot/icub.py), so they are
decimated with quadric edge collapse to keep the Meshcat recording small.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np

from drake_standup.config.chair_mesh import read_stl as read_stl_file

# Bump when the conversion changes so stale cache entries are not reused.
_CONVERTER_VERSION = "1"


def cache_dir() -> Path:
    """Root of the generated-asset cache ($DRAKE_STANDUP_CACHE or ~/.cache)."""
    root = os.environ.get("DRAKE_STANDUP_CACHE")
    if root:
        return Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME", str(Path.home() / ".cache"))
    return Path(xdg) / "drake_standup"


def read_stl(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Reads a binary or ASCII STL; returns (vertices (N, 3), faces (M, 3)).

    Coincident corners are merged so the mesh is indexed, which both shrinks
    the OBJ and lets the decimator see the connectivity. A mesh that is no STL (the
    COLLADA visuals of iCubGenova03) has no triangles here: its link keeps an empty
    visual, as the reader before the one STL reader left it.
    """
    if Path(path).suffix.lower() != ".stl":
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=int)
    corners, _ = read_stl_file(Path(path).read_bytes())  # three corners a triangle
    vertices, inverse = np.unique(corners, axis=0, return_inverse=True)
    faces = inverse.reshape(-1, 3)
    keep = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    return vertices, faces[keep]


def decimate(
    vertices: np.ndarray, faces: np.ndarray, max_faces: int
) -> tuple[np.ndarray, np.ndarray]:
    """Quadric decimation down to about max_faces triangles (no-op if smaller)."""
    if len(faces) <= max_faces:
        return vertices, faces
    import fast_simplification

    reduction = 1.0 - max_faces / len(faces)
    v, f = fast_simplification.simplify(
        vertices.astype(np.float64), faces.astype(np.int64), target_reduction=reduction
    )
    return np.asarray(v), np.asarray(f)


def write_obj(path: Path, vertices: np.ndarray, faces: np.ndarray, scale) -> None:
    """Writes an OBJ with the URDF's scale baked in (0.1 mm resolution)."""
    v = np.asarray(vertices) * np.asarray(scale, dtype=np.float64)
    lines = ["# converted by drake_standup from a third-party STL; do not commit\n"]
    lines += [f"v {x:.4f} {y:.4f} {z:.4f}\n" for x, y, z in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces]
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    tmp.write_text("".join(lines))
    tmp.replace(path)


def converted_obj(stl_path: Path, scale, max_faces: int) -> Path:
    """Returns the cached OBJ for stl_path, converting on first use."""
    stl_path = Path(stl_path)
    key = hashlib.sha1(
        f"{_CONVERTER_VERSION}|{stl_path.resolve()}|{stl_path.stat().st_size}|"
        f"{stl_path.stat().st_mtime_ns}|"
        f"{list(scale)}|{max_faces}".encode()
    ).hexdigest()[:12]
    out = cache_dir() / "meshes" / f"{stl_path.stem}-{key}.obj"
    if not out.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
        vertices, faces = read_stl(stl_path)
        vertices, faces = decimate(vertices, faces, max_faces)
        write_obj(out, vertices, faces, scale)
    return out
