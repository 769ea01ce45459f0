"""A chair from a mesh (issue 61): the seat found in an OBJ or an STL against the numbers
the boxes were made with, the one-line error of a mesh that cannot be a chair (in this
process and through run_diagram.py), the seat height taken from the mesh, and the scene
built on it (tools/make_chair_mesh.py makes the meshes)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from pydrake.geometry import Mesh, Role
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import ChairConfig, Scenario, ScenarioError, apply_overrides
from drake_standup.config.chair_mesh import MIN_SEAT_DEPTH_M, MIN_SEAT_WIDTH_M, SeatGeometry
from drake_standup.config.inputs import CHAIR_MESH_CONTENT, chair_mesh, check_chair_file
from drake_standup.config.loading import load_scenario
from drake_standup.world.scene import add_scene
from tools.make_chair_mesh import (
    FACES,
    OBJ,
    ascii_stl,
    binary_stl,
    box,
    boxes_obj,
    chair_boxes,
    triangles,
)

REPO = Path(__file__).resolve().parents[2]
# A box 0.5 m deep and wide, from 0.05 to 0.29 m: its top is a seat 0.24 m above its floor.
BOX = ((0.1, -0.3, 0.05), (0.6, 0.2, 0.29))
BOX_SEAT = SeatGeometry(0.24, 0.6, 0.5, 0.5, -0.05, 0.05)
SHIPPED_SEAT = SeatGeometry(0.2195, 0.0, 0.40, 0.44, 0.0, 0.0)


def _same(seat: SeatGeometry, expected: SeatGeometry, tol: float = 1e-6) -> None:
    assert np.allclose(list(vars(seat).values()), list(vars(expected).values()), atol=tol)


def _error(path: Path) -> str:
    """The one-line ScenarioError of a scenario whose chair.file is path."""
    with pytest.raises(ScenarioError) as caught:
        apply_overrides(Scenario(), [("chair.file", str(path))])
    assert "\n" not in str(caught.value)
    return str(caught.value)


def test_the_shipped_obj_is_the_generated_chair_and_its_seat_the_chairs():
    assert OBJ.read_text() == boxes_obj(chair_boxes())
    _same(chair_mesh("models/chair_mesh.obj").seat, SHIPPED_SEAT)
    assert check_chair_file("models/chair_mesh.obj").resolve() == OBJ


@pytest.mark.parametrize("kind", ["binary", "ascii", "binary inside out"])
def test_the_seat_of_an_stl_box_is_its_top(tmp_path, kind):
    tris = triangles([BOX])
    if kind.endswith("inside out"):
        tris = tris[:, ::-1]
    path = tmp_path / "box.stl"
    path.write_bytes(binary_stl(tris) if kind.startswith("binary") else ascii_stl(tris).encode())
    _same(chair_mesh(str(path)).seat, BOX_SEAT)


def test_an_obj_with_polygons_texture_normal_and_negative_indices(tmp_path):
    """The OBJ forms a CAD export writes: v/vt/vn indices, counted back from the end, in
    quads and in a hexagon-free mix of quads and triangles, with other lines ignored."""
    lines = ["mtllib chair.mtl", "o box", "vt 0 0", "vn 0 0 1"]
    lines += [f"v {x} {y} {z}" for x, y, z in box(*BOX)]
    a, b, c, d = FACES[0]
    lines.append(f"f {a - 8}/1/1 {b - 8}/1/1 {c - 8}/1/1")  # one face as two triangles
    lines.append(f"f {a + 1}//1 {c + 1}//1 {d + 1}//1")
    lines += ["f " + " ".join(f"{k + 1}/1" for k in face) for face in FACES[1:]]
    path = tmp_path / "box.OBJ"
    path.write_text("\n".join(lines) + "\n")
    _same(chair_mesh(str(path)).seat, BOX_SEAT)


def test_a_seat_is_the_largest_upward_area_below_the_highest_seat(tmp_path):
    """A bench 0.5 m wide under a shelf 0.7 m high (above any seat) and beside a narrower,
    lower step: the bench's top is the seat."""
    bench = ((0.0, 0.0, 0.0), (0.5, 0.5, 0.45))
    shelf = ((0.0, 0.6, 0.0), (0.6, 1.4, 0.7))  # top larger, but too high
    step = ((0.6, 0.0, 0.0), (0.9, 0.3, 0.2))
    path = tmp_path / "bench.obj"
    path.write_text(boxes_obj([bench, shelf, step]))
    _same(chair_mesh(str(path)).seat, SeatGeometry(0.45, 0.5, 0.5, 0.5, 0.25, 0.0))


def test_the_smallest_seat_is_larger_than_a_thigh_pad():
    pads = yaml.safe_load((REPO / "models" / "icub_contact.yaml").read_text())["shapes"]
    thigh = next(p["size_m"] for p in pads if p["name"] == "l_thigh_pad")
    assert MIN_SEAT_DEPTH_M > thigh[0] and MIN_SEAT_WIDTH_M > 2 * thigh[1]


def _open_box(path: Path) -> None:
    """BOX without its top face (two triangles): four edges open."""
    path.write_bytes(binary_stl(np.delete(triangles([BOX]), [2, 3], axis=0)))


@pytest.mark.parametrize(
    ("name", "write", "problem"),
    [
        ("open.stl", _open_box, "is not closed (4 open edges; every edge must be shared by "
         "exactly two triangles)"),
        ("tower.obj", lambda p: p.write_text(boxes_obj([((0, 0, 0), (0.5, 0.5, 1.0))])),
         "has no seat (no upward horizontal area 0.05-0.6 m above its lowest point)"),
        ("stool.obj", lambda p: p.write_text(boxes_obj([((0, 0, 0), (0.15, 0.44, 0.3))])),
         "has a seat too small for the robot's thigh pads (0.150 m deep, 0.440 m wide, "
         "at 0.3000 m)"),
        ("twisted.stl", lambda p: p.write_bytes(binary_stl(_one_flipped())),
         "has triangles wound against their neighbours (3 edges run the same way in both "
         "their triangles)"),
        ("garbage.obj", lambda p: p.write_text("v 0 0 zero\n"),
         "is not a valid OBJ (line 1: 'v 0 0 zero')"),
        ("faces.obj", lambda p: p.write_text("v 0 0 0\nf 1 2 3\n"),
         "is not a valid OBJ (line 2: 'f 1 2 3')"),
        ("binary.obj", lambda p: p.write_bytes(b"\xff\xfe"), "is not OBJ text (byte 0xff)"),
        ("text.stl", lambda p: p.write_text("a chair\n"),
         "is not a valid STL (neither binary nor ASCII 'solid ...')"),
    ],
)  # fmt: skip
def test_a_mesh_that_cannot_be_a_chair_is_one_error_line(tmp_path, name, write, problem):
    path = tmp_path / name
    write(path)
    assert _error(path) == f"chair.file: '{path}' {problem}; accepted: {CHAIR_MESH_CONTENT}"


def _one_flipped() -> np.ndarray:
    tris = triangles([BOX])
    tris[0] = tris[0][::-1]
    return tris


def test_a_missing_mesh_names_the_accepted_files(tmp_path):
    assert _error(tmp_path / "nope.stl").startswith(f"chair.file: file '{tmp_path}/nope.stl'")


def test_the_seat_height_is_the_meshs_whatever_the_scenario_says(tmp_path):
    path = tmp_path / "box.stl"
    path.write_bytes(binary_stl(triangles([BOX])))
    given = [("chair.file", str(path)), ("chair.seat_height_m", 0.25)]
    assert apply_overrides(Scenario(), given).chair.seat_height_m == 0.24
    assert load_scenario("mesh_chair").chair.seat_height_m == 0.2195


def test_the_scene_loads_the_mesh_and_refuses_a_seat_height_it_disagrees_with(tmp_path):
    """The chair's collision geometry is the mesh, posed so that the chair's frame is on the
    floor below the middle of the seat's front edge; a scenario made in code with a seat
    height other than the mesh's is refused as the scene is built."""
    path = tmp_path / "box.stl"
    path.write_bytes(binary_stl(triangles([BOX])))
    scenario = apply_overrides(Scenario(), [("chair.file", str(path))])
    scene = add_scene(DiagramBuilder(), scenario, visuals=False)
    inspector = scene.scene_graph.model_inspector()
    (chair,) = [
        g
        for g in inspector.GetAllGeometryIds(Role.kProximity)
        if inspector.GetName(g) == "chair::chair_collision"
    ]
    assert isinstance(inspector.GetShape(chair), Mesh)
    assert inspector.GetShape(chair).extension() == ".obj"
    assert np.allclose(inspector.GetPoseInFrame(chair).translation(), [-0.6, 0.05, -0.05])
    wrong = Scenario(chair=ChairConfig(file=str(path)))  # seat_height_m 0.2195, not 0.24
    with pytest.raises(ScenarioError, match=r"^chair.seat_height_m: 0.2195; accepted: 0.2400"):
        add_scene(DiagramBuilder(), wrong, visuals=False)


def test_run_diagram_on_an_open_mesh_is_one_error_line_and_exit_2(tmp_path):
    mesh = tmp_path / "open.stl"
    _open_box(mesh)
    scenario = tmp_path / "open.yaml"
    scenario.write_text(f"chair:\n  file: {mesh}\n")
    out = tmp_path / "out"
    done = subprocess.run(
        [sys.executable, str(REPO / "run_diagram.py"), "--scenario", str(scenario)]
        + ["--out", str(out), "--no-recording"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO)},
        check=False,
    )
    assert "Traceback" not in done.stderr
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines() == [
        f"error: chair.file: '{mesh}' is not closed (4 open edges; every edge must be shared "
        f"by exactly two triangles); accepted: {CHAIR_MESH_CONTENT}"
    ]
    assert not list(tmp_path.rglob("metrics.json"))


def test_a_mesh_seat_the_robot_cannot_sit_on_names_the_file(tmp_path):
    path = tmp_path / "high.obj"
    path.write_text(boxes_obj([((0.0, 0.0, 0.0), (0.5, 0.5, 0.3))]))
    scenario = apply_overrides(Scenario(), [("chair.file", str(path))])
    with pytest.raises(ScenarioError) as caught:
        add_scene(DiagramBuilder(), scenario, visuals=False)
    assert str(caught.value).startswith(
        f"chair.file: '{path}' (its seat 0.3 m high); the iCubGazeboV2_5 cannot sit on this "
        "chair with its soles flat on the floor; accepted: a seat 0.174-0.253 m high"
    )
