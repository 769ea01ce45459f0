"""drake-standup compare: the helpers it resolves, its table and summary from records
(fast), and the reactive partner answered three ways on the Dask cluster (slow): the
paper's claim that advancing beats a stiff tracker on a partner whose pull depends on how
the robot moves."""

from __future__ import annotations

import json

import numpy as np
import pytest

from drake_standup.config import RESPONSES, load_scenario, parse_scenario
from drake_standup.studies import compare
from drake_standup.studies.sweep_file import expand, load_sweep
from drake_standup.studies.sweep_table import read_table


def test_a_campaign_helper_is_that_runs_overrides_and_each_response_is_one_more():
    """helpers#3 is run 3 of the helpers sweep: its base and overrides; each response
    adds response = R, and the scenario it gives is the sweep's run with that response."""
    helper = compare.resolve_helper("helpers#3")
    spec = load_sweep("helpers")
    run = expand(spec)[3]
    assert helper.base_text == spec.base_text
    assert list(helper.overrides) == run.overrides
    runs = compare._runs([helper], list(RESPONSES))
    assert [r["params"] for r in runs] == [
        {"helper": "helpers#3", "response": response} for response in RESPONSES
    ]
    for r, response in zip(runs, RESPONSES):
        scenario = parse_scenario(r["base_text"], "x", r["overrides"])
        alone = parse_scenario(spec.base_text, "x", run.overrides)
        assert scenario.response == response
        assert scenario.human == alone.human
    assert len({r["run_id"] for r in runs}) == 3


def test_set_overrides_every_helpers_runs_and_keys_them_apart():
    """compare --set robot.hardware=icub: each run's scenario has it (and the rate it
    sets), and the runs are other runs than without it (their ids differ)."""
    helper = compare.resolve_helper("reactive")
    plain = compare._runs([helper], ["advancement"])
    runs = compare._runs([helper], ["advancement"], (("robot.hardware", "icub"),))
    scenario = parse_scenario(runs[0]["base_text"], "x", runs[0]["overrides"])
    assert scenario.robot.hardware == "icub" and scenario.controller_period_s == 0.01
    assert runs[0]["run_id"] != plain[0]["run_id"]


def _record(helper, response, t, work, success=True):
    metrics = {
        "success": success,
        "failure_reason": None if success else "fell: the CoM left the support",
        "standup_time_s": t,
        "helper_work_J": work,
        "helper_positive_work_J": work + 1.0,
        "helper_peak_force_N": 20.0,
        "helper_impulse_Ns": 100.0,
        "path_deviation_max_m": 0.02,
        "held_back_s": 0.0,
    }
    return {
        "index": 0,
        "run_id": f"{helper}-{response}",
        "params": {"helper": helper, "response": response},
        "metrics": metrics,
    }


RECORDS = [
    _record("reactive", "advancement", 2.71, 9.6),
    _record("reactive", "stiff", 3.51, 4.7),
    _record("reactive", "compliant", 3.48, 3.0),
    _record("pushy", "advancement", None, 1.0, success=False),
    _record("pushy", "stiff", 3.0, 2.0),
]


def test_the_table_says_how_much_sooner_than_stiff(tmp_path):
    """1 - 2.71 / 3.51 = 22.8 %: the table's +23 %, the summary's 23 %; a run that did
    not stand up has no time and no comparison, its reason in the table; results.csv
    has a row per helper and response, helper and response first."""
    assert compare.sooner_than_stiff(RECORDS[0]["metrics"], RECORDS[1]["metrics"]) == (
        pytest.approx(1.0 - 2.71 / 3.51)
    )
    assert compare.sooner_than_stiff(RECORDS[3]["metrics"], RECORDS[4]["metrics"]) is None
    text = compare.markdown(RECORDS)
    rows = [line for line in text.splitlines()[2:]]
    assert len(rows) == len(RECORDS)
    assert rows[0].startswith("| reactive | advancement | yes | 2.71 | +23 % | 0.0 | 9.6 |")
    assert rows[2].startswith("| reactive | compliant | yes | 3.48 | +1 % |")
    assert rows[3].startswith("| pushy | advancement | no: fell: the CoM left the support |  |  |")
    lines = compare.summary(RECORDS)
    assert lines[0] == "compare: 5 runs, 4 stood up, 1 did not"
    assert lines[1].endswith("advancement 23 % sooner than stiff")
    assert "advancement did not stand up" in lines[2]
    paths = compare.write_outputs(RECORDS, tmp_path)
    table = read_table(paths["table"])
    assert [(r["helper"], r["response"]) for r in table] == [
        (r["params"]["helper"], r["params"]["response"]) for r in RECORDS
    ]
    assert list(table[0])[2:4] == ["helper", "response"]
    assert paths["figure"].stat().st_size > 20_000


@pytest.mark.slow
def test_against_the_reactive_partner_advancement_is_sooner_than_stiff(tmp_path, monkeypatch):
    """The reactive partner, answered three ways on a LocalCluster: all stand up;
    stiff and compliant hold psi = t (psi_final is the duration); advancement stands up
    at least 15 % sooner than stiff (issue 23); every run has the helper's work; started
    again, the comparison simulates nothing and writes the same table."""
    records = compare.run_compare(
        [compare.resolve_helper("reactive")], list(RESPONSES), tmp_path, progress=False
    )
    by = {r["params"]["response"]: r["metrics"] for r in records}
    assert all(m["success"] for m in by.values()), by
    duration = load_scenario("reactive").duration_s
    for response in ("stiff", "compliant"):
        assert by[response]["psi_final"] == pytest.approx(duration, abs=1e-9)
        assert by[response]["response"] == response
    assert by["advancement"]["psi_final"] > duration
    assert by["advancement"]["standup_time_s"] <= 0.85 * by["stiff"]["standup_time_s"]
    for m in by.values():
        assert np.isfinite(m["helper_work_J"]) and m["helper_peak_force_N"] > 0.0
    first = (tmp_path / "results.csv").read_text()
    saved = sorted(p.name for p in (tmp_path / "runs").glob("*.json"))
    assert len(saved) == 3
    assert json.loads((tmp_path / "runs" / saved[0]).read_text())["metrics"]["success"]

    def no_cluster(*args, **kwargs):
        raise AssertionError("a resumed comparison simulated again")

    monkeypatch.setattr("drake_standup.studies.sweep.run_on_cluster", no_cluster)
    compare.run_compare(
        [compare.resolve_helper("reactive")], list(RESPONSES), tmp_path, progress=False
    )
    assert (tmp_path / "results.csv").read_text() == first


def test_the_docs_tables_are_what_their_csvs_give():
    """Each results table of the docs is written from its campaign's CSV
    (studies/doc_tables.py): one source for each number."""
    from drake_standup.studies.doc_tables import TABLES, main, placed

    for table in TABLES:
        text = table.document.read_text()
        assert placed(text, table) == text, f"{table.name}: run doc_tables"
    assert main(["--check"]) == 0


def test_a_table_edited_by_hand_is_caught(tmp_path):
    import dataclasses

    from drake_standup.studies.doc_tables import TABLES, placed

    table = TABLES[0]
    document = tmp_path / "doc.md"
    edited = placed(table.document.read_text(), table).replace("| 2.85 |", "| 2.75 |", 1)
    document.write_text(edited)
    moved = dataclasses.replace(table, document=document)
    assert placed(document.read_text(), moved) != document.read_text()
