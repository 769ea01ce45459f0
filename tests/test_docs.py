"""The docs name what a run writes: every metrics.json key of a run is in docs/outputs.md's
metrics.json section (the assisted run's in tests/e2e/test_standup_e2e.py)."""

from __future__ import annotations

import json

from docs_check import metrics_section, undocumented_metrics


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
