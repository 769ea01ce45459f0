"""What a run writes: self-contained HTML with the recording, the DOT graph."""

from __future__ import annotations

import base64
import re

import pytest

from drake_standup.config import load_scenario
from drake_standup.sim.diagram import build_diagram


def _meshcat_commands(html: str) -> list[bytes]:
    """The msgpack commands Meshcat's static HTML replays, base64-decoded."""
    blobs = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"', html)
    return [base64.b64decode(b) for b in blobs]


@pytest.mark.slow
def test_html_is_self_contained_and_holds_the_recording(seated_run):
    _, result, out = seated_run
    html = (out / "recording.html").read_text()
    # No external script, stylesheet or image: it must play back offline.
    assert not re.search(r"<script[^>]+src=", html)
    assert not re.search(r"<link[^>]+href=[\"']https?:", html)
    commands = _meshcat_commands(html)
    assert len(commands) > 10
    animations = [c for c in commands if b"set_animation" in c]
    assert len(animations) == 1
    # The animation moves the robot's bodies (paths under the plant's iCub).
    assert b"iCub" in animations[0]
    # Meshes are shipped inside the page (OBJ text), not referenced by URL.
    assert sum(c.count(b"_meshfile_geometry") for c in commands) >= 30
    assert result.metrics["recording_bytes"] == len(html.encode())


def test_dot_names_every_system(tmp_path):
    """The exported DOT (two levels deep) names every system of the diagram and of its
    two boxes, the station and the stand-up controller."""
    from drake_standup.outputs.recording import export_diagram

    built = build_diagram(load_scenario())
    dot = export_diagram(built.diagram, tmp_path)[0].read_text()
    names = [s.get_name() for s in built.diagram.GetSystems()]
    for box in ("station", "standup_controller"):
        names += [s.get_name() for s in built.diagram.GetSubsystemByName(box).GetSystems()]
    assert len(names) >= 20
    for name in names:
        assert f"name={name}" in dot, name
    for expected in ("plant", "scene_graph", "contact_forces", "controller"):
        assert expected in names
