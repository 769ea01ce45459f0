"""STL reading, OBJ conversion and decimation (drake_standup.robot.meshes).

References are meshes written here by hand: a tetrahedron as binary and as
ASCII STL, and a subdivided icosphere, so every expected count, coordinate
and extent is known without the code under test.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import Mesh, ReadObjToTriangleSurfaceMesh

from drake_standup.robot import meshes

# A tetrahedron, coordinates in mm (exact in float32), faces wound outwards.
TET_VERTICES = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 20.0, 0.0], [0.0, 0.0, 30.0]])
TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def _triangles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(M, 3, 3) corner coordinates of each face."""
    return np.asarray(vertices)[np.asarray(faces)]


def write_binary_stl(path: Path, triangles: np.ndarray) -> Path:
    """Binary STL: 80-byte header, uint32 count, 50 bytes per triangle."""
    with open(path, "wb") as f:
        f.write(b"solid but binary".ljust(80, b" "))  # a header starting like ASCII
        f.write(struct.pack("<I", len(triangles)))
        for tri in triangles:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            f.write(struct.pack("<9f", *np.ravel(tri)))
            f.write(struct.pack("<H", 0))
    return path


def write_ascii_stl(path: Path, triangles: np.ndarray) -> Path:
    lines = ["solid tet"]
    for tri in triangles:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {x:e} {y:e} {z:e}" for x, y, z in tri]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid tet")
    path.write_text("\n".join(lines) + "\n")
    return path


def _midpoint(vertices: list, cache: dict, a: int, b: int) -> int:
    """Index of the unit-sphere point above the middle of edge (a, b), added once."""
    key = (min(a, b), max(a, b))
    if key not in cache:
        p = vertices[a] + vertices[b]
        vertices.append(p / np.linalg.norm(p))
        cache[key] = len(vertices) - 1
    return cache[key]


def icosphere(subdivisions: int, radius: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Indexed icosphere: 20 * 4**subdivisions faces, vertices on the sphere."""
    t = (1 + 5**0.5) / 2
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]  # fmt: skip
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]  # fmt: skip
    vertices = [np.array(p, dtype=float) / np.linalg.norm(p) for p in v]
    faces = f
    for _ in range(subdivisions):
        seen: dict[tuple[int, int], int] = {}
        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = (_midpoint(vertices, seen, i, j) for i, j in ((a, b), (b, c), (c, a)))
            new_faces += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        faces = new_faces
    return radius * np.array(vertices), np.array(faces)


def _read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and 0-based faces of a triangle OBJ, parsed by hand."""
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        words = line.split()
        if words and words[0] == "v":
            vertices.append([float(w) for w in words[1:4]])
        elif words and words[0] == "f":
            faces.append([int(w.split("/")[0]) - 1 for w in words[1:]])
    return np.array(vertices), np.array(faces)


def _same_triangles(a: np.ndarray, b: np.ndarray, atol: float = 0.0) -> bool:
    """True if the two (M, 3, 3) triangle sets match, up to order and cyclic rotation."""

    def canonical(tris):
        out = []
        for tri in np.asarray(tris, dtype=float):
            rotations = [np.roll(tri, k, axis=0) for k in range(3)]
            out.append(min(rotations, key=lambda r: tuple(np.round(r.ravel(), 6))))
        return np.array(sorted(out, key=lambda r: tuple(np.round(r.ravel(), 6))))

    ca, cb = canonical(a), canonical(b)
    return ca.shape == cb.shape and np.allclose(ca, cb, rtol=0, atol=atol)


@pytest.fixture(autouse=True)
def cache(tmp_path, monkeypatch) -> Path:
    """DRAKE_STANDUP_CACHE in tmp_path: no test reads or writes the user's cache."""
    root = tmp_path / "cache"
    monkeypatch.setenv("DRAKE_STANDUP_CACHE", str(root))
    return root


@pytest.fixture
def tet_binary(tmp_path) -> Path:
    return write_binary_stl(tmp_path / "tet_bin.stl", _triangles(TET_VERTICES, TET_FACES))


@pytest.fixture
def tet_ascii(tmp_path) -> Path:
    return write_ascii_stl(tmp_path / "tet_ascii.stl", _triangles(TET_VERTICES, TET_FACES))


# --- read_stl ----------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["tet_binary", "tet_ascii"])
def test_read_stl_tetrahedron(request, kind):
    """read_stl vs the hand-written tetrahedron: 4 merged vertices, the same 4 oriented faces."""
    vertices, faces = meshes.read_stl(request.getfixturevalue(kind))
    assert vertices.shape == (4, 3)
    assert faces.shape == (4, 3)
    assert sorted(map(tuple, vertices)) == sorted(map(tuple, TET_VERTICES))
    assert _same_triangles(_triangles(vertices, faces), _triangles(TET_VERTICES, TET_FACES))


def test_read_stl_binary_and_ascii_agree(tet_binary, tet_ascii):
    """The binary and ASCII encodings of one mesh read to identical arrays."""
    vb, fb = meshes.read_stl(tet_binary)
    va, fa = meshes.read_stl(tet_ascii)
    np.testing.assert_array_equal(vb, va)
    np.testing.assert_array_equal(fb, fa)


def test_read_stl_drops_degenerate_triangles(tmp_path):
    """A triangle with two coincident corners is dropped; the 4 real faces stay."""
    tris = list(_triangles(TET_VERTICES, TET_FACES))
    tris.append(np.array([TET_VERTICES[0], TET_VERTICES[0], TET_VERTICES[1]]))
    _, faces = meshes.read_stl(write_binary_stl(tmp_path / "degenerate.stl", np.array(tris)))
    assert faces.shape == (4, 3)


# --- converted_obj -------------------------------------------------------------------


def test_converted_obj_bakes_scale_and_loads_in_drake(tet_binary, cache):
    """OBJ vertices vs the STL's times a non-uniform scale; Drake reads 4 vertices, 4 faces."""
    scale = [0.001, 0.002, 0.003]
    obj = meshes.converted_obj(tet_binary, scale, max_faces=1000)
    assert obj.is_file()
    assert obj.parent.parent == cache  # under DRAKE_STANDUP_CACHE
    assert obj.suffix == ".obj"

    vertices, faces = _read_obj(obj)
    assert vertices.shape == (4, 3) and faces.shape == (4, 3)
    expected = _triangles(TET_VERTICES * scale, TET_FACES)  # e.g. (0, 0, 30) -> (0, 0, 0.09)
    assert _same_triangles(_triangles(vertices, faces), expected, atol=1e-9)

    surface = ReadObjToTriangleSurfaceMesh(str(obj))
    assert surface.num_vertices() == 4
    assert surface.num_triangles() == 4
    drake_vertices = np.array([surface.vertex(i) for i in range(4)])
    assert sorted(map(tuple, np.round(drake_vertices, 9))) == sorted(
        map(tuple, np.round(TET_VERTICES * scale, 9))
    )
    # Outward winding survives: the enclosed volume is positive (10 * 20 * 30 / 6 mm^3).
    tris = _triangles(vertices, faces)
    volume = np.einsum("ij,ij->i", tris[:, 0], np.cross(tris[:, 1], tris[:, 2])).sum() / 6
    assert volume == pytest.approx(10 * 20 * 30 / 6 * np.prod(scale), rel=1e-6)
    assert Mesh(str(obj)).extension() == ".obj"


def test_converted_obj_reuses_cache(tet_binary):
    """A second call returns the same file without rewriting it (mtime pinned in the past)."""
    first = meshes.converted_obj(tet_binary, [0.001] * 3, max_faces=1000)
    old = 1_000_000_000  # 2001: any rewrite would move the mtime to now
    os.utime(first, ns=(old * 10**9, old * 10**9))
    second = meshes.converted_obj(tet_binary, [0.001] * 3, max_faces=1000)
    assert second == first
    assert second.stat().st_mtime_ns == old * 10**9


def test_converted_obj_keys_on_scale_and_face_budget(tet_binary):
    """Different scale or max_faces give different cache files (no stale reuse)."""
    a = meshes.converted_obj(tet_binary, [0.001] * 3, max_faces=1000)
    b = meshes.converted_obj(tet_binary, [0.002] * 3, max_faces=1000)
    c = meshes.converted_obj(tet_binary, [0.001] * 3, max_faces=500)
    assert len({a, b, c}) == 3
    assert _read_obj(b)[0].max() == pytest.approx(2 * _read_obj(a)[0].max())


# --- decimate --------------------------------------------------------------------------


def test_decimate_reduces_faces_and_keeps_extent():
    """5120-face icosphere to ~500 faces: count within 10 %, bounding box within 3 %."""
    vertices, faces = icosphere(4, radius=0.05)
    assert len(faces) == 5120
    v, f = meshes.decimate(vertices, faces, 500)
    assert 450 <= len(f) <= 550
    assert f.max() < len(v)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    size = hi - lo
    np.testing.assert_allclose(v.min(axis=0), lo, rtol=0, atol=0.03 * size.max())
    np.testing.assert_allclose(v.max(axis=0), hi, rtol=0, atol=0.03 * size.max())


def test_decimate_leaves_small_meshes_alone():
    """A mesh already under the budget comes back unchanged."""
    vertices, faces = icosphere(1)
    v, f = meshes.decimate(vertices, faces, 1000)
    np.testing.assert_array_equal(v, vertices)
    np.testing.assert_array_equal(f, faces)


def test_converted_obj_decimates_fine_stl(tmp_path):
    """A 5120-face STL converted with max_faces=500 gives an OBJ of ~500 faces, same extent."""
    vertices, faces = icosphere(4, radius=50.0)  # mm
    stl = write_binary_stl(tmp_path / "sphere.stl", _triangles(vertices, faces))
    obj = meshes.converted_obj(stl, [0.001] * 3, max_faces=500)
    v, f = _read_obj(obj)
    assert 450 <= len(f) <= 550
    np.testing.assert_allclose(v.min(axis=0), [-0.05] * 3, atol=0.003)
    np.testing.assert_allclose(v.max(axis=0), [0.05] * 3, atol=0.003)
    surface = ReadObjToTriangleSurfaceMesh(str(obj))
    assert surface.num_triangles() == len(f)
