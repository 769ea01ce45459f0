"""The run's figures: the paper's Fig. 3 (figure_advancement) and CoM tracking with the
contact forces and each limb's fastest joint (figure_tracking), from signals.npz."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drake_standup.outputs.signals import group_mean_normal_forces
from drake_standup.robot.limbs import JOINT_GROUPS, joint_group

STATE_COLORS = {2: "tab:orange", 3: "tab:green", 4: "tab:purple"}
# The sit-down's states (standup/sit_down.py), shaded over their spans.
DESCENT_STATES = {5: ("lower", "tab:brown"), 6: ("land", "tab:pink"), 7: ("settle", "tab:olive")}


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


def _mark_cycle(ax, signals: dict[str, np.ndarray], label: bool = False) -> None:
    """A cycle's later states (the sit-downs, shaded, and the stand-ups after them, as
    lines) from the state's samples; nothing where the run never sat down."""
    state, t = signals.get("state"), signals["time_s"]
    if state is None or not np.any(state > max(STATE_COLORS)):
        return
    begins = np.r_[0, np.flatnonzero(np.diff(state)) + 1]
    ends = np.r_[begins[1:], len(t) - 1]
    seen, first_down = set(), float(t[np.argmax(state > max(STATE_COLORS))])
    for i, j in zip(begins, ends, strict=True):
        k = int(state[i])
        tag = label and k not in seen
        seen.add(k)
        if k in DESCENT_STATES:
            name, color = DESCENT_STATES[k]
            ax.axvspan(t[i], t[j], color=color, alpha=0.15, lw=0, label=name if tag else None)
        elif k in STATE_COLORS and t[i] > first_down:
            ax.axvline(t[i], color=STATE_COLORS[k], ls=":", lw=1.2)


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


def _plot_limb_speeds(ax, signals: dict[str, np.ndarray]) -> None:
    """Each limb's fastest joint speed over time (a light limb above the trunk: a whip)."""
    t = signals["time_s"]
    limbs = np.array([joint_group(str(name)) for name in signals["joint_names"]])
    speeds = np.abs(signals["joint_velocities_rad_per_s"])
    for limb in JOINT_GROUPS:
        if (limbs == limb).any():
            ax.plot(t, speeds[:, limbs == limb].max(axis=1), label=limb, lw=1.0)
    ax.set_ylabel("fastest joint [rad/s]")
    ax.legend(fontsize=8, ncol=4)


def figure_tracking(signals: dict[str, np.ndarray], entry_times_s, path: Path) -> None:
    """CoM against its reference, the contact normal forces and each limb's fastest
    joint, with the state switches marked."""
    plt = _plt()
    fig, (ax_x, ax_z, ax_f, ax_v) = plt.subplots(
        4, 1, figsize=(10, 10), sharex=True, gridspec_kw={"height_ratios": [1, 1, 1, 0.8]}
    )
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
    # Each sample the mean over the log period before it: a slap shows whatever the step.
    for group, fz in group_mean_normal_forces(signals).items():
        ax_f.plot(t, fz, label=group)
    ax_f.set_ylabel("normal force [N]\n(mean per log period)")
    ax_f.legend(fontsize=8)
    _plot_limb_speeds(ax_v, signals)
    ax_v.set_xlabel("time [s]")
    for ax in (ax_x, ax_z, ax_f, ax_v):
        _mark_states(ax, entry_times_s, label=ax is ax_x)
        _mark_cycle(ax, signals, label=ax is ax_x)
        ax.grid(alpha=0.3)
    ax_x.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
