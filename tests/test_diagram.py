"""The exported diagram shows the stand-up systems and how they connect."""

from __future__ import annotations

import re

import pytest

from drake_standup.config import load_scenario
from drake_standup.diagram import build_diagram


@pytest.fixture(scope="module")
def built():
    return build_diagram(load_scenario())


def _node_ids(dot: str) -> dict[str, str]:
    """System name -> DOT node id, from the node labels ('name=...')."""
    pattern = (
        r"(s\d+) \[shape=none, border=0, label=<\s*<TABLE[^>]*>\s*<TR><TD[^>]*>\s*"
        r"<B>[^<]*</B><BR/>\s*name=([^<\s]+)"
    )
    return {name: node for node, name in re.findall(pattern, dot)}


def _edges(dot: str) -> set[tuple[str, str]]:
    """(source id, destination id) of every edge in Drake's DOT."""
    return {(a, b) for a, b in re.findall(r"(s\d+):\w+:e\s*->\s*(s\d+):\w+:w", dot)}


def test_dot_shows_systems_and_connections(built):
    diagram = built.diagram
    dot = diagram.GetGraphvizString(max_depth=1)
    systems = {s.get_name(): s for s in diagram.GetSystems()}
    for name in ("human", "advancement", "com_reference", "state_machine", "plant", "sensing"):
        assert name in systems
        assert f"name={name}" in dot
    gid = _node_ids(dot)
    assert set(systems) <= set(gid)
    edges = _edges(dot)
    expected = [
        ("human", "plant"),  # the pull acts on the robot
        ("human", "state_machine"),  # and is measured
        ("plant", "sensing"),
        ("sensing", "advancement"),
        ("advancement", "com_reference"),  # psi, psi_dot, psi_ddot
        ("com_reference", "advancement"),  # the path tangent
        ("state_machine", "com_reference"),  # the active segment
        ("advancement", "state_machine"),  # psi
        ("contact_forces", "state_machine"),  # feet normal forces
    ]
    for src, dst in expected:
        assert (gid[src], gid[dst]) in edges, (src, dst)
