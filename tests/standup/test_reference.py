"""CoM reference: chain-rule derivatives against finite differences, and
continuity of the path across the state machine's switches."""

from __future__ import annotations

import numpy as np
import pytest

from drake_standup.config import StandupConfig
from drake_standup.config.phases import PhaseTable, resolve_com_heights
from drake_standup.standup.com_path import CoMReferenceGenerator, min_jerk, path, reference_at
from drake_standup.standup.transitions import Measurements, initial_mode, next_mode

# psi_e, T, x0, delta, height_follows (off: the path's height)
SEGMENT = np.array([0.7, 1.5, 0.06, 0.0, 0.38, 0.1277, -0.01, 0.03, 0.0])


def test_min_jerk_profile_boundary_values():
    """s(0)=0, s(1)=1, zero slope and curvature at both ends, s(1/2)=1/2."""
    assert min_jerk(0.0) == (0.0, 0.0, 0.0)
    assert min_jerk(1.0) == (1.0, 0.0, 0.0)
    s, ds, dds = min_jerk(0.5)
    assert s == pytest.approx(0.5)
    assert ds == pytest.approx(1.875)  # 30/16: the peak slope
    assert dds == pytest.approx(0.0)
    for tau in (1e-9, 1 - 1e-9):
        s, ds, dds = min_jerk(tau)
        assert abs(ds) < 1e-7 and abs(dds) < 1e-6


def _reference(psi, psi_dot, psi_ddot, segment=SEGMENT):
    system = CoMReferenceGenerator()
    context = system.CreateDefaultContext()
    system.GetInputPort("psi").FixValue(context, [psi])
    system.GetInputPort("psi_dot").FixValue(context, [psi_dot])
    system.GetInputPort("psi_ddot").FixValue(context, [psi_ddot])
    system.GetInputPort("segment").FixValue(context, segment)
    system.GetInputPort("com_W").FixValue(context, [0.5, 0.2, 0.1])  # unread: not following
    out = system.GetOutputPort("com_reference").Eval(context)
    tangent = system.GetOutputPort("path_tangent_W").Eval(context)
    return out[:3], out[3:6], out[6:], tangent


PSI_TRAJECTORIES = {
    "constant_rate": (
        lambda t: 0.7 + 1.6 * t,
        lambda t: 1.6,
        lambda t: 0.0,
    ),
    "varying_rate": (
        lambda t: 0.7 + t + 0.15 * np.sin(3 * t) + 0.1 * t * t,
        lambda t: 1 + 0.45 * np.cos(3 * t) + 0.2 * t,
        lambda t: -1.35 * np.sin(3 * t) + 0.2,
    ),
}


@pytest.mark.parametrize("name", list(PSI_TRAJECTORIES))
def test_velocity_and_acceleration_match_finite_differences(name):
    """xd_dot and xd_ddot vs central differences of x_d(psi(t)) in time."""
    psi, psi_dot, psi_ddot = PSI_TRAJECTORIES[name]
    h = 1e-5
    for t in np.linspace(0.05, 0.85, 9):
        x_m, v_m, _, _ = _reference(psi(t - h), psi_dot(t - h), psi_ddot(t - h))
        x_0, v_0, a_0, tangent = _reference(psi(t), psi_dot(t), psi_ddot(t))
        x_p, v_p, _, _ = _reference(psi(t + h), psi_dot(t + h), psi_ddot(t + h))
        v_fd = (x_p - x_m) / (2 * h)
        a_fd = (v_p - v_m) / (2 * h)
        assert np.linalg.norm(v_0 - v_fd) <= 1e-6 * max(np.linalg.norm(v_0), 1e-3)
        assert np.linalg.norm(a_0 - a_fd) <= 1e-6 * max(np.linalg.norm(a_0), 1e-2)
        # The tangent is d_psi x_d: velocity over psi_dot.
        np.testing.assert_allclose(tangent * psi_dot(t), v_0, rtol=1e-12, atol=1e-15)


def test_reference_is_constant_outside_its_segment():
    for psi, expected in ((0.0, SEGMENT[2:5]), (5.0, SEGMENT[2:5] + SEGMENT[5:8])):
        x, v, a, tangent = _reference(psi, 1.3, 0.4)
        np.testing.assert_allclose(x, expected, atol=1e-15)
        assert not v.any() and not a.any() and not tangent.any()


def _slope(segment, psi):
    """d_psi x_d as the generator gives it: no slope in z where the height follows."""
    d_x = path(segment, psi)[1]
    if segment[8] > 0.5:
        d_x[2] = 0.0
    return d_x


def test_path_is_continuous_in_value_and_slope_across_switches():
    """Drive the state machine through states 1-4 with psi = 1.3 t and check
    x_d (the reference used: its height the CoM's where the segment follows it) and
    d_psi x_d just before and after every switch; the CoM dips from state 2 on (as the
    pelvis' pitch makes it), which the reference follows there."""
    cfg = StandupConfig(trigger="time")
    table = resolve_com_heights(PhaseTable(), lambda posture: 0.575)
    com0 = np.array([0.06, 0.0, 0.38])
    mode = initial_mode(com0)
    segments = [mode.segment()]
    dt = 1e-3
    for k in range(1, 20000):
        t = k * dt
        m = Measurements(
            t=t,
            psi=1.3 * t,
            # Well in front of the heels; seated at com0's height, then dipping 2 cm/s.
            com_W=np.array([0.3, 0.0, 0.38 - 0.02 * max(t - 3.0, 0.0)]),
            heel_x=0.1,
            foot_fz_N=(200.0, 200.0),
            hand_fx_N=(0.0, 0.0),
            thigh_x=0.0,  # and of the thigh pads
        )
        new = next_mode(mode, m, cfg, table)
        if new.state != mode.state:
            before = reference_at(mode.segment(), m.psi, m.com_W)
            after = reference_at(new.segment(), m.psi, m.com_W)
            np.testing.assert_allclose(after, before, atol=1e-12)  # value
            slope = _slope(mode.segment(), m.psi)
            np.testing.assert_allclose(_slope(new.segment(), m.psi), slope, atol=1e-12)
            if new.state == 3:  # the height followed the dipped CoM
                assert before[2] < 0.38 - 0.01
            segments.append(new.segment())
        mode = new
    assert mode.state == 4
    assert len(segments) == 4
    # The last segment ends at the standing height.
    end = path(segments[-1], 1e9)[0]
    assert end[2] == pytest.approx(table.rise.com_height_m)
    np.testing.assert_allclose(
        end[:2],
        (com0 + np.array(table.forward.com_delta_m) + np.array(table.lift_off.com_delta_m))[:2],
    )
