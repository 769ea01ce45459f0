#!/usr/bin/env python
"""Writes recordings/default_pull.csv: the default scenario's scripted pull
(scenarios/assisted.yaml, human.pulls) sampled at 1 kHz from t = 0 to its duration_s, as
a force plate would log it (world frame, forces only). Generated, not a measurement of a
person: scenarios/recorded.yaml replays it and stands up as assisted.yaml does. Its
format: docs/helpers.md.

    PYTHONPATH=. python tools/record_default_pull.py

tests/helper/test_recorded.py checks that the shipped file is what this writes.
"""

from pathlib import Path

from drake_standup.helper.recorded import write_scripted_recording

REPO = Path(__file__).resolve().parent.parent

if __name__ == "__main__":
    write_scripted_recording(
        REPO / "scenarios" / "assisted.yaml", REPO / "recordings" / "default_pull.csv"
    )
