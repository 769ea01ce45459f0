"""The QP consumes task objects generically (drake_standup/control/qp.py, tasks.py).

A task written here, outside the package, is handed to WholeBodyQp like the controller's
own: where it is active the solution meets it, where it is not the solution is the one
without it, bit for bit.
"""

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import Scenario
from drake_standup.control.qp import ContactCommands, ContactMap, QpLayout, Task, WholeBodyQp
from drake_standup.control.references import TaskReferences, static_lean
from drake_standup.control.terms import RobotKinematics, RobotTerms
from drake_standup.controller import ControllerConfig, WholeBodyController
from drake_standup.scene import add_scene, set_seated_state

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
        next_posture=None,
    )


@pytest.fixture(scope="module")
def seated():
    """The default scenario's plant, its seated state's terms for every contact, and
    what WholeBodyQp needs besides its tasks."""
    scenario = Scenario()
    scene = add_scene(DiagramBuilder(), scenario, pd_gains=None, visuals=False)
    plant, robot = scene.plant, scene.robot
    context = plant.CreateDefaultContext()
    set_seated_state(scene, context, scenario)
    x = plant.GetPositionsAndVelocities(context, robot.model_instance)
    specs = WholeBodyController(plant, robot, ControllerConfig()).contact_specs
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


def _qp(plant, specs, task_states):
    """A QP over all contacts with the config's regularisation and, unless task_states is
    None, a _JointAcceleration task active in those states."""
    config = ControllerConfig()
    contact_map = ContactMap(specs, plant.num_velocities())
    tasks = [] if task_states is None else [_JointAcceleration(contact_map.layout, *task_states)]
    return WholeBodyQp(
        contact_map,
        plant.MakeActuationMatrix(),
        torque_limit_Nm=config.torque_limit_Nm,
        torque_weight=config.torque_weight,
        wrench_weight=config.wrench_weight,
        acceleration_weight=config.acceleration_weight,
        tasks=tasks,
    )


def test_a_new_task_acts_only_in_its_active_states(seated):
    """vdot[torso_pitch] = 2 rad/s^2, a task active in state 2 only: met (to 1e-3 of the
    target: the regularisation is 1e-10 of its weight) in state 2; in states 1 and 3 the
    solution is the one of the QP without the task."""
    plant, specs, terms, k = seated
    nc = len(specs)
    commands = ContactCommands(np.full(nc, 10.0), np.full(nc, 1000.0), {})
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
