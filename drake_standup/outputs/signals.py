"""signals.npz: every logged time series of a run on one time grid, by name.

make_signals reads the diagram's loggers (diagram.py: one per named output) and names
each array (docs/outputs.md, "signals.npz"); the controller's diagnostics are read by
their names (control/controller.py: DIAGNOSTICS). write_signals / load_signals keep the
file's format.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drake_standup.config import RESPONSES
from drake_standup.control.contacts import CONTACTS
from drake_standup.control.controller import DIAGNOSTICS
from drake_standup.helper.body import state_order
from drake_standup.helper.work import HELPER_SPENT
from drake_standup.ports.payloads import COM_REFERENCE, SEGMENT
from drake_standup.robot.limbs import joint_group, shoulder_tendon_margin_rad

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


def group_normal_forces(signals: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Group name -> summed normal force of its pads over time, (N,) each, in
    the order the groups first appear in pad_groups."""
    return _by_group(signals, signals["pad_normal_force_N"])


def group_mean_normal_forces(signals: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Group name -> summed normal force of its pads averaged over the interval that ends
    at each sample (the plant's impulse over it, pad_impulses_Ns, divided by its length;
    the first sample's own force), (N,) each. Unlike a sample, the mean does not depend on
    whether a one-step slap fell on a logged instant, nor on the plant's step
    (docs/decisions/017-sole-force-measured.md). signals.npz before issue 60 has no
    impulses: their samples."""
    if "pad_impulses_Ns" not in signals:
        return group_normal_forces(signals)
    t = signals["time_s"]
    mean = np.array(signals["pad_normal_force_N"], dtype=float, copy=True)
    if len(t) > 1:
        mean[1:] = np.diff(signals["pad_impulses_Ns"][:, :, 2], axis=0) / np.diff(t)[:, None]
    return _by_group(signals, mean)


def _by_group(signals: dict[str, np.ndarray], normal: np.ndarray) -> dict[str, np.ndarray]:
    """Each pad group's columns of normal (samples x pads) summed, in pad_groups' order."""
    groups = [str(g) for g in signals["pad_groups"]]
    return {
        group: normal[:, [i for i, g in enumerate(groups) if g == group]].sum(axis=1)
        for group in dict.fromkeys(groups)
    }


def make_signals(built, root_context) -> dict[str, np.ndarray]:
    """Every logger's series (diagram.StandupDiagram.logs) as named arrays on one time grid
    (rows = samples): what signals.npz holds, and what the metrics and figures are
    computed from."""
    logs = _read_logs(built, root_context)
    signals = _station_signals(built.station, logs)
    if "controller_diagnostics" not in logs:  # the seat-hold benchmark: no controller
        return signals
    signals |= _controller_signals(logs, getattr(built, "responses", RESPONSES))
    return signals


def _read_logs(built, root_context) -> dict[str, np.ndarray]:
    """Each logger's data (rows = samples) by name, and time_s, their common time grid."""
    logs = {}
    for name, logger in built.logs.items():
        log = logger.FindLog(root_context)
        logs[name] = log.data().T.copy()
        times = log.sample_times()
        t = logs.setdefault("time_s", times.copy())
        if not np.array_equal(times, t):
            raise RuntimeError(f"logger {name} is not on the common time grid")
    return logs


def _station_signals(station, logs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The station's signals (every run has them), and the human's and pushes' logged."""
    t = logs["time_s"]
    nq = station.plant.num_positions(station.robot.model_instance)
    joints = station.joints
    state = logs["robot_state"]
    pad_forces = logs["pad_forces_W"].reshape(len(t), len(station.pad_groups), 3)
    signals = {
        "time_s": t,
        "com_W": logs["com_W"],
        "hand_wrenches_W": logs["hand_wrenches_W"],
        "pad_names": np.array(list(station.pad_groups), dtype=str),
        "pad_groups": np.array(list(station.pad_groups.values()), dtype=str),
        "pad_forces_W": pad_forces,
        "pad_normal_force_N": pad_forces[:, :, 2].copy(),
        "pad_impulses_Ns": logs["pad_impulses_Ns"].reshape(len(t), len(station.pad_groups), 3),
        "base_quaternion_wxyz": state[:, 0:4],
        "base_position_W": state[:, 4:7],
        "joint_names": np.array(joints.names, dtype=str),
        "joint_positions_rad": state[:, joints.q_index],
        "joint_velocities_rad_per_s": state[:, nq + joints.v_index],
        "joint_torques_Nm": logs["net_actuation"],
        "joint_groups": np.array([joint_group(name) for name in joints.names], dtype=str),
    }
    signals["shoulder_tendon_margin_rad"] = shoulder_tendon_margin_rad(
        signals["joint_positions_rad"], joints.names
    )
    if "push_force_W" in logs:
        signals["push_force_W"] = logs["push_force_W"]
    if "standing_pull_usage" in logs:  # sensing.standing_pull_usage of the measured pull
        signals["standing_pull_usage"] = logs["standing_pull_usage"][:, 0]
    if "braced_pull_usage" in logs:  # the same, the standing robot's arms braced
        signals["braced_pull_usage"] = logs["braced_pull_usage"][:, 0]
    if "pull_cop_shift_m" in logs:  # sensing.pull_cop_shift_m: the pull at the posture now
        signals["pull_cop_shift_m"] = logs["pull_cop_shift_m"][:, 0]
    if "hand_velocities_W" in logs:  # [v_left, v_right] where the hands are pulled
        signals["hand_velocities_W"] = logs["hand_velocities_W"]
    if "helper_spent" in logs:  # helper.work.HelperWork's running totals, on the plant's steps
        for k, name in enumerate(HELPER_SPENT):
            signals[name] = logs["helper_spent"][:, k]
    if "helper_torques_Nm" in logs:  # the helper's body (human.mode: body)
        signals |= _helper_body_signals(station, logs)
    if "estimated_robot_state" in logs:  # robot.hardware: icub
        signals |= _estimation_signals(station, logs)
    return signals


def _estimation_signals(station, logs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """What the robot estimated of itself (drake_standup/senses), beside the truth it
    is judged on: the base, the joints, the CoM, the hands' wrenches, the pads' forces."""
    nq = station.plant.num_positions(station.robot.model_instance)
    joints = station.joints
    state, estimate = logs["robot_state"], logs["estimated_robot_state"]
    n = len(logs["time_s"])
    return {
        "base_velocity_W": state[:, nq : nq + 6],  # [w; v] of the base, its origin's
        "estimated_base_quaternion_wxyz": estimate[:, 0:4],
        "estimated_base_position_W": estimate[:, 4:7],
        "estimated_base_velocity_W": estimate[:, nq : nq + 6],
        "estimated_joint_positions_rad": estimate[:, joints.q_index],
        "estimated_joint_velocities_rad_per_s": estimate[:, nq + joints.v_index],
        "com_velocity_W": logs["com_velocity_W"],
        "estimated_com_W": logs["estimated_com_W"],
        "estimated_com_velocity_W": logs["estimated_com_velocity_W"],
        "estimated_hand_wrenches_W": logs["estimated_hand_wrenches_W"],
        "estimated_pad_forces_W": logs["estimated_pad_forces_W"].reshape(
            n, len(station.pad_groups), 3
        ),
        "imu_attitude_wxyz": logs["imu_attitude_W"],
        # The advancement's law on the estimates, and on the truth at the same instant.
        "psi_dot_law": logs["psi_dot_law"][:, 0],
        "psi_dot_law_from_truth": logs["psi_dot_law_from_truth"][:, 0],
    }


def _helper_body_signals(station, logs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The person's joints (helper/body.py), each in their joint_names' order: angles,
    rates and the torques their muscles applied; their grips' wrenches and their intent."""
    helper = station.scene.helper
    order = state_order(station.plant, helper)
    n = len(order)
    state = logs["helper_state"]
    return {
        "helper_joint_names": np.array(helper.person.joint_names, dtype=str),
        "helper_effort_limits_Nm": helper.effort_limits_Nm,
        "helper_joint_positions_rad": state[:, order],
        "helper_joint_velocities_rad_per_s": state[:, n + order],
        "helper_joint_torques_Nm": logs["helper_torques_Nm"],
        "helper_grip_wrenches_W": logs["helper_grip_wrenches_W"],
        "helper_intent_wrenches_W": logs["helper_intent_wrenches_W"],
    }


def _controller_signals(
    logs: dict[str, np.ndarray], responses: tuple[str, ...] = RESPONSES
) -> dict[str, np.ndarray]:
    """The stand-up controller's signals: the response, the reference, psi, the state,
    the QP's diagnostics, what a pull held back."""
    signals = {}
    if "response" in logs:  # the robot's response to the pull, as an index of responses
        signals["response"] = np.rint(logs["response"][:, 0]).astype(np.int8)
        signals["responses"] = np.array(responses, dtype=str)
    if "compliance_W" in logs:  # the compliant response's offset of the CoM reference
        signals["compliance_offset_W"] = logs["compliance_W"][:, :3]
    reference = COM_REFERENCE.unpack(logs["com_reference"])
    segment = SEGMENT.unpack(logs["segment"])
    diagnostics = DIAGNOSTICS.unpack(logs["controller_diagnostics"])
    held = logs["held_back"]
    signals |= {
        "com_reference_W": reference["x_d"],
        "com_reference_velocity_W": reference["xd_dot"],
        "com_reference_acceleration_W": reference["xd_ddot"],
        "psi": logs["psi"][:, 0],
        "psi_dot": logs["psi_dot"][:, 0],
        "alpha": logs["alpha"][:, 0],
        "state": np.rint(logs["standup_state"][:, 0]).astype(np.int8),
        "segment_psi_entry": segment["psi_entry"][:, 0],
        "segment_psi_length": segment["psi_length"][:, 0],
        "qp_ok": diagnostics["qp_ok"][:, 0] > 0.5,
        "qp_failures": diagnostics["qp_failures"][:, 0].astype(np.int64),
        "joint_limit_slack": diagnostics["joint_limit_slack"][:, 0],
        "qp_relaxed": diagnostics["qp_relaxed"][:, 0].astype(np.int64),
        "qp_fallback": diagnostics["qp_fallback"][:, 0].astype(np.int64),
        "com_lean_W": logs["lean_W"],
        # The controller's model mass over the nominal, as it weighed the robot seated.
        "model_mass_scale": logs["mass_estimate"][:, 0],
        # What the QP asked of each of its contacts (NaN where it failed): against
        # pad_normal_force_N it shows where the controller's contact model is wrong.
        "commanded_contacts": np.array(CONTACTS, dtype=str),
        "commanded_normal_force_N": diagnostics["commanded_normal_force_N"],
        "hindered": held[:, 0] > 0.5,
        "held_back_s": held[:, 1],
        # A pull beyond what the standing robot's feet can hold, and how long it held
        # the stand-up back (standup/transitions.py).
        "pull_beyond_feet": held[:, 2] > 0.5,
        "held_back_beyond_feet_s": held[:, 3],
    }
    if "arms_braced" in logs:  # the arms braced against a pull beyond the reaching feet
        signals["arms_braced"] = logs["arms_braced"][:, 0] > 0.5
    return signals
