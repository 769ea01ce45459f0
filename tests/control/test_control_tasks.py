"""The QP consumes task objects generically (drake_standup/control/qp.py, control/tasks/).

A task written here, outside the package, is handed to WholeBodyQp like the controller's
own: where it is active the solution meets it, where it is not the solution is the one
without it, bit for bit.
"""

import functools

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import EFFORT_LIMIT_NM, ControllerConfig, Scenario
from drake_standup.control.model import contact_specs
from drake_standup.control.qp import ContactMap, QpContactBounds, QpLayout, Task, WholeBodyQp
from drake_standup.control.targets import TaskReferences
from drake_standup.control.tasks import SoleMomentRateTask
from drake_standup.control.terms import RobotKinematics, RobotTerms
from drake_standup.robot.balance import static_lean
from drake_standup.world.scene import add_scene, set_seated_state

TARGET_RAD_PER_S2 = 2.0


class _JointAcceleration(Task):
    """vdot[k] = TARGET_RAD_PER_S2 in the given standup states."""

    name = "joint_acceleration"
    constant_A = True

    def __init__(self, layout: QpLayout, k: int, states: tuple[int, ...]):
        self.weight = 1.0e4
        self.columns = slice(layout.vdot.start + k, layout.vdot.start + k + 1)
        self.A = np.ones((1, 1))
        self.b = np.zeros(1)
        self.active_states = frozenset(states)

    def update(self, terms: RobotTerms, references: TaskReferences) -> None:
        self.b = np.full(1, TARGET_RAD_PER_S2)


def _references(standup_state: int) -> TaskReferences:
    """What a task that reads no references needs: the standup state (no pull)."""
    return TaskReferences(
        standup_state=standup_state,
        state=None,
        Ldot_star=None,
        tau_hand=None,
        q_reference=None,
        R_WB_target=None,
        helpful_force_W=np.zeros(3),
        lean_W=np.zeros(3),
        vertical_weight_scale=1.0,
        stance=0.0,
        next_height_integral=0.0,
        next_momentum_integral=None,
        next_posture=None,
    )


@pytest.fixture(scope="module")
def seated():
    return seated_state()


@functools.cache
def seated_state():
    """The default scenario's plant, its seated state's terms for every contact, and
    what WholeBodyQp needs besides its tasks."""
    scenario = Scenario()
    scene = add_scene(DiagramBuilder(), scenario, pd_gains=None, visuals=False)
    plant, robot = scene.plant, scene.robot
    context = plant.CreateDefaultContext()
    set_seated_state(scene, context)
    x = plant.GetPositionsAndVelocities(context, robot.model_instance)
    specs = contact_specs(plant, robot, ControllerConfig())
    kinematics = RobotKinematics(
        plant,
        robot,
        held_frames=[spec.frame for spec in specs if spec.constrained],
        other_frames=[spec.frame for spec in specs if not spec.constrained],
        hold_points_m={spec.frame: spec.hold_point_m for spec in specs},
    )
    terms = kinematics.calc(x, [spec.frame for spec in specs])
    k = plant.GetJointByName("torso_pitch", robot.model_instance).velocity_start()
    return plant, specs, terms, k


class _FixedBounds:
    """Acceleration bounds that do not depend on the state."""

    def __init__(self, v_indices, vdot_min, vdot_max):
        self.v_indices = np.asarray(v_indices)
        self._bounds = np.asarray(vdot_min, float), np.asarray(vdot_max, float)

    def calc(self, terms):
        return self._bounds


def _qp(plant, specs, task_states, more_tasks=(), **bounds):
    """A QP over all contacts with the config's regularisation and, unless task_states is
    None, a _JointAcceleration task active in those states; then more_tasks."""
    config = ControllerConfig()
    contact_map = ContactMap(specs, plant.num_velocities())
    tasks = [] if task_states is None else [_JointAcceleration(contact_map.layout, *task_states)]
    tasks += list(more_tasks)
    return WholeBodyQp(
        contact_map,
        plant.MakeActuationMatrix(),
        torque_limit_Nm=EFFORT_LIMIT_NM,
        torque_weight=config.torque_weight,
        wrench_weight=config.wrench_weight,
        acceleration_weight=config.acceleration_weight,
        tasks=tasks,
        modes=(1, 2, 3, 4),
        **bounds,
    )


def test_a_new_task_acts_only_in_its_active_states(seated):
    """vdot[torso_pitch] = 2 rad/s^2, a task active in state 2 only: met (to 1e-3 of the
    target: the regularisation is 1e-10 of its weight) in state 2; in states 1 and 3 the
    solution is the one of the QP without the task."""
    plant, specs, terms, k = seated
    nc = len(specs)
    commands = QpContactBounds(np.full(nc, 10.0), np.full(nc, 1000.0), {})
    with_task = _qp(plant, specs, (k, (2,)))
    without = _qp(plant, specs, None)
    for standup_state in (1, 2, 3):
        solution = with_task.solve(terms, _references(standup_state), commands)
        reference = without.solve(terms, _references(standup_state), commands)
        assert solution.ok and reference.ok
        if standup_state == 2:
            assert abs(solution.vdot[k] - TARGET_RAD_PER_S2) < 1e-3 * TARGET_RAD_PER_S2
            assert abs(reference.vdot[k] - TARGET_RAD_PER_S2) > 0.1
        else:
            np.testing.assert_array_equal(solution.vdot, reference.vdot)
            np.testing.assert_array_equal(solution.tau, reference.tau)


@pytest.mark.parametrize("seed", range(5))
def test_static_lean_keeps_the_centre_of_pressure_where_it_was(seed):
    """Static balance, computed independently about the world origin: with the CoM moved
    by static_lean's shift and the pull on, the ground reaction's CoP (on z = 0) lands
    where the CoM stood before the shift, i.e. where the CoP is without the pull."""
    rng = np.random.default_rng(seed)
    weight_N = 324.0
    com = np.array([0.2, 0.0, 0.57]) + rng.uniform(-0.02, 0.02, 3)  # where it leans to
    hand = com + np.array([0.2, 0.0, 0.3]) + rng.uniform(-0.1, 0.1, 3)
    f = rng.uniform(-30.0, 30.0, 3)
    tau_com = np.cross(hand - com, f)
    lean = static_lean(np.r_[tau_com, f], com[2], weight_N, max_lean_m=1.0)
    assert lean[2] == 0.0
    gravity = np.array([0.0, 0.0, -weight_N])
    moment_O = np.cross(com, gravity) + np.cross(hand, f)
    reaction_z = -(gravity + f)[2]
    cop = np.array([moment_O[1] / reaction_z, -moment_O[0] / reaction_z])
    np.testing.assert_allclose(cop, (com - lean)[:2], atol=1e-12)


def test_static_lean_is_bounded_and_zero_without_a_pull():
    assert not static_lean(np.zeros(6), 0.57, 324.0, 0.08).any()
    big = static_lean(np.r_[0.0, 0.0, 0.0, 300.0, -300.0, 0.0], 0.57, 324.0, 0.08)
    np.testing.assert_allclose(big, [-0.08, 0.08, 0.0])
    # A pull that lifts the robot off its feet: no static answer, no lean.
    assert not static_lean(np.r_[0.0, 5.0, 0.0, 10.0, 0.0, 400.0], 0.57, 324.0, 0.08).any()


def test_soft_bounds_that_hold_at_the_optimum_change_nothing(seated):
    plant, specs, terms, k = seated
    nc = len(specs)
    commands = QpContactBounds(np.full(nc, 10.0), np.full(nc, 1000.0), {})
    free = _qp(plant, specs, (k, (2,))).solve(terms, _references(2), commands)
    loose = _FixedBounds([k], [-100.0], [100.0])
    bounded = _qp(plant, specs, (k, (2,)), soft_bounds=loose, soft_bound_weight=1e3).solve(
        terms, _references(2), commands
    )
    assert free.ok and bounded.ok
    # The same optimum, to the active-set solver's round-off on a larger program.
    np.testing.assert_allclose(bounded.vdot, free.vdot, atol=1e-6)
    assert bounded.slack.shape == (1,) and abs(bounded.slack[0]) < 1e-9


@pytest.mark.parametrize("weight", [1e3, 1e4, 1e5])
def test_soft_bound_against_a_task_meets_it_where_the_weights_say(weight):
    """The task asks vdot_k = 2 (weight w_t), the bound vdot_k <= -1 with slack weight w_s:
    min w_t (v - 2)^2 + w_s s^2, s = v + 1, gives v = (2 w_t - w_s) / (w_t + w_s), the
    analytic optimum (to the regularisation's 1e-6 relative)."""
    plant, specs, terms, k = seated_state()
    nc = len(specs)
    commands = QpContactBounds(np.full(nc, 10.0), np.full(nc, 1000.0), {})
    bounds = _FixedBounds([k], [-100.0], [-1.0])
    solution = _qp(plant, specs, (k, (2,)), soft_bounds=bounds, soft_bound_weight=weight).solve(
        terms, _references(2), commands
    )
    w_t = 1.0e4  # _JointAcceleration's weight
    v = (TARGET_RAD_PER_S2 * w_t - weight) / (w_t + weight)
    assert solution.ok
    assert solution.vdot[k] == pytest.approx(v, rel=1e-3, abs=1e-3)
    assert solution.slack[0] == pytest.approx(v + 1.0, rel=1e-3, abs=1e-3)


def test_soft_bounds_keep_an_impossible_bound_feasible(seated):
    """Seated, the held seat and soles pin the knees: vdot_knee >= 5 rad/s^2 is impossible.
    As a hard bound the program is infeasible; as a soft one it solves, the knee does not
    move and the slack takes the whole 5 rad/s^2."""
    plant, specs, terms, _ = seated
    nc = len(specs)
    knee = plant.GetJointByName("l_knee").velocity_start()
    commands = QpContactBounds(np.full(nc, 10.0), np.full(nc, 1000.0), {})
    impossible = _FixedBounds([knee], [5.0], [100.0])
    hard = _qp(plant, specs, None, acceleration_bounds=impossible)
    # As a hard bound: infeasible with the contacts held; only the relaxed fallback (the
    # held rows dropped) solves it.
    assert hard.solve(terms, _references(2), commands).relaxed
    soft = _qp(plant, specs, None, soft_bounds=impossible, soft_bound_weight=1e3)
    solution = soft.solve(terms, _references(2), commands)
    assert solution.ok and not solution.relaxed
    assert abs(solution.vdot[knee]) < 1e-6
    assert abs(solution.slack[0]) == pytest.approx(5.0, rel=1e-6)


def test_an_infeasible_program_falls_back_to_the_relaxed_one(seated):
    """Seated, a minimum normal force of 1 kN on every contact (three times the weight,
    with the dynamics exact) cannot be met: the program is infeasible; the fallback drops
    the minimum forces and the held contact rows and solves, flagged relaxed, with the
    dynamics' base rows still exact and the torques within their limits."""
    plant, specs, terms, _ = seated
    nc = len(specs)
    impossible = QpContactBounds(np.full(nc, 1000.0), np.full(nc, 2000.0), {})
    solution = _qp(plant, specs, None).solve(terms, _references(2), impossible)
    assert solution.ok and solution.relaxed
    assert np.abs(solution.tau).max() <= EFFORT_LIMIT_NM + 1e-6
    # The floating base's rows of M vdot + h = J^T F hold (no actuation there).
    contact_map = ContactMap(specs, plant.num_velocities())
    generalized = contact_map(terms).T @ solution.F_C.reshape(-1)[contact_map.unknowns]
    residual = terms.M[:6] @ solution.vdot + terms.h[:6] - generalized[:6]
    np.testing.assert_allclose(residual, 0.0, atol=1e-6)
    # A feasible program is not relaxed.
    fine = QpContactBounds(np.full(nc, 10.0), np.full(nc, 1000.0), {})
    assert not _qp(plant, specs, None).solve(terms, _references(2), fine).relaxed


def _with_rate(plant, specs, k, weight_s):
    """A QP whose _JointAcceleration task acts in state 2, with the soles' moment rate."""
    layout = ContactMap(specs, plant.num_velocities()).layout
    rate = SoleMomentRateTask(layout, specs, weight_s, period_s=0.004)
    return _qp(plant, specs, (k, (2,)), more_tasks=[rate]), rate


def test_the_sole_moment_rate_picks_the_moments_over_the_cop_box():
    """S picks each sole's moments over l, the half of the CoP box's longer side: the
    soles' box is [-0.05, 0.10] x [-0.025, 0.025] m (controller defaults), l = 0.075."""
    plant, specs, _, _ = seated_state()
    layout = ContactMap(specs, plant.num_velocities()).layout
    task = SoleMomentRateTask(layout, specs, 0.04, period_s=0.004)
    expected = np.zeros((6, 12))
    expected[0:3, 0:3] = expected[3:6, 6:9] = np.eye(3) / 0.075
    np.testing.assert_allclose(task.A, expected)
    frames = [spec.frame for spec in specs]
    assert task.columns == slice(layout.wrench(frames.index("l_sole")).start, layout.n_wrench)
    task.set_last(np.full(12, np.nan))
    assert task.weight == 0.0
    task.set_last(np.ones(12))
    assert task.weight == pytest.approx(0.04 / 0.004)
    np.testing.assert_allclose(task.b, expected @ np.ones(12))


def test_the_sole_moment_rate_pulls_the_soles_cops_toward_the_last_tick():
    """Without a last tick the task changes nothing, bit for bit; with one, the soles'
    moments move toward it as its weight grows (a proximal term: monotone in the weight,
    reaching it in the limit), while the task that changed the plan is still met."""
    plant, specs, terms, k = seated_state()
    nc = len(specs)
    commands = QpContactBounds(np.full(nc, 10.0), np.full(nc, 1000.0), {})
    frames = [spec.frame for spec in specs]
    soles = [frames.index("l_sole"), frames.index("r_sole")]
    # The last tick: state 1, where the joint task is off; this one: state 2.
    qp, rate = _with_rate(plant, specs, k, 0.04)
    rate.set_last(np.full(12, np.nan))
    last = qp.solve(terms, _references(1), commands).F_C[soles].ravel()
    free = qp.solve(terms, _references(2), commands)
    reference = _qp(plant, specs, (k, (2,))).solve(terms, _references(2), commands)
    np.testing.assert_array_equal(free.F_C, reference.F_C)
    S = rate.A

    def gap(F):
        return np.linalg.norm(S @ (F[soles].ravel() - last))

    assert gap(free.F_C) > 1.0  # the joint task moved the soles' CoPs (N)
    gaps = []
    for weight_s in (0.004, 0.04, 0.4, 40.0):
        qp, rate = _with_rate(plant, specs, k, weight_s)
        rate.set_last(last)
        solution = qp.solve(terms, _references(2), commands)
        assert solution.ok
        assert abs(solution.vdot[k] - TARGET_RAD_PER_S2) < 1e-2 * TARGET_RAD_PER_S2
        gaps.append(gap(solution.F_C))
    assert all(a > b for a, b in zip([gap(free.F_C)] + gaps, gaps))
    assert gaps[-1] < 0.01 * gap(free.F_C)
