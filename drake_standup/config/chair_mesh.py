"""A chair from a mesh (chair.file an .obj or .stl, issue 61): the file read with numpy
alone, checked closed, and its seat found.

The mesh is in metres, z up, x forward (the way the seated robot faces). Its seat is the
largest horizontal upward-facing area (triangles whose normal's z is >= UP_NORMAL_Z,
grouped by height within HEIGHT_TOLERANCE_M, area-weighted) SEAT_HEIGHTS_M above the
mesh's lowest point (the floor): its height there is the seat's height, its largest x the
seat's front edge, its x and y extents the seat's depth and width. config/inputs.py turns
a problem (MeshError) into the one-line error of chair.file; world/chair.py loads the
mesh (written again as a plain OBJ) as a rigid hydroelastic chair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MESH_SUFFIXES = (".obj", ".stl")
# A triangle faces up when its unit normal's z is at least this (about 18 degrees). 1.
UP_NORMAL_Z = 0.95
# Upward triangles whose heights differ by less than this are one area. m.
HEIGHT_TOLERANCE_M = 0.002
# Where a seat may be above the floor: the heights world/seating.py's seat_height_range
# searches for the robot's reach. m.
SEAT_HEIGHTS_M = (0.05, 0.6)
# The smallest seat: the thigh pads are 0.14 m long and 0.09 m wide each
# (models/icub_contact.yaml), side by side with the buttocks pad behind them. m.
MIN_SEAT_DEPTH_M = MIN_SEAT_WIDTH_M = 0.2
# Vertices closer than this are one (STL repeats every vertex per triangle). m.
WELD_M = 1e-6


class MeshError(ValueError):
    """What keeps a file from being a chair mesh, worded to follow "chair.file: 'NAME' "."""


@dataclass(frozen=True)
class SeatGeometry:
    """The seat of a chair mesh, in the mesh's own axes. m."""

    height_m: float  # the seat's top above the mesh's lowest point (the floor)
    front_edge_x_m: float  # the seat's largest x
    depth_m: float  # its x extent
    width_m: float  # its y extent
    centre_y_m: float  # the middle of its y extent
    floor_z_m: float  # the mesh's lowest z


@dataclass(frozen=True)
class ChairMesh:
    """A closed triangle mesh, wound outwards, and its seat."""

    vertices: np.ndarray  # (n, 3) m
    triangles: np.ndarray  # (m, 3) vertex indices, counter-clockwise seen from outside
    seat: SeatGeometry


def is_mesh(path) -> bool:
    """Whether a chair file is a mesh, by its suffix (any case)."""
    return str(path).lower().endswith(MESH_SUFFIXES)


def read_chair_mesh(data: bytes, suffix: str) -> ChairMesh:
    """The chair mesh of a file's bytes (suffix .obj or .stl); raises MeshError."""
    read = read_obj if suffix.lower() == ".obj" else read_stl
    vertices, triangles = weld(*read(data))
    triangles = _outwards(vertices, _checked_closed(triangles))
    seat = find_seat(vertices, triangles)
    if seat is None:
        low, high = SEAT_HEIGHTS_M
        raise MeshError(
            f"has no seat (no upward horizontal area {low:g}-{high:g} m above its lowest point)"
        )
    if seat.depth_m < MIN_SEAT_DEPTH_M or seat.width_m < MIN_SEAT_WIDTH_M:
        raise MeshError(
            f"has a seat too small for the robot's thigh pads ({seat.depth_m:.3f} m deep, "
            f"{seat.width_m:.3f} m wide, at {seat.height_m:.4f} m)"
        )
    return ChairMesh(vertices, triangles, seat)


# --- Reading: OBJ ('v' and 'f' lines) and STL (ASCII or binary) ---------------------------


def read_obj(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of an OBJ file: 'v x y z' and 'f' lines (indices as i, i/t,
    i//n or i/t/n, negative ones counted back; polygons fanned into triangles); other
    lines are ignored."""
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise MeshError(f"is not OBJ text (byte 0x{data[err.start]:02x})") from None
    vertices, triangles = [], []
    for number, line in enumerate(text.splitlines(), 1):
        words = line.split()
        try:
            if words[:1] == ["v"]:
                vertices.append([float(w) for w in words[1:4]])
                if len(vertices[-1]) != 3:
                    raise ValueError
            elif words[:1] == ["f"]:
                corners = [_obj_index(w, len(vertices)) for w in words[1:]]
                if len(corners) < 3:
                    raise ValueError
                triangles += [[corners[0], a, b] for a, b in zip(corners[1:-1], corners[2:])]
        except (ValueError, IndexError):
            raise MeshError(f"is not a valid OBJ (line {number}: {line.strip()[:60]!r})") from None
    if not triangles:
        raise MeshError("is not a valid OBJ (no faces)")
    return np.array(vertices, float), np.array(triangles, int)


def _obj_index(word: str, count: int) -> int:
    index = int(word.split("/")[0])
    index = index - 1 if index > 0 else count + index
    if not 0 <= index < count:
        raise IndexError(index)
    return index


def read_stl(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (three per triangle) and triangles of a binary or an ASCII STL file (the
    one STL reader: robot/meshes.py reads the iCub's meshes with it too)."""
    if len(data) >= 84:
        count = int(np.frombuffer(data, "<u4", 1, 80)[0])
        if len(data) == 84 + 50 * count and count:
            record = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
            corners = np.frombuffer(data, record, count, 84)["v"].astype(float)
            return corners.reshape(-1, 3), np.arange(3 * count).reshape(-1, 3)
    return _read_ascii_stl(data)


def _read_ascii_stl(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    try:
        words = data.decode("ascii").split()
    except UnicodeDecodeError:
        raise MeshError("is not a valid STL (neither binary nor ASCII)") from None
    if words[:1] != ["solid"]:
        raise MeshError("is not a valid STL (neither binary nor ASCII 'solid ...')")
    at = [i for i, w in enumerate(words) if w == "vertex"]
    facets = sum(w == "facet" for w in words)
    try:
        corners = np.array([[float(w) for w in words[i + 1 : i + 4]] for i in at], float)
    except ValueError:
        raise MeshError("is not a valid STL (a vertex that is not three numbers)") from None
    if not facets or corners.shape != (3 * facets, 3):
        raise MeshError(f"is not a valid STL ({facets} facets, {len(at)} vertices)")
    return corners, np.arange(3 * facets).reshape(-1, 3)


# --- Checking: closed, consistently wound, outwards ---------------------------------------


def weld(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices within WELD_M made one; triangles that lose a corner dropped."""
    vertices = np.asarray(vertices, float)
    keys = np.round(vertices / WELD_M).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    triangles = inverse.reshape(-1)[triangles]
    a, b, c = triangles.T
    return vertices[first], triangles[(a != b) & (b != c) & (c != a)]


def _checked_closed(triangles: np.ndarray) -> np.ndarray:
    """triangles, if every edge joins exactly two of them, run opposite ways; else
    MeshError saying how many edges do not."""
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    _, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    open_, over = int((counts == 1).sum()), int((counts > 2).sum())
    if open_ or over:
        parts = [f"{open_} open edges"] * bool(open_)
        parts += [f"{over} edges shared by more than two triangles"] * bool(over)
        raise MeshError(
            f"is not closed ({', '.join(parts)}; every edge must be shared by exactly two "
            "triangles)"
        )
    _, counts = np.unique(directed, axis=0, return_counts=True)
    if (counts > 1).any():
        raise MeshError(
            f"has triangles wound against their neighbours ({int((counts > 1).sum())} edges "
            "run the same way in both their triangles)"
        )
    return triangles


def _outwards(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """triangles wound counter-clockwise seen from outside (flipped if the enclosed volume
    comes out negative); MeshError if they enclose none."""
    v0, v1, v2 = (vertices[triangles[:, k]] for k in range(3))
    volume = float(np.einsum("ij,ij->i", v0, np.cross(v1, v2)).sum() / 6.0)
    if abs(volume) < 1e-9:
        raise MeshError("encloses no volume")
    return triangles if volume > 0 else triangles[:, ::-1].copy()


# --- The seat -----------------------------------------------------------------------------


def find_seat(vertices: np.ndarray, triangles: np.ndarray) -> SeatGeometry | None:
    """The seat (module docstring) of a mesh wound outwards, or None if it has none."""
    corners = vertices[triangles]  # (m, 3, 3)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    areas = lengths / 2.0
    floor = float(corners[:, :, 2].min())
    heights = corners[:, :, 2].mean(axis=1) - floor
    low, high = SEAT_HEIGHTS_M
    up = (lengths > 0) & (normals[:, 2] >= UP_NORMAL_Z * lengths)
    candidates = np.flatnonzero(up & (heights >= low) & (heights <= high))
    if not len(candidates):
        return None
    candidates = candidates[np.argsort(heights[candidates], kind="stable")]
    gaps = np.flatnonzero(np.diff(heights[candidates]) > HEIGHT_TOLERANCE_M)
    groups = np.split(candidates, gaps + 1)
    seat = max(groups, key=lambda group: areas[group].sum())
    points = corners[seat].reshape(-1, 3)
    (x0, y0, _), (x1, y1, _) = points.min(axis=0), points.max(axis=0)
    return SeatGeometry(
        height_m=float(np.average(heights[seat], weights=areas[seat])),
        front_edge_x_m=float(x1),
        depth_m=float(x1 - x0),
        width_m=float(y1 - y0),
        centre_y_m=float((y0 + y1) / 2.0),
        floor_z_m=floor,
    )


def obj_text(mesh: ChairMesh) -> str:
    """The mesh as a plain OBJ ('v' and triangle 'f' lines), as Drake reads it."""
    vertices = "".join(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in mesh.vertices)
    faces = "".join(f"f {a} {b} {c}\n" for a, b, c in mesh.triangles + 1)
    return "# a chair mesh, as drake_standup read it\n" + vertices + faces
