"""The controller's model by Pinocchio (control/pinocchio_terms.py) against Drake's own
calls on the simulated plant, on 50 random states of every robot the project supports:
mass matrix, bias and gravity, CoM and its Jacobian, centroidal momentum matrix, every
contact and hand frame's Jacobian, hold-point bias acceleration and orientation, to 1e-9
relative (two seconds for all of them)."""

import dataclasses

import numpy as np
import pytest
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import Scenario
from drake_standup.config.inputs import missing_scene_frames, robot_names
from drake_standup.control.model import HANDS, contact_specs
from drake_standup.control.pinocchio_terms import PinocchioKinematics
from drake_standup.robot.spatial import skew
from drake_standup.world.scene import add_scene, set_seated_state

RTOL = 1e-9
N_STATES = 50
DEFAULT = Scenario().robot.model
SUPPORTED = [name for name in robot_names() if not missing_scene_frames(name)]
kV = JacobianWrtVariable.kV


def _close(actual, expected, what):
    scale = max(float(np.abs(expected).max()), 1.0)
    error = float(np.abs(np.asarray(actual) - expected).max())
    assert error <= RTOL * scale, f"{what}: {error:.2e} against {scale:.2e}"


def _states(plant, x0, rng):
    """Seated joints +-0.5 rad, a random base pose, random rates, a zero-rate one."""
    nq = plant.num_positions()
    for k in range(N_STATES):
        x = x0.copy()
        x[7:nq] += rng.uniform(-0.5, 0.5, nq - 7)
        quaternion = rng.normal(size=4)
        x[:4] = quaternion / np.linalg.norm(quaternion)
        x[4:7] = rng.uniform(-1.0, 1.0, 3)
        x[nq:] = 0.0 if k == 0 else rng.normal(size=plant.num_velocities())
        yield x


def _check_robot(model: str, reflected_inertia: str) -> None:
    base = Scenario()
    scenario = dataclasses.replace(
        base,
        robot=dataclasses.replace(base.robot, model=model, reflected_inertia=reflected_inertia),
    )
    scene = add_scene(DiagramBuilder(), scenario, visuals=False)
    plant, robot = scene.plant, scene.robot
    instance = robot.model_instance
    specs = contact_specs(plant, robot, scenario.controller, scenario.chair)
    frames = [spec.frame for spec in specs]
    kinematics = PinocchioKinematics(
        plant,
        robot,
        held_frames=[s.frame for s in specs if s.constrained],
        other_frames=[s.frame for s in specs if not s.constrained] + list(HANDS),
        hold_points_m={s.frame: s.hold_point_m for s in specs},
    )
    held = [s for s in specs if s.constrained]
    context = plant.CreateDefaultContext()
    set_seated_state(scene, context)
    x0 = plant.GetPositionsAndVelocities(context)
    world = plant.world_frame()
    nq, nv = plant.num_positions(), plant.num_velocities()
    damping = np.zeros(nv)
    for index in plant.GetJointIndices(instance):
        joint = plant.get_joint(index)
        start = joint.velocity_start()
        damping[start : start + joint.num_velocities()] = joint.default_damping_vector()
    bodies = [plant.get_body(i) for i in plant.GetBodyIndices(instance)]
    rng = np.random.default_rng(48)
    for k, x in enumerate(_states(plant, x0, rng)):
        scale = (1.0, 0.85, 1.2)[k % 3]  # the weighing's scale (control/mass.py)
        for body in bodies:
            body.SetMass(context, scale * body.default_mass())
        plant.SetPositionsAndVelocities(context, x)
        kinematics.set_mass_scale(scale)
        terms = kinematics.calc(x, frames, list(HANDS))
        v = x[nq:]
        where = f"{model} state {k}"
        M = plant.CalcMassMatrix(context)
        tau_g = plant.CalcGravityGeneralizedForces(context)
        _close(terms.M, M, f"M, {where}")
        _close(terms.h, plant.CalcBiasTerm(context) - tau_g + damping * v, f"h, {where}")
        if not v.any():  # h at rest is the gravity force
            _close(terms.h, -tau_g, f"gravity, {where}")
        p_WCom = plant.CalcCenterOfMassPositionInWorld(context, [instance])
        _close(terms.p_WCom, p_WCom, f"CoM, {where}")
        J_com = plant.CalcJacobianCenterOfMassTranslationalVelocity(
            context, [instance], kV, world, world
        )
        _close(terms.M[3:6] / terms.mass_kg, J_com, f"CoM Jacobian, {where}")
        # The centroidal momentum matrix the controller uses: M's base rows shifted to the
        # CoM (control/terms.py), against Drake's momentum about the CoM for every v.
        A = terms.M[:6].copy()
        A[:3] -= skew(terms.p_BoCom) @ A[3:]
        momentum = plant.CalcSpatialMomentumInWorldAboutPoint(context, [instance], p_WCom)
        _close(A @ v, momentum.get_coeffs(), f"centroidal momentum, {where}")
        _close(terms.L_WCom, momentum.get_coeffs(), f"L_WCom, {where}")
        if k < 3:  # the whole matrix, a column per unit velocity
            columns = []
            for i in range(nv):
                plant.SetVelocities(context, np.eye(nv)[i])
                columns.append(
                    plant.CalcSpatialMomentumInWorldAboutPoint(
                        context, [instance], p_WCom
                    ).get_coeffs()
                )
            _close(A, np.array(columns).T, f"centroidal momentum matrix, {where}")
            plant.SetVelocities(context, v)
        for i, name in enumerate(frames):
            frame = robot.frame(plant, name)
            J = plant.CalcJacobianSpatialVelocity(context, kV, frame, np.zeros(3), world, frame)
            _close(terms.J_F[i], J, f"J_F {name}, {where}")
        for j, spec in enumerate(held):
            frame = robot.frame(plant, spec.frame)
            p_FP = np.array(spec.hold_point_m or (0.0, 0.0, 0.0))
            J = plant.CalcJacobianSpatialVelocity(context, kV, frame, p_FP, world, frame)
            _close(terms.J_P[j], J, f"J_P {spec.frame}, {where}")
            bias = plant.CalcBiasSpatialAcceleration(context, kV, frame, p_FP, world, frame)
            _close(terms.Jdotv_P[j], bias.get_coeffs(), f"Jdot v {spec.frame}, {where}")
        for i, name in enumerate(HANDS):
            frame = robot.frame(plant, name)
            J = plant.CalcJacobianSpatialVelocity(context, kV, frame, np.zeros(3), world, world)
            _close(terms.J_W[i], J, f"J_W {name}, {where}")
        rotations = terms.frame_rotations()
        for i, name in enumerate(frames):
            R = robot.frame(plant, name).CalcPoseInWorld(context).rotation().matrix()
            _close(rotations[i], R, f"R_WF {name}, {where}")


def test_supported_robots_are_found():
    """The list the slow test runs over holds the default robot and real robots."""
    assert DEFAULT in SUPPORTED and len(SUPPORTED) >= 10


def test_pinocchio_model_equals_drakes_on_the_default_robot():
    _check_robot(DEFAULT, "none")


def test_pinocchio_model_keeps_the_reflected_motor_inertia():
    """With every joint's motor inertia (on M's diagonal, not scaled with the masses)."""
    _check_robot(DEFAULT, "all")


@pytest.mark.parametrize("model", [name for name in SUPPORTED if name != DEFAULT])
def test_pinocchio_model_equals_drakes_on_every_supported_robot(model):
    _check_robot(model, Scenario().robot.reflected_inertia)
