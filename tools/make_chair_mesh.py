"""Writes models/chair_mesh.obj, the shipped chair as one closed mesh: the seat board of
models/chair.sdf (0.40 m deep, 0.44 m wide, 0.04 m thick, its top 0.2195 m above the
floor, its front edge at x = 0) on four legs 0.04 m square, inset 0.03 m, down to the
floor. Each box is a closed surface of its own (the legs touch the board, they share no
edge with it). tests/world/test_chair_mesh.py checks the file is what this writes, and
makes its STL boxes with the same functions.

    python tools/make_chair_mesh.py
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

OBJ = Path(__file__).resolve().parent.parent / "models" / "chair_mesh.obj"
SEAT_TOP_M, BOARD_M, DEPTH_M, WIDTH_M = 0.2195, 0.04, 0.40, 0.44
LEG_M, LEG_INSET_M = 0.04, 0.03
# A box's faces as corner indices (corner k: x high if k & 1, y if k & 2, z if k & 4),
# counter-clockwise seen from outside.
FACES = ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5))


def box(low, high) -> np.ndarray:
    """(8, 3) the corners of the box from low to high."""
    return np.array([[(low, high)[k >> a & 1][a] for a in range(3)] for k in range(8)], float)


def chair_boxes() -> list[tuple[tuple, tuple]]:
    """(low, high) corners of the seat board and the legs, in the chair's frame."""
    board = ((-DEPTH_M, -WIDTH_M / 2, SEAT_TOP_M - BOARD_M), (0.0, WIDTH_M / 2, SEAT_TOP_M))
    boxes = [board]
    for x in (-LEG_INSET_M, LEG_INSET_M - DEPTH_M):
        for y in (WIDTH_M / 2 - LEG_INSET_M, LEG_INSET_M - WIDTH_M / 2):
            low = (x - LEG_M / 2, y - LEG_M / 2, 0.0)
            boxes.append((low, (x + LEG_M / 2, y + LEG_M / 2, SEAT_TOP_M - BOARD_M)))
    return boxes


def boxes_obj(boxes) -> str:
    """The boxes as OBJ text: 'v' lines and one quad 'f' line per face."""
    lines = ["# drake_standup's chair as a mesh (m, z up, x forward): tools/make_chair_mesh.py"]
    for n, (low, high) in enumerate(boxes):
        lines += [f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in box(low, high)]
        lines += ["f " + " ".join(str(8 * n + k + 1) for k in face) for face in FACES]
    return "\n".join(lines) + "\n"


def triangles(boxes) -> np.ndarray:
    """(m, 3, 3) the boxes' triangles, counter-clockwise seen from outside."""
    tris = []
    for low, high in boxes:
        corners = box(low, high)
        for a, b, c, d in FACES:
            tris += [corners[[a, b, c]], corners[[a, c, d]]]
    return np.array(tris)


def binary_stl(tris: np.ndarray) -> bytes:
    """Triangles as a binary STL (normals left zero, as many writers do)."""
    body = b"".join(struct.pack("<12fH", *([0.0] * 3), *t.ravel(), 0) for t in tris)
    return b"drake_standup test box".ljust(80, b" ") + struct.pack("<I", len(tris)) + body


def ascii_stl(tris: np.ndarray) -> str:
    """Triangles as an ASCII STL."""
    facets = "".join(
        "facet normal 0 0 0\n outer loop\n"
        + "".join(f"  vertex {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in t)
        + " endloop\nendfacet\n"
        for t in tris
    )
    return f"solid box\n{facets}endsolid box\n"


if __name__ == "__main__":
    OBJ.write_text(boxes_obj(chair_boxes()))
    print(f"wrote {OBJ}")
