"""The thigh pads' normal stiffness (control/pad_dynamics.py (1)) against Drake's own
hydroelastic contact surfaces: the pad box of models/icub_contact.yaml pressed into the
rigid seat, flat and tilted, its force's derivative by finite differences."""

import numpy as np
import pytest
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    HydroelasticContactRepresentation,
    ProximityProperties,
)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction
from pydrake.multibody.tree import SpatialInertia
from pydrake.systems.framework import DiagramBuilder

from drake_standup.control.pad_dynamics import PadCompliance, pad_rows
from drake_standup.robot.icub import load_contact_model


def _thigh_pad():
    model = load_contact_model()
    shape = next(s for s in model.shapes if s.group == "thigh")
    return tuple(shape.size_m), model.hydroelastic_modulus_Pa


class _PadOnPlane:
    """A compliant box on a rigid plane (z = 0), its normal force by Drake's contact
    surface: the pressure integrated over the polygons."""

    def __init__(self, size_m, modulus_Pa):
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.001)
        self.size = np.array(size_m)
        self.body = plant.AddRigidBody("pad", SpatialInertia.SolidBoxWithMass(1.0, *size_m))
        pad = ProximityProperties()
        AddContactMaterial(friction=CoulombFriction(1.0, 1.0), properties=pad)
        AddCompliantHydroelasticProperties(0.03, modulus_Pa, pad)
        plant.RegisterCollisionGeometry(self.body, RigidTransform(), Box(*size_m), "pad", pad)
        seat = ProximityProperties()
        AddContactMaterial(friction=CoulombFriction(1.0, 1.0), properties=seat)
        AddRigidHydroelasticProperties(seat)
        plant.RegisterCollisionGeometry(
            plant.world_body(), RigidTransform([0, 0, -0.5]), Box(1, 1, 1), "seat", seat
        )
        plant.Finalize()
        self.plant, self.scene_graph = plant, scene_graph
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()

    def force(self, sink_m: float, pitch_rad: float = 0.0, roll_rad: float = 0.0) -> float:
        R = RotationMatrix(RollPitchYaw(roll_rad, pitch_rad, 0.0))
        half = self.size / 2.0
        corners = np.array(
            [[sx * half[0], sy * half[1], -half[2]] for sx in (-1, 1) for sy in (-1, 1)]
        )
        lowest = (R.matrix() @ corners.T)[2].min()
        plant_context = self.plant.GetMyContextFromRoot(self.context)
        self.plant.SetFreeBodyPose(
            plant_context, self.body, RigidTransform(R, [0, 0, -lowest - sink_m])
        )
        query = self.scene_graph.get_query_output_port().Eval(
            self.scene_graph.GetMyContextFromRoot(self.context)
        )
        total = 0.0
        for surface in query.ComputeContactSurfaces(HydroelasticContactRepresentation.kPolygon):
            mesh, pressure = surface.poly_mesh_W(), surface.poly_e_MN()
            for f in range(mesh.num_faces()):
                normal_z = abs(mesh.face_normal(f)[2])
                total += (
                    pressure.EvaluateCartesian(f, mesh.element_centroid(f))
                    * mesh.area(f)
                    * normal_z
                )
        return total


@pytest.fixture(scope="module")
def pad():
    size, modulus = _thigh_pad()
    return _PadOnPlane(size, modulus), PadCompliance.of_box(size, modulus)


@pytest.mark.parametrize(
    "sink_m, pitch_rad, roll_rad",
    [
        (2e-5, 0.0, 0.0),
        (1e-4, 0.0, 0.0),
        (2e-5, 2e-3, 0.0),
        (6e-5, 2e-3, 0.0),
        (4e-5, 1e-2, 0.0),
        (4e-5, 0.0, 5e-3),
        (5e-4, 2e-3, 0.0),  # the wedge spans the pad: flat stiffness again
    ],
)
def test_stiffness_is_drakes(pad, sink_m, pitch_rad, roll_rad):
    drake, compliance = pad
    step = 0.02 * sink_m
    slope = (
        drake.force(sink_m + step, pitch_rad, roll_rad)
        - drake.force(sink_m - step, pitch_rad, roll_rad)
    ) / (2 * step)
    force = drake.force(sink_m, pitch_rad, roll_rad)
    tilt = float(np.hypot(pitch_rad, roll_rad))
    k = compliance.stiffness_N_per_m(force, tilt, rolled=roll_rad > pitch_rad)
    assert force > 0.0
    assert k == pytest.approx(slope, rel=0.03)


def test_flat_stiffness_is_the_foundation_times_the_area():
    size, modulus = _thigh_pad()
    compliance = PadCompliance.of_box(size, modulus)
    # E / (h / 2) L W: 3 MPa / 0.02 m * 0.14 m * 0.09 m
    assert compliance.stiffness_N_per_m(30.0, 0.0) == pytest.approx(
        modulus / (min(size) / 2) * size[0] * size[1]
    )
    cushioned = PadCompliance.of_box(
        size, modulus, seat_modulus_Pa=modulus, seat_thickness_m=min(size)
    )
    assert cushioned.stiffness_N_per_m(30.0, 0.0) == pytest.approx(
        compliance.stiffness_N_per_m(30.0, 0.0) / 2
    )


def test_row_is_the_pads_mean_force_over_the_period():
    """(2): for a flat pad whose normal accelerates at a_n, the force the row plans is the
    mean over T of F - k a_n t^2 / 2, integrated numerically."""
    size, modulus = _thigh_pad()
    compliance = PadCompliance.of_box(size, modulus)
    rng = np.random.default_rng(3)
    nv, period = 8, 0.004
    for _ in range(20):
        J_n, vdot = rng.normal(size=nv), rng.normal(size=nv)
        jdotv, force = rng.normal() * 0.1, rng.uniform(5.0, 80.0)
        f_coefficient, vdot_coefficients, right = pad_rows(
            J_n, jdotv, force, np.eye(3), compliance, period
        )
        planned = (right - vdot_coefficients @ vdot) / f_coefficient
        k = compliance.stiffness_N_per_m(force, 0.0)
        a_n = J_n @ vdot + jdotv
        t = np.linspace(0.0, period, 20001)
        mean = np.trapezoid(force - k * a_n * t**2 / 2, t) / period
        assert planned == pytest.approx(mean, rel=1e-6, abs=1e-6)
    # Off the seat (no force) the row plans none and leaves the thigh free.
    f_coefficient, vdot_coefficients, right = pad_rows(
        J_n, jdotv, 0.0, np.eye(3), compliance, period
    )
    assert right == 0.0 and not vdot_coefficients.any()
