"""chair.kind: the chair a plug-in makes of the chair: section (config/plugins.py), checked.

make_chair(chair) resolves chair.kind (standard: world/chair.py standard_chair; a chair of
your own by name or module:attribute), calls it and checks what it made: a ChairModel whose
SDF parses into one model with a frame 'chair' that welds to the world (inputs.py, as for
chair.file) and a seat height within SEAT_HEIGHTS_M. with_chair_seat sets the scenario's
seat_height_m from it when the scenario loads, so the seating and the plan read the
chair's own seat.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import tempfile
from pathlib import Path

from drake_standup.config.chair import ChairConfig, ChairModel
from drake_standup.config.chair_mesh import SEAT_HEIGHTS_M
from drake_standup.config.inputs import CHAIR_CONTENT, sdf_problem
from drake_standup.config.plugins import PluginError, resolve

_ACCEPTED = (
    "ChairModel(seat_height_m, sdf=... or path=...) of drake_standup.config.chair, "
    f"the seat {SEAT_HEIGHTS_M[0]:g}-{SEAT_HEIGHTS_M[1]:g} m high"
)


def make_chair(chair: ChairConfig) -> ChairModel:
    """The chair chair.kind makes of chair, checked (module docstring)."""
    spec = chair.kind
    model = resolve("chairs", spec).obj(chair)
    if not isinstance(model, ChairModel) or (model.path is None) == (not model.sdf):
        raise PluginError(f"chair.kind: '{spec}' made {_what(model)}; accepted: {_ACCEPTED}")
    low, high = SEAT_HEIGHTS_M
    height = model.seat_height_m
    if not (isinstance(height, int | float) and math.isfinite(height) and low <= height <= high):
        raise PluginError(
            f"chair.kind: '{spec}' made a seat {height!r} m high; accepted: {_ACCEPTED}"
        )
    if spec != "standard":  # the standard chair's file was checked with chair.file
        problem = _problem(model)
        if problem:
            raise PluginError(f"chair.kind: '{spec}' made a model that {problem}; {CHAIR_CONTENT}")
    return model


def with_chair_seat(chair: ChairConfig) -> ChairConfig:
    """chair with seat_height_m the made chair's (to the micrometre)."""
    height = round(float(make_chair(chair).seat_height_m), 6)
    if height == round(chair.seat_height_m, 6):
        return chair
    return dataclasses.replace(chair, seat_height_m=height)


def _problem(model: ChairModel) -> str | None:
    if model.path is not None:
        path = Path(model.path)
        if not path.is_file():
            return f"names the file '{path}', which is not there"
        stat = path.stat()
        return sdf_problem(str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    return _sdf_text_problem(model.sdf)


@functools.lru_cache(maxsize=16)
def _sdf_text_problem(text: str) -> str | None:
    """sdf_problem of SDF text, parsed once per text: validation, the seat's height at load
    and the scene each make the chair, and each temporary file would be a new one to it."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "chair.sdf"
        path.write_text(text, encoding="utf-8")
        stat = path.stat()
        return sdf_problem(str(path), stat.st_mtime_ns, stat.st_size)


def _what(model) -> str:
    if isinstance(model, ChairModel):
        return "a ChairModel with both or neither of sdf and path"
    return f"a {type(model).__name__}"
