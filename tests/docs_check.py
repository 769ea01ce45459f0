"""What the tests check the docs against (imported by the tests, not collected)."""

from __future__ import annotations

from pathlib import Path

OUTPUTS_MD = Path(__file__).resolve().parent.parent / "docs" / "outputs.md"


def metrics_section(text: str | None = None) -> str:
    """docs/outputs.md's "## metrics.json" section."""
    text = OUTPUTS_MD.read_text() if text is None else text
    start = text.index("\n## metrics.json")
    end = text.find("\n## ", start + 1)
    return text[start : end if end >= 0 else len(text)]


def undocumented_metrics(metrics: dict, section: str | None = None) -> list[str]:
    """The keys of a run's metrics.json that the section does not name as `key`."""
    section = metrics_section() if section is None else section
    return sorted(key for key in metrics if f"`{key}`" not in section)
