"""The chair made from the numbers that matter to sitting on it (config ChairConfig).

chair_sdf writes it as SDF text: a seat board whose top is at seat_height_m (rigid
hydroelastic), optionally a cushion on it (compliant hydroelastic, its top at
seat_height_m), four legs and a backrest for show. Its frame 'chair' is on the floor
below the seat's front edge, x forward, as models/chair.sdf (the same chair as a file).

mesh_chair_sdf writes a chair mesh (chair.file an .obj or .stl, config/chair_mesh.py) as
SDF text: the mesh, written again as a plain OBJ where Drake reads it, is the chair's
collision (rigid hydroelastic, all of it) and visual geometry, posed so that the frame
'chair' is on the floor below the middle of the seat's front edge.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

from drake_standup.config.chair import SEAT_BOARD_M, ChairConfig, ChairModel, chair_file
from drake_standup.config.chair_mesh import ChairMesh, is_mesh, obj_text
from drake_standup.config.inputs import chair_mesh
from drake_standup.robot.meshes import cache_dir

# The shipped chair's look (models/chair.sdf): seat 0.40 m deep, 0.44 m wide; legs
# 0.04 m square, inset 0.03 m; a backrest 0.03 m thick from 0.02 m above the seat. m.
SEAT_DEPTH_M, SEAT_WIDTH_M = 0.40, 0.44
_LEG_M, _LEG_INSET_M = 0.04, 0.03
_BACK_THICK_M, _BACK_GAP_M, _BACK_HEIGHT_M, _BACK_X_M = 0.03, 0.02, 0.42, -0.38
# Hunt-Crossley dissipation of the seat and the cushion: rubber-like, as the pads'. s/m.
DISSIPATION_S_PER_M = 5.0
_WOOD, _DARK_WOOD, _FABRIC = "0.55 0.35 0.2 1", "0.4 0.25 0.15 1", "0.25 0.35 0.55 1"


def _box(kind: str, name: str, xyz, size, body: str) -> str:
    pose = " ".join(f"{v:.6g}" for v in (*xyz, 0, 0, 0))
    dims = " ".join(f"{v:.6g}" for v in size)
    return (
        f'      <{kind} name="{name}">\n        <pose>{pose}</pose>\n'
        f"        <geometry><box><size>{dims}</size></box></geometry>\n{body}      </{kind}>\n"
    )


def _proximity(friction: float, modulus_Pa: float | None) -> str:
    kind = (
        "<drake:rigid_hydroelastic/>"
        if modulus_Pa is None
        else "<drake:compliant_hydroelastic/>\n          "
        f"<drake:hydroelastic_modulus>{modulus_Pa:.6g}</drake:hydroelastic_modulus>"
    )
    return (
        "        <drake:proximity_properties>\n"
        f"          {kind}\n"
        f"          <drake:mu_static>{friction:.6g}</drake:mu_static>\n"
        f"          <drake:mu_dynamic>{friction:.6g}</drake:mu_dynamic>\n"
        f"          <drake:hunt_crossley_dissipation>{DISSIPATION_S_PER_M:g}"
        "</drake:hunt_crossley_dissipation>\n"
        "        </drake:proximity_properties>\n"
    )


def _material(rgba: str) -> str:
    return f"        <material><diffuse>{rgba}</diffuse></material>\n"


def chair_sdf(chair: ChairConfig) -> str:
    """The chair of chair's numbers as SDF text (config.rules checked the cushion fits)."""
    top = chair.seat_height_m
    cushion = chair.cushion
    board_top = top - (cushion.thickness_m if cushion else 0.0)
    x_mid, size = -SEAT_DEPTH_M / 2, (SEAT_DEPTH_M, SEAT_WIDTH_M, SEAT_BOARD_M)
    board = (x_mid, 0.0, board_top - SEAT_BOARD_M / 2)
    parts = [
        _box("collision", "seat_collision", board, size, _proximity(chair.friction, None)),
        _box("visual", "seat", board, size, _material(_WOOD)),
    ]
    if cushion:
        layer = (x_mid, 0.0, top - cushion.thickness_m / 2)
        layer_size = (SEAT_DEPTH_M, SEAT_WIDTH_M, cushion.thickness_m)
        soft = _proximity(chair.friction, cushion.modulus_Pa)
        parts.append(_box("collision", "cushion_collision", layer, layer_size, soft))
        parts.append(_box("visual", "cushion", layer, layer_size, _material(_FABRIC)))
    leg_z = board_top - SEAT_BOARD_M
    for side, y in (("left", 1), ("right", -1)):
        for end, x in (("front", -_LEG_INSET_M), ("back", _LEG_INSET_M - SEAT_DEPTH_M)):
            xyz = (x, y * (SEAT_WIDTH_M / 2 - _LEG_INSET_M), leg_z / 2)
            legs = (_LEG_M, _LEG_M, leg_z)
            parts.append(_box("visual", f"leg_{end}_{side}", xyz, legs, _material(_DARK_WOOD)))
    back = (_BACK_X_M, 0.0, top + _BACK_GAP_M + _BACK_HEIGHT_M / 2)
    back_size = (_BACK_THICK_M, SEAT_WIDTH_M, _BACK_HEIGHT_M)
    parts.append(_box("visual", "backrest", back, back_size, _material(_WOOD)))
    return (
        '<?xml version="1.0"?>\n<sdf version="1.9" xmlns:drake="http://drake.mit.edu">\n'
        '  <model name="chair">\n    <link name="chair">\n'
        + "".join(parts)
        + "    </link>\n  </model>\n</sdf>\n"
    )


def mesh_chair_sdf(chair: ChairConfig, mesh: ChairMesh) -> str:
    """The chair mesh as SDF text, with chair's friction (its seat height is the mesh's:
    config/chair_kind.py with_chair_seat)."""
    seat = mesh.seat
    pose = f"{-seat.front_edge_x_m:.9g} {-seat.centre_y_m:.9g} {-seat.floor_z_m:.9g} 0 0 0"
    geometry = f"<geometry><mesh><uri>{cached_obj(mesh).as_uri()}</uri></mesh></geometry>"
    parts = [
        f'      <{kind} name="{name}">\n        <pose>{pose}</pose>\n        {geometry}\n'
        f"{body}      </{kind}>\n"
        for kind, name, body in (
            ("collision", "chair_collision", _proximity(chair.friction, None)),
            ("visual", "chair", _material(_WOOD)),
        )
    ]
    return (
        '<?xml version="1.0"?>\n<sdf version="1.9" xmlns:drake="http://drake.mit.edu">\n'
        '  <model name="chair">\n    <link name="chair">\n'
        + "".join(parts)
        + "    </link>\n  </model>\n</sdf>\n"
    )


def cached_obj(mesh: ChairMesh) -> Path:
    """The mesh as a plain OBJ file (Drake reads OBJ, not STL), in the generated-asset cache
    beside the robot's converted meshes (robot/meshes.py cache_dir), named by its content:
    written once, atomically, for every run that loads it."""
    text = obj_text(mesh)
    folder = cache_dir() / "chairs"
    path = folder / f"{hashlib.sha256(text.encode()).hexdigest()[:20]}.obj"
    if not path.is_file():
        folder.mkdir(parents=True, exist_ok=True)
        handle, part = tempfile.mkstemp(".obj", dir=folder)
        with os.fdopen(handle, "w") as f:
            f.write(text)
        os.replace(part, path)
    return path


def standard_chair(config: ChairConfig) -> ChairModel:
    """The chair of the scenario's numbers, or of chair.file: an SDF, or a mesh whose seat
    is found in it (config/chair_mesh.py)."""
    if not config.file:
        return ChairModel(config.seat_height_m, sdf=chair_sdf(config))
    if is_mesh(config.file):
        mesh = chair_mesh(config.file)
        return ChairModel(mesh.seat.height_m, sdf=mesh_chair_sdf(config, mesh))
    return ChairModel(config.seat_height_m, path=chair_file(config.file))
