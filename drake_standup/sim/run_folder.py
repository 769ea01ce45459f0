"""What a run leaves in its folder (docs/outputs.md): the Meshcat recording, the system
diagram, signals.npz, the scenario it simulated, the two figures and metrics.json."""

from __future__ import annotations

from pathlib import Path

from pydrake.common.yaml import yaml_dump_typed

from drake_standup.outputs import figures
from drake_standup.outputs.estimation import figure_estimation
from drake_standup.outputs.json_files import write_metrics
from drake_standup.outputs.recording import export_diagram, write_recording
from drake_standup.outputs.signals import write_signals
from drake_standup.sim.runner import Run, RunResult


def write_run(
    run: Run, result: RunResult, out_dir: Path, baseline: dict | None = None
) -> dict[str, Path]:
    """Writes the run's files into out_dir (made if missing) and returns them by name;
    baseline: the psi = t run's signals, drawn faded in figure_advancement.png. The
    recording's size goes into result.metrics (recording_bytes) before metrics.json."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = {}
    if run.meshcat is not None:
        run.built.visualizer.StopRecording()
        run.built.visualizer.PublishRecording()
        files["recording"] = out_dir / "recording.html"
        result.metrics["recording_bytes"] = write_recording(run.meshcat, files["recording"])
    for path in export_diagram(run.built.diagram, out_dir / "diagrams"):
        files[path.suffix.lstrip(".")] = path
    files["signals"] = out_dir / "signals.npz"
    write_signals(files["signals"], result.signals)
    # Every value simulated, as a scenario file (--scenario reruns it).
    files["scenario"] = out_dir / "scenario.yaml"
    files["scenario"].write_text(yaml_dump_typed(run.scenario))
    entries = result.metrics.get("state_entry_times_s", [])
    files["figure_advancement"] = out_dir / "figure_advancement.png"
    figures.figure_advancement(result.signals, baseline, entries, files["figure_advancement"])
    files["figure_tracking"] = out_dir / "figure_tracking.png"
    figures.figure_tracking(result.signals, entries, files["figure_tracking"])
    if "estimated_com_W" in result.signals:  # robot.hardware: icub
        files["figure_estimation"] = out_dir / "figure_estimation.png"
        figure_estimation(result.signals, entries, files["figure_estimation"])
    files["metrics"] = out_dir / "metrics.json"
    write_metrics(files["metrics"], result.metrics)
    return files
