"""What a run leaves behind: metrics, the Meshcat HTML, the system diagram."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.framework import Diagram


def json_safe(x):
    """x with numpy scalars and arrays as Python values and non-finite floats
    as None (JSON has no NaN)."""
    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, np.ndarray)):
        return [json_safe(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def write_metrics(path: Path, metrics: dict) -> None:
    """JSON with non-finite numbers written as null."""
    path.write_text(json.dumps(json_safe(metrics), indent=2) + "\n")


def write_json(path: Path, data) -> None:
    """data as JSON (json_safe), written whole or not at all (a temporary file
    renamed over path), its folder made if needed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(json_safe(data), indent=1) + "\n")
    tmp.replace(path)


# --- signals.npz ---------------------------------------------------------------

# Version of signals.npz's layout; bump it (and keep load_signals reading the
# old ones) when an array changes meaning or shape.
SIGNALS_FORMAT = 1


def write_signals(path: Path, signals: dict[str, np.ndarray]) -> None:
    """Saves the run's logged time series (see README, "signals.npz").

    Strings are stored as numpy unicode arrays, so numpy.load needs no pickle.
    """
    np.savez_compressed(path, format=np.array(SIGNALS_FORMAT), **signals)


def load_signals(path: Path) -> dict[str, np.ndarray]:
    """signals.npz as a dict of arrays (the 'format' entry left out)."""
    with np.load(path) as data:
        version = int(data["format"]) if "format" in data.files else 1
        if version > SIGNALS_FORMAT:
            raise ValueError(
                f"{path}: signals format {version} is newer than this drake_standup "
                f"reads ({SIGNALS_FORMAT})"
            )
        return {k: data[k] for k in data.files if k != "format"}


def write_recording(meshcat: Meshcat, path: Path) -> int:
    """Saves Meshcat's self-contained HTML (scene + recording); returns bytes."""
    html = meshcat.StaticHtml()
    path.write_text(html)
    return len(html.encode())


def export_diagram(diagram: Diagram, directory: Path, stem: str = "standup") -> list[Path]:
    """Writes <stem>.dot and, where graphviz's dot exists, <stem>.svg."""
    directory.mkdir(parents=True, exist_ok=True)
    dot_path = directory / f"{stem}.dot"
    dot_path.write_text(diagram.GetGraphvizString(max_depth=1))
    written = [dot_path]
    dot = shutil.which("dot")
    if dot is None:
        print(
            f"notice: graphviz 'dot' not found; wrote {dot_path} only "
            "(apt-get install graphviz, then: dot -Tsvg -O " + str(dot_path) + ")"
        )
        return written
    svg_path = directory / f"{stem}.svg"
    subprocess.run([dot, "-Tsvg", str(dot_path), "-o", str(svg_path)], check=True)
    written.append(svg_path)
    return written


def group_normal_forces(signals: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Group name -> summed normal force of its pads over time, (N,) each, in
    the order the groups first appear in pad_groups."""
    groups = [str(g) for g in signals["pad_groups"]]
    normal = signals["pad_normal_force_N"]
    return {
        group: normal[:, [i for i, g in enumerate(groups) if g == group]].sum(axis=1)
        for group in dict.fromkeys(groups)
    }


def seated_metrics(signals: dict[str, np.ndarray], weight_N: float, settle_s: float = 0.5) -> dict:
    """CoM drift after settling and the contact forces at the end of the run."""
    t = signals["time_s"]
    com = signals["com_W"]
    metrics: dict = {"weight_N": weight_N}
    if len(t) == 0:
        return metrics
    after = t >= settle_s
    if after.any():
        drift = np.linalg.norm(com[after] - com[np.argmax(after)], axis=1)
        metrics["com_drift_after_settle_m"] = float(drift.max())
    metrics["com_final_m"] = com[-1]
    final = signals["pad_forces_W"][-1]  # (pads, 3)
    metrics["contact_force_N"] = {str(n): final[i] for i, n in enumerate(signals["pad_names"])}
    metrics["contact_normal_force_N"] = {
        g: float(fz[-1]) for g, fz in group_normal_forces(signals).items()
    }
    metrics["contact_force_total_N"] = final.sum(axis=0)
    return metrics


def advancement_metrics(
    psi_final: float, psi_dot: np.ndarray, entry_times_s: tuple[float, ...]
) -> dict:
    """psi at the end, the range of psi_dot, when each state was entered."""
    if len(psi_dot) == 0:
        return {"psi_final": float(psi_final)}
    return {
        "psi_final": float(psi_final),
        "psi_dot_min": float(np.min(psi_dot)),
        "psi_dot_max": float(np.max(psi_dot)),
        "state_entry_times_s": [None if np.isnan(t) else float(t) for t in entry_times_s],
    }


# --- Figures -----------------------------------------------------------------

STATE_COLORS = {2: "tab:orange", 3: "tab:green", 4: "tab:purple"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _mark_states(ax, entry_times_s, label: bool = False) -> None:
    for k, t in enumerate(entry_times_s[1:], start=2):
        if t is not None and np.isfinite(t):
            ax.axvline(
                t, color=STATE_COLORS[k], ls=":", lw=1.2, label=f"state {k}" if label else None
            )


def figure_advancement(
    signals: dict[str, np.ndarray],
    baseline: dict[str, np.ndarray] | None,
    entry_times_s,
    path: Path,
) -> None:
    """The paper's Fig. 3: hand wrench, psi_dot, psi, and the CoM reference
    (with the same run's reference without advancement, faded)."""
    plt = _plt()
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    (ax_f, ax_dpsi), (ax_psi, ax_ref) = axes
    t = signals["time_s"]

    w = signals["hand_wrenches_W"]
    for hand, col, ls in (("left", 0, "-"), ("right", 6, "--")):
        for axis, color in ((0, "tab:red"), (2, "tab:blue")):
            name = "xyz"[axis]
            ax_f.plot(t, w[:, col + 3 + axis], ls, color=color, label=f"{hand} f_{name}")
    ax_f.set_ylabel("hand force [N]")
    ax_f.set_title("(a) interaction wrench at the hands")
    ax_f.legend(fontsize=8, ncol=2)

    ax_dpsi.plot(t, signals["psi_dot"], color="tab:green")
    ax_dpsi.axhline(1.0, color="gray", lw=0.8)
    ax_dpsi.set_ylabel("psi_dot [-]")
    ax_dpsi.set_title("(b) rate of the free parameter")

    ax_psi.plot(t, signals["psi"], color="tab:green", label="psi")
    ax_psi.plot(t, t, color="gray", lw=0.8, ls="--", label="psi = t")
    ax_psi.set_ylabel("psi [-]")
    ax_psi.set_title("(c) free parameter")
    ax_psi.legend(fontsize=8)

    ref = signals["com_reference_W"]
    for axis, color in ((0, "tab:red"), (2, "tab:blue")):
        name = "xyz"[axis]
        ax_ref.plot(t, ref[:, axis], color=color, label=f"x_d,{name} with advancement")
        if baseline is not None:
            ax_ref.plot(
                baseline["time_s"],
                baseline["com_reference_W"][:, axis],
                color=color,
                alpha=0.3,
                lw=3,
                label=f"x_d,{name} psi = t",
            )
    ax_ref.set_ylabel("CoM reference [m]")
    ax_ref.set_title("(d) CoM reference")
    ax_ref.legend(fontsize=8)
    for ax in axes.flat:
        _mark_states(ax, entry_times_s)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_tracking(signals: dict[str, np.ndarray], entry_times_s, path: Path) -> None:
    """CoM against its reference, and the contact normal forces, with the
    state switches marked."""
    plt = _plt()
    fig, (ax_x, ax_z, ax_f) = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    t = signals["time_s"]
    for ax, axis in ((ax_x, 0), (ax_z, 2)):
        name = "xyz"[axis]
        ax.plot(
            t,
            signals["com_reference_W"][:, axis],
            color="black",
            ls="--",
            label=f"reference x_d,{name}",
        )
        ax.plot(t, signals["com_W"][:, axis], color="tab:blue", label=f"CoM {name}")
        ax.set_ylabel(f"CoM {name} [m]")
        ax.legend(fontsize=8)
    for group, fz in group_normal_forces(signals).items():
        ax_f.plot(t, fz, label=group)
    ax_f.set_ylabel("normal force [N]")
    ax_f.set_xlabel("time [s]")
    ax_f.legend(fontsize=8)
    for ax in (ax_x, ax_z, ax_f):
        _mark_states(ax, entry_times_s, label=ax is ax_x)
        ax.grid(alpha=0.3)
    ax_x.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def standup_metrics(
    signals: dict[str, np.ndarray],
    entry_times_s,
    *,
    standing_height_m: float | None = None,
    height_tolerance_m: float = 0.01,
    unloaded_N: float = 5.0,
    hold_s: float = 0.2,
) -> dict:
    """Stand-up time, CoM tracking and whether the robot is standing at the end.

    The stand-up is measured from its outcome, not from a guard's instant. Standing at a
    sample: the CoM within height_tolerance_m of the standing height, and every pad group
    but the soles (thighs, buttocks) carrying less than unloaded_N in all. The standing
    height is standing_height_m, the erect height (simulate.py: the CoM height of the
    state-4 posture, scene.erect_com_height_m); without it, the run's own: the CoM
    reference's height at the end of the run, once its last segment (state 4) has run
    through (None otherwise: the run never set it). Where the controller leans the CoM
    against a pull (signals com_lean_W, a horizontal shift d), the standing height is
    that of the posture tilted about the feet, sqrt(height^2 - |d|^2).
    standup_time_s runs from entering state 2 to the first standing sample from which
    the robot stays standing for hold_s (None if never); standing_at_end: standing at
    the last sample. 5 N is the unloading level of issue 12's chatter count: 1.5 % of
    the robot's weight, above the 1-3 N a pad still feels while it lifts off a
    compliant seat, far below the 50-170 N the thighs carry seated.
    """
    t = signals["time_s"]
    error = np.linalg.norm(signals["com_W"] - signals["com_reference_W"], axis=1)
    metrics: dict = {
        "com_tracking_rms_m": float(np.sqrt(np.mean(error**2))) if len(t) else None,
        "standing_at_end": False,
        "standing_com_height_m": None,
        "standup_time_s": None,
    }
    if not len(t):
        return metrics
    if standing_height_m is None:
        done = signals["psi"] - signals["segment_psi_entry"] >= signals["segment_psi_length"]
        if not (signals["state"][-1] == 4 and done[-1]):
            return metrics
        height = float(signals["com_reference_W"][-1, 2])
    else:
        height = float(standing_height_m)
    metrics["standing_com_height_m"] = height
    seat = [f for g, f in group_normal_forces(signals).items() if g != "soles"]
    unloaded = np.all(np.array(seat) < unloaded_N, axis=0) if seat else np.ones(len(t), bool)
    if "com_lean_W" in signals:
        # Leaning against a pull tilts the standing robot about its feet: the erect
        # height is then that of the tilted posture (the controller's own target).
        lean = signals["com_lean_W"]
        height = np.sqrt(np.maximum(height**2 - lean[:, 0] ** 2 - lean[:, 1] ** 2, 0.0))
    standing = (np.abs(signals["com_W"][:, 2] - height) <= height_tolerance_m) & unloaded
    metrics["standing_at_end"] = bool(standing[-1])
    # Standing from sample i through t[i] + hold_s: no non-standing sample up to the
    # last sample within the hold, and the run lasts that long.
    not_standing = np.r_[0, np.cumsum(~standing)]
    last = np.searchsorted(t, t + hold_s - 1e-9, side="right") - 1
    held = (not_standing[last + 1] - not_standing[:-1] == 0) & (t[-1] >= t + hold_s - 1e-9)
    t2 = entry_times_s[1]
    if t2 is not None and np.isfinite(t2):
        held &= t >= t2
        if held.any():
            metrics["standup_time_s"] = float(t[np.argmax(held)] - t2)
    return metrics
