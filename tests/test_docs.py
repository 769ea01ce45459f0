"""The docs are true to the code, and kept so: every link, file, module name and cited
section a doc or a docstring names exists, every commit a doc names is in the history,
and every metrics.json key of a run is in docs/outputs.md (the default scenario's run in
tests/e2e/test_standup_e2e.py). Each check is also shown to fail on a broken name."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import docs_check
import pytest
from docs_check import (
    DOCUMENTS,
    PACKAGE,
    REPO,
    broken_links,
    metrics_section,
    missing_commits,
    missing_names,
    missing_paths,
    missing_sections,
    named_commits,
    outside_citations,
    reference_keys,
    undocumented_metrics,
    unknown_citations,
)

# Sources whose docstrings and comments name files and sections.
SOURCES = [
    *sorted(PACKAGE.rglob("*.py")),
    *sorted((REPO / "tests").rglob("*.py")),
    *sorted((REPO / "scenarios").glob("*.yaml")),
    *sorted((REPO / "sweeps").glob("*.yaml")),
    REPO / "run_diagram.py",
    REPO / "pyproject.toml",
]
SOURCES = [p for p in SOURCES if p.name != "docs_check.py"]  # its own examples


def _ids(paths: list[Path]) -> list[str]:
    return [str(p.relative_to(REPO)) for p in paths]


@pytest.mark.parametrize("doc", DOCUMENTS, ids=_ids(DOCUMENTS))
def test_every_link_of_a_doc_leads_to_a_file_and_heading(doc):
    assert broken_links(doc) == []


@pytest.mark.parametrize("doc", DOCUMENTS, ids=_ids(DOCUMENTS))
def test_every_file_and_module_name_a_doc_names_exists(doc):
    assert missing_paths(doc) == []
    # The changelog names the old places on purpose.
    assert missing_names(doc, backticked_only=True, qualified=doc.name != "CHANGELOG.md") == []


@pytest.mark.parametrize("source", SOURCES, ids=_ids(SOURCES))
def test_every_file_a_docstring_or_comment_names_exists(source):
    assert missing_paths(source) == []
    assert missing_names(source, qualified=False) == []


@pytest.mark.parametrize("path", DOCUMENTS + SOURCES, ids=_ids(DOCUMENTS + SOURCES))
def test_every_section_cited_by_its_heading_exists(path):
    assert missing_sections(path) == []


@pytest.mark.skipif(
    shutil.which("git") is None or not (REPO / ".git").exists(), reason="not a git checkout"
)
def test_every_commit_a_doc_names_is_in_the_history():
    named = set().union(*(named_commits(doc.read_text()) for doc in DOCUMENTS))
    assert len(named) >= 10  # the docs do cite commits: the check has something to check
    assert missing_commits(named) == []


@pytest.mark.parametrize("path", DOCUMENTS + SOURCES, ids=_ids(DOCUMENTS + SOURCES))
def test_every_citation_is_an_entry_of_the_references(path):
    """Sources are cited by their docs/references.md entry ([authors-code]) or by the
    paper, never by a file outside the repository."""
    assert unknown_citations(path) == []
    assert outside_citations(path) == []


def test_the_references_are_cited():
    """Each entry is cited somewhere in the package, scenarios, sweeps or docs, and the
    entries the code leans on most are there."""
    keys = reference_keys()
    assert {"tirupachuri2019", "nava2016", "authors-code", "icub-logs", "early-probe"} <= keys
    cited = set()
    for path in DOCUMENTS + SOURCES:
        if path != docs_check.REFERENCES_MD:
            cited |= set(docs_check._CITATION.findall(docs_check.prose(path)))
    assert keys - cited == set()


def test_the_scenario_block_the_docs_call_defaults_is_the_defaults():
    """docs/outputs.md's public keys "with their defaults" are Scenario()'s."""
    from drake_standup.config import Scenario

    block = docs_check.scenario_block(docs_check.OUTPUTS_MD, "## Scenario files")
    assert docs_check.not_defaults(block, Scenario()) == []
    assert docs_check.not_defaults("duration_s: 15.0\n", Scenario()) == [
        "duration_s: 15.0, default 5.0"
    ]


def test_the_checks_find_a_name_broken_on_purpose(tmp_path):
    """Each check above, on a copy of a true text with one name broken."""
    design = REPO / "docs" / "design.md"
    doc = REPO / "docs" / "broken.md"  # never written: the checks take the text
    assert broken_links(doc, "[the layout](design.md#layout)") == []
    assert broken_links(doc, "[the layout](design.md#no-such-heading)") == [
        "design.md#no-such-heading"
    ]
    assert broken_links(doc, "[gone](no_such_file.md)") == ["no_such_file.md"]
    assert missing_paths(doc, "see drake_standup/sim/diagram.py") == []
    assert missing_paths(doc, "see drake_standup/sim/diagrams.py") == [
        "drake_standup/sim/diagrams.py"
    ]
    assert missing_names(doc, "`diagram.on_step_grid`", backticked_only=True) == []
    assert missing_names(doc, "`diagram.on_step_grids`", backticked_only=True) == [
        "diagram.on_step_grids"
    ]
    assert missing_names(doc, "`references.static_lean`", backticked_only=True) == [
        "references.static_lean"
    ]
    assert missing_names(doc, "`drake_standup.sim.diagram.nothing`", backticked_only=True)
    assert missing_names(doc, "(see reference.py)", qualified=False) == ["reference.py"]
    assert missing_sections(design, 'docs/design.md, "Layout"') == []
    assert missing_sections(design, 'docs/design.md, "The house"') == [
        'docs/design.md, "The house"'
    ]
    if (REPO / ".git").exists():
        assert missing_commits({"0000000abc"}) == ["0000000abc"]
    assert unknown_citations(doc, "K_P 1 ([authors-code]); mu ([no-such-entry])") == [
        "no-such-entry"
    ]
    assert outside_citations(doc, "friction 1/3 (SPEC 3; ../shared/SPEC.md)") == [
        "SPEC 3",
        "../shared/SPEC.md)",
    ]
    assert outside_citations(doc, "the sensors (SPEC: the URDF's), SPEC section 11") == [
        "SPEC",
        "SPEC section 11",
    ]
    assert outside_citations(doc, "a spec, the Spec, SPECS of a motor") == []
    assert named_commits("at 745f4cd, not 1234567 nor abcdefa") == {"745f4cd"}
    assert docs_check.slug("Issue 46, fifth part: the soles' last slaps") == (
        "issue-46-fifth-part-the-soles-last-slaps"
    )


def test_every_metric_of_the_seated_run_is_documented(seated_run):
    _, _, out = seated_run
    metrics = json.loads((out / "metrics.json").read_text())
    assert "recording_bytes" in metrics  # the fixture records: that key is checked too
    assert undocumented_metrics(metrics) == []


def test_the_check_finds_an_undocumented_key():
    section = metrics_section()
    assert undocumented_metrics({"success": True, "no_such_metric_N": 1.0}, section) == [
        "no_such_metric_N"
    ]
    # A key named only outside the section does not count: "signals.npz" is not a metric.
    assert undocumented_metrics({"time_s": 0.0}, section) == ["time_s"]


def test_the_design_is_short_and_its_decisions_are_records():
    """docs/design.md is the design today (at most 500 lines); each measured decision is
    a record in docs/decisions/ with its question, its choice and its commit."""
    assert len((REPO / "docs" / "design.md").read_text().splitlines()) <= 500
    records = sorted((REPO / "docs" / "decisions").glob("[0-9][0-9][0-9]-*.md"))
    assert len(records) >= 10
    index = (REPO / "docs" / "decisions" / "README.md").read_text()
    for record in records:
        text = record.read_text()
        assert "**Question.**" in text and "**Choice.**" in text, record.name
        assert named_commits(text.split("## What was measured")[0]), record.name
        assert f"]({record.name})" in index, record.name
